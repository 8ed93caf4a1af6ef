#include "views/spot_handles.hpp"

#include "document/document.hpp"

#include <QUndoCommand>
#include <QUndoStack>
#include <vtkCamera.h>
#include <vtkCommand.h>
#include <vtkHandleWidget.h>
#include <vtkInteractorObserver.h>
#include <vtkPointHandleRepresentation3D.h>
#include <vtkProperty.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>

#include <algorithm>
#include <cmath>

namespace lcui {

namespace {

// Apart from commands.hpp's ids (1, 2): only commands of one id are offered
// for merging, so a spot drag never merges into a move.
constexpr int kSpotDragId = 0x5350;

// One spot handle drag: the light before it and the newest value. Successive
// pushes with the same light and drag id merge into one undo step.
class SpotDragCommand : public QUndoCommand {
public:
    SpotDragCommand(Document* doc, int index, lc::PointLight from, lc::PointLight to, int dragId,
                    const QString& text)
        : doc_(doc), index_(index), dragId_(dragId), from_(std::move(from)), to_(std::move(to)) {
        setText(text);
    }
    void undo() override { doc_->applyLight(index_, from_); }
    void redo() override { doc_->applyLight(index_, to_); }
    int id() const override { return kSpotDragId; }
    bool mergeWith(const QUndoCommand* other) override {
        auto* o = static_cast<const SpotDragCommand*>(other);
        if (o->index_ != index_ || o->dragId_ != dragId_) return false;
        to_ = o->to_;
        return true;
    }

private:
    Document* doc_;
    int index_, dragId_;
    lc::PointLight from_, to_;
};

glm::dvec3 toVec(const double p[3]) { return {p[0], p[1], p[2]}; }

void setPosition(vtkPointHandleRepresentation3D* rep, const glm::dvec3& p) {
    double wp[3] = {p.x, p.y, p.z};
    rep->SetWorldPosition(wp);
}

} // namespace

SpotHandles::SpotHandles(Document* doc, vtkRenderer* renderer, vtkRenderWindowInteractor* interactor,
                         vtkRenderer* handleLayer)
    : doc_(doc), renderer_(renderer) {
    auto setUp = [&](vtkHandleWidget* w, vtkPointHandleRepresentation3D* rep, double r, double g, double b) {
        rep->SetHandleSize(25);
        rep->GetProperty()->SetColor(r, g, b);
        rep->GetProperty()->SetLineWidth(3);
        rep->GetSelectedProperty()->SetLineWidth(3);
        rep->GetSelectedProperty()->SetColor(1, 0.3, 0.2);
        rep->ActiveRepresentationOff();
        w->SetInteractor(interactor);
        if (handleLayer) w->SetDefaultRenderer(handleLayer);
        w->SetRepresentation(rep);
        w->EnabledOff();
    };
    // The handles draw brighter than their colour (0.6, 0.4, 1.0 read pale
    // pink, 0.7, 1.0, 0.2 pale yellow beside the yellow selection): deep
    // ones, so that they read as STUDIO.md names them.
    setUp(dirWidget_, dirRep_, 0.45, 0.1, 0.9);   // violet: on the axis
    setUp(angleWidget_, angleRep_, 0.3, 0.85, 0.0); // lime: on the rim
    dirWidget_->AddObserver(vtkCommand::StartInteractionEvent, this, &SpotHandles::onDirStart);
    dirWidget_->AddObserver(vtkCommand::InteractionEvent, this, &SpotHandles::onDirMove);
    dirWidget_->AddObserver(vtkCommand::EndInteractionEvent, this, &SpotHandles::onDirEnd);
    angleWidget_->AddObserver(vtkCommand::StartInteractionEvent, this, &SpotHandles::onAngleStart);
    angleWidget_->AddObserver(vtkCommand::InteractionEvent, this, &SpotHandles::onAngleMove);
    angleWidget_->AddObserver(vtkCommand::EndInteractionEvent, this, &SpotHandles::onAngleEnd);
    // After an orbit the angle handle goes back to the rim's right side.
    style_ = interactor ? interactor->GetInteractorStyle() : nullptr;
    if (style_) styleTag_ = style_->AddObserver(vtkCommand::EndInteractionEvent, this, &SpotHandles::update);

    for (auto sig : {&Document::lightsChanged, &Document::sceneReset})
        connect(doc_, sig, this, [this] { update(); });
    connect(&doc_->selection(), &Selection::changed, this, [this] { update(); });
    connect(doc_, &Document::lightChanged, this, [this](int) { update(); });
    update();
}

SpotHandles::~SpotHandles() {
    if (style_) style_->RemoveObserver(styleTag_);
}

vtkHandleWidget* SpotHandles::directionWidget() const { return dirWidget_.Get(); }
vtkPointHandleRepresentation3D* SpotHandles::directionRepresentation() const { return dirRep_.Get(); }
vtkHandleWidget* SpotHandles::angleWidget() const { return angleWidget_.Get(); }
vtkPointHandleRepresentation3D* SpotHandles::angleRepresentation() const { return angleRep_.Get(); }

glm::dvec3 SpotHandles::directionHandlePosition(const lc::PointLight& l) {
    return l.position + glm::normalize(l.direction) * l.radius();
}

glm::dvec3 SpotHandles::angleHandlePosition(const lc::PointLight& l, const glm::dvec3& right) {
    const glm::dvec3 axis = glm::normalize(l.direction);
    // The part of `right` across the axis; any perpendicular when they align.
    glm::dvec3 side = right - glm::dot(right, axis) * axis;
    if (glm::length(side) < 1e-6)
        side = glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0));
    side = glm::normalize(side);
    const double a = glm::radians(l.outerAngleDeg);
    return l.position + l.radius() * (std::cos(a) * axis + std::sin(a) * side);
}

double SpotHandles::angleFromHandle(const lc::PointLight& l, const glm::dvec3& p) {
    const glm::dvec3 axis = glm::normalize(l.direction);
    const glm::dvec3 d = p - l.position;
    const double along = glm::dot(d, axis);
    const double across = glm::length(d - along * axis);
    // atan2 is 90 degrees or more behind the apex plane: clamped to 90.
    const double deg = glm::degrees(std::atan2(across, along));
    return std::clamp(deg, kMinOuterAngleDeg, 90.0);
}

int SpotHandles::selectedSpot() const {
    const auto& sel = doc_->selection().selectedLights();
    const auto& lights = doc_->scene().lights;
    if (sel.size() != 1 || sel[0] < 0 || sel[0] >= int(lights.size())) return -1;
    const lc::PointLight& l = lights[std::size_t(sel[0])];
    return l.isSpot() && l.validate().empty() ? sel[0] : -1;
}

glm::dvec3 SpotHandles::viewRight() const {
    vtkCamera* vc = renderer_->GetActiveCamera();
    double dop[3], up[3];
    vc->GetDirectionOfProjection(dop);
    vc->GetViewUp(up);
    const glm::dvec3 right = glm::cross(toVec(dop), toVec(up));
    return glm::length(right) > 0 ? glm::normalize(right) : glm::dvec3(1, 0, 0);
}

void SpotHandles::update() {
    const int i = dragging() ? dragLight_ : selectedSpot();
    if (i < 0 || i >= int(doc_->scene().lights.size())) {
        dirWidget_->EnabledOff();
        angleWidget_->EnabledOff();
        return;
    }
    const lc::PointLight& l = doc_->scene().lights[std::size_t(i)];
    // The dragged handle leads; the other follows the light.
    if (active_ != Drag::Direction) setPosition(dirRep_, directionHandlePosition(l));
    if (active_ != Drag::Angle) setPosition(angleRep_, angleHandlePosition(l, viewRight()));
    dirWidget_->EnabledOn();
    angleWidget_->EnabledOn();
}

void SpotHandles::onStart(Drag kind) {
    dragLight_ = selectedSpot();
    active_ = dragLight_ >= 0 ? kind : Drag::None;
    dragId_ = doc_->newDragId();
}

void SpotHandles::onMove(Drag kind) {
    if (active_ != kind || dragLight_ < 0 || dragLight_ >= int(doc_->scene().lights.size())) return;
    const lc::PointLight from = doc_->scene().lights[std::size_t(dragLight_)];
    lc::PointLight to = from;
    double p[3];
    QString text;
    if (kind == Drag::Direction) {
        dirRep_->GetWorldPosition(p);
        const glm::dvec3 d = toVec(p) - from.position;
        // A handle dropped on the apex names no direction: keep the old one.
        if (!(glm::length(d) > 1e-9 * (1.0 + from.radius()))) return;
        to.direction = glm::normalize(d);
        text = QObject::tr("Turn spot light");
    } else {
        angleRep_->GetWorldPosition(p);
        to.outerAngleDeg = angleFromHandle(from, toVec(p));
        text = QObject::tr("Change spot angle");
    }
    if (to.direction == from.direction && to.outerAngleDeg == from.outerAngleDeg) return;
    if (!to.validate().empty()) return;
    doc_->undoStack()->push(new SpotDragCommand(doc_, dragLight_, from, to, dragId_, text));
}

void SpotHandles::onEnd(Drag kind) {
    onMove(kind);
    active_ = Drag::None;
    dragLight_ = -1;
    update(); // both handles back on the cone
}

} // namespace lcui
