#pragma once
// The camera view: the culling camera's own image. The scene is shaded through
// a VTK camera that matches the culling camera (position, focal point, view up,
// view angle = fovY, parallel projection for the orthographic kinds), in a
// viewport letterboxed to the culling resolution's aspect so that the tile
// grid and the heat map (2D actors in that viewport's normalised coordinates)
// line up with the pixels the culling saw. A legend sits to the right.

#include <QVTKOpenGLNativeWidget.h>

#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <vector>

class vtkActor;
class vtkActor2D;
class vtkLookupTable;
class vtkPolyData;
class vtkRenderer;
class vtkScalarBarActor;
class vtkTextActor;

namespace lc {
struct RunOutput;
}

namespace lcui {

class Document;

class CameraView : public QVTKOpenGLNativeWidget {
    Q_OBJECT
public:
    explicit CameraView(Document* doc, QWidget* parent = nullptr);
    ~CameraView() override;

    // Tile under a widget position (logical pixels, y down), -1 outside the image.
    int tileAtWidgetPos(const QPoint& pos) const;
    // The heat value of every tile (what the map colours): for `all` the one
    // list's length everywhere; otherwise the longest of the tile's lists (the
    // longest loop a pixel of the tile can run). Tiles without geometry: -1.
    static std::vector<int> tileHeatValues(const lc::RunOutput& run);

    // Tiles outlined by the reverse look-up: those whose lists hold the
    // current light (ascending; empty when no light or the toggle is off).
    const std::vector<int>& highlightedTiles() const { return reverseTiles_; }
    // The values the heat map shows per tile in the document's heat mode
    // (lc::tileHeat; NaN = no geometry, not drawn).
    const std::vector<double>& shownHeat() const { return shownHeat_; }

    vtkRenderer* sceneRenderer() const;
    vtkScalarBarActor* legend() const;
    // Re-renders now (tests, screenshots).
    void renderNow();
    // Renders once when control returns to the event loop, however many
    // document signals asked for it (a Live result fires several).
    void scheduleRender();

signals:
    void tileClicked(int tile);

protected:
    void resizeEvent(QResizeEvent* e) override;

private:
    bool renderPending_ = false;
    void rebuildMeshes();
    void updateCamera();
    void updateOverlay();
    void updateSelectedTile();
    void updateReverseLookup();
    void updateViewport();
    void onLeftPress();

    Document* doc_;
    vtkNew<vtkRenderer> background_; // full window: legend and captions
    vtkNew<vtkRenderer> scene_;      // letterboxed: culling camera image + overlay
    std::vector<vtkSmartPointer<vtkActor>> meshActors_;
    vtkNew<vtkPolyData> heatData_, gridData_, selData_, reverseData_;
    vtkNew<vtkActor2D> heatActor_, gridActor_, selActor_, reverseActor_;
    std::vector<int> reverseTiles_;
    std::vector<double> shownHeat_;
    vtkNew<vtkLookupTable> lut_;
    vtkNew<vtkScalarBarActor> legend_;
    vtkNew<vtkTextActor> caption_;
};

} // namespace lcui
