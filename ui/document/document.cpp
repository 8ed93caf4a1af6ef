#include "document/document.hpp"

#include "document/commands.hpp"
#include "widgets/count_text.hpp"

#include "culling/core/file_io.hpp"
#include "culling/scene/gltf_io.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace lcui {

Document::Document(QObject* parent) : QObject(parent) {
    connect(&undo_, &QUndoStack::cleanChanged, this, [this](bool clean) { emit dirtyChanged(!clean); });
    // First receiver: the new run's receivers see no list picked from the old one.
    connect(&runs_, &RunState::generationChanging, this, [this] { selection_.forgetExplainedList(); });
}

void Document::resetScene(lc::Scene scene, const QString& path) {
    scene_ = std::move(scene);
    ++geometryRevision_;
    undo_.clear();
    undo_.setClean();
    filePath_ = path;
    // Every part reset before anyone hears of it: no receiver sees a
    // selection or run of the old scene beside the new one.
    selection_.reset();
    runs_.resetRun();
    emit sceneReset();
    emit selection_.changed();
    emit selection_.tileChanged(-1);
    emit runs_.runOutputChanged();
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
    addLights(copies, tr("Duplicate %1").arg(countOf(copies.size(), "light", "lights")));
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

void Document::edited() {
    runs_.noteSceneEdit();
    emit sceneEdited();
    runs_.afterSceneEdit();
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
    selection_.replaceLights(select ? indices : std::vector<int>{}, true);
    emit lightsChanged();
    emit selection_.changed();
    edited();
}

void Document::applyRemoveLights(const std::vector<int>& indices) {
    for (auto it = indices.rbegin(); it != indices.rend(); ++it)
        scene_.lights.erase(scene_.lights.begin() + *it);
    selection_.replaceLights({}, false);
    emit lightsChanged();
    emit selection_.changed();
    edited();
}

void Document::applyCamera(const lc::Camera& c) {
    scene_.camera = c;
    selection_.clearTile();
    emit cameraChanged();
    emit selection_.tileChanged(-1);
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
