#include "views/inspector_view.hpp"

#include "views/light_silhouettes.hpp"
#include "views/spot_actor.hpp"
#include "views/vtk_adapters.hpp"

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCameraPass.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGlyph3D.h>
#include <vtkLightsPass.h>
#include <vtkOpaquePass.h>
#include <vtkOverlayPass.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderPassCollection.h>
#include <vtkRenderer.h>
#include <vtkSequencePass.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTranslucentPass.h>
#include <vtkVolumetricPass.h>

// The inspector's actors and render passes, built once by its constructor;
// what they show is set by rebuildLights, updateSelection and updateFrustum.

namespace lcui {

void InspectorView::buildLightActors() {
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

}

void InspectorView::buildRenderPasses(vtkGenericOpenGLRenderWindow* renderWindow) {
    renderWindow->SetAlphaBitPlanes(1);
    renderWindow->SetMultiSamples(0);
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

}

void InspectorView::buildLightNote() {
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

}

} // namespace lcui
