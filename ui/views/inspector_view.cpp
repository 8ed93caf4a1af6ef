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
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkPointData.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <QVTKInteractor.h>

#include <algorithm>
#include <cmath>
#include <numeric>

namespace lcui {

namespace {
// Rings are lines: opaque they would be as loud as the selection outline.
// Fainter as they get denser (10,000 rings at 0.55 hide the scene), and a
// sixth of that while a tile's listed lights are highlighted.
double ringOpacity(std::size_t lights) {
    return std::clamp(0.55 * std::sqrt(1024.0 / double(std::max<std::size_t>(lights, 1))), 0.15, 0.55);
}
} // namespace

InspectorView::InspectorView(Document* doc, QWidget* parent)
    : QVTKOpenGLNativeWidget(parent), doc_(doc) {
    vtkNew<vtkGenericOpenGLRenderWindow> rw;
    setRenderWindow(rw);
    renderer_->SetBackground(0.16, 0.17, 0.2);
    renderer_->SetBackground2(0.05, 0.05, 0.07);
    renderer_->GradientBackgroundOn();
    rw->AddRenderer(renderer_);
    // Handles: a layer above the scene with the same camera. A layer above 0
    // keeps the colour below and clears depth, so a wall never hides a handle.
    rw->SetNumberOfLayers(2);
    handleLayer_->SetLayer(1);
    handleLayer_->InteractiveOff(); // orbits and picks go to the scene's renderer
    handleLayer_->SetActiveCamera(renderer_->GetActiveCamera());
    rw->AddRenderer(handleLayer_);

    buildLightActors();
    // Inspection overlays; translucent volumes over translucent spheres stay
    // readable with depth peeling (order-independent).
    overlays_ = std::make_unique<InspectorOverlays>(renderer_, sphere_);
    buildRenderPasses(rw);
    vtkNew<vtkInteractorStyleTrackballCamera> style;
    interactor()->SetInteractorStyle(style);
    buildHandles(style);
    buildLightNote();

    picker_->SetTolerance(0.0005);
    picker_->PickFromListOn();
    // High priority: see the press before the trackball style or the handle take it.
    interactor()->AddObserver(vtkCommand::LeftButtonPressEvent, this, &InspectorView::onLeftPress, 10.0f);
    // Passive: on a press the trackball style grabs the interactor's focus,
    // and until it lets go only passive observers see the release (a click
    // on a light never reached onLeftRelease before).
    const unsigned long releaseTag = interactor()->AddObserver(vtkCommand::LeftButtonReleaseEvent, this,
                                                               &InspectorView::onLeftRelease, 10.0f);
    interactor()->GetCommand(releaseTag)->PassiveObserverOn();

    connect(doc_, &Document::sceneReset, this, [this] {
        cameraFramed_ = false;
        rebuildMeshes();
        rebuildLights();
        updateFrustum();
        resetCamera();
    });
    connect(doc_, &Document::meshesChanged, this, [this] {
        rebuildMeshes();
        scheduleRender();
    });
    connect(&doc_->viewOptions(), &ViewOptions::overlaysChanged, this, [this] {
        applyMeshDisplay();
        scheduleRender();
    });
    connect(doc_, &Document::lightsChanged, this, [this] {
        rebuildLights();
        updateSelection();
        scheduleRender();
    });
    connect(doc_, &Document::lightChanged, this, [this](int i) {
        updateLight(i);
        updateSelection();
        scheduleRender();
    });
    connect(&doc_->selection(), &Selection::changed, this, [this] {
        updateSelection();
        scheduleRender();
    });
    connect(doc_, &Document::cameraChanged, this, [this] {
        updateFrustum();
        updateOverlays();
        scheduleRender();
    });
    // A stale run's overlays go (the light indices they use may have moved).
    const auto refresh = [this] {
        refreshLightSet();
        updateOverlays();
        scheduleRender();
    };
    connect(&doc_->runs(), &RunState::runOutputChanged, this, refresh);
    connect(&doc_->runs(), &RunState::runWentStale, this, refresh);
    connect(&doc_->viewOptions(), &ViewOptions::overlaysChanged, this, refresh);
    connect(&doc_->selection(), &Selection::changed, this, refresh);
    connect(&doc_->selection(), &Selection::tileChanged, this, refresh);
    connect(doc_, &Document::lightsChanged, this, refresh);
    rebuildMeshes();
    rebuildLights();
    updateFrustum();
    updateSelection();
    updateOverlays();
    resetCamera();
}

InspectorView::~InspectorView() = default;

void InspectorView::updateOverlays() {
    overlays_->update(*doc_);
    // Dim the other lights while a tile's listed lights are highlighted.
    lightActor_->GetProperty()->SetOpacity(overlays_->dimLights() ? 0.06 : 0.22);
    const double rings = ringOpacity(drawn_.size());
    ringActor_->GetProperty()->SetOpacity(overlays_->dimLights() ? 0.15 * rings : rings);
    spotCones_->actor()->GetProperty()->SetOpacity(overlays_->dimLights() ? 0.25 : 1.0);
    // The note: which tile's lights are shown, and what the sphere cap left out.
    const auto& ov = doc_->viewOptions().overlays();
    QStringList note;
    if (ov.showLights && ov.onlyTileLights) {
        if (drawnAreTileLights_)
            note << tr("only tile %1's %2 listed lights").arg(doc_->selection().selectedTile()).arg(drawn_.size() + leftOut_);
        else
            note << tr("only the selected tile's lights: select a tile (after a run)");
    }
    if (leftOut_ > 0)
        note << tr("+%1 more lights not drawn (sphere cap %2: View > Lights)").arg(leftOut_).arg(ov.sphereCap);
    if (overlays_->listedLeftOut() > 0)
        note << tr("+%1 more listed lights not drawn (sphere cap %2)").arg(overlays_->listedLeftOut()).arg(ov.sphereCap);
    lightNote_->SetInput(note.join('\n').toUtf8().constData());
    lightNote_->SetVisibility(!note.isEmpty());
}

vtkRenderer* InspectorView::renderer() const { return renderer_.Get(); }
vtkHandleWidget* InspectorView::handleWidget() const { return handle_.Get(); }
vtkPointHandleRepresentation3D* InspectorView::handleRepresentation() const { return handleRep_.Get(); }
vtkHandleWidget* InspectorView::radiusHandleWidget() const { return radiusHandle_.Get(); }
vtkPointHandleRepresentation3D* InspectorView::radiusHandleRepresentation() const { return radiusRep_.Get(); }
vtkActor* InspectorView::lightActor() const { return silhouettes_ ? ringActor_.Get() : lightActor_.Get(); }
vtkTextActor* InspectorView::lightNote() const { return lightNote_.Get(); }
vtkRenderer* InspectorView::handleLayer() const { return handleLayer_.Get(); }

void InspectorView::scheduleRender() {
    if (renderPending_) return;
    renderPending_ = true;
    QTimer::singleShot(0, this, [this] {
        renderPending_ = false;
        renderNow();
    });
}

void InspectorView::renderNow() {
    if (renderWindow()) renderWindow()->Render();
    update();
}

void InspectorView::rebuildMeshes() {
    for (auto& a : meshActors_) renderer_->RemoveActor(a);
    meshActors_.clear();
    // The picker sees meshes only: lights are picked as exact spheres (pickLight).
    picker_->InitializePickList();
    for (const auto& m : doc_->scene().meshes) {
        auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
        mapper->SetInputData(meshToPolyData(m));
        auto actor = vtkSmartPointer<vtkActor>::New();
        actor->SetMapper(mapper);
        actor->GetProperty()->SetColor(0.72, 0.72, 0.7);
        renderer_->AddActor(actor);
        meshActors_.push_back(actor);
        picker_->AddPickList(actor);
    }
    applyMeshDisplay();
}

void InspectorView::applyMeshDisplay() {
    using MD = OverlayOptions::MeshDisplay;
    const MD mode = doc_->viewOptions().overlays().meshes;
    for (auto& a : meshActors_) {
        // X-ray: translucent, so VTK draws it in the translucent pass without
        // depth writes: it shades what lies behind and hides none of it.
        a->SetVisibility(mode != MD::Hidden);
        a->GetProperty()->SetOpacity(mode == MD::XRay ? 0.12 : 1.0);
        a->GetProperty()->SetBackfaceCulling(false);
    }
}

void InspectorView::refreshLightSet() {
    // Rebuilt only when what chooses the drawn lights changed, so a Live drag
    // (a run per step) does not rebuild them when they do not depend on the run.
    if (lightSetKey() != lightSetKey_) rebuildLights();
}

std::vector<long long> InspectorView::lightSetKey() const {
    const auto& ov = doc_->viewOptions().overlays();
    std::vector<long long> key = {(long long)doc_->scene().lights.size(), int(ov.lights), ov.showLights,
                                  ov.onlyTileLights, ov.sphereCap, int(ov.meshes)};
    if (ov.onlyTileLights || leftOut_ > 0) {
        key.push_back(doc_->selection().selectedTile());
        key.push_back(doc_->selection().selectedCell());
        key.push_back((long long)(std::intptr_t)doc_->runs().runOutput().get());
        key.push_back(doc_->runs().runIsStale());
    }
    if (leftOut_ > 0) // the selection is drawn first
        key.insert(key.end(), doc_->selection().selectedLights().begin(), doc_->selection().selectedLights().end());
    return key;
}

void InspectorView::rebuildLights() {
    const auto& lights = doc_->scene().lights;
    const auto& ov = doc_->viewOptions().overlays();
    using LD = OverlayOptions::LightDisplay;
    using MD = OverlayOptions::MeshDisplay;
    // Which lights: every one, or the selected tile's listed ones.
    std::vector<int> set;
    drawnAreTileLights_ = false;
    if (ov.onlyTileLights)
        if (auto tileLights = InspectorOverlays::tileListLights(*doc_)) {
            set = std::move(*tileLights);
            drawnAreTileLights_ = true;
        }
    if (!drawnAreTileLights_) {
        set.resize(lights.size());
        std::iota(set.begin(), set.end(), 0);
    }
    // How: filled spheres (at most the cap) or silhouette rings.
    const std::size_t cap = std::size_t(std::max(ov.sphereCap, 1));
    silhouettes_ = ov.lights == LD::Outlines || (ov.lights == LD::Auto && set.size() > cap);
    leftOut_ = 0;
    if (!silhouettes_ && set.size() > cap) {
        // The selected lights first, then the nearest to what is looked at:
        // the selected tile's frustum, else the current light, else the view's
        // focal point.
        glm::dvec3 focus = viewBasis().focal;
        const auto run = doc_->runs().runOutput();
        const int tile = doc_->selection().selectedTile();
        if (run && tile >= 0 && std::uint32_t(tile) < run->result.grid.tileCount() && !doc_->runs().runIsStale()) {
            const lc::Projection proj(doc_->scene().camera);
            if (const auto chunk = lc::tileFrustum(run->result, proj, run->lights, std::uint32_t(tile))) {
                glm::dvec3 c(0.0);
                for (const glm::dvec3& v : chunk->corners) c += v;
                focus = glm::dvec3(lc::worldFromView(doc_->scene().camera) * glm::dvec4(c / 8.0, 1.0));
            }
        } else if (doc_->selection().currentLight() >= 0 && std::size_t(doc_->selection().currentLight()) < lights.size()) {
            focus = lights[std::size_t(doc_->selection().currentLight())].position;
        }
        std::vector<char> selected(lights.size(), 0);
        for (int i : doc_->selection().selectedLights())
            if (i >= 0 && std::size_t(i) < lights.size()) selected[std::size_t(i)] = 1;
        std::stable_sort(set.begin(), set.end(), [&](int a, int b) {
            if (selected[std::size_t(a)] != selected[std::size_t(b)]) return selected[std::size_t(a)] > selected[std::size_t(b)];
            return glm::length(lights[std::size_t(a)].position - focus) < glm::length(lights[std::size_t(b)].position - focus);
        });
        leftOut_ = set.size() - cap;
        set.resize(cap);
        std::sort(set.begin(), set.end());
    }
    drawn_ = std::move(set);
    slot_.assign(lights.size(), -1);
    for (std::size_t k = 0; k < drawn_.size(); ++k) slot_[std::size_t(drawn_[k])] = int(k);

    // Peeling only for few filled spheres, and not under x-ray meshes (every
    // peel would redraw every translucent triangle of the scene).
    const bool peel = !silhouettes_ && drawn_.size() <= kMaxPeeledLights && ov.meshes != MD::XRay;
    renderer_->SetUseDepthPeeling(peel ? 1 : 0);
    renderer_->SetPass(peel ? nullptr : blendedPasses_.Get());
    lightActor_->SetVisibility(ov.showLights && !silhouettes_);
    ringActor_->SetVisibility(ov.showLights && silhouettes_);
    spotCones_->actor()->SetVisibility(ov.showLights);
    if (drawn_.size() == lights.size()) {
        lightData_ = lightsToPolyData(lights);
        spotCones_->update(lights);
    } else {
        std::vector<lc::PointLight> sub;
        sub.reserve(drawn_.size());
        for (int i : drawn_) sub.push_back(lights[std::size_t(i)]);
        lightData_ = lightsToPolyData(sub);
        spotCones_->update(sub);
    }
    glyph_->SetInputData(lightData_);
    rings_->SetInputData(lightData_);
    lightSetKey_ = lightSetKey(); // what chose them (refreshLightSet)
}

void InspectorView::updateLight(int index) {
    const auto& lights = doc_->scene().lights;
    if (index < 0 || index >= int(lights.size()) || slot_.size() != lights.size()) {
        rebuildLights();
        return;
    }
    const int s = slot_[std::size_t(index)];
    if (s < 0) return; // not drawn
    const auto& l = lights[std::size_t(index)];
    lightData_->GetPoints()->SetPoint(s, l.position.x, l.position.y, l.position.z);
    lightData_->GetPoints()->Modified();
    lightData_->GetPointData()->GetArray("radius")->SetTuple1(s, lightDisplayRadius(l));
    lightData_->GetPointData()->GetArray("radius")->Modified();
    unsigned char rgb[3];
    lightDisplayColor(l, rgb);
    auto* color = lightData_->GetPointData()->GetArray("color");
    for (int c = 0; c < 3; ++c) color->SetComponent(s, c, rgb[c]);
    color->Modified();
    lightData_->Modified();
    if (drawn_.size() == lights.size()) {
        spotCones_->update(lights);
    } else {
        std::vector<lc::PointLight> sub;
        for (int i : drawn_) sub.push_back(lights[std::size_t(i)]);
        spotCones_->update(sub);
    }
}

void InspectorView::updateSelection() {
    const auto& lights = doc_->scene().lights;
    // Outline at most kMaxOutlined selected lights: wireframes of thousands
    // of spheres hide the scene and cost more than the spheres themselves.
    constexpr std::size_t kMaxOutlined = 256;
    std::vector<lc::PointLight> sel;
    const auto& selected = doc_->selection().selectedLights();
    for (std::size_t k = selected.size() > kMaxOutlined ? selected.size() - kMaxOutlined : 0; k < selected.size(); ++k)
        if (selected[k] < int(lights.size())) sel.push_back(lights[std::size_t(selected[k])]);
    selData_ = lightsToPolyData(sel);
    selGlyph_->SetInputData(selData_);
    const int cur = doc_->selection().currentLight();
    if (cur >= 0 && cur < int(lights.size())) {
        // Keep the handle where the light is, except while it is being dragged
        // (then the handle leads and the light follows).
        if (!handleActive_) {
            const auto& p = lights[std::size_t(cur)].position;
            double wp[3] = {p.x, p.y, p.z};
            handleRep_->SetWorldPosition(wp);
        }
        handle_->EnabledOn();
        radiusHandle_->EnabledOn();
        placeRadiusHandle();
    } else {
        handle_->EnabledOff();
        radiusHandle_->EnabledOff();
    }
}

void InspectorView::updateFrustum() {
    frustumData_->Initialize();
    const lc::Scene& s = doc_->scene();
    const lc::Camera& c = s.camera;
    if (!c.validate().empty()) return;
    try {
        const lc::Projection proj(c);
        const glm::dmat4 worldFromView = glm::inverse(c.viewFromWorld());
        // Far face drawn at the far plane, pulled in to the scene's extent.
        const auto [lo, hi] = s.bounds();
        double farthest = glm::length(c.target - c.position);
        for (int i = 0; i < 8; ++i) {
            const glm::dvec3 k((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
            farthest = std::max(farthest, glm::length(k - c.position));
        }
        const double farD = std::min(proj.farPlane(), farthest * 1.05);
        const double nearD = proj.nearPlane();
        vtkNew<vtkPoints> pts;
        const glm::dvec2 px[4] = {{0, 0}, {double(c.width), 0}, {double(c.width), double(c.height)},
                                  {0, double(c.height)}};
        for (double d : {nearD, farD})
            for (const auto& p : px) {
                const glm::dvec4 w = worldFromView * glm::dvec4(proj.viewPositionAt(p, d), 1.0);
                pts->InsertNextPoint(w.x, w.y, w.z);
            }
        pts->InsertNextPoint(c.position.x, c.position.y, c.position.z); // 8: eye
        vtkNew<vtkCellArray> lines;
        auto line = [&](vtkIdType a, vtkIdType b) {
            const vtkIdType ids[2] = {a, b};
            lines->InsertNextCell(2, ids);
        };
        for (int i = 0; i < 4; ++i) {
            line(i, (i + 1) % 4);         // near face
            line(4 + i, 4 + (i + 1) % 4); // far face
            line(i, 4 + i);               // side edges
            if (!proj.orthographic()) line(8, i);
        }
        frustumData_->SetPoints(pts);
        frustumData_->SetLines(lines);
    } catch (const std::exception&) {
        // An invalid camera shows no frustum; the run reports the error.
    }
}

} // namespace lcui
