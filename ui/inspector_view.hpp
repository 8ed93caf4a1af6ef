#pragma once
// The inspector view: a free-orbit 3D view of the whole scene. Meshes, every
// light's bounding sphere, the culling camera's frustum as lines, the
// selection highlighted, and a handle widget to drag the selected light.
//
// Lights are ONE actor either way. Up to kMaxFilledLights: a glyph actor of
// low-resolution spheres scaled by the radius, coloured by the light's colour,
// translucent (depth-peeled). Above it: each sphere's silhouette ring and a
// dot at its centre (LightSilhouettes), because the software rasteriser pays
// per covered pixel and a thousand overlapping translucent spheres cover the
// view many times; a ring costs its perimeter.
//
// Picking: a click (press and release without moving) selects the light whose
// sphere the view ray through the cursor enters first, unless a mesh surface
// is nearer (exact spheres in world space, whichever way they are drawn).

#include <QVTKOpenGLNativeWidget.h>

#include <glm/glm.hpp>
#include <vtkNew.h>
#include <vtkSmartPointer.h>

#include <memory>
#include <utility>
#include <vector>

class vtkActor;
class vtkCameraPass;
class vtkCellPicker;
class vtkGlyph3D;
class vtkHandleWidget;
class vtkPointHandleRepresentation3D;
class vtkPolyData;
class vtkRenderer;
class vtkSphereSource;

namespace lcui {

class Document;
class InspectorOverlays;

class LightSilhouettes;
class SpotConesActor;
class SpotHandles;

class InspectorView : public QVTKOpenGLNativeWidget {
    Q_OBJECT
public:
    // Depth peeling (order-independent translucency) is used up to this many
    // lights; beyond it every frame would redraw all spheres once per peel.
    static constexpr std::size_t kMaxPeeledLights = 256;
    // Up to this many lights the spheres are drawn filled, above it as
    // silhouette rings (same threshold: filled spheres without peeling would
    // blend in arbitrary order).
    static constexpr std::size_t kMaxFilledLights = kMaxPeeledLights;
    explicit InspectorView(Document* doc, QWidget* parent = nullptr);
    ~InspectorView() override;

    vtkRenderer* renderer() const;
    // Frames the whole scene (meshes, lights and the culling camera).
    void resetCamera();
    // Flies (animated, `ms` milliseconds) to the selection so it fills the
    // view, keeping the viewing direction: the selected cell's or tile's
    // frustum chunk of the latest run, else the current light's sphere.
    // False when nothing is selected.
    bool frameSelected(int ms = 300);
    // The view becomes the culling camera (position, direction, up, field of
    // view or orthographic height): tile frustums line up with the camera
    // view's grid. Orbiting starts from there.
    void lookThroughCullingCamera();
    // Flies to the world-space sphere (centre, radius), keeping the direction.
    void flyTo(const glm::dvec3& center, double radius, int ms = 300);
    // Flies, keeping the direction, to where every world-space point fits the
    // view with a 10% margin.
    void flyToPoints(const std::vector<glm::dvec3>& points, int ms = 300);
    // Light whose sphere is under the widget position (logical px), or -1;
    // `hit` receives the picked point on its sphere.
    int pickLight(const QPoint& pos, glm::dvec3* hit = nullptr);
    // The cell of the selected tile (cells overlay on), else the tile frustum
    // (every tile's with the all-frustums overlay, else the selected one's)
    // that the ray under the widget position enters first; false when none.
    // A click that hits no light selects what this finds.
    bool pickChunk(const QPoint& pos, int* tile, int* cell);
    // Mesh surface point under the widget position; false when none. `normal`
    // is the surface normal facing the viewer.
    bool pickSurface(const QPoint& pos, glm::dvec3* point, glm::dvec3* normal = nullptr);
    // The handle widget that drags the selected light (tests drive it through
    // its own interaction events, exactly as a mouse drag does).
    vtkHandleWidget* handleWidget() const;
    vtkPointHandleRepresentation3D* handleRepresentation() const;
    // The second handle, on the current light's sphere (to the right of its
    // centre as seen from this view): dragging it sets the explicit radius.
    vtkHandleWidget* radiusHandleWidget() const;
    vtkPointHandleRepresentation3D* radiusHandleRepresentation() const;
    // The actor drawing every light's sphere: the filled glyph actor, or the
    // silhouette rings above kMaxFilledLights. Its mapper's input algorithm
    // reads the lights' poly data (points, "radius", "color").
    vtkActor* lightActor() const;
    bool silhouettes() const { return silhouettes_; }
    SpotConesActor* spotCones() const { return spotCones_.get(); }
    // The selected spot light's direction and outer-angle handles (ui/spot_handles.hpp).
    SpotHandles* spotHandles() const { return spotHandles_.get(); }
    // Tile frustums, cells, reverse look-up and list highlights (overlay_actors.hpp).
    InspectorOverlays* overlays() const { return overlays_.get(); }
    void renderNow();
    // Renders once when control returns to the event loop, however many
    // document signals asked for it (a Live result fires several).
    void scheduleRender();

private:
    bool renderPending_ = false;
    // The world-space points under a widget position (logical px) on the
    // near and the far clipping plane: the view ray through that pixel.
    std::pair<glm::dvec3, glm::dvec3> viewRay(const QPoint& pos) const;
    // The inspector camera's eye, focal point and orthonormal view axes.
    struct ViewBasis {
        glm::dvec3 eye, focal, dir, up, right;
    };
    ViewBasis viewBasis() const;
    void rebuildMeshes();
    void rebuildLights();
    void updateLight(int index);
    void updateSelection();
    void updateFrustum();
    void updateOverlays();
    void onHandleStart();
    void onHandleMove();
    void onHandleEnd();
    void placeRadiusHandle();
    void onRadiusStart();
    void onRadiusMove();
    void onRadiusEnd();
    void onLeftPress();
    void onLeftRelease();

    Document* doc_;
    vtkNew<vtkRenderer> renderer_;
    std::vector<vtkSmartPointer<vtkActor>> meshActors_;
    vtkSmartPointer<vtkPolyData> lightData_;
    vtkNew<vtkSphereSource> sphere_;
    vtkNew<vtkGlyph3D> glyph_;
    vtkNew<vtkActor> lightActor_;
    vtkNew<LightSilhouettes> rings_;
    vtkNew<vtkActor> ringActor_;
    bool silhouettes_ = false;
    // The renderer's passes while the rings are drawn: VTK's default, with
    // depth peeling off, composites translucent geometry through an
    // order-independent pass (float buffers and a full-view resolve per
    // frame); this sequence blends it in actor order instead.
    vtkNew<vtkCameraPass> blendedPasses_;
    vtkSmartPointer<vtkPolyData> selData_;
    vtkNew<vtkGlyph3D> selGlyph_;
    vtkNew<vtkActor> selActor_;
    vtkNew<vtkPolyData> frustumData_;
    vtkNew<vtkActor> frustumActor_;
    vtkNew<vtkHandleWidget> handle_;
    vtkNew<vtkPointHandleRepresentation3D> handleRep_;
    vtkNew<vtkHandleWidget> radiusHandle_;
    vtkNew<vtkPointHandleRepresentation3D> radiusRep_;
    bool radiusActive_ = false;
    vtkNew<vtkCellPicker> picker_;
    int dragId_ = 0;
    int dragLight_ = -1;
    bool handleActive_ = false;
    int pressX_ = 0, pressY_ = 0;
    bool cameraFramed_ = false;
    int flight_ = 0; // frameSelected's animation: a newer one supersedes it
    std::unique_ptr<InspectorOverlays> overlays_;
    std::unique_ptr<SpotConesActor> spotCones_; // spot lights' cones (ui/spot_actor.hpp)
    std::unique_ptr<SpotHandles> spotHandles_;  // after the handles above: destroyed first
};

} // namespace lcui
