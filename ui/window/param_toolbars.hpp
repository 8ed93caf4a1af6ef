#pragma once
// The culling parameters' toolbars: the Culling row and the Limits row with
// the engine preset combo, generated from the one parameter table
// (lc::cullParams) that also defines CullSettings and the CLI's flags. The
// widgets show the document's settings; an edit goes to the document (a
// camera edit for width, height and tile, as one undo step) and a refused
// value is logged and shown back as it was.

#include <QObject>

#include <QString>

#include <map>
#include <vector>
#include <string>

class QComboBox;
class QMainWindow;
class QToolBar;
class QWidget;

namespace lcui {

class Document;

class ParamToolbars : public QObject {
    Q_OBJECT
public:
    // Adds the Culling toolbar, a break and the Limits toolbar to `window`.
    ParamToolbars(QMainWindow* window, Document* doc);

    QToolBar* cullBar() const { return cullBar_; }
    // The widgets to the document's settings, and the preset they equal
    // (for this scene), else "(none)".
    void sync();
    // One parameter through its control, as a user would; true when the
    // document took it.
    bool setParam(const QString& name, const QString& value);
    // An engine preset through the combo, as a user would; false for an unknown name.
    bool setPreset(const QString& name);
    // While a custom shader makes the lists (`shader` non-empty) the settings
    // only the built-in algorithms read are greyed out, saying why; the
    // camera's width, height and tile size stay (the shader culls that grid).
    void setListsFromShader(const QString& shader);

signals:
    void logged(const QString& message, bool error);

private:
    void addParamWidgets(QToolBar* limitsBar);
    void onEdited(const std::string& name, const QString& value);
    void applyPreset(const std::string& name);

    Document* doc_;
    QToolBar* cullBar_ = nullptr;
    QComboBox* presetCombo_ = nullptr; // "(none)" or the preset the settings equal
    std::map<std::string, QWidget*> widgets_;
    std::map<std::string, QString> tips_; // each widget's own tool tip
    // raster's proxy settings: a row shown only while the algorithm is raster.
    QToolBar* rasterBar_ = nullptr;
    bool syncing_ = false;
};

} // namespace lcui
