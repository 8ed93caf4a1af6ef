#include "panels/property_panel.hpp"

#include "widgets/field_events.hpp"

#include "document/document.hpp"

#include <QCheckBox>
#include <QAbstractSpinBox>
#include <QColorDialog>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QSpinBox>
#include <QStackedWidget>
#include <QVBoxLayout>

#include <algorithm>
#include <cmath>
#include <limits>

namespace lcui {

namespace {
// x, y, z in one row: no arrow buttons and a modest width keep the dock narrow.
QWidget* row3(QDoubleSpinBox* const (&s)[3]) {
    auto* w = new QWidget;
    auto* h = new QHBoxLayout(w);
    h->setContentsMargins(0, 0, 0, 0);
    h->setSpacing(2);
    for (auto* b : s) {
        b->setButtonSymbols(QAbstractSpinBox::NoButtons);
        b->setMinimumWidth(50);
        b->setMaximumWidth(90);
        h->addWidget(b);
    }
    return w;
}
// Linear RGB is shown as is (clamped to 1 for the swatch); the picker edits [0,1].
QColor toQColor(const glm::dvec3& c) {
    return QColor::fromRgbF(std::clamp(c.r, 0.0, 1.0), std::clamp(c.g, 0.0, 1.0), std::clamp(c.b, 0.0, 1.0));
}
// A spin box rounds to its decimals: a field the user did not touch must give
// back the exact original value, not the rounded one shown.
double edited(const QDoubleSpinBox* s, double original) {
    const double shown = std::round(original * std::pow(10.0, s->decimals())) / std::pow(10.0, s->decimals());
    return std::abs(s->value() - shown) <= 0.5 * std::pow(10.0, -s->decimals()) ? original : s->value();
}
} // namespace

QDoubleSpinBox* PropertyPanel::makeSpin(double lo, double hi, int decimals, const char* objectName) {
    auto* s = new QDoubleSpinBox;
    s->setRange(lo, hi);
    s->setDecimals(decimals);
    s->setKeyboardTracking(false); // one command per committed value, not per keystroke
    s->setObjectName(objectName);
    return s;
}

PropertyPanel::PropertyPanel(Document* doc, QWidget* parent) : QWidget(parent), doc_(doc) {
    pickColor = [](QWidget* parent, QColor initial) {
        return QColorDialog::getColor(initial, parent, tr("Light colour"));
    };
    stack_ = new QStackedWidget;
    auto* outer = new QVBoxLayout(this);
    outer->addWidget(stack_);
    outer->addStretch();

    auto* empty = new QLabel(tr("Select a light or the culling camera."));
    empty->setWordWrap(true);
    stack_->addWidget(empty);

    // --- light page
    auto* lightPage = new QWidget;
    auto* lf = new QFormLayout(lightPage);
    name_ = new QLineEdit;
    name_->setObjectName("lightName");
    lf->addRow(tr("Name"), name_);
    const char* posNames[3] = {"lightX", "lightY", "lightZ"};
    for (int i = 0; i < 3; ++i) pos_[i] = makeSpin(-1e6, 1e6, 3, posNames[i]);
    lf->addRow(tr("Position"), row3(pos_));
    color_ = new QPushButton;
    color_->setObjectName("lightColor");
    lf->addRow(tr("Colour"), color_);
    intensity_ = makeSpin(0, 1e9, 6, "lightIntensity"); // small scenes light in millicandela
    lf->addRow(tr("Intensity"), intensity_);
    minIntensity_ = makeSpin(1e-6, 1e9, 6, "lightMinIntensity");
    lf->addRow(tr("Min intensity"), minIntensity_);
    explicitRadius_ = makeSpin(0, 1e6, 3, "lightExplicitRadius");
    explicitRadius_->setToolTip(tr("0: radius from the inverse-square law, sqrt(max(I*c)/I_min)"));
    lf->addRow(tr("Explicit radius"), explicitRadius_);
    radius_ = new QLabel;
    radius_->setObjectName("lightRadius");
    lf->addRow(tr("Radius"), radius_);
    kind_ = new QComboBox;
    kind_->setObjectName("lightKind");
    kind_->addItem(tr("point"), int(lc::LightKind::Point));
    kind_->addItem(tr("spot"), int(lc::LightKind::Spot));
    lf->addRow(tr("Kind"), kind_);
    const char* dirNames[3] = {"lightDirX", "lightDirY", "lightDirZ"};
    for (int i = 0; i < 3; ++i) direction_[i] = makeSpin(-1e6, 1e6, 3, dirNames[i]);
    directionRow_ = row3(direction_);
    directionRow_->setToolTip(tr("Cone axis, world space (any non-zero length)"));
    lf->addRow(tr("Direction"), directionRow_);
    outerAngle_ = makeSpin(0.01, 90, 2, "lightOuterAngle");
    outerAngle_->setToolTip(tr("Half-angle of the cone in degrees, (0, 90]"));
    lf->addRow(tr("Outer angle"), outerAngle_);
    stack_->addWidget(lightPage);
    // Spot rows hide for point lights (Qt 5's QFormLayout has no row visibility).
    setSpotRowsVisible_ = [lf, this](bool on) {
        for (QWidget* w : {directionRow_, static_cast<QWidget*>(outerAngle_)}) {
            w->setVisible(on);
            if (QWidget* label = lf->labelForField(w)) label->setVisible(on);
        }
    };

    connect(name_, &QLineEdit::editingFinished, this, &PropertyPanel::commitLight);
    for (auto* s : {pos_[0], pos_[1], pos_[2], intensity_, minIntensity_, explicitRadius_, direction_[0],
                    direction_[1], direction_[2], outerAngle_})
        connect(s, qOverload<double>(&QDoubleSpinBox::valueChanged), this, &PropertyPanel::commitLight);
    connect(kind_, qOverload<int>(&QComboBox::currentIndexChanged), this, &PropertyPanel::commitLight);
    connect(color_, &QPushButton::clicked, this, [this] {
        const QColor c = pickColor(this, colorValue_);
        if (!c.isValid()) return;
        colorValue_ = c;
        commitLight();
    });

    // --- camera page
    auto* camPage = new QWidget;
    auto* cf = new QFormLayout(camPage);
    for (int i = 0; i < 3; ++i) {
        camPos_[i] = makeSpin(-1e6, 1e6, 3, "cameraPosition");
        camTarget_[i] = makeSpin(-1e6, 1e6, 3, "cameraTarget");
        camUp_[i] = makeSpin(-1, 1, 3, "cameraUp");
    }
    cf->addRow(tr("Position"), row3(camPos_));
    cf->addRow(tr("Target"), row3(camTarget_));
    cf->addRow(tr("Up"), row3(camUp_));
    projection_ = new QComboBox;
    projection_->setObjectName("cameraProjection");
    for (auto k : {lc::ProjectionKind::Perspective, lc::ProjectionKind::PerspectiveGL,
                   lc::ProjectionKind::ReversedZ, lc::ProjectionKind::Orthographic,
                   lc::ProjectionKind::OrthographicGL})
        projection_->addItem(lc::toString(k), int(k));
    cf->addRow(tr("Projection"), projection_);
    fov_ = makeSpin(1, 179, 2, "cameraFov");
    cf->addRow(tr("FOV Y (deg)"), fov_);
    orthoHeight_ = makeSpin(1e-3, 1e6, 3, "cameraOrthoHeight");
    cf->addRow(tr("Ortho height"), orthoHeight_);
    near_ = makeSpin(1e-4, 1e6, 4, "cameraNear");
    cf->addRow(tr("Near"), near_);
    far_ = makeSpin(1e-3, 1e9, 3, "cameraFar");
    farInfinite_ = new QCheckBox(tr("infinite (reversed-Z)"));
    farInfinite_->setObjectName("cameraFarInfinite");
    auto* farRow = new QWidget;
    auto* fh = new QHBoxLayout(farRow);
    fh->setContentsMargins(0, 0, 0, 0);
    fh->addWidget(far_);
    fh->addWidget(farInfinite_);
    cf->addRow(tr("Far"), farRow);
    auto makeInt = [](int lo, int hi, const char* n) {
        auto* s = new QSpinBox;
        s->setRange(lo, hi);
        s->setKeyboardTracking(false);
        s->setObjectName(n);
        return s;
    };
    width_ = makeInt(1, 16384, "cameraWidth");
    height_ = makeInt(1, 16384, "cameraHeight");
    tile_ = makeInt(1, 256, "cameraTile");
    cf->addRow(tr("Width"), width_);
    cf->addRow(tr("Height"), height_);
    cf->addRow(tr("Tile size"), tile_);
    stack_->addWidget(camPage);

    for (auto* s : {camPos_[0], camPos_[1], camPos_[2], camTarget_[0], camTarget_[1], camTarget_[2],
                    camUp_[0], camUp_[1], camUp_[2], fov_, orthoHeight_, near_, far_})
        connect(s, qOverload<double>(&QDoubleSpinBox::valueChanged), this, &PropertyPanel::commitCamera);
    for (auto* s : {width_, height_, tile_})
        connect(s, qOverload<int>(&QSpinBox::valueChanged), this, &PropertyPanel::commitCamera);
    connect(projection_, qOverload<int>(&QComboBox::currentIndexChanged), this, &PropertyPanel::commitCamera);
    connect(farInfinite_, &QCheckBox::toggled, this, &PropertyPanel::commitCamera);

    connect(&doc_->selection(), &Selection::changed, this, &PropertyPanel::refresh);
    connect(doc_, &Document::lightChanged, this, [this](int i) {
        if (i == doc_->selection().currentLight()) refresh();
    });
    connect(doc_, &Document::lightsChanged, this, &PropertyPanel::refresh);
    connect(doc_, &Document::cameraChanged, this, &PropertyPanel::refresh);
    connect(doc_, &Document::sceneReset, this, &PropertyPanel::refresh);
    (new UndoKeysToWindow(this))->watch(this);
    (new WheelOnlyWhenFocused(this))->watch(this);
    refresh();
}

void PropertyPanel::refresh() {
    updating_ = true;
    const auto& s = doc_->scene();
    const int cur = doc_->selection().currentLight();
    if (cur >= 0 && cur < int(s.lights.size())) {
        const auto& l = s.lights[std::size_t(cur)];
        stack_->setCurrentIndex(1);
        name_->setText(QString::fromStdString(l.name));
        for (int i = 0; i < 3; ++i) pos_[i]->setValue(l.position[i]);
        colorValue_ = toQColor(l.color);
        color_->setText(QStringLiteral("%1, %2, %3").arg(l.color.r, 0, 'g', 3).arg(l.color.g, 0, 'g', 3).arg(l.color.b, 0, 'g', 3));
        color_->setStyleSheet(QStringLiteral("background-color: %1; color: %2")
                                  .arg(colorValue_.name(), colorValue_.lightness() > 128 ? "black" : "white"));
        intensity_->setValue(l.intensity);
        minIntensity_->setValue(l.minIntensity);
        explicitRadius_->setValue(l.explicitRadius);
        kind_->setCurrentIndex(kind_->findData(int(l.kind)));
        for (int i = 0; i < 3; ++i) direction_[i]->setValue(l.direction[i]);
        outerAngle_->setValue(l.outerAngleDeg);
        setSpotRowsVisible_(l.isSpot());
        const std::string err = l.validate();
        radius_->setText(err.empty() ? QString::number(l.radius(), 'g', 6)
                                     : tr("invalid: %1").arg(QString::fromStdString(err)));
    } else if (doc_->selection().cameraSelected()) {
        const auto& c = s.camera;
        stack_->setCurrentIndex(2);
        for (int i = 0; i < 3; ++i) {
            camPos_[i]->setValue(c.position[i]);
            camTarget_[i]->setValue(c.target[i]);
            camUp_[i]->setValue(c.up[i]);
        }
        projection_->setCurrentIndex(projection_->findData(int(c.projection)));
        fov_->setValue(c.fovYDeg);
        orthoHeight_->setValue(c.orthoHeight);
        near_->setValue(c.nearPlane);
        farInfinite_->setChecked(std::isinf(c.farPlane));
        far_->setEnabled(!std::isinf(c.farPlane));
        if (!std::isinf(c.farPlane)) far_->setValue(c.farPlane);
        width_->setValue(int(c.width));
        height_->setValue(int(c.height));
        tile_->setValue(int(c.tileSize));
    } else {
        stack_->setCurrentIndex(0);
    }
    updating_ = false;
}

void PropertyPanel::commitLight() {
    if (updating_) return;
    const int cur = doc_->selection().currentLight();
    if (cur < 0 || cur >= int(doc_->scene().lights.size())) return;
    lc::PointLight l = doc_->scene().lights[std::size_t(cur)];
    const lc::PointLight before = l;
    l.name = name_->text().toStdString();
    for (int i = 0; i < 3; ++i) l.position[i] = edited(pos_[i], before.position[i]);
    // The swatch holds a [0,1] colour; only a picked colour replaces the light's
    // (possibly > 1) linear RGB.
    if (colorValue_ != toQColor(before.color))
        l.color = {colorValue_.redF(), colorValue_.greenF(), colorValue_.blueF()};
    l.intensity = edited(intensity_, before.intensity);
    l.minIntensity = edited(minIntensity_, before.minIntensity);
    l.explicitRadius = edited(explicitRadius_, before.explicitRadius);
    l.kind = lc::LightKind(kind_->currentData().toInt());
    for (int i = 0; i < 3; ++i) l.direction[i] = edited(direction_[i], before.direction[i]);
    l.outerAngleDeg = edited(outerAngle_, before.outerAngleDeg);
    // A zero axis has no direction: refuse it and show the previous one again
    // rather than storing a light that cannot be culled.
    if (l.direction == glm::dvec3(0.0)) {
        refresh();
        return;
    }
    const bool same = l.name == before.name && l.position == before.position && l.color == before.color &&
                      l.intensity == before.intensity && l.minIntensity == before.minIntensity &&
                      l.explicitRadius == before.explicitRadius && l.kind == before.kind &&
                      l.direction == before.direction && l.outerAngleDeg == before.outerAngleDeg;
    if (same) return;
    // A light is found by its name (explain --light, the scene tree's filter).
    if (l.name.empty()) {
        refresh();
        emit editRefused(tr("light %1 not changed: name: must not be empty").arg(cur));
        return;
    }
    if (const std::string err = l.validate(); !err.empty()) {
        refresh();
        emit editRefused(tr("light %1 not changed: %2").arg(cur).arg(QString::fromStdString(err)));
        return;
    }
    doc_->setLight(cur, l);
}

void PropertyPanel::commitCamera() {
    if (updating_) return;
    const lc::Camera before = doc_->scene().camera;
    lc::Camera c = before;
    for (int i = 0; i < 3; ++i) {
        c.position[i] = edited(camPos_[i], before.position[i]);
        c.target[i] = edited(camTarget_[i], before.target[i]);
        c.up[i] = edited(camUp_[i], before.up[i]);
    }
    c.projection = lc::ProjectionKind(projection_->currentData().toInt());
    c.fovYDeg = edited(fov_, before.fovYDeg);
    c.orthoHeight = edited(orthoHeight_, before.orthoHeight);
    c.nearPlane = edited(near_, before.nearPlane);
    c.farPlane = farInfinite_->isChecked() ? std::numeric_limits<double>::infinity()
                 : std::isinf(before.farPlane) ? far_->value() : edited(far_, before.farPlane);
    c.width = std::uint32_t(width_->value());
    c.height = std::uint32_t(height_->value());
    c.tileSize = std::uint32_t(tile_->value());
    const bool same = c.position == before.position && c.target == before.target && c.up == before.up &&
                      c.projection == before.projection && c.fovYDeg == before.fovYDeg &&
                      c.orthoHeight == before.orthoHeight && c.nearPlane == before.nearPlane &&
                      c.farPlane == before.farPlane && c.width == before.width &&
                      c.height == before.height && c.tileSize == before.tileSize;
    if (same) return;
    // A camera that cannot be culled from (the target on the position, a
    // far plane before the near one) is not stored: it would fail every run
    // and save a file that does not open.
    if (const std::string err = c.validate(); !err.empty()) {
        refresh();
        emit editRefused(tr("camera not changed: %1").arg(QString::fromStdString(err)));
        return;
    }
    doc_->setCamera(c);
}

} // namespace lcui
