// The spot light's direction and outer-angle handles and the "Spot test
// primitive" overlay in the studio under Xvfb, driven through real widgets:
// each handle is dragged through its vtkHandleWidget's own interaction
// events (what a mouse drag sends), the new direction and angle are checked
// numerically, each drag is one undo step, Live mode re-culls during a drag,
// and the overlay draws exactly lc::spotTestPrimitive for every spot test.
// A screenshot with both handles and the primitive is written to look at.
#include "studio_test_support.hpp"
#include "document/document.hpp"
#include "views/inspector_view.hpp"
#include "window/main_window.hpp"
#include "views/overlay_actors.hpp"
#include "panels/property_panel.hpp"
#include "views/spot_actor.hpp"
#include "views/spot_handles.hpp"

#include "culling/diagnostics/overlays.hpp"

#include <QAction>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QImage>
#include <QTabBar>
#include <QUndoStack>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkRenderer.h>
#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTextActor.h>

#include <cmath>
#include <memory>

using namespace lcui;

namespace {


glm::dvec3 worldPosition(vtkPointHandleRepresentation3D* rep) {
    double p[3];
    rep->GetWorldPosition(p);
    return {p[0], p[1], p[2]};
}

// One step of a mouse drag as the handle widget reports it.
void dragTo(vtkHandleWidget* w, vtkPointHandleRepresentation3D* rep, const glm::dvec3& p) {
    double wp[3] = {p.x, p.y, p.z};
    rep->SetWorldPosition(wp);
    w->InvokeEvent(vtkCommand::InteractionEvent);
}

double angleDeg(const glm::dvec3& a, const glm::dvec3& b) {
    return glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0, 1.0)));
}

// A unit vector perpendicular to `axis`.
glm::dvec3 across(const glm::dvec3& axis) {
    return glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
}

} // namespace

class SpotHandlesTest : public QObject {
    Q_OBJECT
    std::unique_ptr<MainWindow> w_;
    Document* doc() { return w_->document(); }
    SpotHandles* handles() { return w_->inspectorView()->spotHandles(); }
    template <class T> T* panelField(const char* name) {
        T* f = w_->propertyPanel()->findChild<T*>(name);
        if (!f) qFatal("no field %s", name);
        return f;
    }
    int addSpot() {
        const int before = int(doc()->scene().lights.size());
        w_->action("actionAddSpotLight")->trigger();
        return int(doc()->scene().lights.size()) == before + 1 ? before : -1;
    }
    const lc::PointLight& light(int i) { return doc()->scene().lights[std::size_t(i)]; }
    bool runAndWait() { return lctest::waitRun(*w_, w_->runCulling()); }

private slots:
    void init() {
        w_ = lctest::makeTestWindow();
        QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
        QVERIFY(w_->openBuiltin("wall"));
        QVERIFY(w_->setParamFromUi("width", "320"));
        QVERIFY(w_->setParamFromUi("height", "180"));
    }

    void cleanup() {
        doc()->undoStack()->setClean();
        w_.reset();
    }

    void directionDragIsOneUndoStep() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        const lc::PointLight before = light(i);
        vtkHandleWidget* w = handles()->directionWidget();
        vtkPointHandleRepresentation3D* rep = handles()->directionRepresentation();
        QVERIFY(w->GetEnabled());
        // The handle sits on the axis at the cap's tip.
        const glm::dvec3 axis = glm::normalize(before.direction);
        QVERIFY(glm::length(worldPosition(rep) - (before.position + axis * before.radius())) < 1e-9);

        const int steps = doc()->undoStack()->count();
        w->InvokeEvent(vtkCommand::StartInteractionEvent);
        const glm::dvec3 side = across(axis);
        glm::dvec3 want;
        for (int k = 1; k <= 4; ++k) {
            // Swing the handle sideways by 15, 30, 45, 60 degrees, at varying distance.
            const double a = glm::radians(15.0 * k);
            const glm::dvec3 p = before.position + (1.0 + k) * (std::cos(a) * axis + std::sin(a) * side);
            dragTo(w, rep, p);
            want = glm::normalize(p - before.position);
            QVERIFY(glm::length(light(i).direction - want) < 1e-12); // the light follows during the drag
            QVERIFY(std::abs(angleDeg(light(i).direction, axis) - 15.0 * k) < 1e-9);
            // The property panel follows (2 decimals shown).
            QVERIFY(std::abs(panelField<QDoubleSpinBox>("lightDirX")->value() - want.x) < 0.006);
        }
        // A handle dropped on the apex names no direction: the last one stays.
        dragTo(w, rep, before.position);
        QVERIFY(glm::length(light(i).direction - want) < 1e-12);
        w->InvokeEvent(vtkCommand::EndInteractionEvent);
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
        QCOMPARE(light(i).outerAngleDeg, before.outerAngleDeg);
        QCOMPARE(light(i).position, before.position);
        // After the drag the handle snaps back onto the new axis at the tip.
        QVERIFY(glm::length(worldPosition(rep) - (before.position + want * before.radius())) < 1e-9);
        // The cone drawn follows (its apex-to-rim lines open around the new axis).
        vtkPolyData* cone = w_->inspectorView()->spotCones()->data();
        double rim[3];
        cone->GetPoint(1, rim);
        QVERIFY(std::abs(angleDeg(glm::dvec3(rim[0], rim[1], rim[2]) - before.position, want) -
                         before.outerAngleDeg) < 1e-4);

        doc()->undoStack()->undo();
        QCOMPARE(light(i).direction, before.direction);
        QVERIFY(glm::length(worldPosition(rep) - (before.position + axis * before.radius())) < 1e-9);
        doc()->undoStack()->redo();
        QVERIFY(glm::length(light(i).direction - want) < 1e-12);
        // A second drag is a second step.
        w->InvokeEvent(vtkCommand::StartInteractionEvent);
        dragTo(w, rep, before.position + glm::dvec3(0, 0, -2));
        w->InvokeEvent(vtkCommand::EndInteractionEvent);
        QCOMPARE(doc()->undoStack()->count(), steps + 2);
        QVERIFY(glm::length(light(i).direction - glm::dvec3(0, 0, -1)) < 1e-12);
    }

    void angleDragIsClampedAndOneUndoStep() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        const lc::PointLight before = light(i);
        vtkHandleWidget* w = handles()->angleWidget();
        vtkPointHandleRepresentation3D* rep = handles()->angleRepresentation();
        QVERIFY(w->GetEnabled());
        const glm::dvec3 axis = glm::normalize(before.direction);
        // The handle sits on the rim: at the range, at the outer angle.
        const glm::dvec3 h0 = worldPosition(rep) - before.position;
        QVERIFY(std::abs(glm::length(h0) - before.radius()) < 1e-9 * before.radius());
        QVERIFY(std::abs(angleDeg(h0, axis) - before.outerAngleDeg) < 1e-9);
        const glm::dvec3 dirHandle = worldPosition(handles()->directionRepresentation());

        const int steps = doc()->undoStack()->count();
        const glm::dvec3 side = across(axis);
        w->InvokeEvent(vtkCommand::StartInteractionEvent);
        // Distance to the axis vs distance along it: 50 degrees, whatever the length.
        const double a = glm::radians(50.0);
        dragTo(w, rep, before.position + 0.7 * (std::cos(a) * axis + std::sin(a) * side));
        QVERIFY(std::abs(light(i).outerAngleDeg - 50.0) < 1e-9);
        QVERIFY(std::abs(panelField<QDoubleSpinBox>("lightOuterAngle")->value() - 50.0) < 0.006);
        // The direction handle stays on the (unchanged) axis.
        QVERIFY(glm::length(worldPosition(handles()->directionRepresentation()) - dirHandle) < 1e-9);
        QCOMPARE(light(i).direction, before.direction);
        // Behind the apex plane: clamped to the model's 90 degrees.
        dragTo(w, rep, before.position - 2.0 * axis + 0.5 * side);
        QCOMPARE(light(i).outerAngleDeg, 90.0);
        QVERIFY(light(i).validate().empty());
        // On the axis: clamped to the smallest angle the panel accepts (> 0).
        dragTo(w, rep, before.position + 3.0 * axis);
        QCOMPARE(light(i).outerAngleDeg, SpotHandles::kMinOuterAngleDeg);
        QVERIFY(light(i).validate().empty());
        // And back to 20 degrees before letting go.
        const double b = glm::radians(20.0);
        dragTo(w, rep, before.position + 4.0 * (std::cos(b) * axis - std::sin(b) * side));
        w->InvokeEvent(vtkCommand::EndInteractionEvent);
        QVERIFY(std::abs(light(i).outerAngleDeg - 20.0) < 1e-9);
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
        // Back on the rim of the new cone.
        const glm::dvec3 h1 = worldPosition(rep) - before.position;
        QVERIFY(std::abs(glm::length(h1) - before.radius()) < 1e-9 * before.radius());
        QVERIFY(std::abs(angleDeg(h1, axis) - 20.0) < 1e-9);

        doc()->undoStack()->undo();
        QCOMPARE(light(i).outerAngleDeg, before.outerAngleDeg);
        QCOMPARE(panelField<QDoubleSpinBox>("lightOuterAngle")->value(), before.outerAngleDeg);
        doc()->undoStack()->redo();
        QVERIFY(std::abs(light(i).outerAngleDeg - 20.0) < 1e-9);
    }

    void handlesShowOnlyForOneSelectedSpot() {
        const int spot = addSpot();
        QVERIFY(spot >= 0);
        QVERIFY(handles()->directionWidget()->GetEnabled());
        QVERIFY(handles()->angleWidget()->GetEnabled());
        int point = -1;
        for (int k = 0; k < int(doc()->scene().lights.size()); ++k)
            if (!light(k).isSpot()) point = k;
        QVERIFY(point >= 0);
        doc()->selection().setSelectedLights({point});
        QVERIFY(!handles()->directionWidget()->GetEnabled());
        QVERIFY(!handles()->angleWidget()->GetEnabled());
        QVERIFY(w_->inspectorView()->handleWidget()->GetEnabled()); // the position handle still shows
        doc()->selection().setSelectedLights({point, spot});
        QVERIFY(!handles()->directionWidget()->GetEnabled());
        doc()->selection().setSelectedLights({spot});
        QVERIFY(handles()->directionWidget()->GetEnabled());
        auto* kind = panelField<QComboBox>("lightKind");
        kind->setCurrentIndex(kind->findText("point"));
        QVERIFY(!handles()->directionWidget()->GetEnabled());
        QVERIFY(!handles()->angleWidget()->GetEnabled());
        doc()->undoStack()->undo();
        QVERIFY(handles()->angleWidget()->GetEnabled());
        doc()->selection().setSelectedLights({});
        QVERIFY(!handles()->angleWidget()->GetEnabled());
    }

    void liveModeReCullsDuringADrag() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        QVERIFY(runAndWait());
        w_->setLive(true);
        const lc::PointLight before = light(i);
        vtkHandleWidget* w = handles()->directionWidget();
        vtkPointHandleRepresentation3D* rep = handles()->directionRepresentation();
        const glm::dvec3 axis = glm::normalize(before.direction);
        const glm::dvec3 target = glm::normalize(axis + across(axis));
        const glm::dmat3 viewRot(doc()->scene().camera.viewFromWorld());
        const glm::dvec3 targetView = glm::normalize(viewRot * target);
        const int steps = doc()->undoStack()->count();
        w->InvokeEvent(vtkCommand::StartInteractionEvent);
        dragTo(w, rep, before.position + 2.0 * target);
        // Before the drag ends, a Live run culls the turned spot.
        QElapsedTimer t;
        t.start();
        auto turned = [&] {
            const auto run = doc()->runs().runOutput();
            return run && run->lights.isSpot(std::size_t(i)) &&
                   glm::length(run->lights.spotAxes[std::size_t(i)] - targetView) < 1e-9;
        };
        while (!turned() && t.elapsed() < lctest::kRunTimeoutMs) QTest::qWait(20);
        QVERIFY(turned());
        w->InvokeEvent(vtkCommand::EndInteractionEvent);
        QCOMPARE(doc()->undoStack()->count(), steps + 1);
        w_->setLive(false);
    }

    // The overlay draws lc::spotTestPrimitive of the shown run, for the
    // current spot light and the selected tile, under every spot test.
    void primitiveOverlayIsTheCullingsPrimitive() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        QVERIFY(w_->setParamFromUi("algorithm", "clustered"));
        QAction* toggle = w_->action("actionOverlaySpotPrimitive");
        QVERIFY(toggle);
        QVERIFY(!toggle->isChecked()); // off by default
        InspectorOverlays* ov = w_->inspectorView()->overlays();
        for (const char* test : {"apex-sphere", "tight-sphere", "cone-sphere", "cone-planes"}) {
            QVERIFY(w_->setParamFromUi("spot-test", test));
            QVERIFY(runAndWait());
            const auto run = doc()->runs().runOutput();
            QCOMPARE(QString(lc::toString(run->result.settings.spotTest)), QString(test));
            // A tile whose lists hold the spot.
            const auto tiles = lc::tilesHoldingLight(run->result, std::uint32_t(i));
            QVERIFY(!tiles.empty());
            const int tile = int(tiles[tiles.size() / 2]);
            doc()->selection().setSelectedTile(tile);
            doc()->selection().setSelectedLights({i});
            toggle->setChecked(false);
            QVERIFY(!ov->spotPrimitive());
            QCOMPARE(ov->spotCullSphere()->GetNumberOfCells(), vtkIdType(0));
            toggle->setChecked(true);
            QVERIFY(ov->spotPrimitive());

            const lc::Projection proj(doc()->scene().camera);
            const auto want = lc::spotTestPrimitive(*run, proj, std::uint32_t(i), tile);
            QVERIFY(want);
            const lc::SpotTestPrimitive& got = *ov->spotPrimitive();
            QVERIFY(got.test == want->test);
            QCOMPARE(got.cullSphere.center, want->cullSphere.center);
            QCOMPARE(got.cullSphere.radius, want->cullSphere.radius);
            QCOMPARE(got.chunks.size(), want->chunks.size());
            QVERIFY(!want->chunks.empty());
            // The drawn circles lie on the culling sphere (world space, float points).
            const glm::dmat4 wv = lc::worldFromView(doc()->scene().camera);
            auto onSphere = [&](vtkPolyData* pd, const lc::BoundingSphere& s) {
                const glm::dvec3 c(wv * glm::dvec4(s.center, 1.0));
                for (vtkIdType k = 0; k < pd->GetNumberOfPoints(); ++k) {
                    double p[3];
                    pd->GetPoint(k, p);
                    if (std::abs(glm::length(glm::dvec3(p[0], p[1], p[2]) - c) - s.radius) > 1e-5 * (1 + s.radius))
                        return false;
                }
                return pd->GetNumberOfPoints() > 0;
            };
            QVERIFY(onSphere(ov->spotCullSphere(), want->cullSphere));
            std::size_t passed = 0;
            for (const auto& c : want->chunks) passed += c.passed;
            QVERIFY(passed > 0); // the light is listed in this tile
            const std::size_t rejected = want->chunks.size() - passed;
            const QString caption = ov->spotCaption()->GetInput();
            QVERIFY2(caption.contains(test), qPrintable(caption));
            QVERIFY2(caption.contains(QString("%1 passed (blue), %2 rejected").arg(passed).arg(rejected)),
                     qPrintable(caption));
            if (std::string(test) == "cone-sphere") {
                // 3 circles per chunk sphere, on that sphere, split by verdict.
                QCOMPARE(ov->spotChunksPassed()->GetNumberOfCells(), vtkIdType(3 * passed));
                QCOMPARE(ov->spotChunksRejected()->GetNumberOfCells(), vtkIdType(3 * rejected));
                vtkPolyData* pd = ov->spotChunksPassed();
                vtkIdType cell = 0;
                for (const auto& c : want->chunks) {
                    if (!c.passed) continue;
                    vtkNew<vtkPolyData> one; // the chunk's three circles
                    vtkNew<vtkPoints> pts;
                    for (int circle = 0; circle < 3; ++circle, ++cell) {
                        vtkIdType n;
                        const vtkIdType* ids;
                        pd->GetCellPoints(cell, n, ids);
                        for (vtkIdType k = 0; k < n; ++k) pts->InsertNextPoint(pd->GetPoint(ids[k]));
                    }
                    one->SetPoints(pts);
                    QVERIFY(onSphere(one, c.sphere));
                }
                QVERIFY(caption.contains("bounding sphere"));
            } else if (std::string(test) == "cone-planes") {
                QCOMPARE(ov->spotChunksPassed()->GetNumberOfCells(), vtkIdType(12 * passed));
                QCOMPARE(ov->spotChunksRejected()->GetNumberOfCells(), vtkIdType(12 * rejected));
                QVERIFY(caption.contains("planes"));
            } else {
                QCOMPARE(ov->spotChunksPassed()->GetNumberOfCells(), vtkIdType(0));
                QCOMPARE(ov->spotChunksRejected()->GetNumberOfCells(), vtkIdType(0));
            }
        }
        // A point light shows no spot primitive.
        for (int k = 0; k < int(doc()->scene().lights.size()); ++k)
            if (!light(k).isSpot()) {
                doc()->selection().setSelectedLights({k});
                break;
            }
        QVERIFY(!ov->spotPrimitive());
        QVERIFY(!ov->spotCaption()->GetVisibility());
    }

    // Both handles and the primitive of a clustered run (cone-sphere, then
    // cone-planes), the inspector framed on the spot, to look at.
    void screenshotWithHandlesAndPrimitive() {
        const int i = addSpot();
        QVERIFY(i >= 0);
        w_->action("actionTabbedViews")->setChecked(true); // the inspector gets the width
        for (QTabBar* bar : w_->findChildren<QTabBar*>())
            if (bar->count() == 2 && bar->tabText(1) == "Inspector view") bar->setCurrentIndex(1);
        QVERIFY(w_->setParamFromUi("algorithm", "clustered"));
        w_->action("actionOverlaySpotPrimitive")->setChecked(true);
        // Only the tile frustum besides the primitive: the other overlays
        // (cells, cell range, reverse look-up) would cover it.
        for (const char* name : {"actionOverlayCells", "actionOverlayLightRange", "actionOverlayReverse",
                                 "actionOverlayListHighlight"})
            w_->action(name)->setChecked(false);
        // The wall's 256 point-light spheres hide the cone: not drawn in this shot.
        w_->inspectorView()->lightActor()->SetVisibility(false);
        for (const char* test : {"cone-sphere", "cone-planes"}) {
            QVERIFY(w_->setParamFromUi("spot-test", test));
            QVERIFY(runAndWait());
            const auto tiles = lc::tilesHoldingLight(doc()->runs().runOutput()->result, std::uint32_t(i));
            QVERIFY(!tiles.empty());
            doc()->selection().setSelectedTile(int(tiles[tiles.size() / 2]));
            doc()->selection().setSelectedLights({i});
            QVERIFY(handles()->directionWidget()->GetEnabled() && handles()->angleWidget()->GetEnabled());
            InspectorView* view = w_->inspectorView();
            QVERIFY(view->isVisible());
            // Frame the cone from the side: focal point mid-axis.
            const lc::PointLight& l = light(i);
            const glm::dvec3 axis = glm::normalize(l.direction);
            const glm::dvec3 mid = l.position + 0.5 * l.radius() * axis;
            const glm::dvec3 eye = mid + 3.5 * l.radius() * glm::normalize(across(axis) + 0.6 * glm::cross(axis, across(axis)) - 0.3 * axis);
            vtkCamera* cam = view->renderer()->GetActiveCamera();
            cam->SetFocalPoint(mid.x, mid.y, mid.z);
            cam->SetPosition(eye.x, eye.y, eye.z);
            cam->SetViewUp(0, 1, 0);
            view->renderer()->ResetCameraClippingRange();
            handles()->update(); // the angle handle to the new view's right
            view->renderNow();
            QTest::qWait(50);
            view->renderNow();
            const QImage shot = view->grabFramebuffer();
            QVERIFY(!shot.isNull());
            QDir().mkpath(LC_RENDER_OUT_DIR);
            QVERIFY(shot.save(QString(LC_RENDER_OUT_DIR) + "/spot_handles_" + test + ".png"));
        }
    }
};

LC_STUDIO_TEST_MAIN(SpotHandlesTest)
#include "test_spot_handles.moc"
