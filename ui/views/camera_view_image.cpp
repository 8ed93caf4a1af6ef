// The camera view's image modes: the heat map over the scene, the shaded
// images with the culled lists and with every light, their difference, and
// which one is shown with its figures (camera_view.hpp).
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
    const auto run = doc_->runs().runOutput();
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

} // namespace lcui
