#pragma once
// Scene files, mesh loading, built-in scenes and the light generator.

#include "culling/core/depth.hpp"
#include "culling/scene/scene.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace lc {

// Progress callback: fraction done in [0,1]. May be empty.
using Progress = std::function<void(double)>;

struct MeshLoadReport {
    std::size_t degenerateFacesDropped = 0; // zero-area or repeated-index faces
    std::size_t polygonsTriangulated = 0;
    std::string warning;                    // non-empty when something was dropped
};

// Loads OBJ, PLY and OFF with the project's own readers, STL and OM through
// OpenMesh; polygons are triangulated, degenerate faces dropped and counted. Throws InputError naming the file for
// unreadable, empty or invalid (NaN/Inf coordinates, bad indices) input.
Mesh loadMesh(const std::string& path, MeshLoadReport* report = nullptr,
              const CancelToken* cancel = nullptr, const Progress& progress = {});

// The scene format version this build writes and reads.
constexpr int kSceneFormatVersion = 1;

// Reads a scene JSON file; meshes are loaded relative to the file's folder.
// Errors are InputError naming the file, the field path and its line. What
// loading a mesh file warns about (degenerate faces dropped) goes into
// `warnings`, one line each, where given.
Scene loadSceneFile(const std::string& path, const CancelToken* cancel = nullptr,
                    const Progress& progress = {}, std::vector<std::string>* warnings = nullptr);
// Parses scene JSON text; `path` is used for messages and relative mesh paths.
Scene parseScene(const std::string& json, const std::string& path);
// Serialises a scene. Lossless: parseScene(serializeScene(s)) == s in every
// field (doubles written with round-trip precision; meshes by their sourcePath,
// built-in meshes inline). With `baseDir` set, a mesh loaded from a file is
// written by its path relative to `baseDir` (absolute when no relative path
// exists), so the scene can be saved into any folder.
std::string serializeScene(const Scene& scene, const std::string& baseDir = {});
// Atomic save: writes a temporary file beside `path`, then renames it. Mesh
// paths are written relative to the folder of `path`.
void saveSceneFile(const Scene& scene, const std::string& path);

// Built-in procedural scenes (no files needed).
struct BuiltinInfo {
    std::string name, description;
};
const std::vector<BuiltinInfo>& builtinScenes();
// Throws SettingsError("builtin", ...) listing the valid names.
Scene makeBuiltinScene(const std::string& name);
constexpr const char* kDefaultBuiltin = "atrium";

// Deterministic light generator: the same settings give the same lights on
// every machine (own PRNG, no std distributions).
struct LightGenSettings {
    std::uint32_t count = 256;
    std::uint64_t seed = 1;
    glm::dvec3 boxMin{-10, 0, -10}, boxMax{10, 5, 10}; // placement volume, world space
    double intensityMin = 1, intensityMax = 10;
    double minIntensity = 0.05;                         // I_min of every light
    glm::dvec3 colorMin{0.2}, colorMax{1.0};            // per channel
    // Spot lights: each light is a spot with probability spotFraction (0: all
    // point lights, drawn exactly as before spots existed); a spot gets a
    // direction uniform on the sphere and an outer angle uniform in degrees.
    double spotFraction = 0.0;                          // [0, 1]
    double spotAngleMinDeg = 15, spotAngleMaxDeg = 45;  // within (0, 90]
};
// Deterministic in `s` (seed included). `progress` is told how far it got
// every few thousand lights; a set `cancel` stops it with lc::Cancelled.
// Throws SettingsError naming the field ("lights.intensity: ...") for
// settings generateLights refuses.
void checkLightGen(const LightGenSettings& s);
std::vector<PointLight> generateLights(const LightGenSettings& s, const CancelToken* cancel = nullptr,
                                       const Progress& progress = {});
// Settings suited to a scene: placed in its mesh bounds, slightly grown, with
// I_min chosen so that the brightest light's radius is between
// kLightRadiusMinFraction and kLightRadiusMaxFraction of that box's diagonal
// (unchanged, 14.1 units, where it already is; docs/FORMATS.md).
constexpr double kLightRadiusMinFraction = 0.01, kLightRadiusMaxFraction = 0.2;
LightGenSettings defaultLightGen(const Scene& scene, std::uint32_t count, std::uint64_t seed);

} // namespace lc
