#include "window/overlay_menus.hpp"

#include "document/document.hpp"

#include <QAction>
#include <QActionGroup>
#include <QMenu>
#include <QSignalBlocker>

#include <tuple>

namespace lcui {

namespace {

using Options = OverlayOptions;

// A checkable action in `menu` whose check is `isChecked(options)` and which
// applies `pick` to the options (through the document): when toggled (a
// stand-alone switch, also set by setChecked) or, in an exclusive `group`,
// when triggered (a radio item's unchecking is its sibling's business).
template <class Pick, class IsChecked>
QAction* addOption(Document* doc, QMenu* menu, QActionGroup* group, const QString& text, const QString& name,
                   Pick pick, IsChecked isChecked, std::vector<std::function<void()>>& syncs) {
    QAction* a = menu->addAction(text);
    a->setObjectName(name);
    a->setCheckable(true);
    const auto apply = [doc, pick, a] {
        Options o = doc->viewOptions().overlays();
        pick(o, a->isChecked());
        doc->viewOptions().setOverlays(o);
    };
    if (group) {
        group->addAction(a);
        QObject::connect(a, &QAction::triggered, menu, apply);
    } else {
        QObject::connect(a, &QAction::toggled, menu, apply);
    }
    syncs.push_back([a, doc, isChecked] {
        const QSignalBlocker block(a);
        a->setChecked(isChecked(doc->viewOptions().overlays()));
    });
    return a;
}

} // namespace

OverlayMenus::OverlayMenus(Document* doc, QMenu* view, QObject* parent) : QObject(parent), doc_(doc) {
    buildOverlays(view);
    buildMeshes(view);
    buildLights(view);
    buildHeat(view);
    syncAll();
    connect(&doc_->viewOptions(), &ViewOptions::overlaysChanged, this, &OverlayMenus::syncAll);
}

void OverlayMenus::syncAll() {
    for (const auto& s : syncs_) s();
}

void OverlayMenus::addSwitch(QMenu* menu, const QString& text, const char* name, bool OverlayOptions::*field) {
    addOption(
        doc_, menu, nullptr, text, name, [field](Options& o, bool on) { o.*field = on; },
        [field](const Options& o) { return o.*field; }, syncs_);
}

void OverlayMenus::buildOverlays(QMenu* view) {
    QMenu* menu = view->addMenu(tr("&Overlays"));
    const auto toggle = [&](const QString& text, const char* name, bool Options::*field) {
        addSwitch(menu, text, name, field);
    };
    toggle(tr("Selected tile frustum"), "actionOverlayTileFrustum", &Options::tileFrustum);
    toggle(tr("All tile frustums"), "actionOverlayAllTiles", &Options::allTileFrustums);
    toggle(tr("Depth cells / split / froxels"), "actionOverlayCells", &Options::cells);
    toggle(tr("Light's cell range"), "actionOverlayLightRange", &Options::lightCellRange);
    toggle(tr("Highlight listed lights"), "actionOverlayListHighlight", &Options::listHighlight);
    toggle(tr("Tiles holding the selected light"), "actionOverlayReverse", &Options::reverseLookup);
    toggle(tr("Explain: deciding plane and pixel"), "actionOverlayExplain", &Options::explainMarkers);
    // The culling sphere, chunk spheres or chunk planes the run's spot test
    // evaluated for the current spot light and the selected tile (overlay_actors.hpp).
    toggle(tr("Spot test primitive"), "actionOverlaySpotPrimitive", &Options::spotPrimitive);
}

// The inspector inside a building: meshes as they are, x-ray or hidden.
void OverlayMenus::buildMeshes(QMenu* view) {
    using MD = Options::MeshDisplay;
    QMenu* menu = view->addMenu(tr("&Meshes"));
    menu->setObjectName("menuMeshes");
    auto* group = new QActionGroup(menu);
    const std::tuple<QString, const char*, MD> modes[] = {{tr("Normal"), "actionMeshesNormal", MD::Normal},
                                                          {tr("X-ray (see through walls)"), "actionMeshesXRay", MD::XRay},
                                                          {tr("Hidden"), "actionMeshesHidden", MD::Hidden}};
    for (const auto& [text, name, mode] : modes) {
        const MD m = mode;
        // X-ray (key X) toggles: picked again it goes back to normal.
        QAction* a = addOption(
            doc_, menu, group, text, name,
            [m](Options& o, bool) { o.meshes = m == MD::XRay && o.meshes == MD::XRay ? MD::Normal : m; },
            [m](const Options& o) { return o.meshes == m; }, syncs_);
        if (m == MD::XRay) a->setShortcut(QKeySequence(Qt::Key_X));
    }
}

void OverlayMenus::buildLights(QMenu* view) {
    using LD = Options::LightDisplay;
    QMenu* menu = view->addMenu(tr("&Lights"));
    menu->setObjectName("menuLights");
    addSwitch(menu, tr("Show lights and spot cones"), "actionLightsShow", &Options::showLights);
    addSwitch(menu, tr("Only the selected tile's lights"), "actionLightsOnlyTile", &Options::onlyTileLights);
    menu->addSeparator();
    auto* styleGroup = new QActionGroup(menu);
    const std::tuple<QString, const char*, LD> styles[] = {
        {tr("Spheres up to the cap, outlines above"), "actionLightsAuto", LD::Auto},
        {tr("Spheres (at most the cap)"), "actionLightsSpheres", LD::Spheres},
        {tr("Outlines (silhouette rings)"), "actionLightsOutlines", LD::Outlines}};
    for (const auto& [text, name, style] : styles) {
        const LD st = style;
        addOption(
            doc_, menu, styleGroup, text, name, [st](Options& o, bool) { o.lights = st; },
            [st](const Options& o) { return o.lights == st; }, syncs_);
    }
    QMenu* cap = menu->addMenu(tr("Sphere &cap"));
    cap->setObjectName("menuSphereCap");
    auto* capGroup = new QActionGroup(cap);
    for (int n : {16, 32, 64, 128, 256, 1024})
        addOption(
            doc_, cap, capGroup, tr("%1 spheres").arg(n), QStringLiteral("actionSphereCap%1").arg(n),
            [n](Options& o, bool) { o.sphereCap = n; }, [n](const Options& o) { return o.sphereCap == n; }, syncs_);
}

void OverlayMenus::buildHeat(QMenu* view) {
    QMenu* menu = view->addMenu(tr("&Heat map"));
    auto* group = new QActionGroup(menu);
    const std::pair<QString, lc::HeatMode> modes[] = {{tr("List length"), lc::HeatMode::ListLength},
                                                      {tr("False positives"), lc::HeatMode::FalsePositives},
                                                      {tr("Efficiency"), lc::HeatMode::Efficiency},
                                                      {tr("False negatives (misses)"), lc::HeatMode::FalseNegatives},
                                                      {tr("Over-full lists (engine limits)"), lc::HeatMode::Overflow}};
    for (const auto& [text, mode] : modes) {
        const lc::HeatMode m = mode;
        addOption(
            doc_, menu, group, text, QString("actionHeat_%1").arg(lc::toString(mode)),
            [m](Options& o, bool) { o.heat = m; }, [m](const Options& o) { return o.heat == m; }, syncs_);
    }
}

} // namespace lcui
