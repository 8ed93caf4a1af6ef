#pragma once
// The toolbar that says what runs the culling: the custom shader action, the
// backend and the Vulkan device selector. It shows the document's RunState
// and sets it when the user picks; nothing is read back from its widgets.

#include <QToolBar>

class QAction;
class QComboBox;
class QLineEdit;

namespace lcui {

class RunState;

class RunTargetBar : public QToolBar {
    Q_OBJECT
public:
    RunTargetBar(RunState* runs, QAction* customShader, QWidget* parent);

    // Whether this build can run `backend` (lc::availableBackends).
    bool offers(const QString& backend) const;
    // Shows the run state's backend and device (after a change made with the
    // state's signals blocked).
    void sync();

private:
    RunState* runs_;
    QComboBox* backend_;
    QLineEdit* device_;
};

} // namespace lcui
