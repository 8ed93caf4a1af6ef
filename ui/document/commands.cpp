#include "document/commands.hpp"

#include "document/document.hpp"
#include "widgets/count_text.hpp"

namespace lcui {

MoveLightCommand::MoveLightCommand(Document* doc, int index, glm::dvec3 from, glm::dvec3 to,
                                   int dragId)
    : doc_(doc), index_(index), dragId_(dragId), from_(from), to_(to) {
    setText(QObject::tr("Move light"));
}
void MoveLightCommand::undo() { doc_->applyLightPosition(index_, from_); }
void MoveLightCommand::redo() { doc_->applyLightPosition(index_, to_); }
bool MoveLightCommand::mergeWith(const QUndoCommand* other) {
    auto* o = static_cast<const MoveLightCommand*>(other);
    if (o->index_ != index_ || o->dragId_ != dragId_) return false;
    to_ = o->to_; // keep the position from before the drag, take the newest end
    return true;
}

ResizeLightCommand::ResizeLightCommand(Document* doc, int index, double from, double to, int dragId)
    : doc_(doc), index_(index), dragId_(dragId), from_(from), to_(to) {
    setText(QObject::tr("Resize light"));
}
void ResizeLightCommand::undo() { doc_->applyLightRadius(index_, from_); }
void ResizeLightCommand::redo() { doc_->applyLightRadius(index_, to_); }
bool ResizeLightCommand::mergeWith(const QUndoCommand* other) {
    auto* o = static_cast<const ResizeLightCommand*>(other);
    if (o->index_ != index_ || o->dragId_ != dragId_) return false;
    to_ = o->to_;
    return true;
}

SetLightCommand::SetLightCommand(Document* doc, int index, lc::PointLight from, lc::PointLight to)
    : doc_(doc), index_(index), from_(std::move(from)), to_(std::move(to)) {
    setText(QObject::tr("Edit light %1").arg(QString::fromStdString(to_.name)));
}
SetGltfCutoffCommand::SetGltfCutoffCommand(Document* doc, std::vector<int> lights, double from, double to)
    : doc_(doc), lights_(std::move(lights)), from_(from), to_(to) {
    setText(QObject::tr("glTF light cut-off %1 lux").arg(to));
}
void SetGltfCutoffCommand::undo() { doc_->applyGltfCutoff(lights_, from_); }
void SetGltfCutoffCommand::redo() { doc_->applyGltfCutoff(lights_, to_); }

void SetLightCommand::undo() { doc_->applyLight(index_, from_); }
void SetLightCommand::redo() { doc_->applyLight(index_, to_); }

InsertLightsCommand::InsertLightsCommand(Document* doc, std::vector<int> indices,
                                         std::vector<lc::PointLight> lights, const QString& text,
                                         bool select)
    : doc_(doc), indices_(std::move(indices)), lights_(std::move(lights)), select_(select) {
    setText(text);
}
void InsertLightsCommand::undo() { doc_->applyRemoveLights(indices_); }
void InsertLightsCommand::redo() { doc_->applyInsertLights(indices_, lights_, select_); }

RemoveLightsCommand::RemoveLightsCommand(Document* doc, std::vector<int> indices,
                                         std::vector<lc::PointLight> lights)
    : doc_(doc), indices_(std::move(indices)), lights_(std::move(lights)) {
    setText(QObject::tr("Delete %1").arg(countOf(indices_.size(), "light", "lights")));
}
void RemoveLightsCommand::undo() { doc_->applyInsertLights(indices_, lights_, true); }
void RemoveLightsCommand::redo() { doc_->applyRemoveLights(indices_); }

SetCameraCommand::SetCameraCommand(Document* doc, lc::Camera from, lc::Camera to,
                                   const QString& text)
    : doc_(doc), from_(from), to_(to) {
    setText(text);
}
void SetCameraCommand::undo() { doc_->applyCamera(from_); }
void SetCameraCommand::redo() { doc_->applyCamera(to_); }

AddMeshCommand::AddMeshCommand(Document* doc, lc::Mesh mesh) : doc_(doc), mesh_(std::move(mesh)) {
    setText(QObject::tr("Import mesh %1").arg(QString::fromStdString(mesh_.name)));
}
void AddMeshCommand::undo() { doc_->applyRemoveLastMesh(); }
void AddMeshCommand::redo() { doc_->applyAddMesh(mesh_); }

} // namespace lcui
