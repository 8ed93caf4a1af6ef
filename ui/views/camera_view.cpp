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

// Empties an overlay's polydata but keeps a (empty) point set: the zoom's
// transform filter reports an error for polydata without one.
void clearOverlay(vtkPolyData* pd) {
    pd->Initialize();
    pd->SetPoints(vtkSmartPointer<vtkPoints>::New());
}

// A scalar bar's title for its orientation: two short lines beside the
// image, one line under it.
std::string barTitle(const std::string& twoLines, bool horizontal) {
    std::string t = twoLines;
    if (horizontal) std::replace(t.begin(), t.end(), '\n', ' ');
    return t;
}

// Copies an RGB8 picture (row 0 at the top) into `out` (VTK rows go up).
void fillImage(vtkImageData* out, const lc::RgbImage& p) {
    out->SetDimensions(int(p.width), int(p.height), 1);
    out->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* dst = static_cast<std::uint8_t*>(out->GetScalarPointer());
    const std::size_t row = std::size_t(p.width) * 3;
    for (std::uint32_t y = 0; y < p.height; ++y)
        std::memcpy(dst + std::size_t(p.height - 1 - y) * row, p.rgb.data() + std::size_t(y) * row, row);
    out->Modified();
}

// The sRGB encoding lc::differencePicture applies to |culled - all| / max.
double srgbEncode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }
} // namespace

const char* CameraView::toString(ImageMode m) {
    switch (m) {
    case ImageMode::Heat: return "heat";
    case ImageMode::ShadedCulled: return "shaded-culled";
    case ImageMode::ShadedAll: return "shaded-all";
    case ImageMode::Difference: return "difference";
    }
    return "heat";
}

bool CameraView::fromString(const QString& s, ImageMode* m) {
    for (ImageMode c : {ImageMode::Heat, ImageMode::ShadedCulled, ImageMode::ShadedAll, ImageMode::Difference})
        if (s == toString(c)) {
            *m = c;
            return true;
        }
    return false;
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
    connect(doc_, &Document::runOutputChanged, this, &CameraView::updateOverlay);
    connect(doc_, &Document::tileSelectionChanged, this, [this] {
        updateSelectedTile();
        scheduleRender();
    });
    connect(doc_, &Document::overlaysChanged, this, &CameraView::updateOverlay);
    connect(doc_, &Document::selectionChanged, this, [this] {
        updateReverseLookup();
        scheduleRender();
    });
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

QRect CameraView::imageRect() const {
    const double* vp = scene_->GetViewport();
    const double w = width(), h = height();
    return QRect(QPoint(int(std::lround(vp[0] * w)), int(std::lround((1 - vp[3]) * h))),
                 QPoint(int(std::lround(vp[2] * w)) - 1, int(std::lround((1 - vp[1]) * h)) - 1));
}

QRectF CameraView::zoomedImageRect() const {
    // The whole image at the zoom, placed so that the image point centre_
    // sits mid-area (widget pixels, y down; v runs up).
    const double W = fitRect_.width() * zoom_, H = fitRect_.height() * zoom_;
    const QPointF mid = area_.center();
    return QRectF(mid.x() - centreU_ * W, mid.y() - (1.0 - centreV_) * H, W, H);
}

void CameraView::setZoom(double zoom, QPointF centre) {
    zoom_ = std::isfinite(zoom) ? std::clamp(zoom, 1.0, kMaxZoom) : 1.0;
    centreU_ = std::isfinite(centre.x()) ? centre.x() : 0.5;
    centreV_ = std::isfinite(centre.y()) ? centre.y() : 0.5;
    applyZoom();
}

void CameraView::zoomAt(const QPoint& pos, double factor) {
    const QRectF img = zoomedImageRect();
    if (img.width() <= 0 || img.height() <= 0 || !(factor > 0)) return;
    // The image point under the cursor stays under it.
    const double iu = (pos.x() + 0.5 - img.left()) / img.width();
    const double iv = 1.0 - (pos.y() + 0.5 - img.top()) / img.height();
    const double z = std::clamp(zoom_ * factor, 1.0, kMaxZoom);
    const double W = fitRect_.width() * z, H = fitRect_.height() * z;
    const QPointF mid = area_.center();
    setZoom(z, QPointF(iu + (mid.x() - pos.x() - 0.5) / W, iv - (mid.y() - pos.y() - 0.5) / H));
}

void CameraView::panBy(const QPoint& delta) {
    const QRectF img = zoomedImageRect();
    if (img.width() <= 0 || img.height() <= 0) return;
    setZoom(zoom_, QPointF(centreU_ - delta.x() / img.width(), centreV_ + delta.y() / img.height()));
}

void CameraView::fitImage() { setZoom(1.0, QPointF(0.5, 0.5)); }

void CameraView::applyZoom() {
    // Keep the image over as much of the area as it can cover: a direction
    // in which the zoomed image is narrower than the area is centred, else
    // no edge of the image comes inside the area.
    const double W = fitRect_.width() * zoom_, H = fitRect_.height() * zoom_;
    auto clampCentre = [](double c, double extent, double room) {
        if (extent <= room) return 0.5;
        const double half = room / (2 * extent);
        return std::clamp(c, half, 1.0 - half);
    };
    centreU_ = clampCentre(centreU_, W, area_.width());
    centreV_ = clampCentre(centreV_, H, area_.height());
    // The viewport: the part of the zoomed image inside the area, and the
    // window [u0,u1] x [v0,v1] of the image it shows.
    const QRectF img = zoomedImageRect();
    QRectF vp = img.intersected(area_);
    if (vp.width() < 1 || vp.height() < 1) vp = fitRect_;
    const double u0 = (vp.left() - img.left()) / img.width(), u1 = (vp.right() - img.left()) / img.width();
    const double v0 = 1.0 - (vp.bottom() - img.top()) / img.height(), v1 = 1.0 - (vp.top() - img.top()) / img.height();
    window_ = QRectF(QPointF(u0, v0), QPointF(u1, v1));
    const double w = std::max(1, width()), h = std::max(1, height());
    scene_->SetViewport(vp.left() / w, 1.0 - vp.bottom() / h, vp.right() / w, 1.0 - vp.top() / h);
    image_->SetViewport(scene_->GetViewport());
    meshes_->SetViewport(scene_->GetViewport());
    // Overlay points: image coordinates -> viewport, p' = (p - p0) / (p1 - p0).
    overlayTransform_->Identity();
    overlayTransform_->Scale(1.0 / (u1 - u0), 1.0 / (v1 - v0), 1);
    overlayTransform_->Translate(-u0, -v0, 0);
    // The culling camera's projection narrowed to the window: the whole
    // image spans NDC -1..1; the window's half height is v1 - v0 of that
    // and its centre (u0 + u1 - 1, v0 + v1 - 1). VTK's window centre is in
    // units of the window's half extents; its horizontal extent follows
    // from the viewport's aspect, which is the window's.
    const lc::Camera& c = doc_->scene().camera;
    vtkCamera* vc = scene_->GetActiveCamera();
    const double hv = v1 - v0, hu = u1 - u0;
    const double tanHalf = std::tan(c.fovYDeg * M_PI / 360.0) * hv;
    vc->SetViewAngle(std::atan(tanHalf) * 360.0 / M_PI);
    vc->SetParallelScale(c.orthoHeight / 2 * hv);
    vc->SetWindowCenter((u0 + u1 - 1) / hu, (v0 + v1 - 1) / hv);
    frameImageCamera();
    updateGridVisibility();
    updateLegendAndCaption();
    scheduleRender();
}

void CameraView::frameImageCamera() {
    if (!picturesRun_) return;
    // Pixel (i, j) of the picture is centred at (i, j); the whole picture
    // spans -0.5 .. W - 0.5. Frame the window of it exactly.
    const double W = picturesRun_->depth.width, H = picturesRun_->depth.height;
    const double fx = window_.center().x() * W - 0.5, fy = window_.center().y() * H - 0.5;
    vtkCamera* ic = image_->GetActiveCamera();
    ic->SetFocalPoint(fx, fy, 0);
    ic->SetPosition(fx, fy, 10);
    ic->SetViewUp(0, 1, 0);
    ic->SetParallelScale(H * window_.height() / 2);
    ic->SetClippingRange(1, 20);
}

void CameraView::updateGridVisibility() {
    // A grid finer than ~6 screen pixels per tile is noise: hide it then.
    const auto run = doc_->runOutput();
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

void CameraView::updateOverlay() {
    const auto run = doc_->runOutput();
    clearOverlay(heatData_);
    clearOverlay(gridData_);
    if (!run) {
        heatCaption_ = "no culling run yet (F5)";
        updateImage();
        updateLegendAndCaption();
        updateSelectedTile();
        scheduleRender();
        return;
    }
    const lc::TileGrid& g = run->result.grid;
    const double W = g.width, H = g.height;
    auto nx = [&](double px) { return px / W; };
    auto ny = [&](double py) { return 1.0 - py / H; }; // pixel rows go down, viewport y up

    // Tile corner lattice, clipped to the image (edge tiles are partial).
    vtkNew<vtkPoints> pts;
    auto cornerX = [&](std::uint32_t i) { return std::min<double>(double(i) * g.tileSize, W); };
    auto cornerY = [&](std::uint32_t j) { return std::min<double>(double(j) * g.tileSize, H); };
    for (std::uint32_t j = 0; j <= g.tilesY; ++j)
        for (std::uint32_t i = 0; i <= g.tilesX; ++i) pts->InsertNextPoint(nx(cornerX(i)), ny(cornerY(j)), 0);
    auto pid = [&](std::uint32_t i, std::uint32_t j) { return vtkIdType(j * (g.tilesX + 1) + i); };

    // Heat per tile in the chosen mode. List length and false positives run
    // blue (low) to red (high); efficiency red (0, all wasted) to blue (1).
    const lc::HeatMode mode = doc_->overlays().heat;
    shownHeat_ = lc::tileHeat(*run, mode);
    vtkNew<vtkCellArray> quads;
    vtkNew<vtkDoubleArray> values;
    values->SetName(lc::toString(mode));
    double maxHeat = 0;
    for (std::uint32_t ty = 0; ty < g.tilesY; ++ty)
        for (std::uint32_t tx = 0; tx < g.tilesX; ++tx) {
            const double v = shownHeat_[g.tileIndex(tx, ty)];
            if (std::isnan(v)) continue; // no geometry (or no per-tile figure): nothing drawn
            const vtkIdType q[4] = {pid(tx, ty), pid(tx + 1, ty), pid(tx + 1, ty + 1), pid(tx, ty + 1)};
            quads->InsertNextCell(4, q);
            values->InsertNextValue(v);
            maxHeat = std::max(maxHeat, v);
        }
    heatData_->SetPoints(pts);
    heatData_->SetPolys(quads);
    heatData_->GetCellData()->SetScalars(values);
    if (mode == lc::HeatMode::Overflow) {
        // One hue, the orange that marks over-full lists everywhere (the
        // heat map PNGs' frames): only over-full tiles are drawn at all.
        lut_->SetHueRange(0.08, 0.08);
        lut_->SetSaturationRange(0.6, 1.0);
        lut_->SetValueRange(1.0, 1.0);
        lut_->SetTableRange(0, std::max(1.0, maxHeat));
        legendTitle_ = "dropped\nentries";
        legend_->SetLabelFormat("%.0f");
        legend_->SetNumberOfLabels(maxHeat < 5 ? int(std::max(1.0, maxHeat)) + 1 : 5);
    } else if (mode == lc::HeatMode::Efficiency) {
        lut_->SetSaturationRange(0.9, 0.9);
        lut_->SetValueRange(1.0, 1.0);
        lut_->SetHueRange(0.0, 0.667);
        lut_->SetTableRange(0, 1);
        legendTitle_ = "efficiency\nper tile";
        legend_->SetLabelFormat("%.2f");
        legend_->SetNumberOfLabels(5);
    } else {
        lut_->SetSaturationRange(0.9, 0.9);
        lut_->SetValueRange(1.0, 1.0);
        lut_->SetHueRange(0.667, 0.0);
        const double top = std::max(1.0, maxHeat);
        lut_->SetTableRange(0, top);
        legendTitle_ = mode == lc::HeatMode::ListLength       ? "lights\nper tile"
                       : mode == lc::HeatMode::FalsePositives ? "false\npositives"
                                                              : "false\nnegatives";
        legend_->SetLabelFormat("%.0f");
        // Counts: below 5 a label per whole number (five evenly spaced labels
        // over 0..2 would read 0, 0, 1, 2, 2).
        legend_->SetNumberOfLabels(top < 5 ? int(top) + 1 : 5);
    }
    legend_->SetTitle(barTitle(legendTitle_, legendPlace_ == LegendPlace::Below).c_str());
    lut_->Build();

    vtkNew<vtkCellArray> lines;
    for (std::uint32_t i = 0; i <= g.tilesX; ++i) {
        const vtkIdType l[2] = {pid(i, 0), pid(i, g.tilesY)};
        lines->InsertNextCell(2, l);
    }
    for (std::uint32_t j = 0; j <= g.tilesY; ++j) {
        const vtkIdType l[2] = {pid(0, j), pid(g.tilesX, j)};
        lines->InsertNextCell(2, l);
    }
    gridData_->SetPoints(pts);
    gridData_->SetLines(lines);
    updateGridVisibility();

    const std::string what = run->custom ? "custom " + std::filesystem::path(run->custom->source).filename().string() +
                                               " (" + run->custom->lists + ")"
                                         : std::string(lc::toString(run->result.algorithm));
    heatCaption_ = what + "  " + std::to_string(g.tilesX) + "x" +
                   std::to_string(g.tilesY) + " tiles of " + std::to_string(g.tileSize) + " px";
    // The engine limits, when they took something: over-full lists and lights past the limit.
    if (const lc::ListLimits& lim = run->result.limits; !run->custom && !lim.empty())
        heatCaption_ += "  |  " + std::to_string(lim.overflowLists.size()) + " over-full" +
                        (lim.lightsOverLimit ? ", " + std::to_string(lim.lightsOverLimit) + " past limit" : std::string());
    updateImage();
    updateLegendAndCaption();
    updateSelectedTile();
    updateReverseLookup();
    scheduleRender();
}

void CameraView::setImageMode(ImageMode mode) {
    if (mode == imageMode_) return;
    imageMode_ = mode;
    updateImage();
    updateLegendAndCaption();
    scheduleRender();
    emit imageModeChanged(mode);
}

vtkImageData* CameraView::shownImage() const {
    if (imageMode_ == ImageMode::Heat || !imageActor_->GetVisibility()) return nullptr;
    return imageActor_->GetInput();
}

double CameraView::shownImageRmse() const {
    return picturesRun_ ? picturesRun_->truth.metrics.imageRmse : std::nan("");
}
double CameraView::shownImageMaxError() const {
    return picturesRun_ ? picturesRun_->truth.metrics.imageMaxError : std::nan("");
}

QString CameraView::imageLabelText() const {
    return imageLabel_->GetVisibility() ? QString::fromUtf8(imageLabel_->GetInput()) : QString();
}

void CameraView::updateImage() {
    const bool pictureMode = imageMode_ != ImageMode::Heat;
    for (auto& a : meshActors_) a->SetVisibility(!pictureMode);
    heatActor_->SetVisibility(!pictureMode); // the tint would falsify the picture
    const auto run = doc_->runOutput();
    if (pictureMode && run && !run->shadedAll.empty() && run != picturesRun_) {
        try {
            const lc::ShadedPictures p = lc::shadedPictures(*run);
            fillImage(culledPicture_, p.culled);
            fillImage(allPicture_, p.all);
            fillImage(diffPicture_, p.difference);
            picturesExposure_ = p.exposure;
            picturesRun_ = run;
        } catch (const std::exception&) {
            picturesRun_.reset(); // images that do not match their depth: nothing to show
        }
    }
    // While a newer run is being shaded the last pictures stay up, if they
    // still cover the same pixels.
    const bool show = pictureMode && run && picturesRun_ && picturesRun_->depth.width == run->result.grid.width &&
                      picturesRun_->depth.height == run->result.grid.height;
    imageActor_->SetVisibility(show);
    if (!show) return;
    vtkImageData* picture = imageMode_ == ImageMode::ShadedCulled ? culledPicture_.Get()
                            : imageMode_ == ImageMode::ShadedAll  ? allPicture_.Get()
                                                                  : diffPicture_.Get();
    imageActor_->SetInputData(picture);
    frameImageCamera();
}

void CameraView::updateLegendAndCaption() {
    const auto run = doc_->runOutput();
    legend_->SetVisibility(run && imageMode_ == ImageMode::Heat);
    diffLegend_->SetVisibility(false);
    {
        // The caption says the zoom, and how to get back.
        std::string text = heatCaption_;
        if (zoom_ > 1.0 + 1e-9) {
            char z[96];
            std::snprintf(z, sizeof z, "  zoom %.3gx", zoom_);
            text += z;
        }
        caption_->SetInput(text.c_str());
        caption_->SetDisplayPosition(6, legendPlace_ == LegendPlace::Below ? 4 : 6);
    }
    imageLabel_->SetVisibility(run && imageMode_ != ImageMode::Heat);
    if (!imageLabel_->GetVisibility()) return;
    QString text = imageMode_ == ImageMode::ShadedCulled ? tr("shaded, culled lists")
                   : imageMode_ == ImageMode::ShadedAll  ? tr("shaded, all lights")
                                                         : tr("abs(culled - all lights)");
    if (imageActor_->GetVisibility()) {
        const auto& m = picturesRun_->truth.metrics;
        if (imageMode_ == ImageMode::Difference) {
            text += tr(", white = %1").arg(m.imageMaxError, 0, 'g', 4);
            diffLut_->SetTableRange(0, m.imageMaxError > 0 ? m.imageMaxError : 1.0);
            diffLegend_->SetVisibility(true);
        } else {
            text += tr(", exposure %1").arg(picturesExposure_, 0, 'g', 4);
        }
        text += tr("\nimage RMSE %1, max %2 (%3)")
                    .arg(m.imageRmse, 0, 'g', 6)
                    .arg(m.imageMaxError, 0, 'g', 6)
                    .arg(QString::fromStdString(picturesRun_->result.backend));
        if (picturesRun_ != run) text += tr(", shading the newer run...");
    } else {
        text += tr(": shading...");
    }
    imageLabel_->SetInput(text.toUtf8().constData());
}

void CameraView::updateReverseLookup() {
    clearOverlay(reverseData_);
    reverseTiles_.clear();
    const auto run = doc_->runOutput();
    const int light = doc_->currentLight();
    if (!run || !doc_->overlays().reverseLookup || light < 0 || std::size_t(light) >= run->lights.size()) return;
    const lc::TileGrid& g = run->result.grid;
    for (std::uint32_t t : lc::tilesHoldingLight(run->result, std::uint32_t(light))) reverseTiles_.push_back(int(t));
    // One closed outline per tile, inset by a tenth of a tile so that
    // neighbouring outlines stay apart.
    vtkNew<vtkPoints> pts;
    vtkNew<vtkCellArray> loops;
    const double inset = 0.1 * g.tileSize;
    for (int t : reverseTiles_) {
        const auto rect = g.tileRect(std::uint32_t(t) % g.tilesX, std::uint32_t(t) / g.tilesX);
        const double x0 = rect.x0 + inset, x1 = rect.x1 - inset, y0 = rect.y0 + inset, y1 = rect.y1 - inset;
        const vtkIdType a = pts->InsertNextPoint(x0 / g.width, 1 - y0 / g.height, 0);
        pts->InsertNextPoint(x1 / g.width, 1 - y0 / g.height, 0);
        pts->InsertNextPoint(x1 / g.width, 1 - y1 / g.height, 0);
        pts->InsertNextPoint(x0 / g.width, 1 - y1 / g.height, 0);
        const vtkIdType ids[5] = {a, a + 1, a + 2, a + 3, a};
        loops->InsertNextCell(5, ids);
    }
    reverseData_->SetPoints(pts);
    reverseData_->SetLines(loops);
}

void CameraView::updateSelectedTile() {
    clearOverlay(selData_);
    const auto run = doc_->runOutput();
    const int tile = doc_->selectedTile();
    if (!run || tile < 0 || std::uint32_t(tile) >= run->result.grid.tileCount()) return;
    const lc::TileGrid& g = run->result.grid;
    const auto rect = g.tileRect(std::uint32_t(tile) % g.tilesX, std::uint32_t(tile) / g.tilesX);
    vtkNew<vtkPoints> pts;
    pts->InsertNextPoint(rect.x0 / double(g.width), 1 - rect.y0 / double(g.height), 0);
    pts->InsertNextPoint(rect.x1 / double(g.width), 1 - rect.y0 / double(g.height), 0);
    pts->InsertNextPoint(rect.x1 / double(g.width), 1 - rect.y1 / double(g.height), 0);
    pts->InsertNextPoint(rect.x0 / double(g.width), 1 - rect.y1 / double(g.height), 0);
    vtkNew<vtkCellArray> loop;
    const vtkIdType ids[5] = {0, 1, 2, 3, 0};
    loop->InsertNextCell(5, ids);
    selData_->SetPoints(pts);
    selData_->SetLines(loop);
}

QString CameraView::tileTooltip(int tile) const {
    const auto run = doc_->runOutput();
    if (!run || tile < 0 || std::uint32_t(tile) >= run->result.grid.tileCount()) return {};
    const lc::CullResult& r = run->result;
    const std::uint32_t per = r.algorithm == lc::Algorithm::All ? 0 : std::max(r.listsPerTile, 1u);
    QString lists;
    std::uint64_t w = 0, e = 0, fn = 0;
    for (std::uint32_t k = 0; k < std::max(per, 1u); ++k) {
        const std::uint32_t l = per ? std::uint32_t(tile) * per + k : 0;
        lists += (k ? ", " : "") + QString::number(r.listCount[l]);
        if (run->truthComputed && per) {
            w += run->truth.listShadingWork[l];
            e += run->truth.listExactWork[l];
            fn += run->truth.listFalseNegatives[l];
        }
    }
    const lc::TileGrid& g = r.grid;
    QString text = tr("tile %1,%2: %3 %4").arg(tile % g.tilesX).arg(tile / g.tilesX).arg(per > 1 ? tr("lists of") : tr("list of"), lists) +
                   tr(" lights");
    if (r.tileDepthMin[std::size_t(tile)] <= r.tileDepthMax[std::size_t(tile)])
        text += tr("\nview depth %1 .. %2").arg(r.tileDepthMin[std::size_t(tile)], 0, 'g', 5).arg(r.tileDepthMax[std::size_t(tile)], 0, 'g', 5);
    else
        text += tr("\nno geometry");
    if (run->truthComputed && per) {
        text += tr("\n%1 geometry pixels, efficiency %2")
                    .arg(run->truth.tileGeometryPixels[std::size_t(tile)])
                    .arg(w ? QString::number(double(e) / double(w), 'f', 3) : QStringLiteral("-"));
        if (fn) text += tr("\nMISSING: %1 pixel-lights").arg(fn);
    }
    return text;
}

bool CameraView::handleZoomPanEvent(QEvent* e) {
    switch (e->type()) {
    case QEvent::Wheel: {
        auto* we = static_cast<QWheelEvent*>(e);
        const int steps = we->angleDelta().y();
        if (steps == 0) return false;
        // 1.25x a notch (120 eighths of a degree), about the cursor.
        zoomAt(we->position().toPoint(), std::pow(1.25, steps / 120.0));
        return true;
    }
    case QEvent::MouseButtonPress: {
        auto* me = static_cast<QMouseEvent*>(e);
        if (me->button() != Qt::RightButton && me->button() != Qt::MiddleButton) return false;
        panning_ = true;
        panFrom_ = me->pos();
        return true;
    }
    case QEvent::MouseMove: {
        if (!panning_) return false;
        auto* me = static_cast<QMouseEvent*>(e);
        panBy(me->pos() - panFrom_);
        panFrom_ = me->pos();
        return true;
    }
    case QEvent::MouseButtonRelease: {
        auto* me = static_cast<QMouseEvent*>(e);
        if (me->button() != Qt::RightButton && me->button() != Qt::MiddleButton) return false;
        panning_ = false;
        return true;
    }
    case QEvent::MouseButtonDblClick: {
        auto* me = static_cast<QMouseEvent*>(e);
        if (me->button() != Qt::MiddleButton) return false;
        fitImage();
        return true;
    }
    default: return false;
    }
}

bool CameraView::event(QEvent* e) {
    if (handleZoomPanEvent(e)) return true;
    if (e->type() == QEvent::ToolTip) {
        auto* help = static_cast<QHelpEvent*>(e);
        const QString text = tileTooltip(tileAtWidgetPos(help->pos()));
        if (text.isEmpty()) QToolTip::hideText();
        else QToolTip::showText(help->globalPos(), text, this);
        return true;
    }
    return QVTKOpenGLNativeWidget::event(e);
}

int CameraView::tileAtWidgetPos(const QPoint& pos) const {
    const lc::Camera& cam = doc_->scene().camera;
    const double nxw = (pos.x() + 0.5) / std::max(1, width());
    const double nyw = 1.0 - (pos.y() + 0.5) / std::max(1, height());
    const double* vp = scene_->GetViewport();
    const double vu = (nxw - vp[0]) / (vp[2] - vp[0]);
    const double vv = (nyw - vp[1]) / (vp[3] - vp[1]);
    if (vu < 0 || vu >= 1 || vv <= 0 || vv > 1) return -1;
    // The image point shown there (zoom and pan).
    const double u = window_.left() + vu * window_.width(), v = window_.top() + vv * window_.height();
    if (u < 0 || u >= 1 || v <= 0 || v > 1) return -1;
    const auto px = std::uint32_t(u * cam.width), py = std::uint32_t((1 - v) * cam.height);
    const lc::TileGrid g = lc::TileGrid::make(cam.width, cam.height, cam.tileSize);
    if (px >= cam.width || py >= cam.height) return -1;
    return int(g.tileOfPixel(px, py));
}

void CameraView::onLeftPress() {
    int x = 0, y = 0;
    interactor()->GetEventPosition(x, y); // device pixels, y up
    const double dpr = devicePixelRatioF();
    const QPoint pos(int(x / dpr), int(height() - 1 - y / dpr));
    const int tile = tileAtWidgetPos(pos);
    doc_->setSelectedTile(tile);
    emit tileClicked(tile);
}

} // namespace lcui
