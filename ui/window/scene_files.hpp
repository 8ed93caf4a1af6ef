#pragma once
// The scene's files: new, open (scene JSON, glTF, built-in), import a mesh,
// save (atomically; never over a glTF another tool wrote), the unsaved-changes
// question and the recent-files menu. Loads run with the status bar's
// progress and Cancel; a failure is logged and shown, and the scene being
// edited stays as it was.

#include "window/prompts.hpp"

#include "culling/scene/gltf_io.hpp"

#include <QObject>
#include <QString>

class QMenu;
class QWidget;

namespace lcui {

class Document;
class StatusProgress;

class SceneFiles : public QObject {
    Q_OBJECT
public:
    // `prompts` and `gltf` are the window's, read at each use (tests and the
    // glTF cut-off setting change them).
    SceneFiles(QWidget* window, Document* doc, StatusProgress* progress, const Prompts& prompts,
               const lc::GltfReadOptions& gltf);
    // The File > Open recent menu this keeps.
    void setRecentMenu(QMenu* menu);

    bool maybeSave(); // unsaved changes: Save/Discard/Cancel; true when it is fine to go on
    bool newScene();
    bool openBuiltin(const QString& name);
    bool openSceneFile(const QString& path);
    bool importMeshFile(const QString& path);
    bool save();
    bool saveAs(const QString& path);

signals:
    void logged(const QString& message, bool error);
    void warned(const QString& message);
    // A scene was opened (`what`: its path, or "built-in scene NAME").
    void opened(const QString& what);

private:
    void log(const QString& message, bool error = false) { emit logged(message, error); }
    void warn(const QString& message) { emit warned(message); }
    void addRecentFile(const QString& path);
    void rebuildRecentMenu();

    QWidget* window_;
    Document* doc_;
    StatusProgress* progress_;
    const Prompts& prompts_;
    const lc::GltfReadOptions& gltf_;
    QMenu* recentMenu_ = nullptr;
};

} // namespace lcui
