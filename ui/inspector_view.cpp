#include "inspector_view.hpp"

#include "document.hpp"
#include "light_silhouettes.hpp"
#include "overlay_actors.hpp"
#include "vtk_adapters.hpp"
#include "spot_actor.hpp"
#include "spot_handles.hpp"

#include "culling/math/projection.hpp"

#include <QTimer>

#include "culling/diagnostics/overlays.hpp"

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
#include <vtkTranslucentPass.h>
#include <vtkVolumetricPass.h>
#include <QVTKInteractor.h>

#include <algorithm>
#include <cmath>

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

    // Light spheres: one glyph actor. Sphere of radius 1 scaled by "radius",
    // coloured by "color"; 12x8 facets keep 10k lights interactive.
    sphere_->SetRadius(1.0);
    sphere_->SetThetaResolution(12);
    sphere_->SetPhiResolution(8);
    lightData_ = lightsToPolyData({});
    glyph_->SetSourceConnection(sphere_->GetOutputPort());
    glyph_->SetInputData(lightData_);
    glyph_->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "radius");
    glyph_->SetInputArrayToProcess(3, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "color");
    glyph_->SetScaleModeToScaleByScalar();
    glyph_->SetScaleFactor(1.0);
    glyph_->ClampingOff();
    glyph_->SetColorModeToColorByScalar();
    glyph_->OrientOff();
    vtkNew<vtkPolyDataMapper> lightMapper;
    lightMapper->SetInputConnection(glyph_->GetOutputPort());
    lightMapper->SetScalarModeToUsePointFieldData();
    lightMapper->SelectColorArray("color");
    lightMapper->SetColorModeToDirectScalars();
    lightMapper->ScalarVisibilityOn();
    lightActor_->SetMapper(lightMapper);
    lightActor_->GetProperty()->SetOpacity(0.22);
    // Back faces add nothing but overdraw to a translucent convex shell.
    lightActor_->GetProperty()->BackfaceCullingOn();
    renderer_->AddActor(lightActor_);

    // Many lights: silhouette rings over the same light poly data.
    rings_->SetCamera(renderer_->GetActiveCamera());
    rings_->SetInputData(lightData_);
    vtkNew<vtkPolyDataMapper> ringMapper;
    ringMapper->SetInputConnection(rings_->GetOutputPort());
    ringMapper->SetScalarModeToUsePointFieldData();
    ringMapper->SelectColorArray("color");
    ringMapper->SetColorModeToDirectScalars();
    ringMapper->ScalarVisibilityOn();
    ringActor_->SetMapper(ringMapper);
    ringActor_->GetProperty()->SetLighting(false);
    ringActor_->GetProperty()->SetLineWidth(1);
    ringActor_->GetProperty()->SetPointSize(3);
    ringActor_->PickableOff();
    ringActor_->VisibilityOff();
    renderer_->AddActor(ringActor_);

    // Selected lights: the same spheres as an opaque yellow wireframe.
    selData_ = lightsToPolyData({});
    selGlyph_->SetSourceConnection(sphere_->GetOutputPort());
    selGlyph_->SetInputData(selData_);
    selGlyph_->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "radius");
    selGlyph_->SetScaleModeToScaleByScalar();
    selGlyph_->ClampingOff();
    vtkNew<vtkPolyDataMapper> selMapper;
    selMapper->SetInputConnection(selGlyph_->GetOutputPort());
    selMapper->ScalarVisibilityOff();
    selActor_->SetMapper(selMapper);
    selActor_->GetProperty()->SetRepresentationToWireframe();
    selActor_->GetProperty()->SetColor(1.0, 0.85, 0.1);
    selActor_->GetProperty()->SetLighting(false);
    selActor_->PickableOff();
    renderer_->AddActor(selActor_);

    vtkNew<vtkPolyDataMapper> frustumMapper;
    frustumMapper->SetInputData(frustumData_);
    frustumActor_->SetMapper(frustumMapper);
    frustumActor_->GetProperty()->SetColor(0.3, 0.9, 1.0);
    frustumActor_->GetProperty()->SetLineWidth(2);
    frustumActor_->GetProperty()->SetLighting(false);
    frustumActor_->PickableOff();
    renderer_->AddActor(frustumActor_);
    spotCones_ = std::make_unique<SpotConesActor>(renderer_);

    // Inspection overlays; translucent volumes over translucent spheres stay
    // readable with depth peeling (order-independent).
    overlays_ = std::make_unique<InspectorOverlays>(renderer_, sphere_);
    rw->SetAlphaBitPlanes(1);
    rw->SetMultiSamples(0);
    // Peeling is on only while the lights are few (rebuildLights): every peel
    // redraws every translucent sphere, and with 1,024 lights one frame took
    // 13.6 s on llvmpipe. Above the limit translucency is blended in actor
    // order (overlays last), which keeps a selected tile's volumes readable.
    renderer_->SetUseDepthPeeling(1);
    renderer_->SetMaximumNumberOfPeels(6);
    renderer_->SetOcclusionRatio(0.05);
    // Many lights (rings): VTK's own passes minus the order-independent
    // translucency it substitutes for peeling (measured 4-6 ms of a 31-42 ms
    // frame of 1,024 rings at 468x496 on llvmpipe).
    vtkNew<vtkLightsPass> lightsPass;
    vtkNew<vtkOpaquePass> opaquePass;
    vtkNew<vtkTranslucentPass> translucentPass;
    vtkNew<vtkVolumetricPass> volumetricPass;
    vtkNew<vtkOverlayPass> overlayPass;
    vtkNew<vtkRenderPassCollection> passes;
    for (vtkRenderPass* pass : std::initializer_list<vtkRenderPass*>{lightsPass, opaquePass, translucentPass,
                                                                     volumetricPass, overlayPass})
        passes->AddItem(pass);
    vtkNew<vtkSequencePass> sequence;
    sequence->SetPasses(passes);
    blendedPasses_->SetDelegatePass(sequence);

    vtkNew<vtkInteractorStyleTrackballCamera> style;
    interactor()->SetInteractorStyle(style);

    handleRep_->SetHandleSize(40);
    handleRep_->GetProperty()->SetColor(1, 0.45, 0.1);
    handleRep_->GetProperty()->SetLineWidth(3);
    handleRep_->GetSelectedProperty()->SetLineWidth(3);
    handleRep_->GetSelectedProperty()->SetColor(1, 0.3, 0.2);
    handleRep_->ActiveRepresentationOff();
    handle_->SetInteractor(interactor());
    handle_->SetRepresentation(handleRep_);
    handle_->AddObserver(vtkCommand::StartInteractionEvent, this, &InspectorView::onHandleStart);
    handle_->AddObserver(vtkCommand::InteractionEvent, this, &InspectorView::onHandleMove);
    handle_->AddObserver(vtkCommand::EndInteractionEvent, this, &InspectorView::onHandleEnd);
    handle_->EnabledOff();

    radiusRep_->SetHandleSize(25);
    radiusRep_->GetProperty()->SetColor(0.2, 1.0, 0.9);
    radiusRep_->GetProperty()->SetLineWidth(3);
    radiusRep_->GetSelectedProperty()->SetLineWidth(3);
    radiusRep_->GetSelectedProperty()->SetColor(1, 0.3, 0.2);
    radiusRep_->ActiveRepresentationOff();
    radiusHandle_->SetInteractor(interactor());
    radiusHandle_->SetRepresentation(radiusRep_);
    radiusHandle_->AddObserver(vtkCommand::StartInteractionEvent, this, &InspectorView::onRadiusStart);
    radiusHandle_->AddObserver(vtkCommand::InteractionEvent, this, &InspectorView::onRadiusMove);
    radiusHandle_->AddObserver(vtkCommand::EndInteractionEvent, this, &InspectorView::onRadiusEnd);
    radiusHandle_->EnabledOff();
    // After an orbit, the radius handle goes back to the right of the centre.
    style->AddObserver(vtkCommand::EndInteractionEvent, this, &InspectorView::placeRadiusHandle);
    spotHandles_ = std::make_unique<SpotHandles>(doc_, renderer_, interactor());

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
    connect(doc_, &Document::selectionChanged, this, [this] {
        updateSelection();
        scheduleRender();
    });
    connect(doc_, &Document::cameraChanged, this, [this] {
        updateFrustum();
        updateOverlays();
        scheduleRender();
    });
    // A stale run's overlays go (the light indices they use may have moved).
    for (auto sig : {&Document::runOutputChanged, &Document::overlaysChanged, &Document::selectionChanged,
                     &Document::lightsChanged, &Document::runWentStale})
        connect(doc_, sig, this, [this] {
            updateOverlays();
            scheduleRender();
        });
    connect(doc_, &Document::tileSelectionChanged, this, [this] {
        updateOverlays();
        scheduleRender();
    });
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
    const double rings = ringOpacity(doc_->scene().lights.size());
    ringActor_->GetProperty()->SetOpacity(overlays_->dimLights() ? 0.15 * rings : rings);
}

vtkRenderer* InspectorView::renderer() const { return renderer_.Get(); }
vtkHandleWidget* InspectorView::handleWidget() const { return handle_.Get(); }
vtkPointHandleRepresentation3D* InspectorView::handleRepresentation() const { return handleRep_.Get(); }
vtkHandleWidget* InspectorView::radiusHandleWidget() const { return radiusHandle_.Get(); }
vtkPointHandleRepresentation3D* InspectorView::radiusHandleRepresentation() const { return radiusRep_.Get(); }
vtkActor* InspectorView::lightActor() const { return silhouettes_ ? ringActor_.Get() : lightActor_.Get(); }

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

void InspectorView::resetCamera() {
    // Frame the meshes (not every light sphere: a generated cloud can be far
    // larger than the scene) from above and to the side of the culling camera.
    const auto [lo, hi] = doc_->scene().bounds();
    const lc::Camera& c = doc_->scene().camera;
    glm::dvec3 center = 0.5 * (lo + hi);
    double diag = glm::length(hi - lo);
    if (diag <= 0) {
        center = c.target;
        diag = std::max(1.0, glm::length(c.target - c.position));
    }
    glm::dvec3 dir = c.position - c.target;
    if (glm::length(dir) < 1e-9) dir = {0, 0, 1};
    dir = glm::normalize(dir);
    const glm::dvec3 up = glm::normalize(c.up);
    // Rotate 35 degrees around up and lift: the frustum is seen from outside.
    const glm::dvec3 side = glm::normalize(glm::cross(up, dir));
    glm::dvec3 eyeDir = glm::normalize(std::cos(0.6) * dir + std::sin(0.6) * side + 0.55 * up);
    vtkCamera* vc = renderer_->GetActiveCamera();
    vc->SetFocalPoint(center.x, center.y, center.z);
    const glm::dvec3 eye = center + eyeDir * diag;
    vc->SetPosition(eye.x, eye.y, eye.z);
    vc->SetViewUp(up.x, up.y, up.z);
    vc->SetViewAngle(30);
    vc->ParallelProjectionOff();
    // Keep the direction, move back until the scene and the culling camera's
    // eye (the apex of the frustum) fit.
    if (glm::length(hi - lo) > 0) {
        const glm::dvec3 blo = glm::min(lo, c.position), bhi = glm::max(hi, c.position);
        double b[6] = {blo.x, bhi.x, blo.y, bhi.y, blo.z, bhi.z};
        renderer_->ResetCamera(b);
        vc->Zoom(1.15); // ResetCamera frames the bounding sphere, which leaves a wide margin
    }
    renderer_->ResetCameraClippingRange();
    cameraFramed_ = true;
    renderNow();
}

std::pair<glm::dvec3, glm::dvec3> InspectorView::viewRay(const QPoint& pos) const {
    const double dpr = devicePixelRatioF();
    const double x = pos.x() * dpr, y = (height() - 1 - pos.y()) * dpr;
    auto worldAt = [&](double z) {
        renderer_->SetDisplayPoint(x, y, z);
        renderer_->DisplayToWorld();
        double w[4];
        renderer_->GetWorldPoint(w);
        return glm::dvec3(w[0], w[1], w[2]) / (w[3] != 0.0 ? w[3] : 1.0);
    };
    return {worldAt(0.0), worldAt(1.0)};
}

bool InspectorView::frameSelected(int ms) {
    const auto run = doc_->runOutput();
    const int tile = doc_->selectedTile();
    if (run && tile >= 0 && std::uint32_t(tile) < run->result.grid.tileCount()) {
        const lc::Projection proj(doc_->scene().camera);
        std::optional<lc::FrustumChunk> chunk;
        const int cell = doc_->selectedCell();
        if (cell >= 0)
            for (const lc::DepthCell& c : lc::tileCells(run->result, proj, std::uint32_t(tile)))
                if (int(c.cell) == cell) chunk = c.chunk;
        if (!chunk) chunk = lc::tileFrustum(run->result, proj, run->lights, std::uint32_t(tile));
        if (chunk) {
            const glm::dmat4 world = lc::worldFromView(doc_->scene().camera);
            std::vector<glm::dvec3> corners;
            for (const glm::dvec3& v : chunk->corners) corners.push_back(glm::dvec3(world * glm::dvec4(v, 1.0)));
            // With Explain's markers shown: the pixel that matters (and the
            // nearest point of the light's sphere) come into view too.
            vtkPolyData* marker = overlays_->explainPixel();
            for (vtkIdType i = 0; marker->GetNumberOfCells() > 0 && i < marker->GetNumberOfPoints(); ++i) {
                double p[3];
                marker->GetPoint(i, p);
                corners.push_back({p[0], p[1], p[2]});
            }
            flyToPoints(corners, ms);
            return true;
        }
    }
    const int light = doc_->currentLight();
    if (light >= 0 && std::size_t(light) < doc_->scene().lights.size()) {
        const lc::PointLight& l = doc_->scene().lights[std::size_t(light)];
        flyTo(l.position, std::max(l.radius(), 1e-3), ms);
        return true;
    }
    return false;
}

void InspectorView::flyTo(const glm::dvec3& center, double radius, int ms) {
    // The sphere's six extreme points along the view axes bound it well enough.
    const ViewBasis b = viewBasis();
    flyToPoints({center + radius * b.right, center - radius * b.right, center + radius * b.up, center - radius * b.up,
                 center + radius * b.dir, center - radius * b.dir},
                ms);
}

InspectorView::ViewBasis InspectorView::viewBasis() const {
    vtkCamera* vc = renderer_->GetActiveCamera();
    double p0[3], f0[3], vu[3];
    vc->GetPosition(p0);
    vc->GetFocalPoint(f0);
    vc->GetViewUp(vu);
    ViewBasis b;
    b.eye = {p0[0], p0[1], p0[2]};
    b.focal = {f0[0], f0[1], f0[2]};
    b.dir = b.focal - b.eye;
    if (glm::length(b.dir) < 1e-12) b.dir = {0, 0, -1};
    b.dir = glm::normalize(b.dir);
    b.right = glm::cross(b.dir, glm::dvec3(vu[0], vu[1], vu[2]));
    if (glm::length(b.right) < 1e-12) b.right = glm::dvec3(1, 0, 0);
    b.right = glm::normalize(b.right);
    b.up = glm::cross(b.right, b.dir);
    return b;
}

void InspectorView::flyToPoints(const std::vector<glm::dvec3>& points, int ms) {
    if (points.empty()) return;
    vtkCamera* vc = renderer_->GetActiveCamera();
    const ViewBasis b = viewBasis();
    const glm::dvec3 fromEye = b.eye, fromFocal = b.focal, dir = b.dir, up = b.up, right = b.right;
    glm::dvec3 center(0.0);
    for (const glm::dvec3& p : points) center += p;
    center /= double(points.size());
    // Keep the direction; the nearest eye distance from `center` at which every
    // point projects inside the view, with a 10% margin: x / (d + z) <= tan.
    const double halfY = 0.5 * vc->GetViewAngle() * 3.14159265358979323846 / 180.0;
    const double aspect = height() > 0 ? double(width()) / double(height()) : 1.0;
    const double tanY = std::tan(halfY) / 1.1, tanX = std::tan(halfY) * aspect / 1.1;
    double distance = 1e-6, extentX = 1e-6, extentY = 1e-6;
    for (const glm::dvec3& p : points) {
        const glm::dvec3 q = p - center;
        const double x = std::abs(glm::dot(q, right)), y = std::abs(glm::dot(q, up)), z = glm::dot(q, dir);
        distance = std::max({distance, x / tanX - z, y / tanY - z});
        extentX = std::max(extentX, x);
        extentY = std::max(extentY, y);
    }
    if (vc->GetParallelProjection()) vc->SetParallelScale(1.1 * std::max(extentY, extentX / aspect));
    const glm::dvec3 toEye = center - dir * distance;
    const int steps = std::max(1, ms / 25);
    auto apply = [this, vc, fromEye, fromFocal, toEye, center](double t) {
        const double s = t * t * (3.0 - 2.0 * t); // ease in and out
        const glm::dvec3 e = glm::mix(fromEye, toEye, s), f = glm::mix(fromFocal, center, s);
        vc->SetFocalPoint(f.x, f.y, f.z);
        vc->SetPosition(e.x, e.y, e.z);
        renderer_->ResetCameraClippingRange();
        renderNow();
    };
    if (ms <= 0) {
        apply(1.0);
        return;
    }
    ++flight_;
    const int flight = flight_;
    for (int i = 1; i <= steps; ++i)
        QTimer::singleShot(i * ms / steps, this, [apply, i, steps, flight, this] {
            if (flight == flight_) apply(double(i) / steps); // a newer flight takes over
        });
}

void InspectorView::lookThroughCullingCamera() {
    ++flight_; // stops a flight in progress
    const lc::Camera& c = doc_->scene().camera;
    vtkCamera* vc = renderer_->GetActiveCamera();
    vc->SetPosition(c.position.x, c.position.y, c.position.z);
    vc->SetFocalPoint(c.target.x, c.target.y, c.target.z);
    vc->SetViewUp(c.up.x, c.up.y, c.up.z);
    if (lc::isOrthographic(c.projection)) {
        vc->ParallelProjectionOn();
        vc->SetParallelScale(0.5 * c.orthoHeight);
    } else {
        vc->ParallelProjectionOff();
        vc->SetViewAngle(c.fovYDeg);
    }
    vc->OrthogonalizeViewUp();
    renderer_->ResetCameraClippingRange();
    renderNow();
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
}

void InspectorView::rebuildLights() {
    const std::size_t n = doc_->scene().lights.size();
    renderer_->SetUseDepthPeeling(n <= kMaxPeeledLights ? 1 : 0);
    silhouettes_ = n > kMaxFilledLights;
    renderer_->SetPass(silhouettes_ ? blendedPasses_.Get() : nullptr);
    lightActor_->SetVisibility(!silhouettes_);
    ringActor_->SetVisibility(silhouettes_);
    lightData_ = lightsToPolyData(doc_->scene().lights);
    glyph_->SetInputData(lightData_);
    rings_->SetInputData(lightData_);
    spotCones_->update(doc_->scene().lights);
}

void InspectorView::updateLight(int index) {
    const auto& lights = doc_->scene().lights;
    if (index < 0 || index >= int(lights.size()) || lightData_->GetNumberOfPoints() != vtkIdType(lights.size())) {
        rebuildLights();
        return;
    }
    const auto& l = lights[std::size_t(index)];
    lightData_->GetPoints()->SetPoint(index, l.position.x, l.position.y, l.position.z);
    lightData_->GetPoints()->Modified();
    lightData_->GetPointData()->GetArray("radius")->SetTuple1(index, lightDisplayRadius(l));
    lightData_->GetPointData()->GetArray("radius")->Modified();
    unsigned char rgb[3];
    lightDisplayColor(l, rgb);
    auto* color = lightData_->GetPointData()->GetArray("color");
    for (int c = 0; c < 3; ++c) color->SetComponent(index, c, rgb[c]);
    color->Modified();
    lightData_->Modified();
    spotCones_->update(lights);
}

void InspectorView::updateSelection() {
    const auto& lights = doc_->scene().lights;
    // Outline at most kMaxOutlined selected lights: wireframes of thousands
    // of spheres hide the scene and cost more than the spheres themselves.
    constexpr std::size_t kMaxOutlined = 256;
    std::vector<lc::PointLight> sel;
    const auto& selected = doc_->selectedLights();
    for (std::size_t k = selected.size() > kMaxOutlined ? selected.size() - kMaxOutlined : 0; k < selected.size(); ++k)
        if (selected[k] < int(lights.size())) sel.push_back(lights[std::size_t(selected[k])]);
    selData_ = lightsToPolyData(sel);
    selGlyph_->SetInputData(selData_);
    const int cur = doc_->currentLight();
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

void InspectorView::onHandleStart() {
    handleActive_ = true;
    dragLight_ = doc_->currentLight();
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
    const int cur = doc_->currentLight();
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
    dragLight_ = doc_->currentLight();
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
    // A mesh surface in front hides the spheres behind it.
    if (picker_->Pick(x, y, 0, renderer_) && picker_->GetActor()) {
        double p[3];
        picker_->GetPickPosition(p);
        nearest = std::min(nearest, glm::dot(glm::dvec3(p[0], p[1], p[2]) - origin, dir));
    }
    // The first sphere the ray enters. A sphere around the ray's origin is
    // skipped: its surface is behind the viewer, nothing of it is in view.
    int best = -1;
    const auto& lights = doc_->scene().lights;
    for (std::size_t i = 0; i < lights.size(); ++i) {
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
        std::vector<int> sel = add ? doc_->selectedLights() : std::vector<int>{};
        sel.push_back(light);
        doc_->setSelectedLights(sel);
        return;
    }
    int tile = -1, cell = -1;
    if (pickChunk(pos, &tile, &cell)) {
        doc_->setSelectedTile(tile);
        doc_->setSelectedCell(cell);
    }
}

bool InspectorView::pickChunk(const QPoint& pos, int* tileOut, int* cellOut) {
    const auto run = doc_->runOutput();
    if (!run) return false;
    const auto& ov = doc_->overlays();
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
    const int sel = doc_->selectedTile();
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
