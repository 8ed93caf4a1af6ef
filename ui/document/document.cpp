#include "document/document.hpp"

#include "document/commands.hpp"

#include "culling/core/file_io.hpp"
#include "culling/scene/gltf_io.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace lcui {

Document::Document(QObject* parent) : QObject(parent) {
    connect(&undo_, &QUndoStack::cleanChanged, this, [this](bool clean) { emit dirtyChanged(!clean); });
}

void Document::resetScene(lc::Scene scene, const QString& path) {
    scene_ = std::move(scene);
    ++geometryRevision_;
    undo_.clear();
    undo_.setClean();
    filePath_ = path;
    selectedLights_.clear();
    cameraSelected_ = false;
    selectedTile_ = -1;
    selectedCell_ = -1;
    explainedList_ = -1;
    run_.reset();
    emit sceneReset();
    emit selectionChanged();
    emit tileSelectionChanged(-1);
    emit runOutputChanged();
    emit filePathChanged(path);
    emit dirtyChanged(false);
    edited();
}

void Document::markSaved(const QString& path) {
    filePath_ = path;
    // The scene now is that file: an export records it, unedited.
    scene_.origin = {};
    scene_.origin.file = std::filesystem::absolute(path.toStdString()).lexically_normal().string();
    try {
        scene_.origin.contentHash = lc::fileHashFnv1a64(path.toStdString());
    } catch (const std::exception&) {
        // Saved but unreadable now: the record keeps the path alone.
    }
    undo_.setClean();
    emit filePathChanged(path);
    emit dirtyChanged(false);
}

void Document::setSettings(const lc::CullSettings& s) {
    settings_ = s;
    emit settingsChanged();
}

void Document::setSelectedLights(std::vector<int> lights) {
    const int n = int(scene_.lights.size());
    lights.erase(std::remove_if(lights.begin(), lights.end(), [n](int i) { return i < 0 || i >= n; }),
                 lights.end());
    // Deduplicate keeping the order: the last one is the current light.
    std::vector<int> unique;
    for (int i : lights)
        if (std::find(unique.begin(), unique.end(), i) == unique.end()) unique.push_back(i);
    lights = std::move(unique);
    if (lights == selectedLights_ && !cameraSelected_) return;
    lightSelectedLast_ = !lights.empty();
    selectedLights_ = std::move(lights);
    cameraSelected_ = false;
    emit selectionChanged();
}

void Document::selectCamera() {
    selectedLights_.clear();
    cameraSelected_ = true;
    emit selectionChanged();
}

void Document::setSelectedTile(int tile) {
    if (tile == selectedTile_) return;
    selectedTile_ = tile;
    if (tile >= 0) lightSelectedLast_ = false;
    selectedCell_ = -1;
    explainedList_ = -1;
    emit tileSelectionChanged(tile);
}

void Document::setSelectedCell(int cell) {
    if (cell == selectedCell_) return;
    selectedCell_ = cell;
    explainedList_ = -1;
    emit tileSelectionChanged(selectedTile_);
}

void Document::setOverlays(const OverlayOptions& o) {
    if (o == overlays_) return;
    overlays_ = o;
    emit overlaysChanged();
}

void Document::moveLight(int index, const glm::dvec3& position, int dragId) {
    if (index < 0 || index >= int(scene_.lights.size())) return;
    const glm::dvec3 from = scene_.lights[std::size_t(index)].position;
    if (from == position) return;
    undo_.push(new MoveLightCommand(this, index, from, position, dragId));
}

void Document::resizeLight(int index, double radius, int dragId) {
    if (index < 0 || index >= int(scene_.lights.size()) || !(radius > 0) || !std::isfinite(radius)) return;
    const double from = scene_.lights[std::size_t(index)].explicitRadius;
    if (from == radius) return;
    undo_.push(new ResizeLightCommand(this, index, from, radius, dragId));
}

void Document::setLight(int index, const lc::PointLight& light) {
    if (index < 0 || index >= int(scene_.lights.size())) return;
    undo_.push(new SetLightCommand(this, index, scene_.lights[std::size_t(index)], light));
}

void Document::addLights(const std::vector<lc::PointLight>& lights, const QString& text, bool select) {
    if (lights.empty()) return;
    std::vector<int> idx(lights.size());
    for (std::size_t i = 0; i < lights.size(); ++i) idx[i] = int(scene_.lights.size() + i);
    undo_.push(new InsertLightsCommand(this, std::move(idx), lights, text, select));
}

void Document::duplicateLights(const std::vector<int>& indices) {
    std::vector<lc::PointLight> copies;
    for (int i : indices) {
        if (i < 0 || i >= int(scene_.lights.size())) continue;
        lc::PointLight l = scene_.lights[std::size_t(i)];
        l.name += " copy";
        copies.push_back(std::move(l));
    }
    addLights(copies, tr("Duplicate %n light(s)", nullptr, int(copies.size())));
}

void Document::deleteLights(std::vector<int> indices) {
    const int n = int(scene_.lights.size());
    indices.erase(std::remove_if(indices.begin(), indices.end(), [n](int i) { return i < 0 || i >= n; }),
                  indices.end());
    std::sort(indices.begin(), indices.end());
    indices.erase(std::unique(indices.begin(), indices.end()), indices.end());
    if (indices.empty()) return;
    std::vector<lc::PointLight> removed;
    for (int i : indices) removed.push_back(scene_.lights[std::size_t(i)]);
    undo_.push(new RemoveLightsCommand(this, std::move(indices), std::move(removed)));
}

void Document::setCamera(const lc::Camera& camera, const QString& text) {
    undo_.push(new SetCameraCommand(this, scene_.camera, camera, text));
}

void Document::importMesh(lc::Mesh mesh) { undo_.push(new AddMeshCommand(this, std::move(mesh))); }

bool Document::setRunOutput(std::shared_ptr<const lc::RunOutput> run, quint64 generation) {
    if (generation < runGeneration_) return false;
    // A run nobody noted (a test's) counts as made from the scene as it is.
    runRevision_ = sceneRevision_;
    for (const auto& [g, revision] : pending_)
        if (g == generation) runRevision_ = revision;
    // A generation answers twice (lists, then truth); older ones never will.
    std::erase_if(pending_, [generation](const auto& p) { return p.first < generation; });
    if (generation != runGeneration_) explainedList_ = -1;
    run_ = std::move(run);
    runGeneration_ = generation;
    emit runOutputChanged();
    return true;
}

void Document::edited() {
    ++sceneRevision_;
    emit sceneEdited();
    // After every receiver: a Live re-run asked for by one of them is on its way.
    if (runIsStale()) emit runWentStale();
}

void Document::noteRunRequested(quint64 generation) { pending_.emplace_back(generation, sceneRevision_); }

void Document::noteRunFailed(quint64 generation) {
    std::erase_if(pending_, [generation](const auto& p) { return p.first == generation; });
    if (runIsStale()) emit runWentStale(); // the scene may now be without a run on its way
}

bool Document::runIsStale() const {
    if (!run_ || runRevision_ == sceneRevision_) return false;
    for (const auto& p : pending_)
        if (p.second == sceneRevision_) return false;
    return true;
}

int Document::setGltfCutoff(double lux) {
    const std::vector<std::size_t> cut = lc::gltfCutoffLights(scene_);
    if (cut.empty() || !(lux > 0) || lux == scene_.origin.gltfMinIntensity) return 0;
    std::vector<int> lights(cut.begin(), cut.end());
    const int n = int(lights.size());
    undo_.push(new SetGltfCutoffCommand(this, std::move(lights), scene_.origin.gltfMinIntensity, lux));
    return n;
}

void Document::applyGltfCutoff(const std::vector<int>& lights, double lux) {
    for (int i : lights) scene_.lights[std::size_t(i)].minIntensity = lux;
    scene_.origin.gltfMinIntensity = lux;
    emit lightsChanged();
    edited();
}

void Document::setExplainedList(int list) {
    if (list == explainedList_) return;
    explainedList_ = list;
    emit selectionChanged();
}

// --- applied by the commands --------------------------------------------------

void Document::applyLightPosition(int index, const glm::dvec3& p) {
    scene_.lights[std::size_t(index)].position = p;
    emit lightChanged(index);
    edited();
}

void Document::applyLightRadius(int index, double explicitRadius) {
    scene_.lights[std::size_t(index)].explicitRadius = explicitRadius;
    emit lightChanged(index);
    edited();
}

void Document::applyLight(int index, const lc::PointLight& l) {
    scene_.lights[std::size_t(index)] = l;
    emit lightChanged(index);
    edited();
}

void Document::applyInsertLights(const std::vector<int>& indices,
                                 const std::vector<lc::PointLight>& lights, bool select) {
    // Ascending final indices: inserting in order puts each light exactly there.
    for (std::size_t k = 0; k < indices.size(); ++k)
        scene_.lights.insert(scene_.lights.begin() + indices[k], lights[k]);
    selectedLights_ = select ? indices : std::vector<int>{};
    cameraSelected_ = false;
    emit lightsChanged();
    emit selectionChanged();
    edited();
}

void Document::applyRemoveLights(const std::vector<int>& indices) {
    for (auto it = indices.rbegin(); it != indices.rend(); ++it)
        scene_.lights.erase(scene_.lights.begin() + *it);
    selectedLights_.clear();
    emit lightsChanged();
    emit selectionChanged();
    edited();
}

void Document::applyCamera(const lc::Camera& c) {
    scene_.camera = c;
    selectedTile_ = -1;
    selectedCell_ = -1;
    emit cameraChanged();
    emit tileSelectionChanged(-1);
    edited();
}

void Document::applyAddMesh(const lc::Mesh& m) {
    scene_.meshes.push_back(m);
    ++geometryRevision_;
    emit meshesChanged();
    edited();
}

void Document::applyRemoveLastMesh() {
    scene_.meshes.pop_back();
    ++geometryRevision_;
    emit meshesChanged();
    edited();
}

} // namespace lcui
