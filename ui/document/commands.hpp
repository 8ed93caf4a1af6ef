#pragma once
// The undo commands behind every scene edit. Each stores exactly what it needs
// to go both ways and applies itself through Document::apply*, which emits the
// signals the panels observe.

#include "culling/scene/scene.hpp"

#include <QUndoCommand>

#include <vector>

namespace lcui {

class Document;

enum CommandId { kMoveLightId = 1, kResizeLightId = 2 };

// Moves one light. Successive moves of the same light with the same drag id
// merge, so a whole drag is one undo step.
class MoveLightCommand : public QUndoCommand {
public:
    MoveLightCommand(Document* doc, int index, glm::dvec3 from, glm::dvec3 to, int dragId);
    void undo() override;
    void redo() override;
    int id() const override { return kMoveLightId; }
    bool mergeWith(const QUndoCommand* other) override;

private:
    Document* doc_;
    int index_, dragId_;
    glm::dvec3 from_, to_;
};

// Sets a light's explicit radius (dragging its sphere); merges like a move.
class ResizeLightCommand : public QUndoCommand {
public:
    ResizeLightCommand(Document* doc, int index, double from, double to, int dragId);
    void undo() override;
    void redo() override;
    int id() const override { return kResizeLightId; }
    bool mergeWith(const QUndoCommand* other) override;

private:
    Document* doc_;
    int index_, dragId_;
    double from_, to_;
};

// File > glTF light cut-off on the open scene: the I_min of the lights that
// take their radius from the glTF cut-off, and the scene's record of it.
class SetGltfCutoffCommand : public QUndoCommand {
public:
    SetGltfCutoffCommand(Document* doc, std::vector<int> lights, double from, double to);
    void undo() override;
    void redo() override;

private:
    Document* doc_;
    std::vector<int> lights_;
    double from_, to_;
};

class SetLightCommand : public QUndoCommand {
public:
    SetLightCommand(Document* doc, int index, lc::PointLight from, lc::PointLight to);
    void undo() override;
    void redo() override;

private:
    Document* doc_;
    int index_;
    lc::PointLight from_, to_;
};

// Inserts lights at the given (ascending, final) indices; undo removes them.
// `select`: the inserted lights become the selection (add, duplicate; not a
// generated cloud of thousands).
class InsertLightsCommand : public QUndoCommand {
public:
    InsertLightsCommand(Document* doc, std::vector<int> indices, std::vector<lc::PointLight> lights,
                        const QString& text, bool select = true);
    void undo() override;
    void redo() override;

private:
    Document* doc_;
    std::vector<int> indices_;
    std::vector<lc::PointLight> lights_;
    bool select_;
};

// Removes lights (ascending indices); undo puts them back where they were.
class RemoveLightsCommand : public QUndoCommand {
public:
    RemoveLightsCommand(Document* doc, std::vector<int> indices, std::vector<lc::PointLight> lights);
    void undo() override;
    void redo() override;

private:
    Document* doc_;
    std::vector<int> indices_;
    std::vector<lc::PointLight> lights_;
};

class SetCameraCommand : public QUndoCommand {
public:
    SetCameraCommand(Document* doc, lc::Camera from, lc::Camera to, const QString& text);
    void undo() override;
    void redo() override;

private:
    Document* doc_;
    lc::Camera from_, to_;
};

// Appends an imported mesh; undo removes it again (it is always the last one
// while this command is on top of the stack).
class AddMeshCommand : public QUndoCommand {
public:
    AddMeshCommand(Document* doc, lc::Mesh mesh);
    void undo() override;
    void redo() override;

private:
    Document* doc_;
    lc::Mesh mesh_;
};

} // namespace lcui
