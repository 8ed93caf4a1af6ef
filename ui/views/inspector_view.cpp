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
    handle_->SetDefaultRenderer(handleLayer_);
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
    radiusHandle_->SetDefaultRenderer(handleLayer_);
    radiusHandle_->SetRepresentation(radiusRep_);
    radiusHandle_->AddObserver(vtkCommand::StartInteractionEvent, this, &InspectorView::onRadiusStart);
    radiusHandle_->AddObserver(vtkCommand::InteractionEvent, this, &InspectorView::onRadiusMove);
    radiusHandle_->AddObserver(vtkCommand::EndInteractionEvent, this, &InspectorView::onRadiusEnd);
    radiusHandle_->EnabledOff();
    // After an orbit, the radius handle goes back to the right of the centre.
    style->AddObserver(vtkCommand::EndInteractionEvent, this, &InspectorView::placeRadiusHandle);
    spotHandles_ = std::make_unique<SpotHandles>(doc_, renderer_, interactor(), handleLayer_);

    // "+N more" and which tile's lights are shown: top left, small.
    lightNote_->GetTextProperty()->SetFontSize(13);
    lightNote_->GetTextProperty()->SetColor(1.0, 1.0, 0.85);
    lightNote_->GetTextProperty()->SetBackgroundColor(0, 0, 0);
    lightNote_->GetTextProperty()->SetBackgroundOpacity(0.55);
    lightNote_->GetTextProperty()->SetVerticalJustificationToTop();
    lightNote_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    lightNote_->SetPosition(0.01, 0.985);
    lightNote_->SetVisibility(false);
    lightNote_->PickableOff();
    renderer_->AddActor2D(lightNote_);

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
    connect(doc_, &Document::overlaysChanged, this, [this] {
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
            refreshLightSet();
            updateOverlays();
            scheduleRender();
        });
    connect(doc_, &Document::tileSelectionChanged, this, [this] {
        refreshLightSet();
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
    const double rings = ringOpacity(drawn_.size());
    ringActor_->GetProperty()->SetOpacity(overlays_->dimLights() ? 0.15 * rings : rings);
    spotCones_->actor()->GetProperty()->SetOpacity(overlays_->dimLights() ? 0.25 : 1.0);
    // The note: which tile's lights are shown, and what the sphere cap left out.
    const auto& ov = doc_->overlays();
    QStringList note;
    if (ov.showLights && ov.onlyTileLights) {
        if (drawnAreTileLights_)
            note << tr("only tile %1's %2 listed lights").arg(doc_->selectedTile()).arg(drawn_.size() + leftOut_);
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
    // What to frame (world points, for the view basis they are seen in), the
    // point to look from the culling camera's side at, and the points whose
    // view must not be blocked: the chunk's near face centre and corners (the
    // tile's nearest geometry lies on that face, and the culling camera sees
    // them), or the light's centre and four points halfway to its sphere.
    std::function<std::vector<glm::dvec3>(const ViewBasis&)> pointsFor;
    std::function<std::vector<glm::dvec3>(const ViewBasis&)> samplesFor;
    glm::dvec3 anchor(0.0);
    double keepOutside = 0; // a light's radius: an eye inside its sphere sees only its wireframe
    frameNote_.clear();
    const auto run = doc_->runOutput();
    const int tile = doc_->selectedTile();
    // A light picked after the tile (the scene tree, a click in 3D) is what
    // the user looks at now, unless the tile lists it (Explain's question:
    // the tile's framing then takes in the light's nearest point).
    bool lightFirst = false;
    if (run && doc_->lightSelectedLast() && doc_->currentLight() >= 0 && tile >= 0 &&
        std::uint32_t(tile) < run->result.grid.tileCount()) {
        const auto held = lc::tilesHoldingLight(run->result, std::uint32_t(doc_->currentLight()));
        lightFirst = std::find(held.begin(), held.end(), std::uint32_t(tile)) == held.end();
    }
    if (!lightFirst && run && tile >= 0 && std::uint32_t(tile) < run->result.grid.tileCount()) {
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
            anchor = 0.25 * (corners[0] + corners[1] + corners[2] + corners[3]);
            // Pulled a little towards the face's centre: a corner can touch a wall.
            const std::vector<glm::dvec3> samples = {anchor, glm::mix(anchor, corners[0], 0.9), glm::mix(anchor, corners[1], 0.9),
                                                     glm::mix(anchor, corners[2], 0.9), glm::mix(anchor, corners[3], 0.9)};
            samplesFor = [samples](const ViewBasis&) { return samples; };
            // With Explain's markers shown: the pixel that matters (and the
            // nearest point of the light's sphere) come into view too.
            vtkPolyData* marker = overlays_->explainPixel();
            for (vtkIdType i = 0; marker->GetNumberOfCells() > 0 && i < marker->GetNumberOfPoints(); ++i) {
                double p[3];
                marker->GetPoint(i, p);
                corners.push_back({p[0], p[1], p[2]});
            }
            pointsFor = [corners](const ViewBasis&) { return corners; };
        }
    }
    const int light = doc_->currentLight();
    if (!pointsFor && light >= 0 && std::size_t(light) < doc_->scene().lights.size()) {
        const lc::PointLight& l = doc_->scene().lights[std::size_t(light)];
        const glm::dvec3 c = l.position;
        const double r = std::max(l.radius(), 1e-3);
        anchor = c;
        keepOutside = r;
        // The sphere's six extreme points along the view axes bound it well enough.
        pointsFor = [c, r](const ViewBasis& b) {
            return std::vector<glm::dvec3>{c + r * b.right, c - r * b.right, c + r * b.up,
                                           c - r * b.up,    c + r * b.dir,   c - r * b.dir};
        };
        samplesFor = [c, r](const ViewBasis& b) {
            const double h = 0.5 * r;
            return std::vector<glm::dvec3>{c, c + h * b.right, c - h * b.right, c + h * b.up, c - h * b.up};
        };
    }
    if (!pointsFor) return false;

    framedFromCullingSide_ = false;
    const ViewBasis b = viewBasis();
    glm::dvec3 center;
    const double distance = fitDistance(pointsFor(b), b, &center);
    const glm::dvec3 eye = center - b.dir * distance;
    const lc::Scene& scene = doc_->scene();
    // The kept direction works unless shown meshes stand between the eye and
    // most of the selection (the roof of a building framed from outside; a
    // block hiding a corner of a tile is no reason to turn). Nearly at a
    // sample does not count: that is the selection's own surface.
    const bool meshesShown = doc_->overlays().meshes != Document::OverlayOptions::MeshDisplay::Hidden;
    auto blocked = [&](const glm::dvec3& from) {
        const std::vector<glm::dvec3> samples = samplesFor(b);
        std::size_t hidden = 0;
        for (const glm::dvec3& p : samples) {
            const auto hit = firstMeshHit(scene, from, p);
            hidden += hit && *hit < 1.0 - 1e-3;
        }
        return 2 * hidden > samples.size();
    };
    if (!meshesShown || !blocked(eye)) {
        flyToEye(eye, center, std::nullopt, ms);
        return true;
    }
    // From the culling camera's side: along the line from its eye through the
    // anchor (orthographic: along its direction). The culling camera sees the
    // tile's geometry, so that line is free up to the anchor's depth.
    const lc::Camera& cam = scene.camera;
    glm::dvec3 dir = anchor - cam.position;
    if (lc::isOrthographic(cam.projection) || glm::length(dir) < 1e-9) dir = cam.target - cam.position;
    if (glm::length(dir) < 1e-12) dir = b.dir;
    ViewBasis cb;
    cb.dir = glm::normalize(dir);
    cb.right = glm::cross(cb.dir, glm::normalize(cam.up));
    if (glm::length(cb.right) < 1e-9) cb.right = glm::cross(cb.dir, b.up);
    if (glm::length(cb.right) < 1e-9) cb.right = b.right;
    cb.right = glm::normalize(cb.right);
    cb.up = glm::cross(cb.right, cb.dir);
    glm::dvec3 sideCenter;
    const double sideDistance = fitDistance(pointsFor(cb), cb, &sideCenter);
    // The eye on the line through the anchor (the fit's centre lies near it),
    // pulled in to just before the first surface between them.
    glm::dvec3 sideEye = anchor - cb.dir * (sideDistance + glm::dot(anchor - sideCenter, cb.dir));
    const glm::dvec3 back = sideEye - anchor;
    const glm::dvec3 start = anchor + 1e-3 * back;
    if (const auto hit = firstMeshHit(scene, start, sideEye)) {
        const double along = glm::length(sideEye - start) * *hit;
        const glm::dvec3 pulled = start + glm::normalize(back) * (0.9 * along);
        if (glm::length(pulled - anchor) > keepOutside) {
            sideEye = pulled;
        } else {
            // The room is smaller than the light's sphere: an eye pulled in
            // to the wall would sit inside it and see a wall of wireframe.
            // Frame the whole sphere through the wall, with the meshes in
            // x-ray so that the wall hides nothing.
            Document::OverlayOptions o = doc_->overlays();
            if (o.meshes == Document::OverlayOptions::MeshDisplay::Normal) {
                o.meshes = Document::OverlayOptions::MeshDisplay::XRay;
                doc_->setOverlays(o);
                frameNote_ = tr("Walls stand closer to the light than its radius: meshes in x-ray (X toggles)");
            }
        }
    }
    cb.eye = sideEye;
    framedFromCullingSide_ = true;
    flyToEye(sideEye, anchor + cb.dir * std::max(glm::dot(sideCenter - anchor, cb.dir), 0.0), cb.up, ms);
    return true;
}

std::optional<double> InspectorView::firstMeshHit(const lc::Scene& scene, const glm::dvec3& a, const glm::dvec3& b) {
    // Moller-Trumbore against every triangle; a few rays per F, so no
    // acceleration structure (a 260k-triangle glTF takes milliseconds).
    const glm::dvec3 d = b - a;
    double best = 2.0;
    for (const lc::Mesh& m : scene.meshes) {
        const bool identity = m.transform == glm::dmat4(1.0);
        auto vert = [&](std::uint32_t i) {
            const glm::dvec3 v(m.vertex(i));
            return identity ? v : glm::dvec3(m.transform * glm::dvec4(v, 1.0));
        };
        for (std::size_t t = 0; t + 2 < m.indices.size(); t += 3) {
            if (m.indices[t] >= m.vertexCount() || m.indices[t + 1] >= m.vertexCount() ||
                m.indices[t + 2] >= m.vertexCount())
                continue;
            const glm::dvec3 v0 = vert(m.indices[t]), e1 = vert(m.indices[t + 1]) - v0, e2 = vert(m.indices[t + 2]) - v0;
            const glm::dvec3 p = glm::cross(d, e2);
            const double det = glm::dot(e1, p);
            if (std::abs(det) < 1e-300) continue;
            const double inv = 1.0 / det;
            const glm::dvec3 s = a - v0;
            const double u = glm::dot(s, p) * inv;
            if (u < 0.0 || u > 1.0) continue;
            const glm::dvec3 q = glm::cross(s, e1);
            const double v = glm::dot(d, q) * inv;
            if (v < 0.0 || u + v > 1.0) continue;
            const double h = glm::dot(e2, q) * inv;
            if (h >= 0.0 && h <= 1.0 && h < best) best = h;
        }
    }
    if (best > 1.0) return std::nullopt;
    return best;
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

double InspectorView::fitDistance(const std::vector<glm::dvec3>& points, const ViewBasis& b, glm::dvec3* centerOut) {
    vtkCamera* vc = renderer_->GetActiveCamera();
    glm::dvec3 center(0.0);
    for (const glm::dvec3& p : points) center += p;
    center /= double(std::max<std::size_t>(points.size(), 1));
    // The nearest eye distance from `center` at which every point projects
    // inside the view, with a 10% margin: x / (d + z) <= tan.
    const double halfY = 0.5 * vc->GetViewAngle() * 3.14159265358979323846 / 180.0;
    const double aspect = height() > 0 ? double(width()) / double(height()) : 1.0;
    const double tanY = std::tan(halfY) / 1.1, tanX = std::tan(halfY) * aspect / 1.1;
    double distance = 1e-6, extentX = 1e-6, extentY = 1e-6;
    for (const glm::dvec3& p : points) {
        const glm::dvec3 q = p - center;
        const double x = std::abs(glm::dot(q, b.right)), y = std::abs(glm::dot(q, b.up)), z = glm::dot(q, b.dir);
        distance = std::max({distance, x / tanX - z, y / tanY - z});
        extentX = std::max(extentX, x);
        extentY = std::max(extentY, y);
    }
    if (vc->GetParallelProjection()) vc->SetParallelScale(1.1 * std::max(extentY, extentX / aspect));
    *centerOut = center;
    return distance;
}

void InspectorView::flyToPoints(const std::vector<glm::dvec3>& points, int ms) {
    if (points.empty()) return;
    // Keep the direction.
    const ViewBasis b = viewBasis();
    glm::dvec3 center;
    const double distance = fitDistance(points, b, &center);
    flyToEye(center - b.dir * distance, center, std::nullopt, ms);
}

void InspectorView::flyToEye(const glm::dvec3& toEye, const glm::dvec3& toFocal, std::optional<glm::dvec3> toUp,
                             int ms) {
    vtkCamera* vc = renderer_->GetActiveCamera();
    const ViewBasis b = viewBasis();
    const glm::dvec3 fromEye = b.eye, fromFocal = b.focal, fromUp = b.up;
    const int steps = std::max(1, ms / 25);
    auto apply = [this, vc, fromEye, fromFocal, fromUp, toEye, toFocal, toUp](double t) {
        const double s = t * t * (3.0 - 2.0 * t); // ease in and out
        const glm::dvec3 e = glm::mix(fromEye, toEye, s), f = glm::mix(fromFocal, toFocal, s);
        vc->SetFocalPoint(f.x, f.y, f.z);
        vc->SetPosition(e.x, e.y, e.z);
        // The view up is left alone when the direction is kept (an orbit
        // turns about it).
        if (toUp) {
            glm::dvec3 u = glm::mix(fromUp, *toUp, s);
            if (glm::length(u) < 1e-9) u = *toUp;
            vc->SetViewUp(u.x, u.y, u.z);
            vc->OrthogonalizeViewUp();
        }
        renderer_->ResetCameraClippingRange();
        placeRadiusHandle();
        spotHandles_->update();
        renderNow();
    };
    if (ms <= 0) {
        ++flight_; // stops a flight in progress
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
    applyCullingCamera(renderer_->GetActiveCamera(), c);
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
    applyMeshDisplay();
}

void InspectorView::applyMeshDisplay() {
    using MD = Document::OverlayOptions::MeshDisplay;
    const MD mode = doc_->overlays().meshes;
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
    const auto& ov = doc_->overlays();
    std::vector<long long> key = {(long long)doc_->scene().lights.size(), int(ov.lights), ov.showLights,
                                  ov.onlyTileLights, ov.sphereCap, int(ov.meshes)};
    if (ov.onlyTileLights || leftOut_ > 0) {
        key.push_back(doc_->selectedTile());
        key.push_back(doc_->selectedCell());
        key.push_back((long long)(std::intptr_t)doc_->runOutput().get());
        key.push_back(doc_->runIsStale());
    }
    if (leftOut_ > 0) // the selection is drawn first
        key.insert(key.end(), doc_->selectedLights().begin(), doc_->selectedLights().end());
    return key;
}

void InspectorView::rebuildLights() {
    const auto& lights = doc_->scene().lights;
    const auto& ov = doc_->overlays();
    using LD = Document::OverlayOptions::LightDisplay;
    using MD = Document::OverlayOptions::MeshDisplay;
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
        const auto run = doc_->runOutput();
        const int tile = doc_->selectedTile();
        if (run && tile >= 0 && std::uint32_t(tile) < run->result.grid.tileCount() && !doc_->runIsStale()) {
            const lc::Projection proj(doc_->scene().camera);
            if (const auto chunk = lc::tileFrustum(run->result, proj, run->lights, std::uint32_t(tile))) {
                glm::dvec3 c(0.0);
                for (const glm::dvec3& v : chunk->corners) c += v;
                focus = glm::dvec3(lc::worldFromView(doc_->scene().camera) * glm::dvec4(c / 8.0, 1.0));
            }
        } else if (doc_->currentLight() >= 0 && std::size_t(doc_->currentLight()) < lights.size()) {
            focus = lights[std::size_t(doc_->currentLight())].position;
        }
        std::vector<char> selected(lights.size(), 0);
        for (int i : doc_->selectedLights())
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
    // A mesh surface in front hides the spheres behind it (not an x-ray one:
    // what the view shows through it can be clicked; a hidden one is not picked).
    if (!doc_->overlays().showLights) return -1;
    if (doc_->overlays().meshes == Document::OverlayOptions::MeshDisplay::Normal && picker_->Pick(x, y, 0, renderer_) &&
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
