#pragma once
// The scene model: triangle meshes with a transform, point and spot lights and the
// culling camera. Plain structs of flat arrays; conversions from OpenMesh (and,
// in the studio, to VTK) live in adapters at the edges.

#include <glm/glm.hpp>

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace lc {

// A triangle mesh in its own model space. `positions` are xyz triples,
// `indices` index triples; `transform` maps model to world space.
struct Mesh {
    std::string name;
    std::string sourcePath;          // as written in the scene file (relative); empty if built in
    // Absolute, normalised path of the file the mesh was loaded from; empty if
    // built in or inline. Saving writes the path relative to the new scene
    // file's folder from this, so a scene saved elsewhere still finds it.
    std::string resolvedPath;
    std::vector<float> positions;    // 3 per vertex
    std::vector<std::uint32_t> indices; // 3 per triangle
    glm::dmat4 transform{1.0};

    std::size_t vertexCount() const { return positions.size() / 3; }
    std::size_t triangleCount() const { return indices.size() / 3; }
    glm::vec3 vertex(std::size_t i) const {
        return {positions[3 * i], positions[3 * i + 1], positions[3 * i + 2]};
    }
    // Empty string when valid, else what is wrong (non-finite coordinate,
    // index out of range, index count not a multiple of 3).
    std::string validate() const;
};

enum class LightKind { Point, Spot };
const char* toString(LightKind k); // "point", "spot"

// A light: a point light, or a spot light (kind == Spot) that adds a
// direction and an outer half-angle. Both kinds share one light index space
// (light lists index Scene::lights) and the same range rule: the bounding
// sphere radius follows the inverse-square law,
// r = sqrt(max(I*c.r, I*c.g, I*c.b) / I_min), unless `explicitRadius` > 0.
// The bound PointLight::validate keeps on intensity x the brightest colour
// channel: the float shading passes sum it over lights.
constexpr double kMaxLightPower = 1e24;

// A spot light lights the spherical sector of points within that range of its
// position whose angle to `direction` is at most `outerAngleDeg`
// (docs/SPOT_LIGHTS.md). (The struct keeps its historical name.)
struct PointLight {
    std::string name;
    glm::dvec3 position{0.0};        // world space; a spot light's apex
    glm::dvec3 color{1.0};           // linear RGB, each >= 0
    double intensity = 1.0;          // >= 0
    double minIntensity = 0.01;      // I_min > 0: the cut-off that defines the radius
    double explicitRadius = 0.0;     // > 0 overrides the inverse-square radius
    LightKind kind = LightKind::Point;
    glm::dvec3 direction{0.0, -1.0, 0.0}; // spot: cone axis, world space, non-zero (normalised on use)
    double outerAngleDeg = 30.0;     // spot: half-angle of the cone, in (0, 90] degrees
    // spot: half-angle where the falloff towards the outer angle starts, in
    // [0, outer]. Kept for the shading and for glTF round trips; culling uses
    // only the outer angle.
    double innerAngleDeg = 0.0;

    bool isSpot() const { return kind == LightKind::Spot; }
    // Bounding-sphere radius in world units (a spot light's range).
    // Precondition: validate() is empty.
    double radius() const;
    // Empty when valid; otherwise names the bad field ("outer_angle_deg: ...").
    // Spot fields are checked only for spot lights.
    std::string validate() const;
};
using Light = PointLight;

enum class ProjectionKind {
    Perspective,       // [0,1] window depth, near -> 0, far -> 1
    PerspectiveGL,     // OpenGL-style [-1,1] NDC depth, stored as (ndc+1)/2
    ReversedZ,         // near -> 1, far -> 0; far may be +infinity
    Orthographic,      // [0,1] depth
    OrthographicGL,    // [-1,1] NDC depth, stored as (ndc+1)/2
};

const char* toString(ProjectionKind k);
// Throws SettingsError("projection", ...) for unknown names.
ProjectionKind projectionKindFromString(const std::string& s);
bool isOrthographic(ProjectionKind k);
bool isReversed(ProjectionKind k);

// The culling camera: where the depth pre-pass and the tile grid come from.
struct Camera {
    glm::dvec3 position{0.0, 0.0, 5.0};
    glm::dvec3 target{0.0, 0.0, 0.0};
    glm::dvec3 up{0.0, 1.0, 0.0};
    ProjectionKind projection = ProjectionKind::Perspective;
    double fovYDeg = 60.0;           // perspective: vertical field of view, (0, 180)
    double orthoHeight = 10.0;       // orthographic: vertical extent in world units
    double nearPlane = 0.1;          // > 0
    double farPlane = 1000.0;        // > near; +infinity only with ReversedZ
    std::uint32_t width = 1280;      // pixels, >= 1
    std::uint32_t height = 720;
    std::uint32_t tileSize = 16;     // pixels, >= 1

    glm::dmat4 viewFromWorld() const;
    double aspect() const { return double(width) / double(height); }
    bool operator==(const Camera&) const = default;
    // Empty when valid; otherwise names the bad field ("camera.near: ...").
    std::string validate() const;
};

// Where a scene came from, for the record an export keeps (summary.json's
// scene_source): not part of the scene, never saved with it.
struct SceneOrigin {
    std::string file;        // absolute path of the scene file read; empty for a built-in or a new scene
    std::string contentHash; // fileHashFnv1a64 of that file (a .gltf's own text, not its .bin files)
    std::string builtin;     // the built-in scene's name
    std::string gltfCamera;  // glTF: which camera was used, or how the scene was framed
    double gltfMinIntensity = 0; // glTF: the I_min that set the radii of lights without `range`
    std::string command;     // the CLI command line that made the run, when it came from the CLI
    bool edited = false;     // changed since it was read (the studio's unsaved edits)
    // A glTF another tool wrote: this tool's writer keeps geometry, lights and
    // cameras only, so saving over it would lose its materials, textures and
    // animations (the studio saves such a scene under a new name).
    bool foreignGltf = false;
};

struct Scene {
    std::string name;
    std::vector<Mesh> meshes;
    std::vector<PointLight> lights;
    Camera camera;
    SceneOrigin origin;

    std::size_t triangleCount() const;
    // Whether any light is a spot light (spot parameters decide nothing otherwise).
    bool hasSpotLights() const;
    // Throws LightError for the first bad light, SettingsError for a bad
    // camera, InputError for a bad mesh.
    void validate() const;
    // World-space bounds of all meshes (min, max); (0,0) when there are none.
    std::pair<glm::dvec3, glm::dvec3> bounds() const;
};

} // namespace lc
