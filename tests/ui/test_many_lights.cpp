// The inspector view with many lights (issue 4: views interactive with
// thousands of light spheres; issue 6: Live drag among 1,024 lights): above
// InspectorView::kMaxFilledLights every sphere is drawn as its silhouette
// ring; the selection still stands out; a click still selects the light
// whose sphere is under the cursor; a Live drag ends on the newest result;
// the document's geometry revision follows mesh edits only.

#include "work/cull_worker.hpp"
#include "culling/core/backend.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "views/light_silhouettes.hpp"
#include "views/overlay_actors.hpp"
#include "window/main_window.hpp"
#include "studio_test_support.hpp"

#include <QDir>
#include <QElapsedTimer>
#include <QImage>
#include <QUndoStack>
#include <cmath>
#include <limits>
#include <memory>
#include <vtkActor.h>
#include <vtkAlgorithm.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkMapper.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPolyData.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>

using namespace lcui;

namespace {


// The selection outline's colour (InspectorView: opaque, unlit 1, 0.85, 0.1),
// with room for blending under the translucent rings.
bool selectionYellow(QRgb c) {
    return qRed(c) > 200 && qGreen(c) > 160 && qGreen(c) < 240 && qBlue(c) < 90;
}

} // namespace

class ManyLightsTest : public QObject {
    Q_OBJECT

    std::unique_ptr<MainWindow> w_;

    Document* doc() { return w_->document(); }
    InspectorView* view() { return w_->inspectorView(); }

    bool waitRun(quint64 generation, bool truth = false) { return lctest::waitRun(*w_, generation, truth); }

    // atrium at 320x180 on the CPU backend, with `count` generated lights.
    void openWithLights(std::uint32_t count) {
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(w_->setParamFromUi("width", "320"));
        QVERIFY(w_->setParamFromUi("height", "180"));
        // Replaces the scene's lights, as the studio's --lights does.
        lc::Scene s = doc()->scene();
        lc::LightGenSettings g = lc::defaultLightGen(s, count, 7);
        g.minIntensity = 1.0; // radii up to sqrt(10): a dense, overlapping cloud
        s.lights = lc::generateLights(g);
        doc()->undoStack()->clear();
        doc()->resetScene(std::move(s), {});
        QCOMPARE(doc()->scene().lights.size(), std::size_t(count));
        QVERIFY(waitRun(w_->runCulling()));
    }

    // Widget position (logical px) of a world point, and whether it is well inside.
    QPoint toWidget(const glm::dvec3& p) {
        vtkRenderer* ren = view()->renderer();
        ren->SetWorldPoint(p.x, p.y, p.z, 1.0);
        ren->WorldToDisplay();
        double d[3];
        ren->GetDisplayPoint(d);
        const double dpr = view()->devicePixelRatioF();
        return QPoint(int(std::lround(d[0] / dpr)), int(std::lround(view()->height() - 1 - d[1] / dpr)));
    }

    // The view ray through a widget position: origin on the near plane, unit direction.
    std::pair<glm::dvec3, glm::dvec3> rayAt(const QPoint& pos) {
        vtkRenderer* ren = view()->renderer();
        const double dpr = view()->devicePixelRatioF();
        const double x = pos.x() * dpr, y = (view()->height() - 1 - pos.y()) * dpr;
        auto at = [&](double z) {
            ren->SetDisplayPoint(x, y, z);
            ren->DisplayToWorld();
            double w[4];
            ren->GetWorldPoint(w);
            return glm::dvec3(w[0], w[1], w[2]) / w[3];
        };
        const glm::dvec3 o = at(0.0), f = at(1.0);
        return {o, glm::normalize(f - o)};
    }

    // Entry distance of the ray into light i's sphere; +inf when it misses or starts inside.
    double entry(const glm::dvec3& o, const glm::dvec3& d, std::size_t i) {
        const auto& l = doc()->scene().lights[i];
        const double r = l.radius();
        const glm::dvec3 oc = l.position - o;
        const double b = glm::dot(oc, d), c = glm::dot(oc, oc) - r * r;
        const double disc = b * b - c;
        if (c <= 0 || disc < 0) return std::numeric_limits<double>::infinity();
        const double t = b - std::sqrt(disc);
        return t > 0 ? t : std::numeric_limits<double>::infinity();
    }

  private slots:
    void init() {
        // Wide enough that both views keep ~450 px beside the docks: the outline
        // test below needs spheres large against the fixed-size drag handle.
        w_ = lctest::makeTestWindow(QSize(1800, 950));
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    }

    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    // Few lights keep the filled translucent spheres; many get rings that are
    // the exact outline of each sphere as seen from the camera, also after an orbit.
    void manyLightsAreDrawnAsSilhouetteRings() {
        QVERIFY(w_->openBuiltin("atrium"));
        {
            lc::Scene s = doc()->scene();
            s.lights.resize(InspectorView::kMaxFilledLights);
            doc()->resetScene(std::move(s), {});
        }
        QVERIFY(!view()->silhouettes());
        QVERIFY(view()->lightActor()->GetVisibility());

        openWithLights(1024);
        QVERIFY(view()->silhouettes());
        vtkActor* rings = view()->lightActor();
        QVERIFY(rings->GetVisibility());
        view()->renderNow();
        auto* ringAlg = LightSilhouettes::SafeDownCast(rings->GetMapper()->GetInputAlgorithm());
        QVERIFY(ringAlg);
        constexpr int S = LightSilhouettes::kSegments;
        const auto& lights = doc()->scene().lights;
        for (int orbit = 0; orbit < 2; ++orbit) {
            if (orbit == 1) {
                view()->renderer()->GetActiveCamera()->Azimuth(40);
                view()->renderer()->GetActiveCamera()->Elevation(15);
                view()->renderer()->GetActiveCamera()->OrthogonalizeViewUp();
                view()->renderNow();
            }
            vtkPolyData* out = ringAlg->GetOutput();
            QCOMPARE(out->GetNumberOfPoints(), vtkIdType(lights.size() * (S + 1)));
            QCOMPARE(out->GetNumberOfLines(), vtkIdType(lights.size()));
            double e[3];
            view()->renderer()->GetActiveCamera()->GetPosition(e);
            const glm::dvec3 eye(e[0], e[1], e[2]);
            int checked = 0;
            for (std::size_t i = 0; i < lights.size(); i += 97) {
                const glm::dvec3 c = lights[i].position;
                const double r = lights[i].radius();
                if (glm::length(c - eye) <= r) continue; // eye inside: no outline exists
                ++checked;
                for (int k = 0; k < S; k += 5) {
                    double q[3];
                    out->GetPoint(vtkIdType(i) * S + k, q);
                    const glm::dvec3 p(q[0], q[1], q[2]);
                    // On the sphere, and the line of sight touches it there (tangent).
                    QVERIFY2(std::abs(glm::length(p - c) - r) < 1e-4 * (1 + r),
                             qPrintable(QString("light %1 point %2: |p-c| %3, r %4")
                                            .arg(i)
                                            .arg(k)
                                            .arg(glm::length(p - c))
                                            .arg(r)));
                    const double cosine = glm::dot(glm::normalize(p - c), glm::normalize(p - eye));
                    QVERIFY2(std::abs(cosine) < 1e-3,
                             qPrintable(QString("light %1: not tangent (%2)").arg(i).arg(cosine)));
                }
            }
            QVERIFY(checked > 5);
        }
        // Back to few lights: the filled spheres return.
        doc()->undoStack()->clear();
        lc::Scene s = doc()->scene();
        s.lights.resize(10);
        doc()->resetScene(s, {});
        QVERIFY(!view()->silhouettes());
    }

    // The selected light's yellow outline is drawn over the rings, where that light is.
    void selectedLightStandsOut() {
        openWithLights(1024);
        const auto& lights = doc()->scene().lights;
        // A light in the middle of the view whose sphere is not tiny on screen.
        int pick = -1;
        const QRect inner = view()->rect().adjusted(view()->width() / 4, view()->height() / 4,
                                                    -view()->width() / 4, -view()->height() / 4);
        view()->renderNow();
        // ... and in front at its centre (no mesh or other sphere hides it there).
        for (std::size_t i = 0; i < lights.size() && pick < 0; ++i) {
            const QPoint at = toWidget(lights[i].position);
            if (inner.contains(at) && lights[i].radius() > 1.5 && view()->pickLight(at) == int(i))
                pick = int(i);
        }
        QVERIFY(pick >= 0);
        const QImage before = view()->grabFramebuffer();
        doc()->selection().setSelectedLights({pick});
        view()->renderNow();
        const QImage after = view()->grabFramebuffer();
        QDir().mkpath(LC_RENDER_OUT_DIR);
        after.save(QString(LC_RENDER_OUT_DIR) + "/many_lights_selected.png"); // to look at
        QCOMPARE(after.size(), before.size());
        const double dpr = view()->devicePixelRatioF();
        const QPoint c = toWidget(lights[std::size_t(pick)].position) * dpr;
        // Screen radius: the centre against a point one radius to the side.
        double right[3];
        {
            double dop[3], up[3];
            view()->renderer()->GetActiveCamera()->GetDirectionOfProjection(dop);
            view()->renderer()->GetActiveCamera()->GetViewUp(up);
            const glm::dvec3 rr = glm::normalize(
                glm::cross(glm::dvec3(dop[0], dop[1], dop[2]), glm::dvec3(up[0], up[1], up[2])));
            right[0] = rr.x, right[1] = rr.y, right[2] = rr.z;
        }
        const glm::dvec3 side = lights[std::size_t(pick)].position +
                                lights[std::size_t(pick)].radius() * glm::dvec3(right[0], right[1], right[2]);
        const double rpx = QLineF(QPointF(c), QPointF(toWidget(side) * dpr)).length();
        int added = 0, addedOutside = 0;
        for (int y = 0; y < after.height(); ++y)
            for (int x = 0; x < after.width(); ++x) {
                if (!selectionYellow(after.pixel(x, y)) || selectionYellow(before.pixel(x, y))) continue;
                ++added;
                if (std::hypot(x - c.x(), y - c.y()) > rpx * 1.3 + 4) ++addedOutside;
            }
        qInfo("selected light %d: %d new outline pixels, %d outside its sphere's %.0f px screen radius", pick,
              added, addedOutside, rpx);
        QVERIFY2(added > 2.0 * rpx,
                 qPrintable(QString("only %1 outline pixels for a %2 px sphere").arg(added).arg(rpx)));
        QVERIFY(addedOutside <= added / 50);
    }

    // A tile listing many lights (a glTF Sponza's busiest tile listed 264 of
    // 340, and filled the view with translucent spheres): with more listed
    // lights than the sphere cap the highlight is rings; only the tile's
    // lights draws exactly its list.
    void busyTileIsHighlightedWithRings() {
        openWithLights(1024);
        const auto run = doc()->runs().runOutput();
        const lc::CullResult& r = run->result;
        QCOMPARE(r.listsPerTile, 1u);
        int tile = -1;
        for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t)
            if (tile < 0 || r.listCount[t] > r.listCount[std::size_t(tile)]) tile = int(t);
        const std::uint32_t count = r.listCount[std::size_t(tile)];
        QVERIFY(count > 20);
        OverlayOptions o = doc()->viewOptions().overlays();
        o.sphereCap = int(std::min<std::uint32_t>(count - 1, 256));
        doc()->viewOptions().setOverlays(o);
        doc()->selection().setSelectedTile(tile);
        InspectorOverlays* ov = view()->overlays();
        QVERIFY(ov->listedActor()->GetVisibility());
        QVERIFY(ov->listedAsRings());
        auto* rings = LightSilhouettes::SafeDownCast(ov->listedActor()->GetMapper()->GetInputAlgorithm());
        QVERIFY(rings);
        view()->renderNow();
        QCOMPARE(rings->GetOutput()->GetNumberOfLines(), vtkIdType(ov->listedLights().size()));

        o.onlyTileLights = true;
        doc()->viewOptions().setOverlays(o);
        view()->renderNow();
        QCOMPARE(view()->drawnLights().size(), std::size_t(count));
        QVERIFY(view()->silhouettes()); // more than the cap: rings
        auto* drawn = LightSilhouettes::SafeDownCast(view()->lightActor()->GetMapper()->GetInputAlgorithm());
        QVERIFY(drawn);
        QCOMPARE(drawn->GetOutput()->GetNumberOfLines(), vtkIdType(count));
        QVERIFY(!ov->listedActor()->GetVisibility()); // the view draws them itself
    }

    // A real mouse click on the view selects the light whose sphere the click
    // ray enters first; a click where no sphere is leaves the selection alone.
    void clickSelectsNearestSphere() {
        openWithLights(1024);
        view()->renderNow();
        const auto& lights = doc()->scene().lights;
        int clicked = 0;
        for (std::size_t i = 3; i < lights.size() && clicked < 3; i += 131) {
            const QPoint pos = toWidget(lights[i].position);
            if (!view()->rect().adjusted(10, 10, -10, -10).contains(pos)) continue;
            const auto [o, d] = rayAt(pos);
            double best = std::numeric_limits<double>::infinity();
            for (std::size_t j = 0; j < lights.size(); ++j)
                best = std::min(best, entry(o, d, j));
            if (!std::isfinite(best)) continue; // the eye is inside every sphere on this ray
            doc()->selection().setSelectedLights({});
            QTest::mouseClick(view(), Qt::LeftButton, {}, pos);
            QTRY_COMPARE_WITH_TIMEOUT(doc()->selection().selectedLights().size(), std::size_t(1), 2000);
            const int sel = doc()->selection().currentLight();
            // No sphere is entered before the selected one (a mesh in front would
            // have left the selection empty, which the comparison above rejects).
            QVERIFY2(entry(o, d, std::size_t(sel)) <= best * (1 + 1e-9),
                     qPrintable(QString("clicked light %1 at t=%2, nearest entry %3")
                                    .arg(sel)
                                    .arg(entry(o, d, std::size_t(sel)))
                                    .arg(best)));
            ++clicked;
        }
        QVERIFY(clicked > 0);

        // Somewhere no sphere is hit: the selection stays as it was.
        const std::vector<int> selBefore = doc()->selection().selectedLights();
        bool found = false;
        for (int y = 12; y < view()->height() - 12 && !found; y += 17)
            for (int x = 12; x < view()->width() - 12 && !found; x += 17) {
                const auto [o, d] = rayAt({x, y});
                bool any = false;
                for (std::size_t j = 0; j < lights.size() && !any; ++j) {
                    const glm::dvec3 oc = lights[j].position - o;
                    const double b = glm::dot(oc, d);
                    any = glm::dot(oc, oc) - b * b <= lights[j].radius() * lights[j].radius() * 1.05;
                }
                if (any) continue;
                found = true;
                QTest::mouseClick(view(), Qt::LeftButton, {}, QPoint(x, y));
                QTest::qWait(50);
                QCOMPARE(doc()->selection().selectedLights(), selBefore);
            }
        QVERIFY(found);
    }

    // Dragging one light among 1,024 in Live mode: the views end on the
    // newest request's result, with ground truth, equal to a direct run.
    void liveDragEndsOnNewestResult() {
        openWithLights(1024);
        const int k = 500;
        doc()->selection().setSelectedLights({k});
        w_->setLive(true);
        QVERIFY(waitRun(w_->cullService()->lastGeneration()));
        vtkHandleWidget* handle = view()->handleWidget();
        vtkPointHandleRepresentation3D* rep = view()->handleRepresentation();
        const glm::dvec3 start = doc()->scene().lights[k].position;
        handle->InvokeEvent(vtkCommand::StartInteractionEvent);
        glm::dvec3 p = start;
        for (int i = 1; i <= 12; ++i) {
            p = start + glm::dvec3(0.2 * i, 0.05 * i, -0.1 * i);
            double wp[3] = {p.x, p.y, p.z};
            rep->SetWorldPosition(wp);
            handle->InvokeEvent(vtkCommand::InteractionEvent);
            QTest::qWait(5);
        }
        handle->InvokeEvent(vtkCommand::EndInteractionEvent);
        const quint64 last = w_->cullService()->lastGeneration();
        QVERIFY(waitRun(last, /*truth=*/true));
        QCOMPARE(doc()->runs().runGeneration(), last);
        const auto run = doc()->runs().runOutput();
        QVERIFY(run->depthReused); // only a light moved
        const lc::ViewLights expected = lc::makeViewLights(doc()->scene());
        QVERIFY(glm::length(run->lights.centers[k] - expected.centers[k]) < 1e-9);
        // The lists equal a direct run on the final scene.
        auto cpu = lc::makeBackend("cpu");
        const lc::RunOutput direct = lc::runPipeline(doc()->scene(), doc()->runs().settings(), *cpu);
        QVERIFY(run->result.listCount == direct.result.listCount);
        QVERIFY(run->result.listOffset == direct.result.listOffset);
        QVERIFY(run->result.lightIndices == direct.result.lightIndices);
        QCOMPARE(run->truth.metrics.falseNegatives, direct.truth.metrics.falseNegatives);
        QCOMPARE(run->truth.metrics.falseNegatives, std::uint64_t(0));
        w_->setLive(false);
    }

    // Light and camera edits keep the geometry revision (the worker reuses
    // depth and the request shares the mesh snapshot); mesh import, its undo
    // and a new scene change it, and the worker then renders depth again.
    void geometryRevisionFollowsMeshesOnly() {
        QVERIFY(w_->openBuiltin("atrium"));
        QVERIFY(w_->setParamFromUi("width", "320"));
        QVERIFY(w_->setParamFromUi("height", "180"));
        const quint64 r0 = doc()->geometryRevision();
        QVERIFY(waitRun(w_->runCulling()));
        const auto snapshot = w_->cullService()->meshSnapshot();
        QVERIFY(snapshot);
        QCOMPARE(snapshot->size(), doc()->scene().meshes.size());

        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.3, 0, 0), doc()->newDragId());
        lc::PointLight l = doc()->scene().lights[1];
        l.intensity *= 2;
        doc()->setLight(1, l);
        lc::Camera cam = doc()->scene().camera;
        cam.position.y += 0.25;
        doc()->setCamera(cam);
        QCOMPARE(doc()->geometryRevision(), r0);
        QVERIFY(waitRun(w_->runCulling()));
        QCOMPARE(w_->cullService()->meshSnapshot(), snapshot); // not copied again

        w_->setLive(true);
        QVERIFY(waitRun(w_->cullService()->lastGeneration()));
        doc()->moveLight(0, doc()->scene().lights[0].position + glm::dvec3(0.3, 0, 0), doc()->newDragId());
        QVERIFY(waitRun(w_->cullService()->lastGeneration()));
        QVERIFY(doc()->runs().runOutput()->depthReused);
        const std::vector<float> depthBefore = doc()->runs().runOutput()->depth.depth;

        // A box right in front of the culling camera: same camera, new depth.
        lc::Mesh box;
        box.name = "box";
        const glm::dvec3 fwd = glm::normalize(cam.target - cam.position);
        const glm::vec3 c = glm::vec3(cam.position + fwd * 1.5);
        for (int i = 0; i < 8; ++i) {
            const glm::vec3 v = c + 0.4f * glm::vec3((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1);
            box.positions.insert(box.positions.end(), {v.x, v.y, v.z});
        }
        box.indices = {0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4,
                       2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5};
        doc()->importMesh(box);
        const quint64 r1 = doc()->geometryRevision();
        QVERIFY(r1 != r0);
        QVERIFY(waitRun(w_->cullService()->lastGeneration()));
        QVERIFY(!doc()->runs().runOutput()->depthReused);
        QVERIFY(doc()->runs().runOutput()->depth.depth != depthBefore);
        QCOMPARE(w_->cullService()->meshSnapshot()->size(), doc()->scene().meshes.size());
        QVERIFY(w_->cullService()->meshSnapshot() != snapshot);

        doc()->undoStack()->undo();
        QVERIFY(doc()->geometryRevision() != r1 && doc()->geometryRevision() != r0);
        QVERIFY(waitRun(w_->cullService()->lastGeneration()));
        QVERIFY(!doc()->runs().runOutput()->depthReused);
        QVERIFY(doc()->runs().runOutput()->depth.depth == depthBefore);
        w_->setLive(false);

        const quint64 r2 = doc()->geometryRevision();
        doc()->undoStack()->clear();
        doc()->resetScene(doc()->scene(), {});
        QVERIFY(doc()->geometryRevision() != r2);
    }
};

LC_STUDIO_TEST_MAIN(ManyLightsTest)
#include "test_many_lights.moc"
