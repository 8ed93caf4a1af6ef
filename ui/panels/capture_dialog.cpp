#include "panels/capture_dialog.hpp"

#include "window/prompts.hpp"

#include "culling/core/errors.hpp"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QFileInfo>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QImage>
#include <QLabel>
#include <QLineEdit>
#include <QPixmap>
#include <QPlainTextEdit>
#include <QPushButton>
#include <QTableWidget>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>

namespace lcui {

namespace {

// The depth the culling read, as a user recognises a depth buffer: geometry
// from near (light) to far (dark) over the range the image holds, background
// black.
QImage depthPicture(const lc::DepthImage& d) {
    QImage img(int(d.width), int(d.height), QImage::Format_RGB32);
    float lo = 0, hi = 0;
    bool any = false;
    for (float v : d.depth)
        if (v != d.clearDepth && std::isfinite(v)) {
            lo = any ? std::min(lo, v) : v;
            hi = any ? std::max(hi, v) : v;
            any = true;
        }
    // Nearer is smaller with standard depth, larger with reversed-Z.
    const bool reversed = d.clearDepth < 0.5f;
    for (std::uint32_t y = 0; y < d.height; ++y) {
        auto* row = reinterpret_cast<QRgb*>(img.scanLine(int(y)));
        for (std::uint32_t x = 0; x < d.width; ++x) {
            const float v = d.at(x, y);
            int g = 0;
            if (v != d.clearDepth && std::isfinite(v)) {
                double t = hi > lo ? (v - lo) / double(hi - lo) : 0.0;
                if (!reversed) t = 1.0 - t;
                g = 60 + int(std::lround(195.0 * t));
            }
            row[x] = qRgb(g, g, g);
        }
    }
    return img;
}

QString bindingSize(const lc::CaptureBinding& b) {
    if (b.kind == "image") return QString("%1x%2 %3").arg(b.width).arg(b.height).arg(QString::fromStdString(b.format));
    if (b.kind == "buffer") return QString("%1 bytes at %2").arg(qulonglong(b.size)).arg(qulonglong(b.offset));
    return {};
}

} // namespace

CaptureDialog::CaptureDialog(const Prompts& prompts, Work work, QWidget* parent)
    : QDialog(parent), prompts_(prompts), work_(std::move(work)) {
    setObjectName("captureDialog");
    setWindowTitle(tr("Open RenderDoc capture"));
    capture_ = new QLineEdit;
    capture_->setObjectName("capturePath");
    capture_->setPlaceholderText(tr("frame.rdc, as RenderDoc saved it"));
    description_ = new QLineEdit;
    description_->setObjectName("descriptionPath");
    description_->setPlaceholderText(tr("the light struct, camera and lists (docs/RENDERDOC.md)"));
    dispatch_ = new QComboBox;
    dispatch_->setObjectName("dispatch");
    dispatch_->setToolTip(tr("The culling dispatch: the state after it is read"));
    bindings_ = new QTableWidget(0, 5);
    bindings_->setObjectName("bindings");
    bindings_->setHorizontalHeaderLabels({tr("set.binding"), tr("descriptor"), tr("range / image"), tr("resource"),
                                          tr("shader variable")});
    bindings_->horizontalHeader()->setStretchLastSection(true);
    bindings_->verticalHeader()->hide();
    bindings_->setEditTriggers(QAbstractItemView::NoEditTriggers);
    bindings_->setSelectionBehavior(QAbstractItemView::SelectRows);
    bindings_->setMinimumHeight(150);
    depth_ = new QLabel;
    depth_->setObjectName("depthPreview");
    depth_->setMinimumSize(320, 180);
    depth_->setAlignment(Qt::AlignCenter);
    depth_->setFrameShape(QFrame::StyledPanel);
    echo_ = new QPlainTextEdit;
    echo_->setObjectName("previewText");
    echo_->setReadOnly(true);
    echo_->setLineWrapMode(QPlainTextEdit::WidgetWidth);
    error_ = new QLabel;
    error_->setObjectName("captureError");
    error_->setWordWrap(true);
    error_->setTextInteractionFlags(Qt::TextSelectableByMouse);
    error_->setStyleSheet("color: #c0392b;");
    previewButton_ = new QPushButton(tr("&Preview"));
    previewButton_->setObjectName("previewButton");

    auto* browseCapture = new QPushButton(tr("Browse..."));
    browseCapture->setObjectName("browseCapture");
    auto* browseDescription = new QPushButton(tr("Browse..."));
    browseDescription->setObjectName("browseDescription");
    auto row = [](QWidget* edit, QWidget* button) {
        auto* w = new QWidget;
        auto* l = new QHBoxLayout(w);
        l->setContentsMargins(0, 0, 0, 0);
        l->addWidget(edit, 1);
        l->addWidget(button);
        return w;
    };
    auto* form = new QFormLayout;
    form->addRow(tr("Capture:"), row(capture_, browseCapture));
    form->addRow(tr("Dispatch:"), dispatch_);
    form->addRow(tr("Bindings:"), bindings_);
    form->addRow(tr("Description:"), row(description_, browseDescription));

    auto* previewRow = new QHBoxLayout;
    previewRow->addWidget(depth_);
    previewRow->addWidget(echo_, 1);

    buttons_ = new QDialogButtonBox(QDialogButtonBox::Open | QDialogButtonBox::Cancel);
    buttons_->addButton(previewButton_, QDialogButtonBox::ActionRole);
    buttons_->button(QDialogButtonBox::Open)->setEnabled(false);
    buttons_->button(QDialogButtonBox::Open)->setToolTip(
        tr("Opens the previewed frame: its lights and camera as the scene, its lists judged"));

    auto* top = new QVBoxLayout(this);
    top->addLayout(form);
    top->addWidget(new QLabel(tr("What the description reads at the dispatch (nothing is culled yet):")));
    top->addLayout(previewRow, 1);
    top->addWidget(error_);
    top->addWidget(buttons_);
    resize(900, 640);

    connect(browseCapture, &QPushButton::clicked, this, [this] {
        const QString p = prompts_.openPath(this, tr("RenderDoc capture"), tr("RenderDoc captures (*.rdc)"));
        if (!p.isEmpty()) setCapture(p);
    });
    connect(capture_, &QLineEdit::editingFinished, this, [this] {
        if (capture_->isModified() && !capture_->text().isEmpty()) setCapture(capture_->text());
        capture_->setModified(false);
    });
    connect(browseDescription, &QPushButton::clicked, this, [this] {
        const QString p = prompts_.openPath(this, tr("Capture description"), tr("Descriptions (*.json)"));
        if (!p.isEmpty()) setDescription(p);
    });
    connect(description_, &QLineEdit::editingFinished, this, [this] {
        if (description_->isModified()) setDescription(description_->text());
        description_->setModified(false);
    });
    connect(dispatch_, qOverload<int>(&QComboBox::activated), this, [this] {
        readBindings();
        if (!description_->text().isEmpty()) preview();
    });
    connect(previewButton_, &QPushButton::clicked, this, [this] { preview(); });
    connect(buttons_, &QDialogButtonBox::accepted, this, [this] {
        if (frame_) accept();
    });
    connect(buttons_, &QDialogButtonBox::rejected, this, &QDialog::reject);
}

QString CaptureDialog::capturePath() const { return capture_->text(); }
QString CaptureDialog::descriptionPath() const { return description_->text(); }
QString CaptureDialog::errorText() const { return error_->text(); }
QString CaptureDialog::dispatchText() const {
    return dispatch_->currentIndex() < 0 ? QString() : dispatch_->currentData().toString();
}

void CaptureDialog::showError(const QString& message) { error_->setText(message); }

void CaptureDialog::clearPreview() {
    frame_.reset();
    depth_->clear();
    depth_->setText(tr("no preview"));
    echo_->clear();
    buttons_->button(QDialogButtonBox::Open)->setEnabled(false);
}

bool CaptureDialog::setCapture(const QString& path) {
    capture_->setText(path);
    clearPreview();
    dispatch_->clear();
    bindings_->setRowCount(0);
    info_ = {};
    showError({});
    try {
        lc::CaptureInfo info;
        work_(tr("Reading %1...").arg(QFileInfo(path).fileName()),
              [&] { info = lc::readCaptureInfo(path.toStdString()); });
        info_ = std::move(info);
    } catch (const std::exception& e) {
        showError(QString::fromStdString(e.what()));
        return false;
    }
    // The dispatches, each with its marker path; the first that looks like
    // culling is chosen.
    int chosen = -1;
    for (const lc::CaptureAction& a : info_.actions) {
        if (a.kind != "dispatch") continue;
        const QString markers = QString::fromStdString(a.markerPath());
        const QString label = tr("event %1  %2 (%3 x %4 x %5)%6")
                                  .arg(a.event)
                                  .arg(QString::fromStdString(a.name))
                                  .arg(a.dims[0])
                                  .arg(a.dims[1])
                                  .arg(a.dims[2])
                                  .arg(markers.isEmpty() ? QString() : "  " + markers);
        dispatch_->addItem(label, QString::number(a.event));
        if (chosen < 0 && (markers + QString::fromStdString(a.name)).contains("cull", Qt::CaseInsensitive))
            chosen = dispatch_->count() - 1;
    }
    if (dispatch_->count() == 0) {
        showError(tr("%1: the capture holds no compute dispatch (%2 actions)").arg(path).arg(info_.actions.size()));
        return false;
    }
    dispatch_->setCurrentIndex(std::max(chosen, 0));
    readBindings();
    if (!description_->text().isEmpty()) preview();
    return true;
}

void CaptureDialog::setDescription(const QString& path) {
    description_->setText(path);
    clearPreview();
    if (dispatch_->count() > 0 && !path.isEmpty()) preview();
}

bool CaptureDialog::selectDispatch(const QString& what) {
    try {
        const std::uint32_t event = lc::findDispatch(info_, what.toStdString());
        const int i = dispatch_->findData(QString::number(event));
        if (i < 0) return false;
        dispatch_->setCurrentIndex(i);
    } catch (const std::exception& e) {
        showError(QString::fromStdString(e.what()));
        return false;
    }
    readBindings();
    clearPreview();
    return true;
}

void CaptureDialog::readBindings() {
    bindings_->setRowCount(0);
    clearPreview();
    showError({});
    if (dispatch_->currentIndex() < 0) return;
    const std::uint32_t event = dispatch_->currentData().toUInt();
    lc::CaptureInfo info;
    try {
        work_(tr("Reading the bindings at event %1...").arg(event),
              [&] { info = lc::readCaptureInfo(capture_->text().toStdString(), event); });
    } catch (const std::exception& e) {
        showError(QString::fromStdString(e.what()));
        return;
    }
    bindings_->setRowCount(int(info.bindings.size()));
    for (int r = 0; r < int(info.bindings.size()); ++r) {
        const lc::CaptureBinding& b = info.bindings[std::size_t(r)];
        const QStringList cells = {QString("%1.%2").arg(b.set).arg(b.binding), QString::fromStdString(b.descriptor),
                                   bindingSize(b), QString::fromStdString(b.resource),
                                   QString::fromStdString(b.variable)};
        for (int c = 0; c < cells.size(); ++c) bindings_->setItem(r, c, new QTableWidgetItem(cells[c]));
    }
    bindings_->resizeColumnsToContents();
}

bool CaptureDialog::preview() {
    clearPreview();
    showError({});
    if (dispatch_->currentIndex() < 0) {
        showError(tr("Choose a capture with a dispatch first"));
        return false;
    }
    if (description_->text().isEmpty()) {
        showError(tr("Choose the description of the renderer's lights, camera and lists (docs/RENDERDOC.md)"));
        return false;
    }
    const std::string capture = capture_->text().toStdString();
    const std::string description = description_->text().toStdString();
    const std::uint32_t event = dispatch_->currentData().toUInt();
    try {
        auto frame = std::make_shared<lc::CaptureFrame>();
        work_(tr("Reading event %1 of %2...").arg(event).arg(QFileInfo(capture_->text()).fileName()), [&] {
            const lc::CaptureDescription d = lc::loadCaptureDescription(description);
            const auto blobs = lc::readCaptureBindings(capture, event, lc::captureBindingsNeeded(d));
            *frame = lc::decodeCaptureFrame(d, blobs, capture, event);
        });
        frame_ = std::move(frame);
    } catch (const std::exception& e) {
        showError(QString::fromStdString(e.what()));
        return false;
    }
    const QImage img = depthPicture(frame_->depth);
    depth_->setPixmap(QPixmap::fromImage(img.scaled(320, 180, Qt::KeepAspectRatio, Qt::SmoothTransformation)));
    depth_->setToolTip(tr("The depth the dispatch read, %1x%2 (near light, far dark, empty black)")
                           .arg(frame_->depth.width)
                           .arg(frame_->depth.height));
    QStringList lines;
    for (const std::string& l : frame_->echo) lines << QString::fromStdString(l);
    for (const std::string& w : frame_->warnings) lines << tr("WARNING: %1").arg(QString::fromStdString(w));
    echo_->setPlainText(lines.join("\n"));
    buttons_->button(QDialogButtonBox::Open)->setEnabled(true);
    buttons_->button(QDialogButtonBox::Open)->setDefault(true);
    return true;
}

} // namespace lcui
