#include "views/camera_view.hpp"

#include "culling/custom/custom_cull.hpp"

#include "document/document.hpp"
#include "views/vtk_adapters.hpp"

#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/overlays.hpp"

#include <QHelpEvent>
#include <QMouseEvent>
#include <QWheelEvent>
#include <QTimer>
#include <QToolTip>
#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCoordinate.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageActor.h>
#include <vtkImageData.h>
#include <vtkImageMapper.h>
#include <vtkImageMapper3D.h>
#include <vtkInteractorStyleUser.h>
#include <vtkLookupTable.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataMapper2D.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTransformPolyDataFilter.h>
#include <vtkUnsignedCharArray.h>
#include <QVTKInteractor.h>

#include <algorithm>
#include <filesystem>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace lcui {

namespace {
constexpr int kLegendWidthPx = 110;  // band to the right of the image for the legend
constexpr int kLegendHeightPx = 76;  // or under it: a horizontal legend and the caption

// 2D mapper whose points are in normalised image coordinates: (0,0)
// bottom-left, (1,1) top-right of the whole culling image. `zoom` takes them
// into the renderer's normalised viewport (identity at zoom 1); the renderer
// scissors what falls outside its viewport.
vtkSmartPointer<vtkPolyDataMapper2D> normalizedMapper(vtkPolyData* pd, vtkTransform* zoom) {
    if (!pd->GetPoints()) pd->SetPoints(vtkSmartPointer<vtkPoints>::New()); // see clearOverlay
    auto coord = vtkSmartPointer<vtkCoordinate>::New();
    coord->SetCoordinateSystemToNormalizedViewport();
    auto xf = vtkSmartPointer<vtkTransformPolyDataFilter>::New();
    xf->SetInputData(pd);
    xf->SetTransform(zoom);
    auto m = vtkSmartPointer<vtkPolyDataMapper2D>::New();
    m->SetInputConnection(xf->GetOutputPort());
    m->SetTransformCoordinate(coord);
    return m;
}

// The sRGB encoding lc::differencePicture applies to |culled - all| / max.
double srgbEncode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }
} // namespace

void CameraView::clearOverlay(vtkPolyData* pd) {
    pd->Initialize();
    pd->SetPoints(vtkSmartPointer<vtkPoints>::New());
}

std::string CameraView::barTitle(const std::string& twoLines, bool horizontal) {
    std::string t = twoLines;
    if (horizontal) std::replace(t.begin(), t.end(), '\n', ' ');
    return t;
}

CameraView::CameraView(Document* doc, QWidget* parent) : QVTKOpenGLNativeWidget(parent), doc_(doc) {
    vtkNew<vtkGenericOpenGLRenderWindow> rw;
    setRenderWindow(rw);
    background_->SetBackground(0.12, 0.12, 0.14);
    scene_->SetBackground(0.02, 0.02, 0.03);
    // Layer 0: the window background, then the image renderer clearing the
    // letterboxed viewport (and drawing a shaded picture in image modes).
    // Layer 1: meshes_, the shaded meshes (or their picture), on top without
    // clearing the colour. Layer 2: scene_, the 2D overlay, likewise.
    rw->SetNumberOfLayers(3);
    image_->SetBackground(0.02, 0.02, 0.03);
    image_->InteractiveOff();
    meshes_->SetLayer(1);
    meshes_->InteractiveOff();
    meshes_->SetActiveCamera(scene_->GetActiveCamera());
    scene_->SetLayer(2);
    rw->AddRenderer(background_);
    rw->AddRenderer(image_);
    rw->AddRenderer(meshes_);
    rw->AddRenderer(scene_);
    // The picture of the meshes: bytes 1:1 onto the viewport's pixels.
    vtkNew<vtkImageMapper> pictureMapper;
    pictureMapper->SetInputData(meshPicture_);
    pictureMapper->SetColorWindow(255);
    pictureMapper->SetColorLevel(127.5);
    meshPictureActor_->SetMapper(pictureMapper);
    meshPictureActor_->SetPosition(0, 0);
    meshPictureActor_->SetVisibility(false);
    meshes_->AddActor2D(meshPictureActor_);
    rw->AddObserver(vtkCommand::StartEvent, this, &CameraView::onRenderStart);
    imageActor_->InterpolateOff(); // the picture's pixels, not a blur of them
    imageActor_->SetVisibility(false);
    image_->AddActor(imageActor_);
    vtkCamera* ic = image_->GetActiveCamera();
    ic->ParallelProjectionOn();

    // Heat map: per-tile quads, coloured through the LUT (blue = short list,
    // red = the longest list of this run), translucent over the shaded scene.
    lut_->SetHueRange(0.667, 0.0);
    lut_->SetSaturationRange(0.9, 0.9);
    lut_->SetValueRange(1.0, 1.0);
    lut_->SetAlphaRange(0.55, 0.55);
    lut_->SetNumberOfTableValues(256);
    lut_->Build();
    auto heatMapper = normalizedMapper(heatData_, overlayTransform_);
    heatMapper->SetScalarModeToUseCellData();
    heatMapper->SetLookupTable(lut_);
    heatMapper->UseLookupTableScalarRangeOn();
    heatActor_->SetMapper(heatMapper);
    gridActor_->SetMapper(normalizedMapper(gridData_, overlayTransform_));
    gridActor_->GetProperty()->SetColor(1, 1, 1);
    gridActor_->GetProperty()->SetOpacity(0.3);
    selActor_->SetMapper(normalizedMapper(selData_, overlayTransform_));
    selActor_->GetProperty()->SetColor(1, 1, 0);
    selActor_->GetProperty()->SetLineWidth(3);
    reverseActor_->SetMapper(normalizedMapper(reverseData_, overlayTransform_));
    reverseActor_->GetProperty()->SetColor(1.0, 0.3, 1.0);
    reverseActor_->GetProperty()->SetLineWidth(2);
    scene_->AddActor2D(heatActor_);
    scene_->AddActor2D(gridActor_);
    scene_->AddActor2D(reverseActor_);
    scene_->AddActor2D(selActor_);

    legend_->SetLookupTable(lut_);
    legendTitle_ = "lights\nper tile";
    legend_->SetTitle(legendTitle_.c_str());
    legend_->SetNumberOfLabels(5);
    legend_->SetLabelFormat("%.0f");
    legend_->SetMaximumWidthInPixels(kLegendWidthPx - 10);
    legend_->GetTitleTextProperty()->SetFontSize(14);
    legend_->GetTitleTextProperty()->SetColor(1, 1, 1);
    legend_->GetTitleTextProperty()->ShadowOff();
    legend_->GetTitleTextProperty()->ItalicOff();
    legend_->GetLabelTextProperty()->SetColor(1, 1, 1);
    legend_->GetLabelTextProperty()->ShadowOff();
    legend_->GetLabelTextProperty()->ItalicOff();
    legend_->UnconstrainedFontSizeOn();
    legend_->GetLabelTextProperty()->SetFontSize(13);
    legend_->SetVisibility(false);
    background_->AddActor2D(legend_);

    // Difference legend: the grey ramp differencePicture uses (sRGB of
    // |culled - all| / max), labelled in the shading pass's units.
    diffLut_->SetNumberOfTableValues(256);
    for (int i = 0; i < 256; ++i) {
        const double g = srgbEncode(i / 255.0);
        diffLut_->SetTableValue(i, g, g, g, 1.0);
    }
    diffLegend_->SetLookupTable(diffLut_);
    diffLegend_->SetTitle("abs.\nerror");
    diffLegend_->SetNumberOfLabels(5);
    diffLegend_->SetLabelFormat("%.3g");
    diffLegend_->SetMaximumWidthInPixels(kLegendWidthPx - 10);
    for (vtkTextProperty* tp : {diffLegend_->GetTitleTextProperty(), diffLegend_->GetLabelTextProperty()}) {
        tp->SetColor(1, 1, 1);
        tp->ShadowOff();
        tp->ItalicOff();
    }
    diffLegend_->GetTitleTextProperty()->SetFontSize(14);
    diffLegend_->GetLabelTextProperty()->SetFontSize(13);
    diffLegend_->UnconstrainedFontSizeOn();
    diffLegend_->SetVisibility(false);
    background_->AddActor2D(diffLegend_);

    // Over the picture (the letterbox may leave no room for the caption).
    imageLabel_->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    imageLabel_->SetPosition(0.01, 0.98);
    vtkTextProperty* lp = imageLabel_->GetTextProperty();
    lp->SetFontSize(13);
    lp->SetColor(1, 1, 1);
    lp->SetVerticalJustificationToTop();
    lp->SetBackgroundColor(0, 0, 0);
    lp->SetBackgroundOpacity(0.6);
    imageLabel_->SetVisibility(false);
    scene_->AddActor2D(imageLabel_);

    caption_->GetTextProperty()->SetFontSize(13);
    caption_->GetTextProperty()->SetColor(0.9, 0.9, 0.9);
    caption_->SetDisplayPosition(6, 6);
    background_->AddActor2D(caption_);

    // The camera view is the culling camera: no orbiting here, a click selects a tile.
    vtkNew<vtkInteractorStyleUser> style;
    interactor()->SetInteractorStyle(style);
    interactor()->AddObserver(vtkCommand::LeftButtonPressEvent, this, &CameraView::onLeftPress);

    connect(doc_, &Document::sceneReset, this, [this] {
        picturesRun_.reset();
        zoom_ = 1.0;
        centreU_ = centreV_ = 0.5;
        rebuildMeshes();
        updateCamera();
        updateOverlay();
    });
    connect(doc_, &Document::meshesChanged, this, [this] {
        rebuildMeshes();
        scheduleRender();
    });
    connect(doc_, &Document::cameraChanged, this, [this] {
        updateCamera();
        updateOverlay();
    });
    connect(&doc_->runs(), &RunState::runOutputChanged, this, &CameraView::updateOverlay);
    connect(&doc_->selection(), &Selection::tileChanged, this, [this] {
        updateSelectedTile();
        scheduleRender();
    });
    connect(&doc_->viewOptions(), &ViewOptions::overlaysChanged, this, &CameraView::updateOverlay);
    // A stale run's light indices no longer name the scene's lights: the
    // outlines of the tiles holding the current light go with it.
    const auto refreshReverse = [this] {
        updateReverseLookup();
        scheduleRender();
    };
    connect(&doc_->selection(), &Selection::changed, this, refreshReverse);
    connect(&doc_->runs(), &RunState::runWentStale, this, refreshReverse);
    rebuildMeshes();
    updateCamera();
    updateOverlay();
}

CameraView::~CameraView() = default;

vtkRenderer* CameraView::sceneRenderer() const { return scene_.Get(); }
vtkScalarBarActor* CameraView::legend() const { return legend_.Get(); }

void CameraView::scheduleRender() {
    if (renderPending_) return;
    renderPending_ = true;
    QTimer::singleShot(0, this, [this] {
        renderPending_ = false;
        renderNow();
    });
}

void CameraView::renderNow() {
    if (!renderWindow()) return;
    // Heat mode with a stale picture (other renders, Qt's own, draw the
    // meshes directly until a renderNow takes a picture).
    if (imageMode_ == ImageMode::Heat && !meshActors_.empty() &&
        !(meshPictureValid_ && meshPictureKey() == meshPictureKey_))
        captureMeshPicture();
    renderWindow()->Render();
    update();
}

void CameraView::resizeEvent(QResizeEvent* e) {
    QVTKOpenGLNativeWidget::resizeEvent(e);
    updateViewport();
    // Qt repaints a resized widget from VTK's last frame, drawn for the old
    // size: draw one for the new size (with a new picture of the meshes).
    scheduleRender();
}

void CameraView::updateViewport() {
    const lc::Camera& cam = doc_->scene().camera;
    const double w = std::max(1, width()), h = std::max(1, height());
    const double aspect = cam.aspect();
    // The image's letterbox in a w x h area (its largest size at the aspect).
    auto fit = [aspect](double aw, double ah) {
        double vw = std::max(1.0, aw), vh = vw / aspect;
        if (vh > ah) {
            vh = std::max(1.0, ah);
            vw = vh * aspect;
        }
        return std::pair{vw, vh};
    };
    // The legend never eats the image: it goes beside or under the image,
    // wherever the image then stays larger (a 16:9 image in a tall view
    // leaves the band under it empty anyway).
    const auto [rw, rh] = fit(w - kLegendWidthPx, h);
    const auto [bw, bh] = fit(w, h - kLegendHeightPx);
    legendPlace_ = bw * bh > rw * rh ? LegendPlace::Below : LegendPlace::Right;
    const bool below = legendPlace_ == LegendPlace::Below;
    // The room for the image (widget pixels, y down) and the image fitted in it.
    area_ = below ? QRectF(0, 0, w, std::max(1.0, h - kLegendHeightPx))
                  : QRectF(0, 0, std::max(1.0, w - kLegendWidthPx), h);
    const double vw = below ? bw : rw, vh = below ? bh : rh;
    fitRect_ = QRectF(area_.center().x() - vw / 2, area_.center().y() - vh / 2, vw, vh);
    for (vtkScalarBarActor* bar : {legend_.Get(), diffLegend_.Get()}) {
        if (below) {
            // Labels under the bar, the title over it; 14 px kept free at
            // the right for the last label's overhang.
            const double lw = std::min(vw * 0.55, 340.0);
            bar->SetOrientationToHorizontal();
            bar->SetTextPositionToPrecedeScalarBar();
            bar->SetPosition((fitRect_.right() - lw - 14) / w, 22 / h);
            bar->SetWidth(lw / w);
            bar->SetHeight((kLegendHeightPx - 26) / h);
            bar->SetMaximumWidthInPixels(int(lw));
            bar->SetMaximumHeightInPixels(kLegendHeightPx - 26);
        } else {
            bar->SetOrientationToVertical();
            bar->SetTextPositionToSucceedScalarBar();
            bar->SetPosition((w - kLegendWidthPx + 6) / w, 0.08);
            bar->SetWidth((kLegendWidthPx - 10) / w);
            bar->SetHeight(0.84);
            bar->SetMaximumWidthInPixels(kLegendWidthPx - 10);
            bar->SetMaximumHeightInPixels(100000);
        }
    }
    legend_->SetTitle(barTitle(legendTitle_, below).c_str());
    diffLegend_->SetTitle(barTitle("abs.\nerror", below).c_str());
    applyZoom();
}

void CameraView::updateGridVisibility() {
    // A grid finer than ~6 screen pixels per tile is noise: hide it then.
    const auto run = doc_->runs().runOutput();
    if (!run) return;
    const double tilePx = run->result.grid.tileSize * zoomedImageRect().width() / std::max(1u, run->result.grid.width);
    gridActor_->SetVisibility(tilePx >= 6.0);
}

CameraView::MeshPictureKey CameraView::meshPictureKey() const {
    // Everything the meshes' pixels depend on: the camera (shared with
    // scene_), the mesh actors and where the viewport lies in the window.
    MeshPictureKey key;
    key.cameraTime = meshes_->GetActiveCamera()->GetMTime();
    key.meshes = meshesRevision_;
    meshes_->GetTiledSizeAndOrigin(&key.w, &key.h, &key.x, &key.y);
    return key;
}

void CameraView::onRenderStart() {
    const MeshPictureKey key = meshPictureKey();
    const bool heat = imageMode_ == ImageMode::Heat && !meshActors_.empty();
    const bool cached = heat && !meshPictureCapture_ && meshPictureValid_ && key == meshPictureKey_;
    for (auto& a : meshActors_) a->SetVisibility(heat && !cached);
    meshPictureActor_->SetVisibility(cached);
}

void CameraView::captureMeshPicture() {
    // A frame of the meshes alone, read back. The window multisamples; the
    // picture's anti-aliased edge pixels come out up to 23 of 255 darker than
    // a frame that draws the meshes under the overlay (~0.5% of the pixels,
    // measured against tests/render/baselines; reading VTK's buffers or the
    // widget's gives the same values).
    const MeshPictureKey key = meshPictureKey();
    meshPictureValid_ = false;
    if (key.w <= 0 || key.h <= 0) return;
    meshPictureCapture_ = true;
    scene_->DrawOff();
    renderWindow()->Render();
    scene_->DrawOn();
    meshPictureCapture_ = false;
    vtkNew<vtkUnsignedCharArray> rgb;
    if (!renderWindow()->GetPixelData(key.x, key.y, key.x + key.w - 1, key.y + key.h - 1, 1, rgb) ||
        rgb->GetNumberOfTuples() != vtkIdType(key.w) * key.h)
        return;
    meshPicture_->SetDimensions(key.w, key.h, 1);
    meshPicture_->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    std::memcpy(meshPicture_->GetScalarPointer(), rgb->GetPointer(0), std::size_t(key.w) * key.h * 3);
    meshPicture_->Modified();
    meshPictureKey_ = key;
    meshPictureValid_ = true;
    ++meshPictureCaptures_;
}

void CameraView::rebuildMeshes() {
    for (auto& a : meshActors_) meshes_->RemoveActor(a);
    meshActors_.clear();
    ++meshesRevision_;
    for (const auto& m : doc_->scene().meshes) {
        auto mapper = vtkSmartPointer<vtkPolyDataMapper>::New();
        mapper->SetInputData(meshToPolyData(m));
        auto actor = vtkSmartPointer<vtkActor>::New();
        actor->SetMapper(mapper);
        actor->GetProperty()->SetColor(0.78, 0.78, 0.74);
        actor->GetProperty()->SetAmbient(0.15);
        actor->GetProperty()->SetDiffuse(0.85);
        actor->SetVisibility(imageMode_ == ImageMode::Heat);
        meshes_->AddActor(actor);
        meshActors_.push_back(actor);
    }
}

void CameraView::updateCamera() {
    const lc::Camera& c = doc_->scene().camera;
    vtkCamera* vc = scene_->GetActiveCamera();
    // View angle and parallel scale are then narrowed by the zoom (applyZoom,
    // via updateViewport).
    applyCullingCamera(vc, c);
    // Near plane = the culling camera's; far = its far plane, pulled in to the
    // scene's extent (an infinite or very far plane would waste depth precision).
    const auto [lo, hi] = doc_->scene().bounds();
    double farthest = 0;
    for (int i = 0; i < 8; ++i) {
        const glm::dvec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
        farthest = std::max(farthest, glm::length(corner - c.position));
    }
    double farPlane = std::min(c.farPlane, farthest * 1.05 + 1.0);
    farPlane = std::max(farPlane, c.nearPlane * 2);
    vc->SetClippingRange(c.nearPlane, farPlane);
    updateViewport();
}

} // namespace lcui
