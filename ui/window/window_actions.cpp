#include "window/window_actions.hpp"

#include <QAction>
#include <QUndoStack>

namespace lcui {

WindowActions WindowActions::create(QObject* owner, QUndoStack* undoStack) {
    const auto make = [owner](const QString& text, const char* name, QKeySequence key = {}) {
        auto* a = new QAction(text, owner);
        a->setObjectName(name);
        if (!key.isEmpty()) a->setShortcut(key);
        return a;
    };
    const auto tr = [](const char* s) { return QObject::tr(s); };
    WindowActions a;
    a.newScene = make(tr("&New"), "actionNew", QKeySequence::New);
    a.open = make(tr("&Open scene..."), "actionOpen", QKeySequence::Open);
    a.openCapture = make(tr("Open Render&Doc capture..."), "actionOpenCapture");
    a.openCapture->setStatusTip(tr("Judge the light lists of a renderer's culling dispatch in a RenderDoc capture"));
    a.import = make(tr("&Import mesh..."), "actionImport", QKeySequence(tr("Ctrl+I")));
    a.gltfCutoff = make(tr("glTF light &cut-off..."), "actionGltfCutoff");
    a.save = make(tr("&Save"), "actionSave", QKeySequence::Save);
    a.saveAs = make(tr("Save &as..."), "actionSaveAs", QKeySequence(tr("Ctrl+Shift+S")));
    a.exportDiagnostics = make(tr("E&xport diagnostics..."), "actionExportDiagnostics", QKeySequence(tr("Ctrl+E")));
    a.quit = make(tr("&Quit"), "actionQuit", QKeySequence(tr("Ctrl+Q")));

    a.undo = undoStack->createUndoAction(owner, tr("&Undo"));
    a.undo->setObjectName("actionUndo");
    a.undo->setShortcut(QKeySequence::Undo);
    a.redo = undoStack->createRedoAction(owner, tr("&Redo"));
    a.redo->setObjectName("actionRedo");
    // Ctrl+Shift+Z and the platform's Redo keys, each once: a key bound twice
    // to one action is ambiguous to Qt and does nothing (some platforms'
    // Redo is Ctrl+Shift+Z).
    QList<QKeySequence> redoKeys{QKeySequence(tr("Ctrl+Shift+Z"))};
    for (const QKeySequence& k : QKeySequence::keyBindings(QKeySequence::Redo))
        if (!redoKeys.contains(k)) redoKeys << k;
    a.redo->setShortcuts(redoKeys);
    a.addLight = make(tr("&Add light"), "actionAddLight", QKeySequence(tr("Ctrl+L")));
    a.addSpotLight = make(tr("Add &spot light"), "actionAddSpotLight", QKeySequence(tr("Ctrl+Shift+L")));
    a.duplicate = make(tr("&Duplicate"), "actionDuplicate", QKeySequence(tr("Ctrl+D")));
    a.remove = make(tr("De&lete"), "actionDelete", QKeySequence::Delete);
    a.generate = make(tr("&Generate lights..."), "actionGenerate", QKeySequence(tr("Ctrl+G")));
    a.cameraFromView = make(tr("Set culling camera from this view"), "actionCameraFromView");

    a.tabbedViews = make(tr("Tabbed views"), "actionTabbedViews");
    a.tabbedViews->setCheckable(true);
    a.resetView = make(tr("Reset inspector camera"), "actionResetView");
    a.frameSelected = make(tr("&Frame selected"), "actionFrameSelected", QKeySequence(Qt::Key_F));
    a.lookThrough = make(tr("&Look through the culling camera"), "actionLookThrough", QKeySequence(Qt::Key_C));
    // The camera view's zoom (the wheel zooms, a right or middle drag pans).
    a.fitCameraImage = make(tr("Fit camera &image"), "actionFitCameraImage", QKeySequence(tr("Ctrl+0")));

    a.run = make(tr("&Run culling"), "actionRun", QKeySequence(Qt::Key_F5));
    a.live = make(tr("Live"), "actionLive");
    a.live->setCheckable(true);
    a.live->setToolTip(tr("Re-run culling after every edit"));
    a.hunt = make(tr("&Hunt for a miss..."), "actionHunt", QKeySequence(tr("Ctrl+H")));
    a.customShader = make(tr("Custom &shader..."), "actionCustomShader");
    a.builtinAlgorithm = make(tr("&Built-in algorithm"), "actionBuiltinAlgorithm");
    a.captureLists = make(tr("The capture's &lists"), "actionCaptureLists");
    a.captureLists->setStatusTip(tr("Judge the lists of the RenderDoc capture the scene came from"));
    a.captureLists->setEnabled(false);
    a.captureRenderDoc = make(tr("Capture in Render&Doc..."), "actionCaptureRenderDoc");
    a.captureRenderDoc->setStatusTip(
        tr("Write a RenderDoc capture of the tool's depth pre-pass and culling of this scene"));
    return a;
}

} // namespace lcui
