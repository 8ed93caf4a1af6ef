#pragma once
// The Generate lights dialog: the settings of lc::generateLights (count, seed,
// placement volume, intensity and colour ranges, I_min), prefilled with the
// scene's default placement volume, and the share of spot lights with their
// outer-angle range.

#include "culling/scene/scene_io.hpp"

#include <QDialog>

class QDoubleSpinBox;
class QLabel;
class QSpinBox;

namespace lcui {

class GenerateLightsDialog : public QDialog {
    Q_OBJECT
public:
    GenerateLightsDialog(const lc::LightGenSettings& initial, QWidget* parent = nullptr);
    lc::LightGenSettings settings() const;

private:
    QSpinBox* count_;
    QSpinBox* seed_;
    QDoubleSpinBox* boxMin_[3];
    QDoubleSpinBox* boxMax_[3];
    QDoubleSpinBox* intensityMin_;
    QDoubleSpinBox* intensityMax_;
    QDoubleSpinBox* colorMin_[3];
    QDoubleSpinBox* colorMax_[3];
    QDoubleSpinBox* minIntensity_;
    QDoubleSpinBox* spotFraction_;
    QDoubleSpinBox* spotAngleMin_;
    QDoubleSpinBox* spotAngleMax_;
    QLabel* error_;
};

} // namespace lcui
