#pragma once
// The properties dock: edits the current light (point or spot: kind,
// direction, outer angle) or the culling camera. Every
// change becomes one undo command in the document (a value committed in a
// field, a colour picked, ...).

#include <QWidget>

#include <functional>

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QSpinBox;
class QStackedWidget;

namespace lcui {

class Document;

class PropertyPanel : public QWidget {
    Q_OBJECT
public:
    explicit PropertyPanel(Document* doc, QWidget* parent = nullptr);

    // Replaceable colour picker (tests substitute it; default QColorDialog).
    std::function<QColor(QWidget*, QColor)> pickColor;

signals:
    // An edit that would make the camera or the light invalid was not taken
    // (the fields show the previous values again); `why` names the field.
    void editRefused(const QString& why);

private:
    void refresh();
    void commitLight();
    void commitCamera();
    QDoubleSpinBox* makeSpin(double lo, double hi, int decimals, const char* objectName);

    Document* doc_;
    bool updating_ = false;
    QStackedWidget* stack_;
    // light page
    QLineEdit* name_;
    QDoubleSpinBox* pos_[3];
    QPushButton* color_;
    QDoubleSpinBox* intensity_;
    QDoubleSpinBox* minIntensity_;
    QDoubleSpinBox* explicitRadius_;
    QLabel* radius_;
    QColor colorValue_;
    // spot fields (shown for spot lights only)
    QComboBox* kind_;
    QDoubleSpinBox* direction_[3];
    QWidget* directionRow_;
    QDoubleSpinBox* outerAngle_;
    std::function<void(bool)> setSpotRowsVisible_;
    // camera page
    QDoubleSpinBox* camPos_[3];
    QDoubleSpinBox* camTarget_[3];
    QDoubleSpinBox* camUp_[3];
    QComboBox* projection_;
    QDoubleSpinBox* fov_;
    QDoubleSpinBox* orthoHeight_;
    QDoubleSpinBox* near_;
    QDoubleSpinBox* far_;
    QCheckBox* farInfinite_;
    QSpinBox* width_;
    QSpinBox* height_;
    QSpinBox* tile_;
};

} // namespace lcui
