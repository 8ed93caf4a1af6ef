#pragma once
// Culling > Hunt for a miss... (issue 35): what the studio's hunt searches
// and where it writes the repro. The culling under test is the window's own
// (its built-in settings or its custom shader, on its backend); the dialog
// says which. Values the hunt refuses (no budget, nothing varied, a folder
// that holds other files) keep it open with the reason, every value as typed.

#include "culling/diagnostics/hunt.hpp"

#include <QDialog>
#include <QString>

#include <cstdint>

class QCheckBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QRadioButton;
class QSpinBox;

namespace lcui {

struct HuntRequest {
    std::uint64_t seed = 1;
    std::uint64_t trials = 200; // 0: no count limit
    double seconds = 60;        // 0: no time limit
    unsigned vary = lc::HuntAll;
    bool openScene = true;      // the open scene's meshes; false: generated scenes
    bool overflow = false;      // custom shader: a list over its capacity is a failure
    QString folder;             // the repro folder
};

class HuntDialog : public QDialog {
    Q_OBJECT
public:
    // `underTest`: the culling in words; `sceneHasMeshes`: the open scene can
    // be hunted in; `customShader`: the overflow choice applies.
    HuntDialog(const HuntRequest& initial, const QString& underTest, bool sceneHasMeshes, bool customShader,
               QWidget* parent = nullptr);
    HuntRequest request() const;
    void accept() override; // refuses what the hunt would refuse

private:
    QSpinBox* seed_;
    QSpinBox* trials_;
    QDoubleSpinBox* seconds_;
    QCheckBox* vary_[6];
    QRadioButton* openScene_;
    QRadioButton* generated_;
    QCheckBox* overflow_;
    QLineEdit* folder_;
    QLabel* error_;
};

} // namespace lcui
