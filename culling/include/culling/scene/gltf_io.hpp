#pragma once
// glTF 2.0 scenes in and out (docs/FORMATS.md, "glTF 2.0"): geometry of every
// triangle primitive, KHR_lights_punctual point and spot lights, and cameras.
// The parsing is Debian's tinygltf (image decoding left out: culling never
// needs texels); everything tinygltf accepts is checked again here, so bad
// input is an InputError naming the file and the JSON path, never a crash,
// and nothing is allocated beyond what the file's own bytes justify (apart
// from instancing, which is capped at kGltfMaxTriangles).

#include "culling/core/depth.hpp"
#include "culling/scene/scene.hpp"
#include "culling/scene/scene_io.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace lc {

// I_min (lux: candela over metres squared) that gives a light without `range`
// its inverse-square culling radius, r = sqrt(max(I*c) / I_min). The same
// default as a light in our scene JSON, so a light means the same in both.
constexpr double kGltfDefaultMinIntensity = 0.01;
// Instanced triangles a glTF scene may expand to (a small file can place one
// large mesh many times); past this the load is refused before allocating.
constexpr std::uint64_t kGltfMaxTriangles = std::uint64_t(1) << 25;

struct GltfReadOptions {
    double minIntensity = kGltfDefaultMinIntensity; // > 0, finite
    // The culling camera: a camera or camera-node name, or an index into the
    // file's `cameras`. Empty: the first camera in the scene's node order.
    std::string camera;
};

struct GltfReadReport {
    std::vector<std::string> warnings;       // one line each: what was skipped and why
    std::size_t degenerateTrianglesDropped = 0;
    std::string camera;                      // "cameras[2] 'Main' on nodes[7]", or how it was framed
    std::string generator;                   // the file's asset.generator ("LightCull Studio" for ours)
};

// True for names ending in .gltf or .glb (any case).
bool isGltfPath(const std::string& path);

// Loads the default scene of a .gltf (external .bin files and data: URIs) or
// .glb. All geometry becomes one mesh in world space named after the file
// (its sourcePath is the file, so a scene JSON saved from it refers to it);
// lights and the camera as described in docs/FORMATS.md. Throws InputError
// naming the file and the JSON path.
Scene loadGltfScene(const std::string& path, const GltfReadOptions& options = {}, GltfReadReport* report = nullptr,
                    const CancelToken* cancel = nullptr, const Progress& progress = {});
// The same geometry as loadGltfScene, without lights or camera (loadMesh uses
// it for .gltf and .glb).
Mesh loadGltfMesh(const std::string& path, GltfReadReport* report = nullptr, const CancelToken* cancel = nullptr,
                  const Progress& progress = {});

// A scene as glTF 2.0: each mesh with its transform, the lights as
// KHR_lights_punctual with `range` set to their culling radius, the culling
// camera as a camera node; what glTF cannot say (the projection's depth
// convention, the resolution and tile size, a light's I_min) goes in
// `extras.lightcull`, so loadGltfScene gives the same scene back.
// `binary`: GLB bytes, else .gltf JSON with the buffer as a data: URI.
std::string serializeGltf(const Scene& scene, bool binary);
// Atomic save; .glb or .gltf by the extension of `path`.
void saveGltfScene(const Scene& scene, const std::string& path);

// Any scene file: .gltf/.glb through loadGltfScene, everything else as scene JSON.
// The lights of a glTF scene that take their radius from the cut-off (no
// `range`: explicitRadius 0 and I_min the scene was read with,
// SceneOrigin::gltfMinIntensity), by index. Empty for other scenes.
std::vector<std::size_t> gltfCutoffLights(const Scene& scene);
// A warning when cut-off radii reach farther than the scene is wide (such a
// light lands in every list around it, and the heat map turns uniform): how
// many, the largest radius, the scene's size and what to do. Empty otherwise.
std::string cutoffCoverageWarning(const Scene& scene);

Scene loadSceneAny(const std::string& path, const GltfReadOptions& options = {}, GltfReadReport* report = nullptr,
                   const CancelToken* cancel = nullptr, const Progress& progress = {});
// Saves by extension: .gltf/.glb as glTF, anything else as scene JSON.
void saveSceneAny(const Scene& scene, const std::string& path);

// A camera (resolution, tile size and projection kept from `base`) that looks
// at the world-space box [lo, hi] from above and in front, so that the box's
// bounding sphere fits the view, with near and far planes around it.
Camera frameBounds(const glm::dvec3& lo, const glm::dvec3& hi, const Camera& base);

} // namespace lc
