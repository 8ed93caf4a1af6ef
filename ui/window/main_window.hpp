#pragma once
// The studio's main window: it makes the document, the culling worker and
// the window's parts, and wires them. Each concern is a class of its own:
// the views (view_area.hpp), the docks and panels (docks.hpp), the actions
// (window_actions.hpp), the parameter rows (param_toolbars.hpp), files
// (scene_files.hpp), the status bar and run log lines (run_status.hpp), new
// lights (light_placement.hpp), the overlay and image-mode menus
// (overlay_menus.hpp, image_modes.hpp), the export (diagnostics_export.hpp)
// and the custom shader's file (custom_shader_source.hpp). What to run (the
// settings, backend, device and Live) is the document's (run_state.hpp): the
// toolbar's controls show it.
//
// Dialogs that ask the user something go through the replaceable functions in
// `prompts`, so tests (and scripts) can answer them without a modal loop.

#include "window/prompts.hpp"
#include "window/window_actions.hpp"

#include "culling/core/params.hpp"
#include "culling/scene/scene_io.hpp"

#include "culling/custom/custom_cull.hpp"
#include "culling/scene/gltf_io.hpp"

#include <QMainWindow>
#include <QMessageBox>

#include <functional>
#include <map>
#include <memory>

class QAction;
class QCheckBox;
class QLabel;
class QMenu;
class QPlainTextEdit;
class QSplitter;
class QTabBar;

namespace lc {
struct CaptureFrame;
struct RunOutput;
}


namespace lcui {

class DiagnosticsExport;
class Docks;
class LightPlacement;
class MissNavigator;
class ParamToolbars;
class RunStatus;
class RunTargetBar;
class ViewArea;
class SceneFiles;
class CustomShaderSource;
struct HuntRequest; // hunt_dialog.hpp

class CameraView;
class CullService;
class ExplainPanel;
class Document;
class InspectorView;
class PropertyPanel;
class SceneTree;
class StatusProgress;
class TileInspector;


class MainWindow : public QMainWindow {
    Q_OBJECT
public:
    explicit MainWindow(QWidget* parent = nullptr);
    ~MainWindow() override;

    Document* document() const { return doc_; }
    CullService* cullService() const { return service_; }
    CameraView* cameraView() const { return cameraView_; }
    InspectorView* inspectorView() const { return inspectorView_; }
    SceneTree* sceneTree() const;
    PropertyPanel* propertyPanel() const;
    TileInspector* tileInspector() const;
    ExplainPanel* explainPanel() const;
    MissNavigator* missNavigator() const { return misses_; }
    QPlainTextEdit* messageLog() const;
    QAction* action(const QString& objectName) const; // e.g. "actionRun"
    Prompts prompts;
    // Opening a scene runs culling once (tests turn this off to set up first).
    bool runOnOpen = true;
    // How glTF scenes are read: I_min of lights without `range` (File > glTF
    // light cut-off..., kept in the settings) and the camera (empty: the
    // file's first).
    lc::GltfReadOptions gltfOptions;
    void setGltfMinIntensity(double lux);

    // A custom culling shader (Culling > Custom shader...; docs/CUSTOM_CULLING.md)
    // runs instead of the built-in algorithm, its first-line settings applied.
    // The file is watched: saving it re-runs culling. An empty path goes back
    // to the built-in algorithm. False (logged, shown) for a bad first line.
    bool setCustomShader(const QString& path);
    QString customShaderPath() const;

    // --- RenderDoc (main_window_capture.cpp; docs/RENDERDOC.md) -----------------
    // Opens a renderer's culling dispatch: the frame's lights and camera
    // become the scene (no meshes), its depth is the depth every run of it
    // uses, and its lists are judged (until Culling > Built-in algorithm or
    // Custom shader...; The capture's lists goes back). False (logged,
    // shown) when the capture or description cannot be read; the scene being
    // edited is then untouched.
    bool openCapture(const QString& capture, const QString& dispatch, const QString& description);
    bool openCaptureFrame(std::shared_ptr<const lc::CaptureFrame> frame);
    std::shared_ptr<const lc::CaptureFrame> captureFrame() const { return capture_; }
    bool cullsCaptureLists() const { return captureLists_; }
    void setCaptureLists(bool on);
    // Culling > Capture in RenderDoc...: writes `rdcPath`, a capture of the
    // tool's own passes on this scene (`lightcull run --renderdoc-capture`
    // with the window's settings or custom shader, on Vulkan). False (logged,
    // shown) when it could not.
    bool captureInRenderDoc(const QString& rdcPath);

    // --- file operations (return false on failure or cancel; the current
    // scene is then untouched and the error is logged and shown) -------------
    bool newScene();
    bool openBuiltin(const QString& name);
    bool openSceneFile(const QString& path);
    bool importMeshFile(const QString& path);
    bool save();
    bool saveAs(const QString& path);
    // Unsaved changes: asks Save/Discard/Cancel. True when it is fine to go on.
    bool maybeSave();

    // --- culling ----------------------------------------------------------------
    // Posts a run of the current scene and settings; returns its generation.
    // `liveEdit`: a Live re-run after a scene edit; its lists are shown first
    // and ground truth follows (CullRequest::deferTruth).
    quint64 runCulling(bool liveEdit = false);
    void setLive(bool live);
    bool isLive() const;
    // The backend and device selector the next run uses.
    void setBackend(const QString& backend, const QString& device = {});
    // Sets one culling parameter through its toolbar control (as a user would).
    bool setParamFromUi(const QString& name, const QString& value);
    // Picks an engine preset in the Limits toolbar's combo (as a user would):
    // its algorithm, grid and limits for this scene. False for an unknown name.
    bool setPresetFromUi(const QString& name);

    // --- editing ----------------------------------------------------------------
    // Adds a light under the inspector-view position `pos` (logical px) when a
    // surface is there, else at the scene centre. Returns its index. A spot
    // light stands off the surface and points back at it (30 degrees).
    int addLightAt(const QPoint& inspectorPos, lc::LightKind kind = lc::LightKind::Point);
    int addLightAtCentre();
    // Generates lights as one undo step (progress + cancel for large counts).
    bool generateLights(const lc::LightGenSettings& settings);
    // Culling > Hunt for a miss... (main_window_hunt.cpp): hunts the window's
    // culling (its settings or custom shader, on its backend) with the status
    // bar's progress and Cancel, writes the repro into r.folder and, when a
    // miss is found, opens the repro scene with the miss selected and
    // Explain showing it. False when nothing was found, on error or cancel.
    bool hunt(const HuntRequest& r);
    // Once run `generation` (or a newer one) shows with its ground truth,
    // selects its first miss as Culling > Next miss does and shows Explain
    // (a hunt's repro; the studio's --first-miss).
    void selectFirstMissOfRun(quint64 generation) { firstMissOfRun_ = generation; }
    void setCullingCameraFromInspector();

    // Export diagnostics (File menu; diagnostics_export.hpp) into `dir`: ends
    // with diagnosticsExported, at once when the run has its shaded images,
    // else once the worker has shaded it. False (logged, shown) when there is
    // no run to export or the scene changed since it.
    bool exportDiagnostics(const QString& dir);

    // Whole-window image with both views' GL content.
    QImage grabWindow();
    void log(const QString& message, bool error = false);
    // A line marked WARNING: the action went through, with something to know
    // (faces dropped on import, a glTF light skipped, false negatives).
    void warn(const QString& message);

signals:
    void runFinished(quint64 generation);
    void runFailed(quint64 generation, const QString& message);
    // An export ended: `ok`, or logged and shown why not.
    void diagnosticsExported(const QString& dir, bool ok);

protected:
    void closeEvent(QCloseEvent* e) override;
    void dragEnterEvent(QDragEnterEvent* e) override;
    void dropEvent(QDropEvent* e) override;

private:
    void huntFromDialog(); // Culling > Hunt for a miss... (main_window_hunt.cpp)
    void openCaptureFromDialog(); // File > Open RenderDoc capture... (main_window_capture.cpp)
    void forgetCapture();
    void wireActions();
    void wireReport();
    void buildMenus();
    void buildToolbars();
    void onRunFinished(quint64 generation, std::shared_ptr<const lc::RunOutput> out);
    void onRunFailed(quint64 generation, const QString& message);
    void updateTitle();
    void restoreSettings();
    void saveSettings();
    void afterSceneOpened(const QString& what);

    Document* doc_;
    CullService* service_;
    MissNavigator* misses_;
    ViewArea* views_;
    CameraView* cameraView_;
    InspectorView* inspectorView_;
    Docks* docks_;
    WindowActions actions_;
    QMenu* recentMenu_ = nullptr;
    RunTargetBar* runTarget_ = nullptr;
    ParamToolbars* params_ = nullptr; // the Culling and Limits rows
    SceneFiles* files_ = nullptr;     // open, save, import, recent files
    StatusProgress* statusProgress_ = nullptr; // loads, shading and reports, with Cancel
    RunStatus* runStatus_ = nullptr;
    LightPlacement* lights_ = nullptr;
    DiagnosticsExport* export_ = nullptr;
    bool restoringSettings_ = false; // restoreSettings() is setting the widgets
    bool sceneOpen_ = false;         // a scene was opened (the document starts empty)
    CustomShaderSource* customShader_ = nullptr; // the user's culling shader, watched
    quint64 firstMissOfRun_ = 0; // selectFirstMissOfRun's generation; 0: none
    // The RenderDoc capture the scene came from (null: none), whether its
    // lists are what runs judge, and that the capture's scene is being set.
    std::shared_ptr<const lc::CaptureFrame> capture_;
    bool captureLists_ = false;
    bool openingCapture_ = false;
};

} // namespace lcui
