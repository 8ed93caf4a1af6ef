#pragma once
// The studio's central document: the scene being edited with its undo stack
// and the file it came from. Its three other parts are objects of their own,
// each with its signals: the selection (selection.hpp), how the views show it
// (view_options.hpp) and what to cull and what came back (run_state.hpp). The
// Document keeps them consistent with the scene (a new scene clears the
// selection and the run; removed lights leave the selection; every edit is
// counted for the run's staleness). Every edit of the scene goes through the
// QUndoStack (the public edit functions below push commands).

#include "document/explained_selection.hpp"
#include "document/run_state.hpp"
#include "document/selection.hpp"
#include "document/view_options.hpp"

#include "culling/scene/scene.hpp"

#include <QObject>
#include <QString>
#include <QUndoStack>

#include <memory>
#include <vector>

namespace lcui {

class Document : public QObject {
    Q_OBJECT
public:
    explicit Document(QObject* parent = nullptr);

    const lc::Scene& scene() const { return scene_; }
    // Changes whenever the meshes do (import, its undo, a new scene), never
    // for a light or camera edit: what depends on the meshes only (the depth
    // image with an unchanged camera, a copy of the meshes) is still valid
    // while it is the same. Never 0.
    quint64 geometryRevision() const { return geometryRevision_; }
    QUndoStack* undoStack() { return &undo_; }

    // --- file state ---------------------------------------------------------
    QString filePath() const { return filePath_; }
    // Unsaved edits: the undo stack is not at its clean index.
    bool isDirty() const { return !undo_.isClean(); }
    // Replaces the whole scene (New, Open, built-in picker): clears the undo
    // stack, the selection and the shown run. Not undoable by design (the
    // unsaved-changes prompt guards it).
    void resetScene(lc::Scene scene, const QString& path);
    // Marks the current state as saved under `path`.
    void markSaved(const QString& path);

    // --- the document's other parts ---------------------------------------------
    Selection& selection() { return selection_; }
    const Selection& selection() const { return selection_; }
    ViewOptions& viewOptions() { return view_; }
    const ViewOptions& viewOptions() const { return view_; }
    RunState& runs() { return runs_; }
    const RunState& runs() const { return runs_; }
    // The explanation of the selection in the shown run (explained_selection.hpp),
    // worked out once per selection and run.
    const ExplainedSelection::Result& explained() const { return explained_.of(*this); }

    // --- edits: each pushes one undo command ----------------------------------
    // A light drag: every call with the same `dragId` for the same light merges
    // into one undo step (the handle widget starts a new id per drag).
    void moveLight(int index, const glm::dvec3& position, int dragId);
    int newDragId() { return ++dragCounter_; }
    // Dragging a light's sphere: sets its explicit radius (> 0), merging per drag id.
    void resizeLight(int index, double radius, int dragId);
    // Property change of one light (name, colour, intensity, radius, ...).
    void setLight(int index, const lc::PointLight& light);
    // Appends lights as one step (add, duplicate, generate); `select` makes
    // them the selection.
    void addLights(const std::vector<lc::PointLight>& lights, const QString& text, bool select = true);
    void duplicateLights(const std::vector<int>& indices);
    void deleteLights(std::vector<int> indices);
    void setCamera(const lc::Camera& camera, const QString& text = tr("Edit camera"));
    // A new glTF light cut-off for the open scene: the lights that took their
    // radius from the cut-off (lc::gltfCutoffLights) get I_min = `lux`, one
    // undo step. Returns how many; 0 (and no step) when the scene has none.
    int setGltfCutoff(double lux);
    void importMesh(lc::Mesh mesh);

    // --- used by the undo commands only --------------------------------------
    void applyLightPosition(int index, const glm::dvec3& p);
    void applyLight(int index, const lc::PointLight& l);
    void applyLightRadius(int index, double explicitRadius);
    void applyInsertLights(const std::vector<int>& indices, const std::vector<lc::PointLight>& lights,
                           bool select);
    void applyRemoveLights(const std::vector<int>& indices); // ascending
    void applyCamera(const lc::Camera& c);
    void applyGltfCutoff(const std::vector<int>& lights, double lux);
    void applyAddMesh(const lc::Mesh& m);
    void applyRemoveLastMesh();

signals:
    void sceneReset();              // whole scene replaced
    void lightsChanged();           // lights added/removed (indices may shift)
    void lightChanged(int index);   // one light's values changed
    void cameraChanged();
    void meshesChanged();
    void sceneEdited();             // any scene edit (for Live re-runs)
    void filePathChanged(const QString& path);
    void dirtyChanged(bool dirty);

private:
    // Counts the edit, tells sceneEdited's receivers, then runWentStale's.
    void edited();

    lc::Scene scene_;
    quint64 geometryRevision_ = 1;
    QUndoStack undo_;
    QString filePath_;
    int dragCounter_ = 0;
    Selection selection_{scene_};
    ViewOptions view_;
    RunState runs_;
    mutable ExplainedSelection explained_;
};

} // namespace lcui
