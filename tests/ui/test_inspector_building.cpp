// The 3D inspector inside a building (a glTF Sponza with 340 lights: a tile
// of 264 lights filled the view with spheres, F framed from outside the roof
// or behind a wall, walls hid the handles, spot cones could not be hidden).
// A closed box room built here, with a partition that makes a side room, 36
// point lights, a spot light and one light in the side room that the culling
// camera cannot see. Real widgets under Xvfb; the View menu's actions.
// - F on a tile and F on a light look from the culling camera's side when a
//   mesh would hide the selection: no triangle between the eye and it;
// - View > Meshes: x-ray (translucent, clicks go through) and hidden;
// - View > Lights: only the selected tile's lights, spheres capped with a
//   "+N more" note, outlines, and lights hidden with the spot cones;
// - the handles drawn over the walls (their own renderer layer), still dragged.
// A screenshot of the room in x-ray is written to look at.

#include "studio_test_support.hpp"
#include "../support/box_mesh.hpp"

#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "views/light_silhouettes.hpp"
#include "window/main_window.hpp"
#include "views/overlay_actors.hpp"
#include "views/spot_actor.hpp"
#include "views/spot_handles.hpp"

#include "culling/diagnostics/overlays.hpp"

#include <QAction>
#include <QDir>
#include <QStatusBar>
#include <QImage>
#include <QUndoStack>

#include <vtkActor.h>
#include <vtkAlgorithm.h>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkMapper.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>

#include <cmath>
#include <memory>
#include <optional>

using namespace lcui;

namespace {

using lctest::addBox;

// The room: inside x, z in (-5, 5), y in (0, 3); walls, floor and roof are
// 0.2 thick slabs. A partition at x = 2.5 (z from -5 to 2) closes off a side
// room that the culling camera cannot see into.
constexpr int kSideLight = 36; // the light in the side room
constexpr int kSpotLight = 37;

lc::Scene roomScene() {
    lc::Scene s;
    s.name = "room";
    lc::Mesh m;
    m.name = "room";
    addBox(m, {-5.2f, -0.2f, -5.2f}, {5.2f, 0.0f, 5.2f}); // floor
    addBox(m, {-5.2f, 3.0f, -5.2f}, {5.2f, 3.2f, 5.2f});  // roof
    addBox(m, {-5.2f, 0.0f, -5.2f}, {-5.0f, 3.0f, 5.2f}); // west
    addBox(m, {5.0f, 0.0f, -5.2f}, {5.2f, 3.0f, 5.2f});   // east
    addBox(m, {-5.0f, 0.0f, -5.2f}, {5.0f, 3.0f, -5.0f}); // north
    addBox(m, {-5.0f, 0.0f, 5.0f}, {5.0f, 3.0f, 5.2f});   // south
    addBox(m, {2.4f, 0.0f, -5.0f}, {2.6f, 3.0f, 2.0f});   // partition
    addBox(m, {-2.0f, 0.0f, -2.5f}, {-1.0f, 1.0f, -1.5f}); // a block on the floor
    s.meshes.push_back(std::move(m));
    s.camera.position = {-3.5, 1.7, 4.2};
    s.camera.target = {0.0, 0.3, -2.0};
    s.camera.fovYDeg = 70;
    s.camera.nearPlane = 0.05;
    s.camera.farPlane = 100;
    s.camera.width = 320;
    s.camera.height = 180;
    s.camera.tileSize = 16;
    // 36 lights in the back left of the main room, low over the floor, away
    // from the line between the culling camera and the side room's light.
    for (int i = 0; i < 36; ++i) {
        lc::PointLight l;
        l.name = "L" + std::to_string(i);
        l.position = {-4.5 + 1.0 * (i % 6), 0.4 + 0.35 * (i % 3), -4.5 + 0.6 * (i / 6)};
        l.color = {0.3 + 0.7 * ((i * 37) % 11) / 10.0, 0.3 + 0.7 * ((i * 53) % 7) / 6.0, 0.9};
        l.intensity = 10;
        l.explicitRadius = 1.1;
        s.lights.push_back(l);
    }
    lc::PointLight side;
    side.name = "side room";
    side.position = {3.8, 1.5, -3.0};
    side.color = {1.0, 0.4, 0.4};
    side.intensity = 10;
    side.explicitRadius = 0.6;
    s.lights.push_back(side);
    lc::PointLight spot;
    spot.name = "spot";
    spot.kind = lc::LightKind::Spot;
    spot.position = {-1.5, 2.8, -3.0};
    spot.direction = {0.0, -1.0, 0.0};
    spot.outerAngleDeg = 35;
    spot.intensity = 10;
    spot.explicitRadius = 2.5;
    s.lights.push_back(spot);
    return s;
}

bool insideRoom(const glm::dvec3& p) {
    return p.x > -5 && p.x < 5 && p.y > 0 && p.y < 3 && p.z > -5 && p.z < 5;
}

// The first triangle of the scene the segment a -> b crosses, as a fraction
// of its length (Moller-Trumbore; written here apart from the view's own).
std::optional<double> segmentHit(const lc::Scene& s, const glm::dvec3& a, const glm::dvec3& b) {
    std::optional<double> best;
    const glm::dvec3 d = b - a;
    for (const lc::Mesh& m : s.meshes)
        for (std::size_t t = 0; t < m.indices.size(); t += 3) {
            const glm::dvec3 v0(m.vertex(m.indices[t])), v1(m.vertex(m.indices[t + 1])), v2(m.vertex(m.indices[t + 2]));
            const glm::dvec3 e1 = v1 - v0, e2 = v2 - v0, p = glm::cross(d, e2);
            const double det = glm::dot(e1, p);
            if (std::abs(det) < 1e-15) continue;
            const glm::dvec3 o = a - v0;
            const double u = glm::dot(o, p) / det;
            const glm::dvec3 q = glm::cross(o, e1);
            const double v = glm::dot(d, q) / det, h = glm::dot(e2, q) / det;
            if (u >= 0 && v >= 0 && u + v <= 1 && h >= 0 && h <= 1 && (!best || h < *best)) best = h;
        }
    return best;
}

// The position handle's warm colour (InspectorView: 1, 0.45, 0.1 lit: it
// draws orange to yellow), not the walls' grey or the background's blue.
bool handleWarm(QRgb c) { return qRed(c) > 180 && qGreen(c) > 50 && qBlue(c) < 90; }

} // namespace

class InspectorBuildingTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() { return w_->document(); }
    InspectorView* view() { return w_->inspectorView(); }

    void trigger(const char* name) {
        QAction* a = w_->action(name);
        if (!a) QFAIL(qPrintable(QString("no action ") + name));
        a->trigger();
        QCoreApplication::processEvents();
    }
    glm::dvec3 eye() {
        double e[3];
        view()->renderer()->GetActiveCamera()->GetPosition(e);
        return {e[0], e[1], e[2]};
    }
    // Display coordinates (device px, y up, depth) of a world point.
    glm::dvec3 display(const glm::dvec3& p) {
        vtkRenderer* ren = view()->renderer();
        ren->SetWorldPoint(p.x, p.y, p.z, 1.0);
        ren->WorldToDisplay();
        double d[3];
        ren->GetDisplayPoint(d);
        return {d[0], d[1], d[2]};
    }
    QPoint toWidget(const glm::dvec3& p) {
        const glm::dvec3 d = display(p);
        const double dpr = view()->devicePixelRatioF();
        return QPoint(int(std::lround(d.x / dpr)), int(std::lround(view()->height() - 1 - d.y / dpr)));
    }
    bool inView(const glm::dvec3& p) {
        const glm::dvec3 d = display(p);
        const int* size = view()->renderer()->GetSize();
        return d.x >= 0 && d.x <= size[0] && d.y >= 0 && d.y <= size[1] && d.z > 0 && d.z < 1;
    }
    // The selected tile's chunk: world corners and the near face's centre.
    std::vector<glm::dvec3> tileCorners(int tile) {
        const auto run = doc()->runs().runOutput();
        const lc::Projection proj(doc()->scene().camera);
        const auto chunk = lc::tileFrustum(run->result, proj, run->lights, std::uint32_t(tile));
        std::vector<glm::dvec3> out;
        if (!chunk) return out;
        const glm::dmat4 world = lc::worldFromView(doc()->scene().camera);
        for (const glm::dvec3& v : chunk->corners) out.push_back(glm::dvec3(world * glm::dvec4(v, 1.0)));
        return out;
    }
    // The tile holding the most lights (ties: the lowest index).
    int busiestTile() {
        const auto run = doc()->runs().runOutput();
        int best = -1;
        std::uint32_t most = 0;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount(); ++t)
            if (run->result.listCount[t] > most) most = run->result.listCount[t], best = int(t);
        return best;
    }
    // Looks at `p` from `distance` beyond it, away from the culling camera:
    // from outside the room, through the floor or a wall.
    void lookFromBehind(const glm::dvec3& p, double distance = 15.0) {
        const glm::dvec3 dir = glm::normalize(p - doc()->scene().camera.position);
        const glm::dvec3 e = p + dir * distance;
        vtkCamera* vc = view()->renderer()->GetActiveCamera();
        vc->SetPosition(e.x, e.y, e.z);
        vc->SetFocalPoint(p.x, p.y, p.z);
        vc->SetViewUp(0, 1, 0);
        vc->OrthogonalizeViewUp();
        view()->renderer()->ResetCameraClippingRange();
        view()->renderNow();
    }

private slots:
    void init() {
        w_ = lctest::makeTestWindow(QSize(1500, 900));
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        doc()->resetScene(roomScene(), {});
        QVERIFY(lctest::waitRun(*w_, w_->runCulling()));
        QCOMPARE(doc()->runs().runOutput()->truth.metrics.falseNegatives, std::uint64_t(0));
    }

    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    // F on a tile seen from outside (through the floor slab and the walls):
    // the inspector flies to the culling camera's side of the tile, and no
    // triangle lies between its eye and the tile's near face.
    void frameTileFromTheCullingCamerasSide() {
        const int tile = busiestTile();
        QVERIFY(tile >= 0);
        const std::vector<glm::dvec3> corners = tileCorners(tile);
        QCOMPARE(corners.size(), std::size_t(8));
        const glm::dvec3 nearCentre = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
        doc()->selection().setSelectedTile(tile);
        lookFromBehind(nearCentre);
        QVERIFY(!insideRoom(eye()));
        QVERIFY(segmentHit(doc()->scene(), eye(), nearCentre)); // hidden from here

        trigger("actionFrameSelected");
        QTest::qWait(600); // the flight takes 300 ms
        const glm::dvec3 e = eye();
        qInfo("eye after F: %.3f %.3f %.3f", e.x, e.y, e.z);
        QVERIFY(view()->framedFromCullingSide());
        QVERIFY2(insideRoom(e), "F left the eye outside the room");
        const glm::dvec3 cullEye = doc()->scene().camera.position;
        QVERIFY(glm::dot(e - nearCentre, cullEye - nearCentre) > 0);
        const auto hit = segmentHit(doc()->scene(), e, nearCentre);
        QVERIFY2(!hit || *hit > 0.999, qPrintable(QString("a triangle at %1 of the way to the tile").arg(hit.value_or(-1))));
        QVERIFY(inView(nearCentre));
        for (const glm::dvec3& c : corners) QVERIFY(inView(c)); // the whole chunk is in view
        view()->renderNow();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        view()->grabFramebuffer().save(LC_RENDER_OUT_DIR "/inspector_framed_in_room.png"); // to look at

        // F from a view that sees the tile keeps its direction, as before.
        double dopBefore[3];
        view()->renderer()->GetActiveCamera()->GetDirectionOfProjection(dopBefore);
        QVERIFY(view()->frameSelected(0));
        QVERIFY(!view()->framedFromCullingSide());
        double dopAfter[3];
        view()->renderer()->GetActiveCamera()->GetDirectionOfProjection(dopAfter);
        for (int k = 0; k < 3; ++k) QVERIFY(std::abs(dopAfter[k] - dopBefore[k]) < 1e-6);
    }

    // F on the side room's light, viewed from outside: the eye lands in the
    // side room, on the culling camera's side, with nothing between it and
    // the light (the partition is between the light and the culling camera:
    // the eye stops before it).
    void frameLightBehindAWall() {
        const glm::dvec3 light = doc()->scene().lights[kSideLight].position;
        QVERIFY(segmentHit(doc()->scene(), doc()->scene().camera.position, light)); // the partition
        doc()->selection().setSelectedTile(-1);
        doc()->selection().setSelectedLights({kSideLight});
        lookFromBehind(light);
        QVERIFY(!insideRoom(eye()));
        trigger("actionFrameSelected");
        QTest::qWait(600);
        const glm::dvec3 e = eye();
        qInfo("eye after F: %.3f %.3f %.3f", e.x, e.y, e.z);
        QVERIFY(view()->framedFromCullingSide());
        QVERIFY(insideRoom(e));
        QVERIFY(glm::dot(e - light, doc()->scene().camera.position - light) > 0);
        QVERIFY(!segmentHit(doc()->scene(), e, light));
        QVERIFY(inView(light));
    }

    // F on a light whose sphere is wider than its room: the eye pulled in
    // to the partition would sit inside the sphere (a view of wireframe). It
    // frames the whole sphere instead and turns the meshes to x-ray, saying so.
    void frameLightWiderThanItsRoomUsesXRay() {
        lc::Scene s = roomScene();
        s.lights[kSideLight].explicitRadius = 3.0; // the side room is 2.4 wide
        doc()->resetScene(std::move(s), {});
        QVERIFY(lctest::waitRun(*w_, w_->runCulling()));
        const glm::dvec3 light = doc()->scene().lights[kSideLight].position;
        doc()->selection().setSelectedLights({kSideLight});
        lookFromBehind(light);
        QVERIFY(doc()->viewOptions().overlays().meshes == OverlayOptions::MeshDisplay::Normal);
        trigger("actionFrameSelected");
        QTest::qWait(600);
        const glm::dvec3 e = eye();
        QVERIFY2(glm::length(e - light) > 3.0, qPrintable(QString("eye %1 from the light").arg(glm::length(e - light))));
        QVERIFY(doc()->viewOptions().overlays().meshes == OverlayOptions::MeshDisplay::XRay);
        QVERIFY2(w_->statusBar()->currentMessage().contains("x-ray"), qPrintable(w_->statusBar()->currentMessage()));
        // The whole sphere in view.
        for (const glm::dvec3& d : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)}) {
            QVERIFY(inView(light + 2.9 * d));
            QVERIFY(inView(light - 2.9 * d));
        }
    }

    // A light picked after the tile (from the scene tree, say) is framed,
    // unless the tile lists it (then the tile, as Explain frames it).
    void frameFramesTheLightPickedAfterTheTile() {
        const int tile = busiestTile();
        doc()->selection().setSelectedTile(tile);
        const auto held = lc::tilesHoldingLight(doc()->runs().runOutput()->result, kSideLight);
        QVERIFY(std::find(held.begin(), held.end(), std::uint32_t(tile)) == held.end());
        doc()->selection().setSelectedLights({kSideLight});
        QVERIFY(doc()->selection().lightSelectedLast());
        QVERIFY(view()->frameSelected(0));
        const glm::dvec3 light = doc()->scene().lights[kSideLight].position;
        double fp[3];
        view()->renderer()->GetActiveCamera()->GetFocalPoint(fp);
        QVERIFY2(glm::length(glm::dvec3(fp[0], fp[1], fp[2]) - light) < 1.0, "F did not frame the light picked last");
        // Picking the tile again makes it the subject.
        doc()->selection().setSelectedTile(-1);
        doc()->selection().setSelectedTile(tile);
        QVERIFY(!doc()->selection().lightSelectedLast());
        QVERIFY(view()->frameSelected(0));
        view()->renderer()->GetActiveCamera()->GetFocalPoint(fp);
        QVERIFY(glm::length(glm::dvec3(fp[0], fp[1], fp[2]) - light) > 1.0);
    }

    // View > Meshes: x-ray draws them translucent and lets a click through to
    // the light behind the partition; hidden does not draw them.
    void meshesXRayAndHidden() {
        QCOMPARE(doc()->viewOptions().overlays().meshes, OverlayOptions::MeshDisplay::Normal);
        view()->lookThroughCullingCamera();
        const glm::dvec3 light = doc()->scene().lights[kSideLight].position;
        QVERIFY(inView(light));
        const QPoint at = toWidget(light);
        // Normal: the partition takes the click.
        doc()->selection().setSelectedLights({});
        QTest::mouseClick(view(), Qt::LeftButton, {}, at);
        QTest::qWait(50);
        QVERIFY(doc()->selection().selectedLights().empty());

        trigger("actionMeshesXRay");
        QCOMPARE(doc()->viewOptions().overlays().meshes, OverlayOptions::MeshDisplay::XRay);
        QVERIFY(w_->action("actionMeshesXRay")->isChecked());
        QVERIFY(!view()->meshActors().empty());
        for (const auto& a : view()->meshActors()) {
            QVERIFY(a->GetVisibility());
            QVERIFY(a->GetProperty()->GetOpacity() < 0.5);
        }
        QTest::mouseClick(view(), Qt::LeftButton, {}, at);
        QTRY_COMPARE_WITH_TIMEOUT(doc()->selection().selectedLights(), std::vector<int>{kSideLight}, 2000);

        // The screenshot: the room from above and outside, in x-ray, a tile
        // selected with its lights and the side room's light current.
        doc()->selection().setSelectedTile(busiestTile());
        view()->resetCamera();
        view()->renderNow();
        QTest::qWait(50);
        view()->renderNow();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        QVERIFY(view()->grabFramebuffer().save(LC_RENDER_OUT_DIR "/inspector_xray_room.png"));

        // X again: back to normal; then hidden.
        trigger("actionMeshesXRay");
        QCOMPARE(doc()->viewOptions().overlays().meshes, OverlayOptions::MeshDisplay::Normal);
        QVERIFY(w_->action("actionMeshesNormal")->isChecked());
        trigger("actionMeshesHidden");
        for (const auto& a : view()->meshActors()) QVERIFY(!a->GetVisibility());
        // The state is the document's: set there, the menu follows.
        OverlayOptions o = doc()->viewOptions().overlays();
        o.meshes = OverlayOptions::MeshDisplay::Normal;
        doc()->viewOptions().setOverlays(o);
        QVERIFY(w_->action("actionMeshesNormal")->isChecked());
        for (const auto& a : view()->meshActors()) {
            QVERIFY(a->GetVisibility());
            QCOMPARE(a->GetProperty()->GetOpacity(), 1.0);
        }
    }

    // View > Lights > Only the selected tile's lights: the light actor draws
    // exactly the tile's list (and the spot cones only its spots).
    void onlyTheSelectedTilesLights() {
        const int tile = busiestTile();
        const auto run = doc()->runs().runOutput();
        const std::uint32_t count = run->result.listCount[std::size_t(tile)];
        QVERIFY(count > 3 && count < doc()->scene().lights.size());
        std::vector<int> listed;
        for (std::uint32_t k = 0; k < count; ++k)
            listed.push_back(int(run->result.lightIndices[run->result.listOffset[std::size_t(tile)] + k]));
        doc()->selection().setSelectedTile(tile);
        QCOMPARE(view()->drawnLights().size(), doc()->scene().lights.size());

        trigger("actionLightsOnlyTile");
        QVERIFY(doc()->viewOptions().overlays().onlyTileLights);
        view()->renderNow();
        QCOMPARE(view()->drawnLights(), listed);
        vtkAlgorithm* input = view()->lightActor()->GetMapper()->GetInputAlgorithm();
        input->Update();
        vtkPolyData* drawnData = vtkPolyData::SafeDownCast(input->GetInputDataObject(0, 0));
        QVERIFY(drawnData);
        QCOMPARE(drawnData->GetNumberOfPoints(), vtkIdType(count));
        const bool spotListed = std::find(listed.begin(), listed.end(), kSpotLight) != listed.end();
        QCOMPARE(view()->spotCones()->data()->GetNumberOfLines() > 0, spotListed);
        QVERIFY(view()->lightNote()->GetVisibility());
        QVERIFY(QString(view()->lightNote()->GetInput()).contains(QString("only tile %1").arg(tile)));
        // The listed highlight adds nothing over them, the others are gone.
        QVERIFY(!view()->overlays()->dimLights());
        QVERIFY(!view()->overlays()->listedActor()->GetVisibility());

        // Another tile: its list.
        int other = -1;
        for (std::uint32_t t = 0; t < run->result.grid.tileCount() && other < 0; ++t)
            if (int(t) != tile && run->result.listCount[t] > 0 && run->result.listCount[t] != count) other = int(t);
        QVERIFY(other >= 0);
        doc()->selection().setSelectedTile(other);
        QCOMPARE(view()->drawnLights().size(), std::size_t(run->result.listCount[std::size_t(other)]));
        // No tile: every light, and the note says to pick one.
        doc()->selection().setSelectedTile(-1);
        QCOMPARE(view()->drawnLights().size(), doc()->scene().lights.size());
        QVERIFY(QString(view()->lightNote()->GetInput()).contains("select a tile"));
        trigger("actionLightsOnlyTile");
        QVERIFY(!view()->lightNote()->GetVisibility());
    }

    // View > Lights > Spheres with a cap of 16: 16 spheres (the selected light
    // among them however far it is), and "+22 more" in the view. Auto with the
    // same cap draws every light as a ring instead, and a tile whose list
    // exceeds the cap is highlighted with rings, not a fog of spheres.
    void sphereCapShowsMore() {
        const std::size_t n = doc()->scene().lights.size();
        doc()->selection().setSelectedLights({kSideLight});
        trigger("actionLightsSpheres");
        trigger("actionSphereCap16");
        QCOMPARE(doc()->viewOptions().overlays().sphereCap, 16);
        QVERIFY(w_->action("actionSphereCap16")->isChecked());
        view()->renderNow();
        QVERIFY(!view()->silhouettes());
        QCOMPARE(view()->drawnLights().size(), std::size_t(16));
        QCOMPARE(view()->lightsLeftOut(), n - 16);
        const auto& drawn = view()->drawnLights();
        QVERIFY(std::find(drawn.begin(), drawn.end(), kSideLight) != drawn.end());
        QVERIFY(view()->lightNote()->GetVisibility());
        const QString note = view()->lightNote()->GetInput();
        QVERIFY2(note.contains(QString("+%1 more").arg(n - 16)), qPrintable(note));
        // The note is drawn: the view's top-left corner is not the background.
        const QImage shot = view()->grabFramebuffer();
        int bright = 0;
        for (int y = 0; y < 30 * view()->devicePixelRatioF(); ++y)
            for (int x = 0; x < 200 * view()->devicePixelRatioF(); ++x) bright += qGray(shot.pixel(x, y)) > 200;
        QVERIFY2(bright > 20, "no note text in the corner");

        trigger("actionLightsAuto");
        QVERIFY(view()->silhouettes());
        QCOMPARE(view()->drawnLights().size(), n);
        QCOMPARE(view()->lightsLeftOut(), std::size_t(0));
        QVERIFY(!view()->lightNote()->GetVisibility());
        // A tile listing more lights than the cap: its highlight is rings.
        int tile = -1;
        const auto run = doc()->runs().runOutput();
        for (std::uint32_t t = 0; t < run->result.grid.tileCount() && tile < 0; ++t)
            if (run->result.listCount[t] > 16) tile = int(t);
        QVERIFY(tile >= 0);
        doc()->selection().setSelectedTile(tile);
        QVERIFY(view()->overlays()->listedActor()->GetVisibility());
        QVERIFY(view()->overlays()->listedAsRings());
        QVERIFY(LightSilhouettes::SafeDownCast(view()->overlays()->listedActor()->GetMapper()->GetInputAlgorithm()));
        trigger("actionLightsOutlines");
        QVERIFY(view()->silhouettes());
        trigger("actionSphereCap256");
        QVERIFY(view()->silhouettes()); // outlines whatever the cap
    }

    // View > Lights > Show lights and spot cones: off hides spheres, rings,
    // the listed highlight and the spot cones together; lights are then not
    // clicked.
    void hidingLightsHidesSpotCones() {
        QVERIFY(view()->spotCones()->data()->GetNumberOfLines() > 0);
        QVERIFY(view()->spotCones()->actor()->GetVisibility());
        doc()->selection().setSelectedTile(busiestTile());
        trigger("actionLightsShow");
        QVERIFY(!doc()->viewOptions().overlays().showLights);
        QVERIFY(!view()->lightActor()->GetVisibility());
        QVERIFY(!view()->spotCones()->actor()->GetVisibility());
        QVERIFY(!view()->overlays()->listedActor()->GetVisibility());
        view()->lookThroughCullingCamera();
        const lc::PointLight& l = doc()->scene().lights[0];
        QCOMPARE(view()->pickLight(toWidget(l.position)), -1);
        trigger("actionLightsShow");
        QVERIFY(view()->lightActor()->GetVisibility());
        QVERIFY(view()->spotCones()->actor()->GetVisibility());
    }

    // The current light's handles are drawn in a layer above the scene: seen
    // through the culling camera the side room's light is behind the
    // partition, and its handle still shows there; a drag through the
    // interactor's own events still moves the light.
    void handlesDrawnOverWalls() {
        view()->lookThroughCullingCamera();
        const glm::dvec3 light = doc()->scene().lights[kSideLight].position;
        QVERIFY(segmentHit(doc()->scene(), eye(), light)); // the partition hides it
        auto warmAround = [&](const QImage& img) {
            const glm::dvec3 d = display(light);
            const int cx = int(d.x), cy = img.height() - 1 - int(d.y);
            int n = 0;
            for (int y = cy - 30; y <= cy + 30; ++y)
                for (int x = cx - 30; x <= cx + 30; ++x)
                    if (img.rect().contains(x, y) && handleWarm(img.pixel(x, y))) ++n;
            return n;
        };
        view()->renderNow();
        const int without = warmAround(view()->grabFramebuffer());
        doc()->selection().setSelectedLights({kSideLight});
        view()->renderNow();
        QVERIFY(view()->handleWidget()->GetEnabled());
        QCOMPARE(view()->handleRepresentation()->GetRenderer(), view()->handleLayer());
        QCOMPARE(view()->radiusHandleRepresentation()->GetRenderer(), view()->handleLayer());
        QVERIFY(view()->handleLayer()->GetLayer() > view()->renderer()->GetLayer());
        const QImage withImage = view()->grabFramebuffer();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        withImage.save(LC_RENDER_OUT_DIR "/inspector_handle_over_wall.png"); // to look at
        const int with = warmAround(withImage);
        qInfo("handle-coloured pixels around the light: %d without the handle, %d with it", without, with);
        QVERIFY2(with > without + 20, "the partition hides the handle");

        // Spot handles too.
        doc()->selection().setSelectedLights({kSpotLight});
        QVERIFY(view()->spotHandles()->directionWidget()->GetEnabled());
        QCOMPARE(view()->spotHandles()->directionRepresentation()->GetRenderer(), view()->handleLayer());
        QCOMPARE(view()->spotHandles()->angleRepresentation()->GetRenderer(), view()->handleLayer());

        // A drag as the mouse makes it (the interactor's events in display
        // coordinates) still grabs the handle in its layer.
        doc()->selection().setSelectedLights({kSideLight});
        view()->renderNow();
        const glm::dvec3 d = display(light);
        vtkRenderWindowInteractor* iren = view()->interactor();
        const int steps = doc()->undoStack()->count();
        iren->SetEventInformation(int(d.x), int(d.y));
        iren->InvokeEvent(vtkCommand::MouseMoveEvent);
        iren->InvokeEvent(vtkCommand::LeftButtonPressEvent);
        for (int k = 1; k <= 5; ++k) {
            iren->SetEventInformation(int(d.x) + 8 * k, int(d.y));
            iren->InvokeEvent(vtkCommand::MouseMoveEvent);
        }
        iren->InvokeEvent(vtkCommand::LeftButtonReleaseEvent);
        const glm::dvec3 moved = doc()->scene().lights[kSideLight].position;
        qInfo("dragged the handle: the light moved by %.3f", glm::length(moved - light));
        QVERIFY(glm::length(moved - light) > 0.05);
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
    }
};

LC_STUDIO_TEST_MAIN(InspectorBuildingTest)
#include "test_inspector_building.moc"
