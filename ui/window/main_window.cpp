#include "window/main_window.hpp"
#include "document/miss_navigator.hpp"
#include "window/param_toolbars.hpp"
#include "window/scene_files.hpp"
#include "work/custom_shader_source.hpp"

#include "views/camera_view.hpp"
#include "work/cull_worker.hpp"
#include "document/document.hpp"
#include "panels/explain_panel.hpp"
#include "panels/generate_dialog.hpp"
#include "views/inspector_view.hpp"
#include "work/progress_task.hpp"
#include "widgets/status_progress.hpp"
#include "panels/property_panel.hpp"
#include "panels/scene_tree.hpp"
#include "panels/tile_inspector.hpp"
#include "widgets/field_events.hpp"
#include "panels/report_dock.hpp"
#include "views/vtk_adapters.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/presets.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QCloseEvent>
#include <QComboBox>
#include <QCursor>
#include <QDateTime>
#include <QDockWidget>
#include <QDragEnterEvent>
#include <QDropEvent>
#include <QElapsedTimer>
#include <QFile>
#include <QFileDialog>
#include <QHBoxLayout>
#include <QScrollArea>
#include <QScrollBar>
#include <QTimer>
#include <QInputDialog>
#include <QFileInfo>
#include <QLabel>
#include <QLineEdit>
#include <QMenuBar>
#include <QMimeData>
#include <QPlainTextEdit>
#include <QSettings>
#include <QSpinBox>
#include <QSplitter>
#include <QStatusBar>
#include <QTabBar>
#include <QToolBar>
#include <QUndoStack>
#include <QVBoxLayout>

#include <vtkCamera.h>
#include <vtkRenderer.h>

#include <cmath>
#include <set>

namespace lcui {

namespace {

QString describe(const std::exception& e) { return QString::fromStdString(e.what()); }
} // namespace

MainWindow::MainWindow(QWidget* parent) : QMainWindow(parent) {
    setObjectName("LightCullStudio");
    doc_ = new Document(this);
    service_ = new CullService(this);
    misses_ = new MissNavigator(doc_, this);
    connect(misses_, &MissNavigator::message, this, [this](const QString& text) {
        log(text);
        statusBar()->showMessage(text, 10000);
    });

    prompts.askUnsaved = [](QWidget* parent, const QString& text) {
        return QMessageBox::question(parent, tr("Unsaved changes"), text,
                                     QMessageBox::Save | QMessageBox::Discard | QMessageBox::Cancel,
                                     QMessageBox::Save);
    };
    prompts.showError = [](QWidget* parent, const QString& title, const QString& text) {
        QMessageBox::critical(parent, title, text);
    };
    prompts.openPath = [](QWidget* parent, const QString& caption, const QString& filter) {
        return QFileDialog::getOpenFileName(parent, caption, {}, filter);
    };
    prompts.savePath = [](QWidget* parent, const QString& caption, const QString& filter) {
        return QFileDialog::getSaveFileName(parent, caption, {}, filter);
    };
    prompts.askNumber = [](QWidget* parent, const QString& title, const QString& label, double min, double max,
                           double& value) {
        bool ok = false;
        const double v = QInputDialog::getDouble(parent, title, label, value, min, max, 6, &ok);
        if (ok) value = v;
        return ok;
    };

    // Views: side by side in a splitter; "tabbed" shows one at a time through
    // the tab bar (no re-parenting of the GL widgets).
    cameraView_ = new CameraView(doc_);
    cameraView_->setObjectName("cameraView");
    inspectorView_ = new InspectorView(doc_);
    inspectorView_->setObjectName("inspectorView");
    viewSplitter_ = new QSplitter(Qt::Horizontal);
    viewSplitter_->setObjectName("viewSplitter");
    viewSplitter_->addWidget(cameraView_);
    viewSplitter_->addWidget(inspectorView_);
    viewTabs_ = new QTabBar;
    viewTabs_->addTab(tr("Camera view"));
    viewTabs_->addTab(tr("Inspector view"));
    connect(viewTabs_, &QTabBar::currentChanged, this, [this](int i) {
        if (!viewTabs_->isVisible()) return;
        cameraView_->setVisible(i == 0);
        inspectorView_->setVisible(i == 1);
    });
    auto* central = new QWidget;
    auto* vl = new QVBoxLayout(central);
    vl->setContentsMargins(0, 0, 0, 0);
    vl->setSpacing(0);
    vl->addWidget(viewTabs_);
    vl->addWidget(viewSplitter_, 1);
    setCentralWidget(central);

    buildDocks();
    buildActions();
    buildMenus();
    buildToolbar();
    buildStatusBar();
    customShader_ = new CustomShaderSource(this);
    connect(customShader_, &CustomShaderSource::changed, this, [this] { runCulling(); });
    connect(customShader_, &CustomShaderSource::logged, this, [this](const QString& m, bool error) { log(m, error); });
    files_ = new SceneFiles(this, doc_, statusProgress_, prompts, gltfOptions);
    files_->setRecentMenu(recentMenu_);
    connect(files_, &SceneFiles::logged, this, [this](const QString& m, bool error) { log(m, error); });
    connect(files_, &SceneFiles::warned, this, &MainWindow::warn);
    connect(files_, &SceneFiles::opened, this, &MainWindow::afterSceneOpened);
    setAcceptDrops(true);

    connect(service_, &CullService::finished, this, &MainWindow::onRunFinished);
    connect(service_, &CullService::failed, this, &MainWindow::onRunFailed);
    connect(service_, &CullService::backendReady, this, [this](const QString& name, const QString& device) {
        lastBackendName_ = name;
        lastDeviceName_ = device;
        log(tr("backend %1 on %2").arg(name, device));
        updateStatus();
    });
    connect(doc_, &Document::sceneEdited, this, [this] {
        if (isLive()) runCulling(/*liveEdit=*/true);
    });
    connect(doc_, &Document::settingsChanged, this, [this] {
        params_->sync();
        if (isLive()) runCulling();
    });
    connect(doc_, &Document::cameraChanged, params_, &ParamToolbars::sync);
    connect(doc_, &Document::sceneReset, params_, &ParamToolbars::sync);
    connect(doc_, &Document::dirtyChanged, this, &MainWindow::updateTitle);
    connect(doc_, &Document::filePathChanged, this, &MainWindow::updateTitle);
    connect(doc_, &Document::runOutputChanged, this, &MainWindow::updateStatus);
    connect(doc_, &Document::runWentStale, this, &MainWindow::updateStatus);
    // The cut-off label follows the scene (a new file, an undone cut-off).
    connect(doc_, &Document::sceneReset, this, &MainWindow::updateCutoffStatus);
    connect(doc_, &Document::lightsChanged, this, &MainWindow::updateCutoffStatus);

    resize(1600, 900);
    // First start: views get the room, the log stays a strip at the bottom,
    // the scene tree is tall and the tile inspector and Explain are wide
    // enough for their columns (a saved layout wins from then on).
    resizeDocks({findChild<QDockWidget*>("logDock")}, {110}, Qt::Vertical);
    resizeDocks({findChild<QDockWidget*>("sceneDock"), findChild<QDockWidget*>("propertiesDock")}, {420, 300},
                Qt::Vertical);
    resizeDocks({findChild<QDockWidget*>("sceneDock"), findChild<QDockWidget*>("tileDock")}, {260, 330},
                Qt::Horizontal);
    restoreSettings();
    params_->sync();
    updateTitle();
    updateStatus();
    updateCutoffStatus();
}

MainWindow::~MainWindow() = default;

QAction* MainWindow::action(const QString& objectName) const { return findChild<QAction*>(objectName); }

// --- construction ---------------------------------------------------------------

void MainWindow::buildDocks() {
    auto dock = [this](const QString& title, const char* name, QWidget* w, Qt::DockWidgetArea area) {
        auto* d = new QDockWidget(title, this);
        d->setObjectName(name);
        d->setWidget(w);
        addDockWidget(area, d);
        return d;
    };
    tree_ = new SceneTree(doc_);
    tree_->setObjectName("sceneTree");
    properties_ = new PropertyPanel(doc_);
    connect(properties_, &PropertyPanel::editRefused, this, [this](const QString& why) {
        log(why, true);
        statusBar()->showMessage(why, 10000);
    });
    properties_->setObjectName("propertyPanel");
    tileInspector_ = new TileInspector(doc_);
    tileInspector_->setObjectName("tileInspector");
    log_ = new QPlainTextEdit;
    log_->setObjectName("messageLog");
    log_->setReadOnly(true);
    log_->setMaximumBlockCount(5000);
    // The scene tree with a filter box and the light order above it.
    auto* scenePane = new QWidget;
    {
        auto* filter = new QLineEdit;
        filter->setObjectName("sceneFilter");
        filter->setPlaceholderText(tr("Filter lights by name or index"));
        filter->setClearButtonEnabled(true);
        connect(filter, &QLineEdit::textChanged, tree_, &SceneTree::setLightFilter);
        auto* sort = new QComboBox;
        sort->setObjectName("sceneSort");
        sort->addItem(tr("by index"), int(SceneTree::LightSort::Index));
        sort->addItem(tr("by name"), int(SceneTree::LightSort::Name));
        sort->addItem(tr("by radius"), int(SceneTree::LightSort::Radius));
        sort->addItem(tr("by tiles reached"), int(SceneTree::LightSort::TilesReached));
        connect(sort, qOverload<int>(&QComboBox::currentIndexChanged), this, [this, sort] {
            tree_->setLightSort(SceneTree::LightSort(sort->currentData().toInt()));
        });
        auto* row = new QHBoxLayout;
        row->addWidget(filter, 1);
        row->addWidget(sort);
        auto* col = new QVBoxLayout(scenePane);
        col->setContentsMargins(0, 0, 0, 0);
        col->addLayout(row);
        col->addWidget(tree_, 1);
    }
    dock(tr("Scene"), "sceneDock", scenePane, Qt::LeftDockWidgetArea);
    // The properties scroll inside their dock: a spot light's fields are 400
    // px tall, and as the dock's minimum they would keep the bottom area a
    // strip on a laptop's screen.
    auto* propertiesScroll = new QScrollArea;
    propertiesScroll->setWidget(properties_);
    propertiesScroll->setWidgetResizable(true);
    propertiesScroll->setFrameShape(QFrame::NoFrame);
    propertiesScroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
    propertiesScroll->setMinimumWidth(properties_->minimumSizeHint().width() +
                                      propertiesScroll->verticalScrollBar()->sizeHint().width());
    dock(tr("Properties"), "propertiesDock", propertiesScroll, Qt::LeftDockWidgetArea);
    auto* tileDock = dock(tr("Tile inspector"), "tileDock", tileInspector_, Qt::RightDockWidgetArea);
    explain_ = new ExplainPanel(doc_);
    explain_->setObjectName("explainPanel");
    auto* explainDock = dock(tr("Explain"), "explainDock", explain_, Qt::RightDockWidgetArea);
    connect(misses_, &MissNavigator::missSelected, this, [explainDock] {
        explainDock->show();
        explainDock->raise();
    });
    splitDockWidget(tileDock, explainDock, Qt::Vertical);
    dock(tr("Message log"), "logDock", log_, Qt::BottomDockWidgetArea);
    auto* logDock = findChild<QDockWidget*>("logDock");
    // The Report's chart and table scroll inside their dock, so that the
    // bottom area can be a strip of a few log lines.
    auto* reportScroll = new QScrollArea;
    auto* report = new ReportDock(doc_);
    reportScroll->setWidget(report);
    // The sweep's progress also in the status bar, with its Cancel.
    connect(report, &ReportDock::started, this, [this, report] {
        statusProgress_->begin("report", tr("report..."), [report] { report->cancel(); }, 0);
    });
    connect(report, &ReportDock::progressed, this, [this](int done, int total, const QString& label) {
        statusProgress_->setProgress("report", double(done) / std::max(total, 1),
                                     tr("report %1/%2 %3").arg(done).arg(total).arg(label));
    });
    connect(report, &ReportDock::finished, this, [this] { statusProgress_->end("report"); });
    // A point loaded from the chart is culled at once, on its backend and
    // with the built-in algorithm, so the views show its result.
    connect(report, &ReportDock::cullRequested, this, [this](const QString& backend) {
        if (backendCombo_->findText(backend) >= 0) backendCombo_->setCurrentText(backend);
        if (customShader_->options())
            setCustomShader({}); // runs culling
        else
            runCulling();
    });
    reportScroll->setWidgetResizable(true);
    reportScroll->setFrameShape(QFrame::NoFrame);
    auto* reportDock = dock(tr("Report"), "reportDock", reportScroll, Qt::BottomDockWidgetArea);
    tabifyDockWidget(logDock, reportDock);
    // A first start shows the log; the Report tab is one click away (a saved
    // layout wins).
    logDock->raise();
    // The log is a strip of a few lines; the Report's chart is not readable
    // in one. Raising the Report tab grows the bottom area to a readable
    // height, and raising the log again gives the strip back, unless the
    // user has resized it in between. Deferred: while the tab bar switches,
    // the dock layout has not yet taken the new tab.
    connect(reportDock, &QDockWidget::visibilityChanged, this, [this, reportDock](bool visible) {
        if (!visible || reportDock->isFloating()) return;
        QTimer::singleShot(0, this, [this, reportDock] {
            const int want = std::clamp(height() * 45 / 100, 120, 420);
            if (!reportDock->isVisible() || reportDock->isFloating() || reportDock->height() >= want) return;
            stripHeight_ = reportDock->height();
            resizeDocks({reportDock}, {want}, Qt::Vertical);
            // What the docks around let it have (the left and right columns'
            // minimum heights bound it).
            QTimer::singleShot(0, this, [this, reportDock] { grownHeight_ = reportDock->height(); });
        });
    });
    connect(logDock, &QDockWidget::visibilityChanged, this, [this, logDock](bool visible) {
        if (!visible || logDock->isFloating() || grownHeight_ == 0) return;
        QTimer::singleShot(0, this, [this, logDock] {
            // Only the height the Report tab set is given back.
            if (logDock->isVisible() && std::abs(logDock->height() - grownHeight_) <= 2)
                resizeDocks({logDock}, {stripHeight_}, Qt::Vertical);
            grownHeight_ = 0;
        });
    });
}

void MainWindow::buildActions() {
    auto make = [this](const QString& text, const char* name, QKeySequence key = {}) {
        auto* a = new QAction(text, this);
        a->setObjectName(name);
        if (!key.isEmpty()) a->setShortcut(key);
        return a;
    };
    connect(make(tr("&New"), "actionNew", QKeySequence::New), &QAction::triggered, this, [this] { newScene(); });
    connect(make(tr("&Open scene..."), "actionOpen", QKeySequence::Open), &QAction::triggered, this, [this] {
        const QString p = prompts.openPath(this, tr("Open scene"),
                                           tr("Scenes (*.json *.gltf *.glb);;Scene JSON (*.json);;glTF 2.0 (*.gltf *.glb)"));
        if (!p.isEmpty()) openSceneFile(p);
    });
    connect(make(tr("&Import mesh..."), "actionImport", QKeySequence(tr("Ctrl+I"))), &QAction::triggered, this,
            [this] {
                const QString p = prompts.openPath(this, tr("Import mesh"),
                                                   tr("Meshes (*.obj *.ply *.off *.stl *.om *.gltf *.glb)"));
                if (!p.isEmpty()) importMeshFile(p);
            });
    connect(make(tr("&Save"), "actionSave", QKeySequence::Save), &QAction::triggered, this, [this] { save(); });
    connect(make(tr("Save &as..."), "actionSaveAs", QKeySequence(tr("Ctrl+Shift+S"))), &QAction::triggered, this, [this] {
        const QString p = prompts.savePath(this, tr("Save scene as"),
                                           tr("Scene JSON (*.json);;Binary glTF (*.glb);;glTF 2.0 (*.gltf)"));
        if (!p.isEmpty()) saveAs(p);
    });
    connect(make(tr("&Quit"), "actionQuit", QKeySequence(tr("Ctrl+Q"))), &QAction::triggered, this, &QWidget::close);
    connect(make(tr("glTF light &cut-off..."), "actionGltfCutoff"), &QAction::triggered, this, [this] {
        double v = gltfOptions.minIntensity;
        if (prompts.askNumber(this, tr("glTF light cut-off"),
                              tr("I_min (lux) for glTF lights without a range:\nradius = sqrt(intensity x colour / "
                                 "I_min). Applies to the open scene's lights without a range (one undo step) "
                                 "and to the next glTF opened."),
                              1e-6, 1e6, v))
            setGltfMinIntensity(v);
    });

    QAction* undo = doc_->undoStack()->createUndoAction(this, tr("&Undo"));
    undo->setObjectName("actionUndo");
    undo->setShortcut(QKeySequence::Undo);
    QAction* redo = doc_->undoStack()->createRedoAction(this, tr("&Redo"));
    redo->setObjectName("actionRedo");
    // Ctrl+Shift+Z and the platform's Redo keys, each once: a key bound twice
    // to one action is ambiguous to Qt and does nothing (some platforms'
    // Redo is Ctrl+Shift+Z).
    QList<QKeySequence> redoKeys{QKeySequence(tr("Ctrl+Shift+Z"))};
    for (const QKeySequence& k : QKeySequence::keyBindings(QKeySequence::Redo))
        if (!redoKeys.contains(k)) redoKeys << k;
    redo->setShortcuts(redoKeys);

    connect(make(tr("&Add light"), "actionAddLight", QKeySequence(tr("Ctrl+L"))), &QAction::triggered, this,
            [this] { addLightAt(inspectorView_->mapFromGlobal(QCursor::pos())); });
    connect(make(tr("Add &spot light"), "actionAddSpotLight", QKeySequence(tr("Ctrl+Shift+L"))),
            &QAction::triggered, this, [this] {
                addLightAt(inspectorView_->mapFromGlobal(QCursor::pos()), lc::LightKind::Spot);
            });
    connect(make(tr("&Duplicate"), "actionDuplicate", QKeySequence(tr("Ctrl+D"))), &QAction::triggered, this,
            [this] { doc_->duplicateLights(doc_->selectedLights()); });
    connect(make(tr("De&lete"), "actionDelete", QKeySequence::Delete), &QAction::triggered, this,
            [this] { doc_->deleteLights(doc_->selectedLights()); });
    connect(make(tr("&Generate lights..."), "actionGenerate", QKeySequence(tr("Ctrl+G"))), &QAction::triggered,
            this, [this] {
                GenerateLightsDialog dlg(lc::defaultLightGen(doc_->scene(), 256, 1), this);
                if (dlg.exec() == QDialog::Accepted) generateLights(dlg.settings());
            });
    connect(make(tr("Set culling camera from this view"), "actionCameraFromView"), &QAction::triggered, this,
            &MainWindow::setCullingCameraFromInspector);
    connect(make(tr("Reset inspector camera"), "actionResetView"), &QAction::triggered, this,
            [this] { inspectorView_->resetCamera(); });
    connect(make(tr("&Frame selected"), "actionFrameSelected", QKeySequence(Qt::Key_F)), &QAction::triggered, this,
            [this] {
                if (!inspectorView_->frameSelected())
                    statusBar()->showMessage(tr("Nothing selected to frame: click a tile or pick a light"), 4000);
                else if (!inspectorView_->frameNote().isEmpty())
                    statusBar()->showMessage(inspectorView_->frameNote(), 6000);
            });
    connect(make(tr("&Look through the culling camera"), "actionLookThrough", QKeySequence(Qt::Key_C)),
            &QAction::triggered, this, [this] { inspectorView_->lookThroughCullingCamera(); });
    // The camera view's zoom (the wheel zooms, a right or middle drag pans).
    connect(make(tr("Fit camera &image"), "actionFitCameraImage", QKeySequence(tr("Ctrl+0"))), &QAction::triggered,
            this, [this] { cameraView_->fitImage(); });
    QAction* tabbed = make(tr("Tabbed views"), "actionTabbedViews");
    tabbed->setCheckable(true);
    connect(tabbed, &QAction::toggled, this, &MainWindow::setTabbedViews);

    connect(make(tr("&Run culling"), "actionRun", QKeySequence(Qt::Key_F5)), &QAction::triggered, this,
            [this] { runCulling(); });
    connect(make(tr("Custom &shader..."), "actionCustomShader"), &QAction::triggered, this, [this] {
        const QString p = prompts.openPath(this, tr("Custom culling shader"),
                                           tr("Culling shaders (*.comp *.glsl *.hlsl *.spv)"));
        if (!p.isEmpty()) setCustomShader(p);
    });
    connect(make(tr("&Built-in algorithm"), "actionBuiltinAlgorithm"), &QAction::triggered, this,
            [this] { setCustomShader({}); });
    connect(make(tr("&Hunt for a miss..."), "actionHunt", QKeySequence(tr("Ctrl+H"))), &QAction::triggered, this,
            &MainWindow::huntFromDialog);
    // A hunt's repro opens with its miss selected once its run has the truth
    // (selectFirstMissOfRun).
    connect(this, &MainWindow::runFinished, this, [this] {
        const auto run = doc_->runOutput();
        if (!firstMissOfRun_ || doc_->runGeneration() < firstMissOfRun_ || !run || !run->truthComputed ||
            doc_->runIsStale())
            return;
        firstMissOfRun_ = 0;
        misses_->step(+1);
    });
    QAction* live = make(tr("Live"), "actionLive");
    live->setCheckable(true);
    live->setToolTip(tr("Re-run culling after every edit"));
    connect(live, &QAction::toggled, this, [this](bool on) {
        if (on && !restoringSettings_) runCulling();
    });
}

void MainWindow::buildMenus() {
    QMenu* file = menuBar()->addMenu(tr("&File"));
    file->addAction(action("actionNew"));
    file->addAction(action("actionOpen"));
    recentMenu_ = file->addMenu(tr("Open &recent"));
    QMenu* builtins = file->addMenu(tr("&Built-in scene"));
    for (const auto& b : lc::builtinScenes()) {
        QAction* a = builtins->addAction(QString::fromStdString(b.name));
        a->setToolTip(QString::fromStdString(b.description));
        a->setStatusTip(QString::fromStdString(b.description));
        const QString name = QString::fromStdString(b.name);
        connect(a, &QAction::triggered, this, [this, name] { openBuiltin(name); });
    }
    file->addAction(action("actionImport"));
    file->addAction(action("actionGltfCutoff"));
    file->addSeparator();
    file->addAction(action("actionSave"));
    file->addAction(action("actionSaveAs"));
    file->addSeparator();
    QMenu* overlayFileMenu = file; // File > Export diagnostics... (main_window_overlays.cpp)
    file->addAction(action("actionQuit"));

    QMenu* edit = menuBar()->addMenu(tr("&Edit"));
    edit->addAction(action("actionUndo"));
    edit->addAction(action("actionRedo"));
    edit->addSeparator();
    edit->addAction(action("actionAddLight"));
    edit->addAction(action("actionAddSpotLight"));
    edit->addAction(action("actionDuplicate"));
    edit->addAction(action("actionDelete"));
    edit->addAction(action("actionGenerate"));
    edit->addSeparator();
    edit->addAction(action("actionCameraFromView"));

    QMenu* view = menuBar()->addMenu(tr("&View"));
    view->addAction(action("actionTabbedViews"));
    view->addAction(action("actionResetView"));
    view->addAction(action("actionFrameSelected"));
    view->addAction(action("actionLookThrough"));
    view->addAction(action("actionFitCameraImage"));
    view->addSeparator();
    for (auto* d : findChildren<QDockWidget*>()) view->addAction(d->toggleViewAction());
    buildOverlayMenus(overlayFileMenu, view);
    buildImageModes(view);

    QMenu* cull = menuBar()->addMenu(tr("&Culling"));
    cull->addAction(action("actionRun"));
    cull->addAction(action("actionLive"));
    cull->addSeparator();
    cull->addAction(misses_->nextAction());
    cull->addAction(misses_->previousAction());
    cull->addAction(action("actionHunt"));
    cull->addSeparator();
    cull->addAction(action("actionCustomShader"));
    cull->addAction(action("actionBuiltinAlgorithm"));
}

void MainWindow::buildToolbar() {
    QToolBar* fileBar = addToolBar(tr("File"));
    fileBar->setObjectName("fileToolbar");
    fileBar->addAction(action("actionOpen"));
    fileBar->addAction(action("actionSave"));
    fileBar->addAction(action("actionUndo"));
    fileBar->addAction(action("actionRedo"));
    fileBar->addAction(action("actionAddLight"));
    fileBar->addAction(action("actionGenerate"));
    // Run and Live on the first row: at the default 1600-pixel window the
    // culling row's parameters fill its width and push its end out of sight.
    fileBar->addSeparator();
    fileBar->addAction(action("actionRun"));
    fileBar->addAction(action("actionLive"));

    // The culling parameters and the engine limits (param_toolbars.hpp).
    params_ = new ParamToolbars(this, doc_);
    connect(params_, &ParamToolbars::logged, this, [this](const QString& m, bool error) { log(m, error); });
    QToolBar* bar = params_->cullBar();

    // What runs the culling (custom shader, backend, device) sits on the
    // first row beside the file actions: with it on the parameter row, a
    // 1280-pixel window hid Height, Custom shader, backend and device
    // behind the toolbar's extension arrow.
    QToolBar* runBar = new QToolBar(tr("Run target"));
    runBar->setObjectName("runToolbar");
    insertToolBar(bar, runBar);
    insertToolBarBreak(bar);
    bar = runBar;
    bar->addAction(action("actionCustomShader"));
    bar->addSeparator();
    bar->addWidget(new QLabel(tr("backend ")));
    backendCombo_ = new QComboBox;
    backendCombo_->setObjectName("backendCombo");
    for (const auto& b : lc::availableBackends()) backendCombo_->addItem(QString::fromStdString(b));
    backendCombo_->setCurrentText(CullService::defaultBackend());
    bar->addWidget(backendCombo_);
    deviceEdit_ = new QLineEdit;
    deviceEdit_->setObjectName("deviceEdit");
    deviceEdit_->setPlaceholderText(tr("device (default)"));
    deviceEdit_->setToolTip(tr("Vulkan device: index or name substring; empty = LIGHTCULL_DEVICE or the first"));
    deviceEdit_->setMaximumWidth(140);
    bar->addWidget(deviceEdit_);
    connect(backendCombo_, &QComboBox::textActivated, this, [this] {
        if (isLive()) runCulling();
    });
    connect(deviceEdit_, &QLineEdit::editingFinished, this, [this] {
        if (isLive()) runCulling();
    });
}

void MainWindow::buildStatusBar() {
    statusProgress_ = new StatusProgress;
    statusBar()->addPermanentWidget(statusProgress_);
    auto label = [this](const char* name) {
        auto* l = new QLabel;
        l->setObjectName(name);
        statusBar()->addPermanentWidget(l);
        return l;
    };
    statusBackend_ = label("statusBackend");
    statusTimes_ = label("statusTimes");
    statusFn_ = label("statusFalseNegatives");
    statusEfficiency_ = label("statusEfficiency");
    statusLists_ = label("statusLists");
    statusCutoff_ = label("statusCutoff");
}

// --- parameters --------------------------------------------------------------------

bool MainWindow::setParamFromUi(const QString& name, const QString& value) { return params_->setParam(name, value); }

bool MainWindow::setPresetFromUi(const QString& name) { return params_->setPreset(name); }

void MainWindow::setBackend(const QString& backend, const QString& device) {
    backendCombo_->setCurrentText(backend);
    deviceEdit_->setText(device);
}

// --- culling -------------------------------------------------------------------------

quint64 MainWindow::runCulling(bool liveEdit) {
    const quint64 gen = service_->request(doc_->scene(), doc_->settings(), backendCombo_->currentText(),
                                          deviceEdit_->text(), liveEdit,
                                          CameraView::needsShading(cameraView_->imageMode()),
                                          doc_->geometryRevision(), customShader_->options());
    doc_->noteRunRequested(gen);
    statusBar()->showMessage(tr("culling (run %1)...").arg(gen));
    return gen;
}

void MainWindow::setLive(bool live) { action("actionLive")->setChecked(live); }
bool MainWindow::isLive() const { return action("actionLive")->isChecked(); }

namespace {
// How a run's all-lights image was made, when not shaded from every light.
QString allLightsNote(const lc::RunOutput& out) {
    if (out.allLightsReused) return MainWindow::tr(" (the all-lights image kept: same pixels and lights)");
    if (!out.allLightsUpdate) return {};
    const auto& u = *out.allLightsUpdate;
    return MainWindow::tr(" (the all-lights image updated for the lights that changed: terms out %1, in %2; "
                          "pixels shaded again from every light %3)")
        .arg(qulonglong(u.removed))
        .arg(qulonglong(u.added))
        .arg(qulonglong(u.pixelsShadedAgain));
}
} // namespace

void MainWindow::onRunFinished(quint64 generation, std::shared_ptr<const lc::RunOutput> out) {
    if (!doc_->setRunOutput(out, generation)) return; // an older run finished late
    const auto& m = out->truth.metrics;
    // A Live edit's lists arrive before its ground truth: log once, with it;
    // the shaded images come last, with the image error.
    if (!out->shadedAll.empty()) {
        log(tr("run %1: image RMSE %2, max error %3, shading %4 ms%5")
                .arg(generation)
                .arg(m.imageRmse, 0, 'g', 6)
                .arg(m.imageMaxError, 0, 'g', 6)
                .arg(out->result.timings.shadeMs, 0, 'f', 2)
                .arg(allLightsNote(*out)));
        emit runFinished(generation);
        return;
    }
    if (out->custom && out->truthComputed) {
        const lc::CustomCullReport& c = *out->custom;
        log(tr("custom shader %1 (%2, %3): overflowed lists %4, invalid indices %5, validation messages %6, "
               "%7 lists differ from built-in %8")
                .arg(QString::fromStdString(c.source), QString::fromStdString(c.layout), QString::fromStdString(c.lists))
                .arg(c.overflowLists)
                .arg(c.invalidIndices)
                .arg(c.validationMessages.size())
                .arg(c.listsDifferingFromBuiltin)
                .arg(QString::fromStdString(c.builtinAlgorithm)),
            c.overflowLists > 0 || c.invalidIndices > 0 || !c.validationMessages.empty());
        for (const std::string& m : c.validationMessages) log(QString::fromStdString(m), true);
    }
    // The pre-pass's triangles, where it ran (the Vulkan backend draws only
    // the faces of closed solids turned towards the camera).
    const QString depthTriangles =
        out->result.depthTriangles == 0
            ? QString()
            : tr(" (%1 of %2 triangles)")
                  .arg(qulonglong(out->result.depthTrianglesDrawn))
                  .arg(qulonglong(out->result.depthTriangles));
    // The worker keeps the last depth image while the camera and meshes stay.
    const QString depthTime = out->depthReused ? tr("reused (camera and meshes unchanged)")
                                               : tr("%1 ms").arg(out->result.timings.depthMs, 0, 'f', 2);
    if (out->truthComputed) {
        const QString line = tr("run %1: %2, %3 lights, depth %4%8, cull %5 ms, false negatives %6, efficiency %7")
                                 .arg(generation)
                                 .arg(out->custom ? QStringLiteral("custom") : QString(lc::toString(out->result.algorithm)))
                                 .arg(out->lights.size())
                                 .arg(depthTime)
                                 .arg(out->result.timings.cullMs, 0, 'f', 2)
                                 .arg(m.falseNegatives)
                                 .arg(m.efficiency, 0, 'f', 4)
                                 .arg(depthTriangles);
        if (m.falseNegatives > 0) warn(line); // a finding about the culling, not a failure of the run
        else log(line);
        // The engine limits: what they took, by cause, and what would keep it.
        const lc::ListLimits& lim = out->result.limits;
        if (!out->custom && out->result.settings.hasLimits() && (!lim.empty() || m.falseNegatives)) {
            QString keep;
            if (m.falseNegativesListFull)
                keep += tr("; a cap of %1 (the longest list) never overflows").arg(lim.longestUncapped);
            if (m.falseNegativesLightLimit)
                keep += tr("; %1 lights past max-lights %2").arg(qulonglong(lim.lightsOverLimit))
                            .arg(out->result.settings.maxLights);
            log(tr("run %1 limits: %2 over-full lists, %3 entries dropped; misses by cause: culling test %4, list "
                   "full %5, light limit %6%7 (lightcull report --presets finds the smallest values that keep every "
                   "light)")
                    .arg(generation)
                    .arg(qulonglong(lim.overflowLists.size()))
                    .arg(qulonglong(lim.droppedLights.size()))
                    .arg(qulonglong(m.falseNegativesCullingTest()))
                    .arg(qulonglong(m.falseNegativesListFull))
                    .arg(qulonglong(m.falseNegativesLightLimit))
                    .arg(keep));
        }
    }
    statusBar()->showMessage(tr("culling done (run %1)").arg(generation), 4000);
    emit runFinished(generation);
}

void MainWindow::onRunFailed(quint64 generation, const QString& message) {
    failedGeneration_ = std::max(failedGeneration_, generation);
    doc_->noteRunFailed(generation);
    log(tr("run %1 failed: %2").arg(generation).arg(message), true);
    statusBar()->showMessage(tr("culling failed: %1").arg(message), 10000);
    updateStatus();
    emit runFailed(generation, message);
}

void MainWindow::updateCutoffStatus() {
    // The cut-off that sized the lights without a range: a radius the file
    // did not give, so the user should see where it came from.
    const std::size_t cut = lc::gltfCutoffLights(doc_->scene()).size();
    statusCutoff_->setVisible(cut > 0);
    statusCutoff_->setText(tr("cut-off %1 lux (%2 lights)").arg(doc_->scene().origin.gltfMinIntensity).arg(cut));
    statusCutoff_->setToolTip(tr("%1 lights have no glTF range: their radius is sqrt(intensity x colour / I_min) "
                                 "at I_min = %2 lux. File > glTF light cut-off... changes it.")
                                  .arg(cut)
                                  .arg(doc_->scene().origin.gltfMinIntensity));
}

void MainWindow::updateStatus() {
    const auto run = doc_->runOutput();
    const QString backend = run ? QString::fromStdString(run->result.backend) : lastBackendName_;
    const QString device = run ? QString::fromStdString(run->result.device) : lastDeviceName_;
    statusBackend_->setText(backend.isEmpty() ? tr("no backend yet") : tr("%1 | %2").arg(backend, device));
    if (!run) {
        statusTimes_->setText(tr("depth - ms | cull - ms"));
        statusFn_->setText(tr("FN -"));
        statusFn_->setStyleSheet({});
        statusEfficiency_->setText(tr("efficiency -"));
        statusLists_->setText(tr("mean/max list -"));
        return;
    }
    const auto& m = run->truth.metrics;
    // A run that only moved lights reuses the previous depth image (cull_worker).
    const QString depth = run->depthReused ? tr("depth reused")
                                           : tr("depth %1 ms").arg(run->result.timings.depthMs, 0, 'f', 2);
    statusTimes_->setText(tr("%1 | cull %2 ms").arg(depth).arg(run->result.timings.cullMs, 0, 'f', 2));
    // The figures stay (they describe the run shown) but say they are old.
    statusTimes_->setStyleSheet(doc_->runIsStale() ? "color: white; background: #b9770e; padding: 0 4px" : "");
    statusTimes_->setToolTip(doc_->runIsStale() ? tr("The scene changed since this run: F5 runs it again.") : QString());
    if (doc_->runIsStale()) statusTimes_->setText(tr("stale: %1").arg(statusTimes_->text()));
    // A failed run (a custom shader that does not compile, settings the
    // device refuses) leaves the last good run on screen: say whose it is.
    if (failedGeneration_ > doc_->runGeneration()) {
        const QString what = run->custom ? tr("custom shader") : QString(lc::toString(run->result.algorithm));
        statusTimes_->setStyleSheet("color: white; background: #b9770e; padding: 0 4px");
        statusTimes_->setText(tr("run %1 failed, showing run %2 (%3): %4")
                                  .arg(failedGeneration_)
                                  .arg(doc_->runGeneration())
                                  .arg(what, statusTimes_->text()));
        statusTimes_->setToolTip(tr("The last run failed (the message log says why): the view, the tile inspector "
                                    "and these figures are an earlier run's."));
    }
    if (!run->truthComputed) {
        // Live edit: ground truth is still being computed (or was superseded).
        const auto& counts = run->result.listCount;
        std::uint64_t sum = 0, mx = 0;
        for (std::uint32_t c : counts) {
            sum += c;
            mx = std::max<std::uint64_t>(mx, c);
        }
        statusFn_->setText(tr("FN ..."));
        statusFn_->setStyleSheet("color: gray");
        statusEfficiency_->setText(tr("efficiency ..."));
        statusLists_->setText(tr("mean/max list %1 / %2")
                                  .arg(counts.empty() ? 0.0 : double(sum) / double(counts.size()), 0, 'f', 2)
                                  .arg(mx));
        return;
    }
    statusFn_->setText(m.falseNegatives > 0 ? tr("MISSES LIGHTS: FN %1").arg(m.falseNegatives)
                                            : tr("FN %1").arg(m.falseNegatives));
    // By cause, where the engine limits took some of them.
    if (m.falseNegativesListFull || m.falseNegativesLightLimit)
        statusFn_->setText(statusFn_->text() + tr(" (test %1, list full %2, light limit %3)")
                                                   .arg(qulonglong(m.falseNegativesCullingTest()))
                                                   .arg(qulonglong(m.falseNegativesListFull))
                                                   .arg(qulonglong(m.falseNegativesLightLimit)));
    statusFn_->setStyleSheet(m.falseNegatives > 0 ? "color: white; background: #c0392b; padding: 0 4px"
                                                  : "color: #2e7d32");
    // With misses efficiency is no score: lists that drop needed lights look
    // tighter than any correct list can be.
    if (m.falseNegatives > 0)
        statusEfficiency_->setText(tr("efficiency %1: not a score with false negatives").arg(m.efficiency, 0, 'f', 4));
    else
        statusEfficiency_->setText(tr("efficiency %1 (%2% of this grid's optimum)")
                                       .arg(m.efficiency, 0, 'f', 4)
                                       .arg(100.0 * m.efficiencyVsOptimal, 0, 'f', 1));
    statusEfficiency_->setToolTip(tr("Exact work / shading work. The optimum is the shading work of lists holding "
                                     "exactly the lights their pixels need together (optimal work %1): no culling "
                                     "with these tiles, cells or froxels can do better.")
                                      .arg(m.optimalWork));
    statusLists_->setText(tr("mean/max list %1 / %2").arg(m.meanList, 0, 'f', 2).arg(m.maxList));
}

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
    log(tr("opened %1: %2 meshes, %3 triangles, %4 lights")
            .arg(what)
            .arg(s.meshes.size())
            .arg(s.triangleCount())
            .arg(s.lights.size()));
    // With Live on, the new scene's sceneEdited has asked for its run already.
    if (runOnOpen && !isLive()) runCulling();
}

// --- editing ------------------------------------------------------------------------------

int MainWindow::addLightAtCentre() { return addLightAt(QPoint(-1, -1)); }

int MainWindow::addLightAt(const QPoint& pos, lc::LightKind kind) {
    const lc::Scene& s = doc_->scene();
    const auto [lo, hi] = s.bounds();
    double diag = glm::length(hi - lo);
    if (diag <= 0) diag = std::max(1.0, glm::length(s.camera.target - s.camera.position));
    glm::dvec3 p = diag > 0 && s.triangleCount() > 0 ? 0.5 * (lo + hi) : s.camera.target;
    glm::dvec3 hit, normal(0.0, 1.0, 0.0);
    const bool onSurface = inspectorView_->rect().contains(pos) && inspectorView_->pickSurface(pos, &hit, &normal);
    lc::PointLight l;
    l.kind = kind;
    // A spot light stands off the surface by a tenth of the scene and points
    // back at it (no surface: above the centre, pointing down).
    const double standOff = kind == lc::LightKind::Spot ? 0.1 * diag : 0.01 * diag;
    if (onSurface) p = hit + normal * standOff; // off the surface, on the viewer's side
    else if (kind == lc::LightKind::Spot) p += normal * standOff;
    l.direction = -normal;
    l.outerAngleDeg = 30;
    l.name = QStringLiteral("%1 %2").arg(kind == lc::LightKind::Spot ? "spot" : "light").arg(s.lights.size()).toStdString();
    l.position = p;
    l.color = {1, 1, 1};
    l.minIntensity = 0.05;
    // Radius a tenth of the scene (a spot's range a fifth): r^2 = I / I_min.
    const double r = (kind == lc::LightKind::Spot ? 0.2 : 0.1) * diag;
    l.intensity = r * r * l.minIntensity;
    doc_->addLights({l}, kind == lc::LightKind::Spot ? tr("Add spot light") : tr("Add light"));
    return int(doc_->scene().lights.size()) - 1;
}

bool MainWindow::generateLights(const lc::LightGenSettings& g) {
    std::vector<lc::PointLight> lights;
    try {
        lights = runWithProgressResult<std::vector<lc::PointLight>>(
            statusProgress_, tr("Generating %1 lights...").arg(g.count),
            [g](const lc::CancelToken& c, const lc::Progress& p) { return lc::generateLights(g, &c, p); });
    } catch (const lc::Cancelled&) {
        log(tr("light generation cancelled"));
        return false;
    } catch (const std::exception& e) {
        log(tr("cannot generate lights: %1").arg(describe(e)), true);
        prompts.showError(this, tr("Generate lights"), describe(e));
        return false;
    }
    // The generator numbers from light_0; beside the scene's lights the
    // numbering goes on past theirs, so names (explain --light NAME, the
    // scene tree's filter) stay unique.
    std::set<std::string> taken;
    for (const lc::PointLight& l : doc_->scene().lights) taken.insert(l.name);
    std::size_t next = doc_->scene().lights.size();
    for (lc::PointLight& l : lights) {
        if (!taken.count(l.name)) {
            taken.insert(l.name);
            continue;
        }
        while (taken.count("light_" + std::to_string(next))) ++next;
        l.name = "light_" + std::to_string(next++);
        taken.insert(l.name);
    }
    doc_->addLights(lights, tr("Generate %1 lights").arg(lights.size()), /*select=*/false);
    log(tr("generated %1 lights (seed %2)").arg(lights.size()).arg(g.seed));
    return true;
}

void MainWindow::setCullingCameraFromInspector() {
    doc_->setCamera(cullingCameraFromVtk(inspectorView_->renderer()->GetActiveCamera(), doc_->scene().camera),
                    tr("Set culling camera from view"));
}

// --- window ------------------------------------------------------------------------------

QImage MainWindow::grabWindow() {
    cameraView_->renderNow();
    inspectorView_->renderNow();
    return grab().toImage();
}

void MainWindow::log(const QString& message, bool error) { logLine(error ? "ERROR " : "", message); }

void MainWindow::warn(const QString& message) { logLine("WARNING ", message); }

void MainWindow::logLine(const QString& level, const QString& message) {
    log_->appendPlainText(QDateTime::currentDateTime().toString("hh:mm:ss ") + level + message);
}

void MainWindow::updateTitle() {
    const QString file = doc_->filePath().isEmpty() ? QString::fromStdString(doc_->scene().name)
                                                    : QFileInfo(doc_->filePath()).fileName();
    setWindowTitle(tr("%1[*] - LightCull Studio").arg(file.isEmpty() ? tr("untitled") : file));
    setWindowModified(doc_->isDirty());
}

void MainWindow::setTabbedViews(bool tabbed) {
    viewTabs_->setVisible(tabbed);
    if (tabbed) {
        cameraView_->setVisible(viewTabs_->currentIndex() == 0);
        inspectorView_->setVisible(viewTabs_->currentIndex() == 1);
    } else {
        cameraView_->setVisible(true);
        inspectorView_->setVisible(true);
    }
}

bool MainWindow::setCustomShader(const QString& path) {
    const bool had = customShader_->options() != nullptr;
    try {
        customShader_->set(path);
    } catch (const std::exception& e) {
        log(tr("cannot use %1: %2").arg(path, describe(e)), true);
        prompts.showError(this, tr("Custom shader"), describe(e));
        return false;
    }
    if (const auto o = customShader_->options())
        log(tr("culling with custom shader %1 (layout %2, lists %3); saving it re-runs")
                .arg(path, QString::fromStdString(lc::toString(o->layout)),
                     QString::fromStdString(lc::toString(o->lists))));
    else if (had)
        log(tr("culling with the built-in algorithm again"));
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
        log(tr("glTF light cut-off I_min = %1 lux: radii of %2 lights without a range re-derived (Ctrl+Z undoes), "
               "and for the next glTF opened")
                .arg(lux)
                .arg(n));
        if (const std::string w = lc::cutoffCoverageWarning(doc_->scene()); !w.empty()) warn(QString::fromStdString(w));
    } else {
        log(tr("glTF light cut-off I_min = %1 lux (for the next glTF opened; the open scene has no glTF light "
               "without a range)")
                .arg(lux));
    }
    updateCutoffStatus();
}

void MainWindow::restoreSettings() {
    QSettings st;
    {
        const double lux = st.value("gltf/minIntensity", lc::kGltfDefaultMinIntensity).toDouble();
        if (lux > 0.0 && std::isfinite(lux)) gltfOptions.minIntensity = lux;
    }
    restoreGeometry(st.value("window/geometry").toByteArray());
    restoreState(st.value("window/state").toByteArray());
    viewSplitter_->restoreState(st.value("window/splitter").toByteArray());
    const bool tabbed = st.value("window/tabbedViews", false).toBool();
    action("actionTabbedViews")->setChecked(tabbed);
    setTabbedViews(tabbed);
    viewTabs_->setCurrentIndex(st.value("window/currentView", 0).toInt());
    // Last culling parameters (the camera-owned ones belong to the scene).
    lc::CullSettings s = doc_->settings();
    lc::Camera dummy;
    st.beginGroup("params");
    for (const auto& p : lc::cullParams()) {
        if (!st.contains(QString::fromStdString(p.name))) continue;
        try {
            lc::setParam(s, dummy, p.name, st.value(QString::fromStdString(p.name)).toString().toStdString());
        } catch (const lc::Error&) {
        }
    }
    st.endGroup();
    doc_->setSettings(s);
    const QString backend = st.value("backend").toString();
    if (!backend.isEmpty() && backendCombo_->findText(backend) >= 0) backendCombo_->setCurrentText(backend);
    deviceEdit_->setText(st.value("device").toString());
    // Live comes back on without a run: the window holds no scene yet, and
    // the scene opened next runs once (a run here logged 'run 1: 0 lights').
    restoringSettings_ = true;
    action("actionLive")->setChecked(st.value("live", false).toBool());
    restoringSettings_ = false;
}

void MainWindow::saveSettings() {
    QSettings st;
    st.setValue("window/geometry", saveGeometry());
    st.setValue("window/state", saveState());
    st.setValue("window/splitter", viewSplitter_->saveState());
    st.setValue("window/tabbedViews", action("actionTabbedViews")->isChecked());
    st.setValue("window/currentView", viewTabs_->currentIndex());
    st.beginGroup("params");
    lc::Camera dummy;
    for (const auto& p : lc::cullParams())
        st.setValue(QString::fromStdString(p.name),
                    QString::fromStdString(lc::getParam(doc_->settings(), dummy, p.name)));
    st.endGroup();
    st.setValue("backend", backendCombo_->currentText());
    st.setValue("device", deviceEdit_->text());
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
