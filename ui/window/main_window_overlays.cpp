// MainWindow: the overlay toggles (View > Overlays), the heat-map mode and
// File > Export diagnostics. Kept apart from main_window.cpp so that the
// overlays stay one small hook there.
#include "window/main_window.hpp"

#include "views/camera_view.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "views/overlay_actors.hpp"

#include "culling/core/errors.hpp"
#include "culling/diagnostics/export.hpp"

#include <QAction>
#include <QActionGroup>
#include <QImage>
#include <QMenu>
#include <QSignalBlocker>

#include <functional>
#include <tuple>
#include <vector>

namespace lcui {

namespace {

lc::RgbImage toRgb(const QImage& image) {
    const QImage img = image.convertToFormat(QImage::Format_RGB888);
    lc::RgbImage out;
    out.width = std::uint32_t(img.width());
    out.height = std::uint32_t(img.height());
    out.rgb.resize(std::size_t(out.width) * out.height * 3);
    for (int y = 0; y < img.height(); ++y)
        std::copy_n(img.constScanLine(y), std::size_t(out.width) * 3, out.rgb.begin() + std::ptrdiff_t(y) * out.width * 3);
    return out;
}

} // namespace

// View > Meshes and View > Lights: the inspector inside a building. Every
// pick goes to the document's overlay options; the checks follow them.
static void buildInsideMenus(MainWindow* w, Document* doc, QMenu* view);

void MainWindow::buildOverlayMenus(QMenu* file, QMenu* view) {
    QAction* exportAction = new QAction(tr("E&xport diagnostics..."), this);
    exportAction->setObjectName("actionExportDiagnostics");
    exportAction->setShortcut(QKeySequence(tr("Ctrl+E")));
    connect(exportAction, &QAction::triggered, this, [this] {
        const QString dir = prompts.savePath(this, tr("Export diagnostics into a new folder"), tr("Folder (*)"));
        if (!dir.isEmpty()) exportDiagnostics(dir);
    });
    QAction* quit = action("actionQuit");
    file->insertAction(quit, exportAction);
    file->insertSeparator(quit);

    using Options = Document::OverlayOptions;
    QMenu* overlays = view->addMenu(tr("&Overlays"));
    auto toggle = [&](const QString& text, const char* name, bool Options::*field) {
        QAction* a = overlays->addAction(text);
        a->setObjectName(name);
        a->setCheckable(true);
        a->setChecked(doc_->overlays().*field);
        connect(a, &QAction::toggled, this, [this, field](bool on) {
            Options o = doc_->overlays();
            o.*field = on;
            doc_->setOverlays(o);
        });
    };
    toggle(tr("Selected tile frustum"), "actionOverlayTileFrustum", &Options::tileFrustum);
    toggle(tr("All tile frustums"), "actionOverlayAllTiles", &Options::allTileFrustums);
    toggle(tr("Depth cells / split / froxels"), "actionOverlayCells", &Options::cells);
    toggle(tr("Light's cell range"), "actionOverlayLightRange", &Options::lightCellRange);
    toggle(tr("Highlight listed lights"), "actionOverlayListHighlight", &Options::listHighlight);
    toggle(tr("Tiles holding the selected light"), "actionOverlayReverse", &Options::reverseLookup);
    toggle(tr("Explain: deciding plane and pixel"), "actionOverlayExplain", &Options::explainMarkers);
    // A view toggle of the inspector (not a document option): the culling
    // sphere, chunk spheres or chunk planes the run's spot test evaluated for
    // the current spot light and the selected tile (overlay_actors.hpp).
    QAction* spotPrimitive = overlays->addAction(tr("Spot test primitive"));
    spotPrimitive->setObjectName("actionOverlaySpotPrimitive");
    spotPrimitive->setCheckable(true);
    spotPrimitive->setChecked(inspectorView_->overlays()->showSpotPrimitive());
    connect(spotPrimitive, &QAction::toggled, this, [this](bool on) {
        inspectorView_->overlays()->setShowSpotPrimitive(on);
        inspectorView_->overlays()->update(*doc_);
        inspectorView_->scheduleRender();
    });

    buildInsideMenus(this, doc_, view);

    QMenu* heat = view->addMenu(tr("&Heat map"));
    auto* group = new QActionGroup(this);
    const std::pair<QString, lc::HeatMode> modes[] = {{tr("List length"), lc::HeatMode::ListLength},
                                                      {tr("False positives"), lc::HeatMode::FalsePositives},
                                                      {tr("Efficiency"), lc::HeatMode::Efficiency},
                                                      {tr("False negatives (misses)"), lc::HeatMode::FalseNegatives},
                                                      {tr("Over-full lists (engine limits)"), lc::HeatMode::Overflow}};
    for (const auto& [text, mode] : modes) {
        QAction* a = heat->addAction(text);
        a->setObjectName(QString("actionHeat_%1").arg(lc::toString(mode)));
        a->setCheckable(true);
        a->setChecked(doc_->overlays().heat == mode);
        group->addAction(a);
        const lc::HeatMode m = mode;
        connect(a, &QAction::triggered, this, [this, m] {
            Options o = doc_->overlays();
            o.heat = m;
            doc_->setOverlays(o);
        });
    }
}

static void buildInsideMenus(MainWindow* w, Document* doc, QMenu* view) {
    using Options = Document::OverlayOptions;
    using MD = Options::MeshDisplay;
    using LD = Options::LightDisplay;
    // Re-checks every action from the options (they change from elsewhere too).
    std::vector<std::function<void()>> syncs;
    auto radio = [&](QMenu* menu, QActionGroup* group, const QString& text, const char* name, auto pick,
                     auto isChecked) {
        QAction* a = menu->addAction(text);
        a->setObjectName(name);
        a->setCheckable(true);
        group->addAction(a);
        QObject::connect(a, &QAction::triggered, w, [doc, pick] {
            Options o = doc->overlays();
            pick(o);
            doc->setOverlays(o);
        });
        syncs.push_back([a, doc, isChecked] {
            const QSignalBlocker block(a);
            a->setChecked(isChecked(doc->overlays()));
        });
        return a;
    };
    auto toggle = [&](QMenu* menu, const QString& text, const char* name, bool Options::*field) {
        QAction* a = menu->addAction(text);
        a->setObjectName(name);
        a->setCheckable(true);
        QObject::connect(a, &QAction::toggled, w, [doc, field](bool on) {
            Options o = doc->overlays();
            o.*field = on;
            doc->setOverlays(o);
        });
        syncs.push_back([a, doc, field] {
            const QSignalBlocker block(a);
            a->setChecked(doc->overlays().*field);
        });
        return a;
    };

    QMenu* meshes = view->addMenu(QObject::tr("&Meshes"));
    meshes->setObjectName("menuMeshes");
    auto* meshGroup = new QActionGroup(meshes);
    const std::tuple<QString, const char*, MD> meshModes[] = {
        {QObject::tr("Normal"), "actionMeshesNormal", MD::Normal},
        {QObject::tr("X-ray (see through walls)"), "actionMeshesXRay", MD::XRay},
        {QObject::tr("Hidden"), "actionMeshesHidden", MD::Hidden}};
    for (const auto& [text, name, mode] : meshModes) {
        const MD m = mode;
        // X-ray (key X) toggles: picked again it goes back to normal.
        QAction* a = radio(
            meshes, meshGroup, text, name,
            [m](Options& o) { o.meshes = m == MD::XRay && o.meshes == MD::XRay ? MD::Normal : m; },
            [m](const Options& o) { return o.meshes == m; });
        if (m == MD::XRay) a->setShortcut(QKeySequence(Qt::Key_X));
    }

    QMenu* lights = view->addMenu(QObject::tr("&Lights"));
    lights->setObjectName("menuLights");
    toggle(lights, QObject::tr("Show lights and spot cones"), "actionLightsShow", &Options::showLights);
    toggle(lights, QObject::tr("Only the selected tile's lights"), "actionLightsOnlyTile", &Options::onlyTileLights);
    lights->addSeparator();
    auto* styleGroup = new QActionGroup(lights);
    const std::tuple<QString, const char*, LD> styles[] = {
        {QObject::tr("Spheres up to the cap, outlines above"), "actionLightsAuto", LD::Auto},
        {QObject::tr("Spheres (at most the cap)"), "actionLightsSpheres", LD::Spheres},
        {QObject::tr("Outlines (silhouette rings)"), "actionLightsOutlines", LD::Outlines}};
    for (const auto& [text, name, style] : styles) {
        const LD st = style;
        radio(
            lights, styleGroup, text, name, [st](Options& o) { o.lights = st; },
            [st](const Options& o) { return o.lights == st; });
    }
    QMenu* cap = lights->addMenu(QObject::tr("Sphere &cap"));
    cap->setObjectName("menuSphereCap");
    auto* capGroup = new QActionGroup(cap);
    for (int n : {16, 32, 64, 128, 256, 1024}) {
        const QByteArray name = "actionSphereCap" + QByteArray::number(n);
        QAction* a = radio(
            cap, capGroup, QObject::tr("%1 spheres").arg(n), name.constData(), [n](Options& o) { o.sphereCap = n; },
            [n](const Options& o) { return o.sphereCap == n; });
        a->setObjectName(QString::fromLatin1(name));
    }
    auto syncAll = [syncs] {
        for (const auto& s : syncs) s();
    };
    syncAll();
    QObject::connect(doc, &Document::overlaysChanged, w, syncAll);
}

bool MainWindow::exportDiagnostics(const QString& dir) {
    if (!doc_->runOutput()) {
        log(tr("export diagnostics: no culling run yet (F5)"), true);
        prompts.showError(this, tr("Export diagnostics"), tr("There is no culling run to export yet: press F5."));
        return false;
    }
    // The export pairs the scene with the run's lists and truth light by light.
    if (doc_->runIsStale()) {
        log(tr("export diagnostics: the scene changed since the last run (F5 runs it again); nothing exported"), true);
        prompts.showError(this, tr("Export diagnostics"),
                          tr("The scene changed since the last culling run: press F5 to run it again, then export. "
                             "Nothing was exported."));
        return false;
    }
    // shaded_culled.png, shaded_all.png and shaded_diff.png come with it:
    // shaded on the worker now if the run was not shaded yet.
    const auto run = shadedRunOutput();
    if (!run) {
        prompts.showError(this, tr("Export diagnostics"), tr("The shading pass did not finish; nothing was exported."));
        return false;
    }
    try {
        cameraView_->renderNow();
        inspectorView_->renderNow();
        std::vector<lc::NamedImage> views;
        views.push_back({"camera_view.png", toRgb(cameraView_->grabFramebuffer())});
        views.push_back({"inspector_view.png", toRgb(inspectorView_->grabFramebuffer())});
        // The settings the run used (the toolbar may have changed since).
        // Unsaved edits: the export records them and writes the edited scene
        // beside summary.json, so that the figures can be reproduced.
        lc::Scene scene = doc_->scene();
        scene.origin.edited = doc_->isDirty();
        lc::exportDiagnostics(scene, run->result.settings, *run, dir.toStdString(), views);
    } catch (const std::exception& e) {
        const QString msg = QString::fromStdString(e.what());
        log(tr("export diagnostics: %1").arg(msg), true);
        prompts.showError(this, tr("Export diagnostics"), msg);
        return false;
    }
    log(tr("exported diagnostics to %1").arg(dir));
    return true;
}

} // namespace lcui
