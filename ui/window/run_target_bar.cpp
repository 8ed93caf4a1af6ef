#include "window/run_target_bar.hpp"

#include "document/run_state.hpp"

#include "culling/core/backend.hpp"

#include <QComboBox>
#include <QLabel>
#include <QLineEdit>

namespace lcui {

RunTargetBar::RunTargetBar(RunState* runs, QAction* customShader, QWidget* parent)
    : QToolBar(tr("Run target"), parent), runs_(runs), backend_(new QComboBox), device_(new QLineEdit) {
    setObjectName("runToolbar");
    addAction(customShader);
    addSeparator();
    addWidget(new QLabel(tr("backend ")));
    backend_->setObjectName("backendCombo");
    for (const auto& b : lc::availableBackends()) backend_->addItem(QString::fromStdString(b));
    addWidget(backend_);
    device_->setObjectName("deviceEdit");
    device_->setPlaceholderText(tr("device (default)"));
    device_->setToolTip(tr("Vulkan device: index or name substring; empty = LIGHTCULL_DEVICE or the first"));
    device_->setMaximumWidth(140);
    addWidget(device_);
    sync();
    connect(backend_, &QComboBox::textActivated, runs_, &RunState::setBackend);
    connect(device_, &QLineEdit::editingFinished, this, [this] { runs_->setDevice(device_->text()); });
    connect(runs_, &RunState::backendChanged, this, &RunTargetBar::sync);
}

bool RunTargetBar::offers(const QString& backend) const { return backend_->findText(backend) >= 0; }

void RunTargetBar::sync() {
    backend_->setCurrentText(runs_->backend());
    device_->setText(runs_->device());
}

} // namespace lcui
