// The inspector view's pointer: picking lights, surfaces and frustum chunks
// under the cursor, clicks that select, and the position and radius handles
// that drag the current light (inspector_view.hpp).
#include "views/inspector_view.hpp"

#include "document/document.hpp"
#include "views/light_silhouettes.hpp"
#include "views/overlay_actors.hpp"
#include "views/vtk_adapters.hpp"
#include "views/spot_actor.hpp"
#include "views/spot_handles.hpp"

#include "culling/math/projection.hpp"

#include <QStringList>
#include <QTimer>

#include "culling/diagnostics/overlays.hpp"

#include <functional>
#include <optional>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCameraPass.h>
#include <vtkCellArray.h>
#include <vtkCellPicker.h>
#include <vtkDataArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGlyph3D.h>
#include <vtkHandleWidget.h>
#include <vtkInteractorStyle.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLightsPass.h>
#include <vtkOpaquePass.h>
#include <vtkOverlayPass.h>
#include <vtkPointData.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderPassCollection.h>
#include <vtkRenderer.h>
#include <vtkSequencePass.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTranslucentPass.h>
#include <vtkVolumetricPass.h>
#include <QVTKInteractor.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace lcui {

namespace {

// A handle on the handle layer, its colours and size, disabled until a light
// is selected; `start`, `move` and `end` observe its drag.
template <class View>
void setUpHandle(vtkHandleWidget* widget, vtkPointHandleRepresentation3D* rep, int size, const double colour[3],
                 vtkRenderWindowInteractor* interactor, vtkRenderer* layer, View* view, void (View::*start)(),
                 void (View::*move)(), void (View::*end)()) {
    rep->SetHandleSize(size);
    rep->GetProperty()->SetColor(colour[0], colour[1], colour[2]);
    rep->GetProperty()->SetLineWidth(3);
    rep->GetSelectedProperty()->SetLineWidth(3);
    rep->GetSelectedProperty()->SetColor(1, 0.3, 0.2);
    rep->ActiveRepresentationOff();
    widget->SetInteractor(interactor);
    widget->SetDefaultRenderer(layer);
    widget->SetRepresentation(rep);
    widget->AddObserver(vtkCommand::StartInteractionEvent, view, start);
    widget->AddObserver(vtkCommand::InteractionEvent, view, move);
    widget->AddObserver(vtkCommand::EndInteractionEvent, view, end);
    widget->EnabledOff();
}

} // namespace

void InspectorView::buildHandles(vtkInteractorStyle* style) {
    const double position[3] = {1, 0.45, 0.1}, radius[3] = {0.2, 1.0, 0.9};
    setUpHandle(handle_.Get(), handleRep_.Get(), 40, position, interactor(), handleLayer_.Get(), this,
                &InspectorView::onHandleStart, &InspectorView::onHandleMove, &InspectorView::onHandleEnd);
    setUpHandle(radiusHandle_.Get(), radiusRep_.Get(), 25, radius, interactor(), handleLayer_.Get(), this,
                &InspectorView::onRadiusStart, &InspectorView::onRadiusMove, &InspectorView::onRadiusEnd);
    // After an orbit, the radius handle goes back to the right of the centre.
    style->AddObserver(vtkCommand::EndInteractionEvent, this, &InspectorView::placeRadiusHandle);
    spotHandles_ = std::make_unique<SpotHandles>(doc_, renderer_, interactor(), handleLayer_);
}

void InspectorView::onHandleStart() {
    handleActive_ = true;
    dragLight_ = doc_->selection().currentLight();
    dragId_ = doc_->newDragId();
}

void InspectorView::onHandleMove() {
    if (dragLight_ < 0) return;
    double p[3];
    handleRep_->GetWorldPosition(p);
    doc_->moveLight(dragLight_, {p[0], p[1], p[2]}, dragId_);
}

void InspectorView::onHandleEnd() {
    onHandleMove();
    handleActive_ = false;
    dragLight_ = -1;
}

void InspectorView::placeRadiusHandle() {
    const int cur = doc_->selection().currentLight();
    const auto& lights = doc_->scene().lights;
    if (radiusActive_ || cur < 0 || cur >= int(lights.size())) return;
    // The view's right vector: direction of projection x view up.
    vtkCamera* vc = renderer_->GetActiveCamera();
    double dop[3], up[3];
    vc->GetDirectionOfProjection(dop);
    vc->GetViewUp(up);
    glm::dvec3 right = glm::cross(glm::dvec3(dop[0], dop[1], dop[2]), glm::dvec3(up[0], up[1], up[2]));
    right = glm::length(right) > 0 ? glm::normalize(right) : glm::dvec3(1, 0, 0);
    const auto& l = lights[std::size_t(cur)];
    const glm::dvec3 p = l.position + right * lightDisplayRadius(l);
    double wp[3] = {p.x, p.y, p.z};
    radiusRep_->SetWorldPosition(wp);
}

void InspectorView::onRadiusStart() {
    radiusActive_ = true;
    dragLight_ = doc_->selection().currentLight();
    dragId_ = doc_->newDragId();
}

void InspectorView::onRadiusMove() {
    if (dragLight_ < 0 || dragLight_ >= int(doc_->scene().lights.size())) return;
    double p[3];
    radiusRep_->GetWorldPosition(p);
    const glm::dvec3 c = doc_->scene().lights[std::size_t(dragLight_)].position;
    doc_->resizeLight(dragLight_, glm::length(glm::dvec3(p[0], p[1], p[2]) - c), dragId_);
}

void InspectorView::onRadiusEnd() {
    onRadiusMove();
    radiusActive_ = false;
    dragLight_ = -1;
    placeRadiusHandle();
}

int InspectorView::pickLight(const QPoint& pos, glm::dvec3* hit) {
    const double dpr = devicePixelRatioF();
    const double x = pos.x() * dpr, y = (height() - 1 - pos.y()) * dpr;
    const auto [origin, farPoint] = viewRay(pos);
    double nearest = glm::length(farPoint - origin);
    if (!(nearest > 0)) return -1;
    const glm::dvec3 dir = (farPoint - origin) / nearest;
    // A mesh surface in front hides the spheres behind it (not an x-ray one:
    // what the view shows through it can be clicked; a hidden one is not picked).
    if (!doc_->viewOptions().overlays().showLights) return -1;
    if (doc_->viewOptions().overlays().meshes == OverlayOptions::MeshDisplay::Normal && picker_->Pick(x, y, 0, renderer_) &&
        picker_->GetActor()) {
        double p[3];
        picker_->GetPickPosition(p);
        nearest = std::min(nearest, glm::dot(glm::dvec3(p[0], p[1], p[2]) - origin, dir));
    }
    // The first sphere the ray enters. A sphere around the ray's origin is
    // skipped: its surface is behind the viewer, nothing of it is in view.
    // Only the lights drawn (View > Lights) can be clicked.
    int best = -1;
    const auto& lights = doc_->scene().lights;
    for (int k : drawn_) {
        const std::size_t i = std::size_t(k);
        if (i >= lights.size()) continue;
        const double r = lightDisplayRadius(lights[i]);
        if (!(r > 0)) continue;
        const glm::dvec3 oc = lights[i].position - origin;
        const double b = glm::dot(oc, dir), c = glm::dot(oc, oc) - r * r;
        if (c <= 0) continue;
        const double disc = b * b - c;
        if (disc < 0) continue;
        const double t = b - std::sqrt(disc);
        if (t > 0 && t < nearest) {
            nearest = t;
            best = int(i);
        }
    }
    if (best >= 0 && hit) *hit = origin + nearest * dir;
    return best;
}

bool InspectorView::pickSurface(const QPoint& pos, glm::dvec3* point, glm::dvec3* normal) {
    const double dpr = devicePixelRatioF();
    const double x = pos.x() * dpr, y = (height() - 1 - pos.y()) * dpr;
    if (!picker_->Pick(x, y, 0, renderer_) || !picker_->GetActor()) return false;
    double p[3], n[3];
    picker_->GetPickPosition(p);
    picker_->GetPickNormal(n);
    *point = {p[0], p[1], p[2]};
    if (normal) {
        glm::dvec3 nn(n[0], n[1], n[2]);
        double cp[3];
        renderer_->GetActiveCamera()->GetPosition(cp);
        if (glm::dot(nn, glm::dvec3(cp[0], cp[1], cp[2]) - *point) < 0) nn = -nn;
        *normal = glm::length(nn) > 0 ? glm::normalize(nn) : glm::dvec3(0, 1, 0);
    }
    return true;
}

void InspectorView::onLeftPress() { interactor()->GetEventPosition(pressX_, pressY_); }

void InspectorView::onLeftRelease() {
    int x = 0, y = 0;
    interactor()->GetEventPosition(x, y);
    if (std::abs(x - pressX_) > 3 || std::abs(y - pressY_) > 3 || handleActive_ || radiusActive_ ||
        spotHandles_->dragging())
        return; // an orbit or a handle drag, not a click
    const double dpr = devicePixelRatioF();
    const QPoint pos(int(x / dpr), int(height() - 1 - y / dpr));
    const int light = pickLight(pos);
    if (light >= 0) {
        const bool add = interactor()->GetControlKey() || interactor()->GetShiftKey();
        std::vector<int> sel = add ? doc_->selection().selectedLights() : std::vector<int>{};
        sel.push_back(light);
        doc_->selection().setSelectedLights(sel);
        return;
    }
    int tile = -1, cell = -1;
    if (pickChunk(pos, &tile, &cell)) {
        doc_->selection().setSelectedTile(tile);
        doc_->selection().setSelectedCell(cell);
    }
}

bool InspectorView::pickChunk(const QPoint& pos, int* tileOut, int* cellOut) {
    const auto run = doc_->runs().runOutput();
    if (!run) return false;
    const auto& ov = doc_->viewOptions().overlays();
    const auto [nearPoint, farPoint] = viewRay(pos);
    // The click ray in the culling camera's view space, where chunks live.
    const glm::dmat4 view = doc_->scene().camera.viewFromWorld();
    const glm::dvec3 o = glm::dvec3(view * glm::dvec4(nearPoint, 1.0));
    glm::dvec3 d = glm::dvec3(view * glm::dvec4(farPoint, 1.0)) - o;
    if (!(glm::length(d) > 0)) return false;
    d = glm::normalize(d);
    // Entry distance of the ray into a convex chunk (inside: n.p + w >= 0), or -1.
    auto enter = [&](const lc::FrustumChunk& c) {
        double t0 = 0, t1 = 1e300;
        for (const lc::Plane& pl : c.planes) {
            const double denom = pl.x * d.x + pl.y * d.y + pl.z * d.z, dist = lc::signedDistance(pl, o);
            if (denom == 0.0) {
                if (dist < 0) return -1.0;
                continue;
            }
            const double t = -dist / denom;
            if (denom > 0) t0 = std::max(t0, t);
            else t1 = std::min(t1, t);
        }
        return t0 <= t1 ? t0 : -1.0;
    };
    const lc::Projection proj(doc_->scene().camera);
    const lc::CullResult& r = run->result;
    double best = 1e300;
    // The selected tile's cells (drawn with the cells overlay) first: they are
    // inside its frustum, so a click on one must select the cell.
    const int sel = doc_->selection().selectedTile();
    if (ov.cells && sel >= 0 && std::uint32_t(sel) < r.grid.tileCount())
        for (const lc::DepthCell& c : lc::tileCells(r, proj, std::uint32_t(sel))) {
            const double t = enter(c.chunk);
            if (t >= 0 && t < best) best = t, *tileOut = sel, *cellOut = int(c.cell);
        }
    if (best < 1e300) return true;
    // Then every tile's frustum, when they are drawn; else the selected one.
    for (std::uint32_t t = 0; t < r.grid.tileCount(); ++t) {
        if (!ov.allTileFrustums && !(ov.tileFrustum && int(t) == sel)) continue;
        const auto chunk = lc::tileFrustum(r, proj, run->lights, t);
        if (!chunk) continue;
        const double h = enter(*chunk);
        if (h >= 0 && h < best) best = h, *tileOut = int(t), *cellOut = -1;
    }
    return best < 1e300;
}

} // namespace lcui
