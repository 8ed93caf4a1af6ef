#pragma once
// The studio's central document: the scene being edited, the selection, the
// file it came from, the culling settings and the latest finished culling run.
// Panels and views observe it through signals; every edit of the scene goes
// through its QUndoStack (the public edit functions below push commands).

#include "culling/diagnostics/overlays.hpp"
#include "culling/core/params.hpp"
#include "culling/core/pipeline.hpp"
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
    // stack, the selection and the last result. Not undoable by design (the
    // unsaved-changes prompt guards it).
    void resetScene(lc::Scene scene, const QString& path);
    // Marks the current state as saved under `path`.
    void markSaved(const QString& path);

    // --- culling settings (not part of the scene, not undoable) --------------
    const lc::CullSettings& settings() const { return settings_; }
    void setSettings(const lc::CullSettings& s);

    // --- selection ----------------------------------------------------------
    // Selected light indices in selection order; currentLight(): the last one
    // (what the property panel and the drag handle act on), or -1.
    const std::vector<int>& selectedLights() const { return selectedLights_; }
    int currentLight() const { return selectedLights_.empty() ? -1 : selectedLights_.back(); }
    void setSelectedLights(std::vector<int> lights);
    bool cameraSelected() const { return cameraSelected_; }
    void selectCamera();
    // Tile of the culling grid selected in the camera view (-1: none).
    int selectedTile() const { return selectedTile_; }
    void setSelectedTile(int tile);
    // Whether the current light was picked after the selected tile (Frame
    // selected then frames the light, unless the tile lists it).
    bool lightSelectedLast() const { return lightSelectedLast_; }

    // Depth cell of the selected tile (tileCells order, -1: the whole tile).
    // Emits tileSelectionChanged; selecting another tile clears it.
    int selectedCell() const { return selectedCell_; }
    void setSelectedCell(int cell);

    // --- inspection overlays (view state: not part of the scene, not undoable)
    struct OverlayOptions {
        bool tileFrustum = true;      // the selected tile's frustum, translucent + outline
        bool allTileFrustums = false; // every tile's frustum, one wireframe by list length
        bool cells = true;            // 2.5d cells, halfz split, clustered froxels
        bool lightCellRange = true;   // cells the current light's sphere spans
        bool listHighlight = true;    // listed lights highlighted, others dimmed, missing red
        bool reverseLookup = true;    // tiles whose lists hold the current light
        bool explainMarkers = true;   // Explain in 3D: the deciding plane, the nearest or needing pixel
        lc::HeatMode heat = lc::HeatMode::ListLength;
        // The inspector inside a building (View > Meshes, View > Lights; docs/STUDIO.md):
        // meshes drawn as they are, translucent without depth writes (x-ray:
        // they hide and block nothing), or not at all.
        enum class MeshDisplay { Normal, XRay, Hidden };
        MeshDisplay meshes = MeshDisplay::Normal;
        // Lights: filled spheres up to sphereCap and silhouette rings above it
        // (Auto), spheres only (at most sphereCap, "+N more" for the rest), or
        // rings only. showLights hides them and the spot cones together;
        // onlyTileLights draws only the selected tile's (cell's) listed lights.
        enum class LightDisplay { Auto, Spheres, Outlines };
        LightDisplay lights = LightDisplay::Auto;
        bool showLights = true;
        bool onlyTileLights = false;
        int sphereCap = 256;
        bool operator==(const OverlayOptions&) const = default;
    };
    const OverlayOptions& overlays() const { return overlays_; }
    void setOverlays(const OverlayOptions& o);

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

    // --- latest culling run ----------------------------------------------------
    // The newest finished run, or null. `generation` is the request number the
    // worker answered; older generations than the one shown are dropped.
    std::shared_ptr<const lc::RunOutput> runOutput() const { return run_; }
    quint64 runGeneration() const { return runGeneration_; }
    // Returns false (and ignores it) when `generation` is older than the shown one.
    bool setRunOutput(std::shared_ptr<const lc::RunOutput> run, quint64 generation);
    // A run asked for the scene as it is now (its result, when it comes,
    // belongs to this scene), or that run failed.
    void noteRunRequested(quint64 generation);
    void noteRunFailed(quint64 generation);
    // The shown run was made from an earlier scene (an edit since), and no run
    // of the scene as it is now is on its way: its lists, truth and light
    // indices no longer describe the scene, so what reads them per light (the
    // tile inspector, Explain, the export) must not. A Live edit's run is on
    // its way at once, so Live does not go stale.
    bool runIsStale() const;

    // The list the user picked for Explain (a tile inspector row: halfz and
    // clustered tiles have several), or -1: the panel then takes the tile's
    // first list that holds or needs the current light. Cleared with the tile
    // or cell selection and by a new run.
    int explainedList() const { return explainedList_; }
    void setExplainedList(int list);

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
    void selectionChanged();
    void tileSelectionChanged(int tile); // also when the selected cell changes
    void overlaysChanged();
    void settingsChanged();
    void sceneEdited();             // any scene edit (for Live re-runs)
    // The shown run became stale (runIsStale): after an edit's receivers
    // have all run, or when the run asked for the scene as it is failed.
    void runWentStale();
    void runOutputChanged();
    void filePathChanged(const QString& path);
    void dirtyChanged(bool dirty);

private:
    // Counts the edit, tells sceneEdited's receivers, then runWentStale's.
    void edited();

    lc::Scene scene_;
    quint64 geometryRevision_ = 1;
    lc::CullSettings settings_;
    QUndoStack undo_;
    QString filePath_;
    std::vector<int> selectedLights_;
    bool cameraSelected_ = false;
    int selectedTile_ = -1;
    bool lightSelectedLast_ = false;
    int selectedCell_ = -1;
    OverlayOptions overlays_;
    int dragCounter_ = 0;
    std::shared_ptr<const lc::RunOutput> run_;
    quint64 runGeneration_ = 0;
    // Scene edits counted (edited()), the count the shown run was
    // asked for, and the runs asked for and not yet answered.
    quint64 sceneRevision_ = 0, runRevision_ = 0;
    std::vector<std::pair<quint64, quint64>> pending_; // generation, scene revision
    int explainedList_ = -1;
};

} // namespace lcui
