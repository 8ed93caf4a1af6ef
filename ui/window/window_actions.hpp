#pragma once
// Every action of the window's menus and toolbars, by name: created once with
// its text, object name (what tests and scripts find it by) and shortcuts; the
// window wires them to what they do.

class QAction;
class QObject;
class QUndoStack;

namespace lcui {

struct WindowActions {
    // File
    QAction *newScene, *open, *openCapture, *import, *gltfCutoff, *save, *saveAs, *exportDiagnostics, *quit;
    // Edit
    QAction *undo, *redo, *addLight, *addSpotLight, *duplicate, *remove, *generate, *cameraFromView;
    // View
    QAction *tabbedViews, *resetView, *frameSelected, *lookThrough, *fitCameraImage;
    // Culling
    QAction *run, *live, *hunt, *customShader, *builtinAlgorithm, *captureLists, *captureRenderDoc;

    // The actions, owned by `owner`; undo and redo are `undo`'s.
    static WindowActions create(QObject* owner, QUndoStack* undo);
};

} // namespace lcui
