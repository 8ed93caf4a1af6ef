#pragma once
// The window's centre: the camera view and the inspector view side by side in
// a splitter or, tabbed, one at a time through a tab bar (the GL widgets are
// never re-parented). Its layout is kept in the settings.

#include <QWidget>

class QSettings;
class QSplitter;
class QTabBar;

namespace lcui {

class CameraView;
class Document;
class InspectorView;

class ViewArea : public QWidget {
    Q_OBJECT
public:
    explicit ViewArea(Document* doc, QWidget* parent = nullptr);
    CameraView* camera() const { return camera_; }
    InspectorView* inspector() const { return inspector_; }
    void setTabbed(bool tabbed);
    bool tabbed() const;
    void restore(const QSettings& st);
    void save(QSettings& st) const;

private:
    CameraView* camera_;
    InspectorView* inspector_;
    QSplitter* splitter_;
    QTabBar* tabs_;
};

} // namespace lcui
