// The camera view's zoom and pointer: the image's rectangle in the widget,
// wheel zoom and drag pan, fit, the tile under the cursor, its tooltip and the
// click that selects it (camera_view.hpp).
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

QString CameraView::tileTooltip(int tile) const {
    const auto run = doc_->runs().runOutput();
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
    if (doc_->runs().runIsStale()) text += tr("\n(the last run's: the scene changed since; F5 runs it again)");
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
    doc_->selection().setSelectedTile(tile);
    emit tileClicked(tile);
}

} // namespace lcui
