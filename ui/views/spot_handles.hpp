#pragma once
// The selected spot light's two drag handles in the inspector view, next to
// the position and radius handles the view owns (docs/STUDIO.md):
// - the direction handle on the cone's axis, at the tip of its spherical cap
//   (apex + axis * range): dragging sets direction = normalize(handle - apex);
// - the outer-angle handle on the cap's rim, on the side facing the view's
//   right: dragging sets the angle between the axis and (handle - apex),
//   clamped to [kMinOuterAngleDeg, 90] (the model accepts (0, 90]).
// Both show only while the selection is exactly one valid spot light. Each
// drag is one undo step (SpotDragCommand merges by drag id, like
// MoveLightCommand); the edits go through Document::applyLight, so Live mode
// re-culls during the drag and the property panel follows.

#include <QObject>

#include <glm/glm.hpp>
#include <vtkNew.h>
#include <vtkWeakPointer.h>

class vtkHandleWidget;
class vtkInteractorObserver;
class vtkPointHandleRepresentation3D;
class vtkRenderer;
class vtkRenderWindowInteractor;

namespace lc {
struct PointLight;
}

namespace lcui {

class Document;

class SpotHandles : public QObject {
public:
    // The property panel's lower bound for the outer angle (degrees).
    static constexpr double kMinOuterAngleDeg = 0.01;

    // `renderer` gives the view's camera; the handles are drawn in
    // `handleLayer` when given (a layer above the scene: never hidden).
    SpotHandles(Document* doc, vtkRenderer* renderer, vtkRenderWindowInteractor* interactor,
                vtkRenderer* handleLayer = nullptr);
    ~SpotHandles();

    // Re-places or hides both handles from the document's selection and
    // lights. Connected to the document's signals and the view's orbit end.
    void update();
    // True while one of the two is being dragged (a release is then no click).
    bool dragging() const { return dragLight_ >= 0; }

    vtkHandleWidget* directionWidget() const;
    vtkPointHandleRepresentation3D* directionRepresentation() const;
    vtkHandleWidget* angleWidget() const;
    vtkPointHandleRepresentation3D* angleRepresentation() const;

    // Where the handles sit for light `l` (world space); `right` is the view's
    // right vector (the rim side the angle handle takes).
    static glm::dvec3 directionHandlePosition(const lc::PointLight& l);
    static glm::dvec3 angleHandlePosition(const lc::PointLight& l, const glm::dvec3& right);
    // The outer angle (degrees) a handle at `p` asks for: the angle between
    // (p - apex) and the axis, clamped to [kMinOuterAngleDeg, 90].
    static double angleFromHandle(const lc::PointLight& l, const glm::dvec3& p);

private:
    enum class Drag { None, Direction, Angle };
    void onStart(Drag kind);
    void onMove(Drag kind);
    void onEnd(Drag kind);
    // vtkObject::AddObserver takes plain member functions.
    void onDirStart() { onStart(Drag::Direction); }
    void onDirMove() { onMove(Drag::Direction); }
    void onDirEnd() { onEnd(Drag::Direction); }
    void onAngleStart() { onStart(Drag::Angle); }
    void onAngleMove() { onMove(Drag::Angle); }
    void onAngleEnd() { onEnd(Drag::Angle); }
    int selectedSpot() const; // the single selected valid spot light, or -1
    glm::dvec3 viewRight() const;

    Document* doc_;
    vtkRenderer* renderer_;
    vtkNew<vtkHandleWidget> dirWidget_, angleWidget_;
    vtkNew<vtkPointHandleRepresentation3D> dirRep_, angleRep_;
    vtkWeakPointer<vtkInteractorObserver> style_; // its orbit-end observer is removed with us
    unsigned long styleTag_ = 0;
    Drag active_ = Drag::None;
    int dragLight_ = -1;
    int dragId_ = 0;
};

} // namespace lcui
