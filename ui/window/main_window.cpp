#include "window/main_window.hpp"

#include "document/document.hpp"
#include "document/miss_navigator.hpp"
#include "document/run_state.hpp"
#include "document/settings_store.hpp"
#include "panels/generate_dialog.hpp"
#include "panels/property_panel.hpp"
#include "panels/report_dock.hpp"
#include "views/camera_view.hpp"
#include "views/inspector_view.hpp"
#include "views/vtk_adapters.hpp"
#include "widgets/count_text.hpp"
#include "widgets/message_log.hpp"
#include "widgets/status_progress.hpp"
#include "window/diagnostics_export.hpp"
#include "window/docks.hpp"
#include "window/image_modes.hpp"
#include "window/light_placement.hpp"
#include "window/overlay_menus.hpp"
#include "window/param_toolbars.hpp"
#include "window/run_status.hpp"
#include "window/run_target_bar.hpp"
#include "window/scene_files.hpp"
#include "window/view_area.hpp"
#include "work/cull_worker.hpp"
#include "work/custom_shader_source.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/presets.hpp"

#include <QAction>
#include <QCloseEvent>
#include <QCursor>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QFileInfo>
#include <QLabel>
#include <QMenuBar>
#include <QMimeData>
#include <QSettings>
#include <QSignalBlocker>
#include <QStatusBar>
#include <QToolBar>
#include <QUndoStack>

#include <vtkCamera.h>
#include <vtkRenderer.h>

#include <cmath>

namespace lcui {

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent), prompts(Prompts::dialogs()) {
    setObjectName("LightCullStudio");
    doc_ = new Document(this);
    service_ = new CullService(this);
    misses_ = new MissNavigator(doc_, this);
    views_ = new ViewArea(doc_);
    cameraView_ = views_->camera();
    inspectorView_ = views_->inspector();
    setCentralWidget(views_);
    docks_ = new Docks(this, doc_, misses_, service_);
    actions_ = WindowActions::create(this, doc_->undoStack());
    statusProgress_ = new StatusProgress;
    statusBar()->addPermanentWidget(statusProgress_);
    runStatus_ = new RunStatus(doc_, docks_->log(), statusBar(), this);
    lights_ = new LightPlacement(doc_, inspectorView_, statusProgress_, docks_->log(), prompts, this);
    export_ = new DiagnosticsExport(doc_, service_, cameraView_, inspectorView_, this);
    customShader_ = new CustomShaderSource(this);
    files_ = new SceneFiles(this, doc_, statusProgress_, prompts, gltfOptions);
    doc_->runs().setBackend(CullService::defaultBackend());
    wireActions();
    buildMenus();
    buildToolbars();
    wireReport();
    setAcceptDrops(true);

    connect(misses_, &MissNavigator::message, this, [this](const QString& text) {
        log(text);
        statusBar()->showMessage(text, 10000);
    });
    connect(docks_->properties(), &PropertyPanel::editRefused, this, [this](const QString& why) {
        log(why, true);
        statusBar()->showMessage(why, 10000);
    });
    connect(customShader_, &CustomShaderSource::changed, this, [this] { runCulling(); });
    connect(customShader_, &CustomShaderSource::refusalChanged, this,
            [this](const QString& why) { runStatus_->setShaderRefused(customShader_->path(), why); });
    connect(customShader_, &CustomShaderSource::logged, this, &MainWindow::log);
    files_->setRecentMenu(recentMenu_);
    connect(files_, &SceneFiles::logged, this, &MainWindow::log);
    connect(files_, &SceneFiles::warned, this, &MainWindow::warn);
    connect(files_, &SceneFiles::opened, this, &MainWindow::afterSceneOpened);
    connect(export_, &DiagnosticsExport::finished, this, [this](const QString& dir, bool ok, const QString& why) {
        if (ok) {
            log(tr("exported diagnostics to %1").arg(dir));
        } else {
            log(tr("export diagnostics: %1").arg(why), true);
            prompts.showError(this, tr("Export diagnostics"), why);
        }
        emit diagnosticsExported(dir, ok);
    });

    connect(service_, &CullService::finished, this, &MainWindow::onRunFinished);
    connect(service_, &CullService::failed, this, &MainWindow::onRunFailed);
    connect(service_, &CullService::backendReady, runStatus_, &RunStatus::backendReady);
    // What to run is the document's; a change of it re-runs under Live, once
    // a scene is open (settings given before it, as the studio's --param
    // are, are for its first run: a run of the empty document is no answer).
    RunState& runs = doc_->runs();
    connect(doc_, &Document::sceneReset, this, [this] {
        sceneOpen_ = true;
        if (!openingCapture_) forgetCapture(); // another scene: not the capture's
    });
    connect(doc_, &Document::sceneEdited, this, [this] {
        if (isLive()) runCulling(/*liveEdit=*/true);
    });
    connect(&runs, &RunState::settingsChanged, this, [this] {
        params_->sync();
        if (isLive() && sceneOpen_) runCulling();
    });
    connect(&runs, &RunState::backendChanged, this, [this] {
        if (isLive() && sceneOpen_) runCulling();
    });
    connect(&runs, &RunState::liveChanged, this, [this](bool on) {
        actions_.live->setChecked(on);
        if (on && sceneOpen_ && !restoringSettings_) runCulling();
    });
    connect(doc_, &Document::cameraChanged, params_, &ParamToolbars::sync);
    connect(doc_, &Document::sceneReset, params_, &ParamToolbars::sync);
    connect(doc_, &Document::dirtyChanged, this, &MainWindow::updateTitle);
    connect(doc_, &Document::filePathChanged, this, &MainWindow::updateTitle);

    resize(1600, 900);
    docks_->initialSizes();
    restoreSettings();
    params_->sync();
    updateTitle();
}

MainWindow::~MainWindow() = default;

QAction* MainWindow::action(const QString& objectName) const { return findChild<QAction*>(objectName); }
QPlainTextEdit* MainWindow::messageLog() const { return docks_->log(); }
SceneTree* MainWindow::sceneTree() const { return docks_->tree(); }
PropertyPanel* MainWindow::propertyPanel() const { return docks_->properties(); }
TileInspector* MainWindow::tileInspector() const { return docks_->tileInspector(); }
ExplainPanel* MainWindow::explainPanel() const { return docks_->explain(); }

// --- construction ---------------------------------------------------------------

void MainWindow::wireActions() {
    const WindowActions& a = actions_;
    connect(a.newScene, &QAction::triggered, this, [this] { newScene(); });
    connect(a.open, &QAction::triggered, this, [this] {
        const QString p = prompts.openPath(this, tr("Open scene"),
                                           tr("Scenes (*.json *.gltf *.glb);;Scene JSON (*.json);;glTF 2.0 (*.gltf *.glb)"));
        if (!p.isEmpty()) openSceneFile(p);
    });
    connect(a.openCapture, &QAction::triggered, this, &MainWindow::openCaptureFromDialog);
    connect(a.import, &QAction::triggered, this, [this] {
        const QString p =
            prompts.openPath(this, tr("Import mesh"), tr("Meshes (*.obj *.ply *.off *.stl *.om *.gltf *.glb)"));
        if (!p.isEmpty()) importMeshFile(p);
    });
    connect(a.save, &QAction::triggered, this, [this] { save(); });
    connect(a.saveAs, &QAction::triggered, this, [this] {
        const QString p = prompts.savePath(this, tr("Save scene as"),
                                           tr("Scene JSON (*.json);;Binary glTF (*.glb);;glTF 2.0 (*.gltf)"));
        if (!p.isEmpty()) saveAs(p);
    });
    connect(a.exportDiagnostics, &QAction::triggered, this, [this] {
        // Nothing to export (no run, or the scene changed since): say so
        // before asking for a folder.
        if (!doc_->runs().runOutput() || doc_->runs().runIsStale()) {
            exportDiagnostics({});
            return;
        }
        const QString dir = prompts.savePath(this, tr("Export diagnostics into a new folder"), tr("Folder (*)"));
        if (!dir.isEmpty()) exportDiagnostics(dir);
    });
    connect(a.quit, &QAction::triggered, this, &QWidget::close);
    connect(a.gltfCutoff, &QAction::triggered, this, [this] {
        double v = gltfOptions.minIntensity;
        if (prompts.askNumber(this, tr("glTF light cut-off"),
                              tr("I_min (lux) for glTF lights without a range:\nradius = sqrt(intensity x colour / "
                                 "I_min). Applies to the open scene's lights without a range (one undo step) "
                                 "and to the next glTF opened."),
                              1e-6, 1e6, v))
            setGltfMinIntensity(v);
    });

    connect(a.addLight, &QAction::triggered, this, [this] { addLightAt(inspectorView_->mapFromGlobal(QCursor::pos())); });
    connect(a.addSpotLight, &QAction::triggered, this,
            [this] { addLightAt(inspectorView_->mapFromGlobal(QCursor::pos()), lc::LightKind::Spot); });
    connect(a.duplicate, &QAction::triggered, this, [this] { doc_->duplicateLights(doc_->selection().selectedLights()); });
    connect(a.remove, &QAction::triggered, this, [this] { doc_->deleteLights(doc_->selection().selectedLights()); });
    connect(a.generate, &QAction::triggered, this, [this] {
        GenerateLightsDialog dlg(lc::defaultLightGen(doc_->scene(), 256, 1), this);
        if (dlg.exec() == QDialog::Accepted) generateLights(dlg.settings());
    });
    connect(a.cameraFromView, &QAction::triggered, this, &MainWindow::setCullingCameraFromInspector);

    connect(a.resetView, &QAction::triggered, inspectorView_, &InspectorView::resetCamera);
    connect(a.frameSelected, &QAction::triggered, this, [this] {
        if (!inspectorView_->frameSelected())
            statusBar()->showMessage(tr("Nothing selected to frame: click a tile or pick a light"), 4000);
        else if (!inspectorView_->frameNote().isEmpty())
            statusBar()->showMessage(inspectorView_->frameNote(), 6000);
    });
    connect(a.lookThrough, &QAction::triggered, inspectorView_, &InspectorView::lookThroughCullingCamera);
    connect(a.fitCameraImage, &QAction::triggered, cameraView_, &CameraView::fitImage);
    connect(a.tabbedViews, &QAction::toggled, views_, &ViewArea::setTabbed);

    connect(a.run, &QAction::triggered, this, [this] { runCulling(); });
    connect(a.live, &QAction::toggled, &doc_->runs(), &RunState::setLive);
    connect(a.customShader, &QAction::triggered, this, [this] {
        const QString p =
            prompts.openPath(this, tr("Custom culling shader"), tr("Culling shaders (*.comp *.glsl *.hlsl *.spv)"));
        if (!p.isEmpty()) setCustomShader(p);
    });
    connect(a.builtinAlgorithm, &QAction::triggered, this, [this] { setCustomShader({}); });
    connect(a.hunt, &QAction::triggered, this, &MainWindow::huntFromDialog);
    connect(a.captureLists, &QAction::triggered, this, [this] { setCaptureLists(true); });
    connect(a.captureRenderDoc, &QAction::triggered, this, [this] {
        const QString p = prompts.savePath(this, tr("Capture in RenderDoc"), tr("RenderDoc captures (*.rdc)"));
        if (!p.isEmpty()) captureInRenderDoc(p.endsWith(".rdc", Qt::CaseInsensitive) ? p : p + ".rdc");
    });
    // A hunt's repro opens with its miss selected once its run has the truth
    // (selectFirstMissOfRun).
    connect(this, &MainWindow::runFinished, this, [this] {
        const RunState& runs = doc_->runs();
        const auto run = runs.runOutput();
        if (!firstMissOfRun_ || runs.runGeneration() < firstMissOfRun_ || !run || !run->truthComputed ||
            runs.runIsStale())
            return;
        firstMissOfRun_ = 0;
        misses_->step(+1);
    });
}

// The Report dock: its sweep's progress also in the status bar, with its
// Cancel; a point loaded from the chart is culled at once, on its backend and
// with the built-in algorithm, so the views show its result.
void MainWindow::wireReport() {
    ReportDock* report = docks_->report();
    connect(report, &ReportDock::started, this, [this, report] {
        statusProgress_->begin("report", tr("report..."), [report] { report->cancel(); }, 0);
    });
    connect(report, &ReportDock::progressed, this, [this](int done, int total, const QString& label) {
        statusProgress_->setProgress("report", double(done) / std::max(total, 1),
                                     tr("report %1/%2 %3").arg(done).arg(total).arg(label));
    });
    connect(report, &ReportDock::finished, this, [this] { statusProgress_->end("report"); });
    connect(report, &ReportDock::cullRequested, this, [this](const QString& backend) {
        if (runTarget_->offers(backend)) setBackend(backend, doc_->runs().device());
        if (customShader_->options() || captureLists_)
            setCustomShader({}); // runs culling
        else
            runCulling();
    });
}

void MainWindow::buildMenus() {
    const WindowActions& a = actions_;
    QMenu* file = menuBar()->addMenu(tr("&File"));
    file->addActions({a.newScene, a.open});
    recentMenu_ = file->addMenu(tr("Open &recent"));
    file->addAction(a.openCapture);
    QMenu* builtins = file->addMenu(tr("&Built-in scene"));
    for (const auto& b : lc::builtinScenes()) {
        QAction* act = builtins->addAction(QString::fromStdString(b.name));
        act->setToolTip(QString::fromStdString(b.description));
        act->setStatusTip(QString::fromStdString(b.description));
        const QString name = QString::fromStdString(b.name);
        connect(act, &QAction::triggered, this, [this, name] { openBuiltin(name); });
    }
    file->addActions({a.import, a.gltfCutoff});
    file->addSeparator();
    file->addActions({a.save, a.saveAs});
    file->addSeparator();
    file->addAction(a.exportDiagnostics);
    file->addSeparator();
    file->addAction(a.quit);

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    edit->addActions({a.undo, a.redo});
    edit->addSeparator();
    edit->addActions({a.addLight, a.addSpotLight, a.duplicate, a.remove, a.generate});
    edit->addSeparator();
    edit->addAction(a.cameraFromView);

    QMenu* view = menuBar()->addMenu(tr("&View"));
    view->addActions({a.tabbedViews, a.resetView, a.frameSelected, a.lookThrough, a.fitCameraImage});
    view->addSeparator();
    for (auto* d : findChildren<QDockWidget*>()) view->addAction(d->toggleViewAction());
    new OverlayMenus(doc_, view, this);
    new ImageModes(doc_, service_, cameraView_, statusProgress_, view, this);

    QMenu* cull = menuBar()->addMenu(tr("&Culling"));
    cull->addActions({a.run, a.live});
    cull->addSeparator();
    cull->addActions({misses_->nextAction(), misses_->previousAction(), a.hunt});
    cull->addSeparator();
    cull->addActions({a.customShader, a.builtinAlgorithm, a.captureLists});
    cull->addSeparator();
    cull->addAction(a.captureRenderDoc);
}

void MainWindow::buildToolbars() {
    const WindowActions& a = actions_;
    QToolBar* fileBar = addToolBar(tr("File"));
    fileBar->setObjectName("fileToolbar");
    fileBar->addActions({a.open, a.save, a.undo, a.redo, a.addLight, a.generate});
    // Run and Live on the first row: at the default 1600-pixel window the
    // culling row's parameters fill its width and push its end out of sight.
    fileBar->addSeparator();
    fileBar->addActions({a.run, a.live});

    // The culling parameters and the engine limits (param_toolbars.hpp).
    params_ = new ParamToolbars(this, doc_);
    connect(params_, &ParamToolbars::logged, this, &MainWindow::log);

    // What runs the culling (custom shader, backend, device) sits on the
    // first row beside the file actions: with it on the parameter row, a
    // 1280-pixel window hid Height, Custom shader, backend and device
    // behind the toolbar's extension arrow.
    runTarget_ = new RunTargetBar(&doc_->runs(), a.customShader, this);
    insertToolBar(params_->cullBar(), runTarget_);
    insertToolBarBreak(params_->cullBar());
}

// --- parameters and culling ------------------------------------------------------------

bool MainWindow::setParamFromUi(const QString& name, const QString& value) { return params_->setParam(name, value); }

bool MainWindow::setPresetFromUi(const QString& name) { return params_->setPreset(name); }

void MainWindow::setBackend(const QString& backend, const QString& device) {
    const QSignalBlocker quiet(&doc_->runs()); // the two in one change
    doc_->runs().setBackend(backend);
    doc_->runs().setDevice(device);
    runTarget_->sync();
}

quint64 MainWindow::runCulling(bool liveEdit) {
    const RunState& runs = doc_->runs();
    const quint64 gen = service_->request(doc_->scene(), runs.settings(), runs.backend(), runs.device(), liveEdit,
                                          CameraView::needsShading(cameraView_->imageMode()),
                                          doc_->geometryRevision(), customShader_->options(), capture_,
                                          captureLists_);
    doc_->runs().noteRunRequested(gen);
    statusBar()->showMessage(tr("culling (run %1)...").arg(gen));
    return gen;
}

void MainWindow::setLive(bool live) { doc_->runs().setLive(live); }
bool MainWindow::isLive() const { return doc_->runs().live(); }

void MainWindow::onRunFinished(quint64 generation, std::shared_ptr<const lc::RunOutput> out) {
    if (!doc_->runs().setRunOutput(out, generation)) return; // an older run finished late
    runStatus_->finished(generation, *out);
    emit runFinished(generation);
}

void MainWindow::onRunFailed(quint64 generation, const QString& message) {
    doc_->runs().noteRunFailed(generation);
    runStatus_->failed(generation, message);
    emit runFailed(generation, message);
}

bool MainWindow::exportDiagnostics(const QString& dir) { return export_->start(dir); }

// --- files -------------------------------------------------------------------------------

bool MainWindow::maybeSave() { return files_->maybeSave(); }
bool MainWindow::newScene() { return files_->newScene(); }
bool MainWindow::openBuiltin(const QString& name) { return files_->openBuiltin(name); }
bool MainWindow::openSceneFile(const QString& path) { return files_->openSceneFile(path); }
bool MainWindow::importMeshFile(const QString& path) { return files_->importMeshFile(path); }
bool MainWindow::save() { return files_->save(); }
bool MainWindow::saveAs(const QString& path) { return files_->saveAs(path); }

void MainWindow::afterSceneOpened(const QString& what) {
    const auto& s = doc_->scene();
    log(tr("opened %1: %2, %3, %4")
            .arg(what)
            .arg(countOf(s.meshes.size(), "mesh", "meshes"))
            .arg(countOf(s.triangleCount(), "triangle", "triangles"))
            .arg(countOf(s.lights.size(), "light", "lights")));
    // With Live on, the new scene's sceneEdited has asked for its run already.
    if (runOnOpen && !isLive()) runCulling();
}

// --- editing ------------------------------------------------------------------------------

int MainWindow::addLightAtCentre() { return addLightAt(QPoint(-1, -1)); }

int MainWindow::addLightAt(const QPoint& pos, lc::LightKind kind) { return lights_->addAt(pos, kind); }

bool MainWindow::generateLights(const lc::LightGenSettings& g) { return lights_->generate(g); }

void MainWindow::setCullingCameraFromInspector() {
    doc_->setCamera(cullingCameraFromVtk(inspectorView_->renderer()->GetActiveCamera(), doc_->scene().camera),
                    tr("Set culling camera from view"));
}

bool MainWindow::setCustomShader(const QString& path) {
    const bool had = customShader_->options() != nullptr || captureLists_;
    try {
        customShader_->set(path);
        captureLists_ = false;
    } catch (const std::exception& e) {
        log(tr("cannot use %1: %2").arg(path, QString::fromStdString(e.what())), true);
        prompts.showError(this, tr("Custom shader"), QString::fromStdString(e.what()));
        return false;
    }
    params_->setListsFromShader(customShader_->options() ? path : QString());
    if (const auto o = customShader_->options())
        log(tr("culling with custom shader %1 (layout %2, lists %3); saving it re-runs")
                .arg(path, QString::fromStdString(lc::toString(o->layout)),
                     QString::fromStdString(lc::toString(o->lists))));
    else if (had)
        log(capture_ ? tr("culling with the built-in algorithm on the capture's depth")
                     : tr("culling with the built-in algorithm again"));
    runCulling();
    return true;
}

QString MainWindow::customShaderPath() const { return customShader_->path(); }

void MainWindow::setGltfMinIntensity(double lux) {
    if (!(lux > 0.0) || !std::isfinite(lux)) return;
    gltfOptions.minIntensity = lux;
    QSettings().setValue("gltf/minIntensity", lux);
    // The open scene's lights without a range take their radius from the
    // cut-off they were read with: re-derive them now (undoable), so the
    // setting does what it says on the scene in front of the user.
    const int n = doc_->setGltfCutoff(lux);
    if (n > 0) {
        log(tr("glTF light cut-off I_min = %1 lux: radii of %2 without a range re-derived (Ctrl+Z undoes), "
               "and for the next glTF opened")
                .arg(lux)
                .arg(countOf(std::uint64_t(n), "light", "lights")));
        if (const std::string w = lc::cutoffCoverageWarning(doc_->scene()); !w.empty()) warn(QString::fromStdString(w));
    } else {
        log(tr("glTF light cut-off I_min = %1 lux (for the next glTF opened; the open scene has no glTF light "
               "without a range)")
                .arg(lux));
    }
}

// --- window ------------------------------------------------------------------------------

QImage MainWindow::grabWindow() {
    cameraView_->renderNow();
    inspectorView_->renderNow();
    return grab().toImage();
}

void MainWindow::log(const QString& message, bool error) { docks_->log()->log(message, error); }

void MainWindow::warn(const QString& message) { docks_->log()->warn(message); }

void MainWindow::updateTitle() {
    const QString file = doc_->filePath().isEmpty() ? QString::fromStdString(doc_->scene().name)
                                                    : QFileInfo(doc_->filePath()).fileName();
    setWindowTitle(tr("%1[*] - LightCull Studio").arg(file.isEmpty() ? tr("untitled") : file));
    setWindowModified(doc_->isDirty());
}

void MainWindow::restoreSettings() {
    QSettings st;
    {
        const double lux = st.value("gltf/minIntensity", lc::kGltfDefaultMinIntensity).toDouble();
        if (lux > 0.0 && std::isfinite(lux)) gltfOptions.minIntensity = lux;
    }
    restoreGeometry(st.value("window/geometry").toByteArray());
    restoreState(st.value("window/state").toByteArray());
    views_->restore(st);
    actions_.tabbedViews->setChecked(st.value("window/tabbedViews", false).toBool());
    views_->setTabbed(actions_.tabbedViews->isChecked());
    // Last culling parameters (the camera-owned ones belong to the scene).
    const lc::CullSettings s = readCullSettings(st, doc_->runs().settings());
    // Live comes back on without a run: the window holds no scene yet, and
    // the scene opened next runs once (a run here logged 'run 1: 0 lights').
    restoringSettings_ = true;
    doc_->runs().setSettings(s);
    const QString backend = st.value("backend").toString();
    setBackend(runTarget_->offers(backend) ? backend : doc_->runs().backend(), st.value("device").toString());
    doc_->runs().setLive(st.value("live", false).toBool());
    restoringSettings_ = false;
}

void MainWindow::saveSettings() {
    QSettings st;
    st.setValue("window/geometry", saveGeometry());
    st.setValue("window/state", saveState());
    views_->save(st);
    st.setValue("window/tabbedViews", views_->tabbed());
    writeCullSettings(st, doc_->runs().settings());
    st.setValue("backend", doc_->runs().backend());
    st.setValue("device", doc_->runs().device());
    st.setValue("live", isLive());
}

void MainWindow::closeEvent(QCloseEvent* e) {
    if (!maybeSave()) {
        e->ignore();
        return;
    }
    saveSettings();
    e->accept();
}

void MainWindow::dragEnterEvent(QDragEnterEvent* e) {
    if (e->mimeData()->hasUrls()) e->acceptProposedAction();
}

void MainWindow::dropEvent(QDropEvent* e) {
    for (const QUrl& url : e->mimeData()->urls()) {
        if (!url.isLocalFile()) continue;
        const QString f = url.toLocalFile();
        // Scene files (with lights and a camera) open; meshes are imported.
        if (f.endsWith(".json", Qt::CaseInsensitive) || lc::isGltfPath(f.toStdString())) openSceneFile(f);
        else importMeshFile(f);
    }
    e->acceptProposedAction();
}

} // namespace lcui
