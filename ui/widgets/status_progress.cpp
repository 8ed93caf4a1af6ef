#include "widgets/status_progress.hpp"

#include <QApplication>
#include <QEvent>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QTimer>
#include <QToolButton>

namespace lcui {

StatusProgress::StatusProgress(QWidget* parent) : QWidget(parent) {
    setObjectName("statusProgress");
    auto* layout = new QHBoxLayout(this);
    layout->setContentsMargins(0, 0, 0, 0);
    layout->setSpacing(8);
}

StatusProgress::~StatusProgress() {
    if (blockers_ > 0) qApp->removeEventFilter(this);
}

void StatusProgress::begin(const QString& key, const QString& label, std::function<void()> onCancel,
                           int showAfterMs) {
    end(key);
    Row row;
    row.box = new QWidget(this);
    auto* h = new QHBoxLayout(row.box);
    h->setContentsMargins(0, 0, 0, 0);
    h->setSpacing(4);
    row.label = new QLabel(label);
    row.label->setObjectName("statusTask_" + key);
    row.bar = new QProgressBar;
    row.bar->setObjectName("statusProgress_" + key);
    row.bar->setRange(0, 0); // busy until the first fraction
    row.bar->setMaximumWidth(140);
    row.bar->setMaximumHeight(16);
    row.bar->setTextVisible(false);
    h->addWidget(row.label);
    h->addWidget(row.bar);
    if (onCancel) {
        row.cancel = new QToolButton;
        row.cancel->setObjectName("statusCancel_" + key);
        row.cancel->setText(tr("Cancel"));
        row.cancel->setToolTip(tr("Stop: %1").arg(label));
        h->addWidget(row.cancel);
        row.onCancel = std::move(onCancel);
        connect(row.cancel, &QToolButton::clicked, this, [this, key] {
            auto it = rows_.find(key);
            if (it == rows_.end()) return;
            it->second.cancel->setEnabled(false);
            it->second.label->setText(tr("%1 (cancelling)").arg(it->second.label->text()));
            if (it->second.onCancel) it->second.onCancel();
        });
    }
    static_cast<QHBoxLayout*>(layout())->addWidget(row.box);
    row.box->setVisible(showAfterMs <= 0);
    if (showAfterMs > 0) {
        row.showTimer = new QTimer(row.box);
        row.showTimer->setSingleShot(true);
        QWidget* box = row.box;
        connect(row.showTimer, &QTimer::timeout, box, [box] { box->setVisible(true); });
        row.showTimer->start(showAfterMs);
    }
    rows_[key] = row;
}

void StatusProgress::setProgress(const QString& key, double fraction, const QString& label) {
    auto it = rows_.find(key);
    if (it == rows_.end()) return;
    Row& r = it->second;
    if (fraction < 0) {
        r.bar->setRange(0, 0);
    } else {
        r.bar->setRange(0, 1000);
        r.bar->setValue(int(std::min(fraction, 1.0) * 1000));
    }
    if (!label.isEmpty() && (!r.cancel || r.cancel->isEnabled())) r.label->setText(label);
}

void StatusProgress::end(const QString& key) {
    auto it = rows_.find(key);
    if (it == rows_.end()) return;
    it->second.box->hide();
    it->second.box->deleteLater();
    rows_.erase(it);
}

bool StatusProgress::running(const QString& key) const { return rows_.count(key) > 0; }

bool StatusProgress::shown(const QString& key) const {
    auto it = rows_.find(key);
    return it != rows_.end() && it->second.box->isVisible();
}

void StatusProgress::blockInput(bool on) {
    if (on && blockers_++ == 0) qApp->installEventFilter(this);
    if (!on && blockers_ > 0 && --blockers_ == 0) qApp->removeEventFilter(this);
}

bool StatusProgress::eventFilter(QObject* watched, QEvent* event) {
    switch (event->type()) {
    case QEvent::MouseButtonPress:
    case QEvent::MouseButtonRelease:
    case QEvent::MouseButtonDblClick:
    case QEvent::MouseMove:
    case QEvent::KeyPress:
    case QEvent::KeyRelease:
    case QEvent::Shortcut:
    case QEvent::ShortcutOverride:
    case QEvent::Wheel:
    case QEvent::ContextMenu:
    case QEvent::DragEnter:
    case QEvent::DragMove:
    case QEvent::Drop:
    case QEvent::Close:
        break;
    default: return false;
    }
    // Input from the window system reaches a QWindow first and is then sent
    // on to the widget under the cursor or with the focus, where this filter
    // sees it again: judge it there (dropping it at the window dropped the
    // clicks on Cancel itself; tests that sent them to the button directly
    // did not see that).
    if (!watched->isWidgetType()) return false;
    // The Cancel buttons (and their rows) take input; nothing else does.
    for (auto* w = qobject_cast<QWidget*>(watched); w; w = w->parentWidget())
        if (w == this) return false;
    if (event->type() == QEvent::Close) event->ignore();
    return true;
}

} // namespace lcui
