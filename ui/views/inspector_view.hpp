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
//
// Inside a building (OverlayOptions, View > Meshes and View >
// Lights): the meshes can be drawn as x-ray (translucent, no depth writes;
// they then hide no light from a click) or hidden; the lights drawn can be
// only the selected tile's listed ones, as spheres, rings or automatic, with
// at most sphereCap filled spheres (a "+N more" note in the view's corner
// says what was left out); lights and spot cones hide together. The current
// light's handles live in a renderer layer above the scene (handleLayer()),
// so walls never hide them. Frame selected looks from the culling camera's
// side when a mesh would stand between the kept direction and the selection.

#include <QVTKOpenGLNativeWidget.h>

#include <glm/glm.hpp>
#include <vtkNew.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>

#include <memory>
#include <optional>
#include <utility>
#include <vector>

class vtkActor;
class vtkCameraPass;
class vtkCellPicker;
class vtkGenericOpenGLRenderWindow;
class vtkGlyph3D;
class vtkHandleWidget;
class vtkInteractorStyle;
class vtkPointHandleRepresentation3D;
class vtkPolyData;
class vtkRenderer;
class vtkSphereSource;

namespace lc {
struct Scene;
}

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
    // When shown meshes would hide most of the selection from that eye (of
    // the chunk's near face: its centre and corners; of a light: its centre
    // and four points around it), it looks from the culling camera's side: along the line from the culling camera through
    // that point, no farther back than the first surface on it (so the eye
    // stays inside the room the culling camera sees). False when nothing is
    // selected.
    bool frameSelected(int ms = 300);
    // Whether the last frameSelected turned to the culling camera's side.
    bool framedFromCullingSide() const { return framedFromCullingSide_; }
    // What the last frameSelected changed besides the camera, for the status
    // bar (it turned the meshes to x-ray); empty when nothing.
    QString frameNote() const { return frameNote_; }
    // Where the segment a -> b first crosses a triangle of the scene's meshes,
    // as a fraction of its length in [0, 1]; nullopt when it crosses none.
    static std::optional<double> firstMeshHit(const lc::Scene& scene, const glm::dvec3& a, const glm::dvec3& b);
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
    // The lights the light actor draws (ascending indices; every light unless
    // only the tile's are shown or the sphere cap left some out), and how many
    // of the lights it should show were left out by the cap.
    const std::vector<int>& drawnLights() const { return drawn_; }
    std::size_t lightsLeftOut() const { return leftOut_; }
    // The note in the view's top-left corner ("+N more ...", the tile whose
    // lights are shown); hidden when there is nothing to say.
    vtkTextActor* lightNote() const;
    // The renderer layer above the scene that holds every handle (depth
    // cleared before it draws: geometry never hides a handle).
    vtkRenderer* handleLayer() const;
    const std::vector<vtkSmartPointer<vtkActor>>& meshActors() const { return meshActors_; }
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
    // Construction steps (inspector_actors.cpp, inspector_picking.cpp).
    void buildLightActors();
    void buildRenderPasses(vtkGenericOpenGLRenderWindow* renderWindow);
    void buildHandles(vtkInteractorStyle* style);
    void buildLightNote();
    void rebuildMeshes();
    void applyMeshDisplay();
    void rebuildLights();
    // Rebuilds the drawn lights when what chooses them changed (options, tile,
    // run, the selection while the cap leaves lights out).
    void refreshLightSet();
    std::vector<long long> lightSetKey() const;
    // Animates the camera to (eye, focal, up); no `up`: the view up stays.
    void flyToEye(const glm::dvec3& eye, const glm::dvec3& focal, std::optional<glm::dvec3> up, int ms);
    // The eye distance from the points' centre at which every point fits the
    // view along `dir` (10% margin); also sets the parallel scale.
    double fitDistance(const std::vector<glm::dvec3>& points, const ViewBasis& b, glm::dvec3* center);
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
    vtkNew<vtkRenderer> handleLayer_;
    vtkNew<vtkTextActor> lightNote_;
    std::vector<int> drawn_; // light indices in lightData_'s order
    std::vector<int> slot_;  // per light: its point in lightData_, or -1
    std::size_t leftOut_ = 0;
    bool drawnAreTileLights_ = false; // drawn_ is the selected tile's list
    std::vector<long long> lightSetKey_; // what chose drawn_ (refreshLightSet)
    bool framedFromCullingSide_ = false;
    QString frameNote_;
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
