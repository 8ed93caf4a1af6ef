#pragma once
// The camera view: the culling camera's own image. The scene is shaded through
// a VTK camera that matches the culling camera (position, focal point, view up,
// view angle = fovY, parallel projection for the orthographic kinds), in a
// viewport letterboxed to the culling resolution's aspect so that the tile
// grid and the heat map (2D actors in that viewport's normalised coordinates)
// line up with the pixels the culling saw. A legend sits to the right.
//
// Image modes (setImageMode): the scene with the heat map, or the shading
// pass's pictures (lc::shadedPictures, the pixels `run --shaded-images`
// writes) drawn 1:1 in the same letterboxed viewport under the tile grid,
// the selected tile and the reverse look-up outlines.
//
// Renderers, bottom up: background_ (window, legend, caption), image_ (the
// letterboxed viewport's clear, the shaded pictures), meshes_ (the culling
// camera's shaded meshes) and scene_ (the 2D overlay). In Heat mode,
// renderNow() after the camera, the meshes or the viewport changed first
// renders a frame of the meshes alone and reads it back; meshes_ then draws
// that picture instead of the meshes (a Live drag changes the overlay only).
// Renders Qt starts itself draw the meshes while the picture is stale.

#include <QVTKOpenGLNativeWidget.h>

#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkTransform.h>

#include <QPointF>
#include <QRect>
#include <QString>

#include <memory>
#include <string>
#include <vector>

class vtkActor;
class vtkImageActor;
class vtkImageData;
class vtkActor2D;
class vtkLookupTable;
class vtkPolyData;
class vtkRenderer;
class vtkScalarBarActor;
class vtkTextActor;
class vtkTransform;

namespace lc {
struct RunOutput;
}

namespace lcui {

class Document;

class CameraView : public QVTKOpenGLNativeWidget {
    Q_OBJECT
public:
    enum class ImageMode {
        Heat,         // the scene shaded by VTK, heat map of the tiles
        ShadedCulled, // the shading pass with each pixel's list
        ShadedAll,    // the shading pass with every light
        Difference,   // |culled - all| per channel, the largest error white
    };
    static const char* toString(ImageMode m); // "heat", "shaded-culled", "shaded-all", "difference"
    static bool fromString(const QString& s, ImageMode* m);
    static bool needsShading(ImageMode m) { return m != ImageMode::Heat; }

    explicit CameraView(Document* doc, QWidget* parent = nullptr);
    ~CameraView() override;
    bool event(QEvent* e) override; // hover tooltips

    // Tile under a widget position (logical pixels, y down), -1 outside the image.
    int tileAtWidgetPos(const QPoint& pos) const;
    // The hover tooltip of a tile of the latest run: its list lengths, view
    // depth range, geometry pixels, efficiency and misses; empty without a run.
    QString tileTooltip(int tile) const;

    // Tiles outlined by the reverse look-up: those whose lists hold the
    // current light (ascending; empty when no light or the toggle is off).
    const std::vector<int>& highlightedTiles() const { return reverseTiles_; }
    // The values the heat map shows per tile in the document's heat mode
    // (lc::tileHeat; NaN = no geometry, not drawn).
    const std::vector<double>& shownHeat() const { return shownHeat_; }

    vtkRenderer* sceneRenderer() const;
    vtkScalarBarActor* legend() const;
    // How often the meshes were drawn and read back (diagnostics, probe).
    int meshPictureCaptures() const { return meshPictureCaptures_; }

    ImageMode imageMode() const { return imageMode_; }
    void setImageMode(ImageMode mode);
    // The picture an image mode shows (VTK rows: row 0 at the bottom), or null
    // in Heat mode and while no shaded run has arrived.
    vtkImageData* shownImage() const;
    // Generation-independent identity of the run whose pictures are shown
    // (null: none) and the image error the legend states (its RMSE and max
    // are the run's truth.metrics, the numbers summary.json writes).
    const lc::RunOutput* shownImageRun() const { return picturesRun_.get(); }
    double shownImageRmse() const;
    double shownImageMaxError() const;
    // The label over an image mode's picture (mode, exposure or difference
    // scale, image RMSE and max error, backend); empty in Heat mode.
    QString imageLabelText() const;
    // Zoom and pan of the picture (the wheel zooms about the cursor, a right
    // or middle drag pans, View > Fit camera image or a middle double-click
    // fits). zoom() 1 shows the whole image letterboxed; zoomed, the image
    // grows over the whole view beside the legend. The centre is the image
    // point, in normalised image coordinates (u right, v up, 0..1), at the
    // middle of that room (kept so that no image edge comes inside the room
    // where the image could cover it). Tiles, overlays, pictures and picking
    // follow.
    double zoom() const { return zoom_; }
    QPointF viewCentre() const { return {centreU_, centreV_}; }
    void setZoom(double zoom, QPointF centre);
    // Zooms by `factor` keeping the image point under `pos` (widget pixels) there.
    void zoomAt(const QPoint& pos, double factor);
    // Moves the picture by `delta` widget pixels (as a drag does).
    void panBy(const QPoint& delta);
    void fitImage();
    static constexpr double kMaxZoom = 64.0;
    // Where the legend sits: a band right of the image, or under it when
    // that leaves the image larger (a wide, short view).
    enum class LegendPlace { Right, Below };
    LegendPlace legendPlace() const { return legendPlace_; }
    // The viewport: the part of the image on screen, in widget pixels (y
    // down); at zoom 1 the letterboxed image, zoomed the part of the zoomed
    // image inside the view (beside or above the legend).
    QRect imageRect() const;
    // Where the whole image lies at the current zoom and pan (widget pixels,
    // y down; may reach beyond the view).
    QRectF zoomedImageRect() const;

    // Re-renders now (tests, screenshots).
    void renderNow();
    // Renders once when control returns to the event loop, however many
    // document signals asked for it (a Live result fires several).
    void scheduleRender();

signals:
    void tileClicked(int tile);
    void imageModeChanged(ImageMode mode);

protected:
    void resizeEvent(QResizeEvent* e) override;

private:
    // Empties an overlay's polydata but keeps a (empty) point set: the zoom's
    // transform filter reports an error for polydata without one.
    static void clearOverlay(vtkPolyData* pd);
    // A scalar bar's title for its orientation: two short lines beside the
    // image, one line under it.
    static std::string barTitle(const std::string& twoLines, bool horizontal);
    bool renderPending_ = false;
    // Zoom and pan (setZoom); the overlay's normalised points go through
    // overlayTransform_ into the zoomed viewport.
    double zoom_ = 1.0, centreU_ = 0.5, centreV_ = 0.5;
    QRectF area_{0, 0, 1, 1};    // the room for the image (widget pixels, y down)
    QRectF fitRect_{0, 0, 1, 1}; // the whole image at zoom 1 (letterboxed in area_)
    QRectF window_{0, 0, 1, 1};  // the image window the viewport shows (u right, v up)
    QPoint panFrom_;
    bool panning_ = false;
    LegendPlace legendPlace_ = LegendPlace::Right;
    vtkNew<vtkTransform> overlayTransform_;
    void applyZoom();
    void frameImageCamera();
    void updateGridVisibility();
    bool handleZoomPanEvent(QEvent* e);
    std::string legendTitle_;
    // Heat mode during a Live drag: the meshes do not change, the overlay
    // does. The meshes' pixels are read back once per camera, meshes and
    // viewport (a meshes-only frame) and drawn as a picture after that;
    // llvmpipe paid ~12 ms a frame for the meshes at 469x496.
    struct MeshPictureKey {
        unsigned long cameraTime = 0;
        quint64 meshes = 0;
        int x = 0, y = 0, w = 0, h = 0;
        bool operator==(const MeshPictureKey&) const = default;
    };
    MeshPictureKey meshPictureKey() const;
    void onRenderStart();
    void captureMeshPicture();
    void rebuildMeshes();
    void updateCamera();
    void updateOverlay();
    void updateSelectedTile();
    void updateReverseLookup();
    void updateViewport();
    void onLeftPress();
    void updateImage();
    void updateLegendAndCaption();

    Document* doc_;
    vtkNew<vtkRenderer> background_; // full window: legend and captions
    vtkNew<vtkRenderer> scene_;      // letterboxed: culling camera image + overlay
    vtkNew<vtkRenderer> meshes_;     // under scene_, same viewport and camera: the shaded meshes
    std::vector<vtkSmartPointer<vtkActor>> meshActors_;
    vtkNew<vtkImageData> meshPicture_; // the meshes-only frame's viewport pixels (with image_'s background)
    vtkNew<vtkActor2D> meshPictureActor_;
    MeshPictureKey meshPictureKey_;
    bool meshPictureValid_ = false, meshPictureCapture_ = false;
    quint64 meshesRevision_ = 0;
    int meshPictureCaptures_ = 0;
    vtkNew<vtkPolyData> heatData_, gridData_, selData_, reverseData_;
    vtkNew<vtkActor2D> heatActor_, gridActor_, selActor_, reverseActor_;
    std::vector<int> reverseTiles_;
    std::vector<double> shownHeat_;
    vtkNew<vtkLookupTable> lut_;
    vtkNew<vtkScalarBarActor> legend_;
    vtkNew<vtkTextActor> caption_;

    // Image modes: a renderer under scene_ (same viewport, layer 0) with a
    // parallel camera framing the picture pixel for pixel.
    ImageMode imageMode_ = ImageMode::Heat;
    vtkNew<vtkRenderer> image_;
    vtkNew<vtkImageActor> imageActor_;
    vtkNew<vtkImageData> culledPicture_, allPicture_, diffPicture_;
    std::shared_ptr<const lc::RunOutput> picturesRun_; // the run the pictures were made from
    double picturesExposure_ = 1;
    vtkNew<vtkLookupTable> diffLut_;
    vtkNew<vtkScalarBarActor> diffLegend_;
    vtkNew<vtkTextActor> imageLabel_; // in scene_, top left of the picture
    std::string heatCaption_;
};

} // namespace lcui
