#pragma once
// The hard cases of issue 7: each a named generator of a scene (and the
// settings it needs) that breaks naive culling implementations. The test
// (test_hardcases.cpp) runs every case through every algorithm on both
// backends. docs/TESTING.md lists the cases; tests/hardcase/cases.txt holds
// their names for CTest registration and a test keeps the two in step.
//
// Scenes are small on purpose (tens of pixels to a few hundred) so the whole
// tier stays fast; the cases that need a size (1366x768) or a real asset
// (maize, buildings) say so.
#include "culling/core/backend.hpp"
#include "culling/core/depth.hpp"
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/math/projection.hpp"
#include "culling/scene/scene_io.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <vector>

namespace lc::hardcase {

struct HardCase {
    std::string name;      // [a-z0-9_]: part of the gtest and CTest names
    std::string exercises; // one line, for docs/TESTING.md
    std::function<Scene()> make;
    SphereTest test = SphereTest::Planes;
    std::uint32_t cells = 16;
    Slicing slicing = Slicing::Log;
    // Invalid input: the exact what() of the error runPipeline must throw
    // (and the light index for a LightError). Empty: a valid case.
    std::string expectedError;
    std::size_t expectedLightIndex = 0;
    // Checks that the case really is the hard case it claims to be (for
    // example: every tile's min equals its max). Empty string: it is.
    std::function<std::string(const RunOutput&)> selfCheck;
};

// ---------------------------------------------------------------- builders

inline constexpr double kInf = std::numeric_limits<double>::infinity();

inline void addQuad(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
    const auto base = std::uint32_t(m.positions.size() / 3);
    for (const glm::dvec3& p : {a, b, c, d}) {
        m.positions.push_back(float(p.x));
        m.positions.push_back(float(p.y));
        m.positions.push_back(float(p.z));
    }
    for (std::uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
}

inline void addTriangle(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const auto base = std::uint32_t(m.positions.size() / 3);
    for (const glm::dvec3& p : {a, b, c}) {
        m.positions.push_back(float(p.x));
        m.positions.push_back(float(p.y));
        m.positions.push_back(float(p.z));
    }
    for (std::uint32_t i : {0u, 1u, 2u}) m.indices.push_back(base + i);
}

// Axis-aligned box, all six faces.
inline void addBox(Mesh& m, glm::dvec3 lo, glm::dvec3 hi) {
    const glm::dvec3 v[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                             {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    addQuad(m, v[0], v[1], v[2], v[3]);
    addQuad(m, v[4], v[5], v[6], v[7]);
    addQuad(m, v[0], v[1], v[5], v[4]);
    addQuad(m, v[3], v[2], v[6], v[7]);
    addQuad(m, v[0], v[3], v[7], v[4]);
    addQuad(m, v[1], v[2], v[6], v[5]);
}

inline PointLight light(const std::string& name, glm::dvec3 pos, double radius) {
    PointLight l;
    l.name = name;
    l.position = pos;
    l.explicitRadius = radius;
    return l;
}

// Deterministic lights in a box (the library's own generator: same on every machine).
inline std::vector<PointLight> lightsIn(glm::dvec3 lo, glm::dvec3 hi, std::uint32_t n, std::uint64_t seed,
                                        double iMin = 1, double iMax = 10, double minIntensity = 0.05) {
    LightGenSettings g;
    g.count = n;
    g.seed = seed;
    g.boxMin = lo;
    g.boxMax = hi;
    g.intensityMin = iMin;
    g.intensityMax = iMax;
    g.minIntensity = minIntensity;
    return generateLights(g);
}

inline Camera camera(glm::dvec3 pos, glm::dvec3 target, std::uint32_t w, std::uint32_t h, std::uint32_t tile = 16) {
    Camera c;
    c.position = pos;
    c.target = target;
    c.width = w;
    c.height = h;
    c.tileSize = tile;
    return c;
}

// A small "room": floor, back wall, a few boxes at different depths, so tiles
// hold depth discontinuities. Spans x in [-10, 10], z in [-30, 2], y in [0, 8].
inline Scene room(std::uint32_t w = 96, std::uint32_t h = 64, std::uint32_t tile = 16) {
    Scene s;
    s.name = "room";
    Mesh m;
    m.name = "room";
    addQuad(m, {-10, 0, 2}, {10, 0, 2}, {10, 0, -30}, {-10, 0, -30});   // floor
    addQuad(m, {-10, 0, -30}, {10, 0, -30}, {10, 8, -30}, {-10, 8, -30}); // back wall
    addBox(m, {-6, 0, -8}, {-4, 3, -6});
    addBox(m, {2, 0, -14}, {5, 5, -11});
    addBox(m, {-2, 0, -22}, {1, 6, -20});
    addBox(m, {6, 0, -4}, {7, 1.5, -3});
    s.meshes.push_back(std::move(m));
    s.camera = camera({0, 3, 8}, {0, 2.5, -20}, w, h, tile);
    s.camera.nearPlane = 0.1;
    s.camera.farPlane = 100;
    s.lights = lightsIn({-9, 0.2, -29}, {9, 7.5, 1}, 96, 7);
    return s;
}

// A camera's view direction and its right/up vectors (world space).
inline glm::dvec3 worldFromViewPoint(const Camera& c, const glm::dvec3& pView) {
    return glm::dvec3(glm::inverse(c.viewFromWorld()) * glm::dvec4(pView, 1.0));
}

inline std::string checkAllTilesMinEqualsMax(const RunOutput& run) {
    std::size_t filled = 0;
    for (std::size_t t = 0; t < run.result.tileDepthMin.size(); ++t) {
        const double lo = run.result.tileDepthMin[t], hi = run.result.tileDepthMax[t];
        if (!(lo <= hi)) return "tile " + std::to_string(t) + " is empty";
        if (lo != hi) return "tile " + std::to_string(t) + " has min != max";
        ++filled;
    }
    return filled ? "" : "no tiles";
}

inline std::string checkSomeEmptyTiles(const RunOutput& run) {
    std::size_t empty = 0, filled = 0;
    for (std::size_t t = 0; t < run.result.tileDepthMin.size(); ++t)
        (run.result.tileDepthMin[t] <= run.result.tileDepthMax[t] ? filled : empty) += 1;
    if (!empty || !filled) return "expected both empty and filled tiles";
    return "";
}

inline std::string checkHasGeometry(const RunOutput& run) {
    return run.depth.geometryPixelCount() ? "" : "no geometry pixel";
}

// The scene's far plane spans `ratio` times its near plane; geometry from just
// beyond the near plane to just before the far plane.
inline Scene farNearRatio(double nearPlane, double ratio) {
    const double farPlane = nearPlane * ratio;
    Scene s;
    s.name = "far_near";
    Mesh m;
    m.name = "depth_ladder";
    // Panels at depths spread logarithmically over [2 near, 0.9 far], each
    // wider than the view at its depth fraction, stacked left to right.
    const int kPanels = 8;
    for (int i = 0; i < kPanels; ++i) {
        const double t = double(i) / (kPanels - 1);
        const double d = 2 * nearPlane * std::pow(0.45 * ratio, t);
        const double half = d * 0.6; // fov 60: half-height at d is 0.577 d
        const double x0 = -half + 2 * half * i / kPanels, x1 = -half + 2 * half * (i + 1) / kPanels;
        addQuad(m, {x0, -half, -d}, {x1, -half, -d}, {x1, half, -d}, {x0, half, -d});
    }
    s.meshes.push_back(std::move(m));
    s.camera = camera({0, 0, 0}, {0, 0, -1}, 96, 64);
    s.camera.nearPlane = nearPlane;
    s.camera.farPlane = farPlane;
    // Lights at every scale: each near one of the panels, radius a fraction of its depth.
    for (int i = 0; i < 48; ++i) {
        const double t = double(i % 8) / 7;
        const double d = 2 * nearPlane * std::pow(0.45 * ratio, t);
        const double ang = 0.37 * i;
        s.lights.push_back(light("l" + std::to_string(i), {0.3 * d * std::cos(ang), 0.2 * d * std::sin(ang), -d * 0.98},
                                 d * (0.05 + 0.02 * (i % 5))));
    }
    return s;
}

inline Scene projectionKind(ProjectionKind k, double farPlane) {
    Scene s = room();
    s.camera.projection = k;
    s.camera.farPlane = farPlane;
    if (isOrthographic(k)) s.camera.orthoHeight = 14.0;
    return s;
}

inline Mesh loadAsset(const std::string& relative) {
    return loadMesh(std::string(LC_ASSETS_DIR) + "/" + relative);
}

// Frames a mesh: camera at `dir` from its bounds' centre, far enough to see it all.
inline void frame(Scene& s, glm::dvec3 dir, double distanceScale) {
    const auto [lo, hi] = s.bounds();
    const glm::dvec3 centre = 0.5 * (lo + hi);
    const double size = glm::length(hi - lo);
    s.camera.target = centre;
    s.camera.position = centre + glm::normalize(dir) * size * distanceScale;
    s.camera.nearPlane = size * 1e-3;
    s.camera.farPlane = size * 10;
}

// ---------------------------------------------------------------- the cases

inline const std::vector<HardCase>& hardCases() {
    static const std::vector<HardCase> cases = [] {
        std::vector<HardCase> v;
        auto add = [&](HardCase c) { v.push_back(std::move(c)); };

        add({"far_near_1e6", "perspective far/near = 1e6 (near 1e-2, far 1e4): float depth precision at the far end",
             [] { return farNearRatio(1e-2, 1e6); }, SphereTest::Exact, 32, Slicing::Log, "", 0, checkHasGeometry});
        add({"far_near_1e9", "perspective far/near = 1e9 (near 1e-3, far 1e6): window depth of far panels within a few ulps of 1",
             [] { return farNearRatio(1e-3, 1e9); }, SphereTest::PlanesAabb, 32, Slicing::Log, "", 0, checkHasGeometry});
        add({"reversed_z_infinite_far", "reversed-Z with an infinite far plane: naive/clustered use the farthest light reach",
             [] { return projectionKind(ProjectionKind::ReversedZ, kInf); }, SphereTest::Exact, 16, Slicing::Log, "", 0,
             checkHasGeometry});
        add({"perspective_gl_depth", "OpenGL-style [-1,1] NDC depth stored as (ndc+1)/2",
             [] { return projectionKind(ProjectionKind::PerspectiveGL, 100); }, SphereTest::Planes, 16, Slicing::Linear,
             "", 0, checkHasGeometry});
        add({"orthographic_01", "orthographic projection, [0,1] depth: parallel side planes",
             [] { return projectionKind(ProjectionKind::Orthographic, 100); }, SphereTest::PlanesAabb, 16, Slicing::Log, "",
             0, checkHasGeometry});
        add({"orthographic_gl", "orthographic projection, [-1,1] NDC depth",
             [] { return projectionKind(ProjectionKind::OrthographicGL, 100); }, SphereTest::Exact, 8, Slicing::Linear, "",
             0, checkHasGeometry});
        add({"camera_inside_light", "the eye lies inside a light's sphere: its projection covers the whole screen",
             [] {
                 Scene s = room();
                 s.lights.push_back(light("around_eye", s.camera.position, 6.0));
                 s.lights.push_back(light("eye_exact", s.camera.position + glm::dvec3(0, 0, -0.05), 0.5));
                 return s;
             },
             SphereTest::Exact});
        add({"light_straddling_near", "lights whose spheres cross the near plane (centre in front, behind, on it)",
             [] {
                 Scene s = room();
                 const Camera& c = s.camera;
                 for (double z : {-c.nearPlane, -0.5 * c.nearPlane, -2 * c.nearPlane, 0.0})
                     for (double x : {-0.3, 0.0, 0.4})
                         s.lights.push_back(light("near_" + std::to_string(s.lights.size()),
                                                  worldFromViewPoint(c, {x, 0.1, z}), 0.35));
                 return s;
             },
             SphereTest::PlanesAabb});
        add({"light_behind_camera", "lights centred behind the eye: some reach in front of it, some do not",
             [] {
                 Scene s = room();
                 const Camera& c = s.camera;
                 s.lights.push_back(light("behind_reaching", worldFromViewPoint(c, {0, 0, 2.0}), 5.0));
                 s.lights.push_back(light("behind_short", worldFromViewPoint(c, {1, 0, 3.0}), 2.0));
                 s.lights.push_back(light("behind_side", worldFromViewPoint(c, {4, -2, 1.0}), 6.0));
                 s.lights.push_back(light("behind_far", worldFromViewPoint(c, {0, 0, 50.0}), 60.0));
                 return s;
             },
             SphereTest::Exact});
        add({"lights_on_far_plane", "a wall just before the far plane, lights centred on the far plane",
             [] {
                 Scene s;
                 Mesh m;
                 m.name = "far_wall";
                 addQuad(m, {-80, -50, -99.5}, {80, -50, -99.5}, {80, 50, -99.5}, {-80, 50, -99.5});
                 s.meshes.push_back(std::move(m));
                 s.camera = camera({0, 0, 0}, {0, 0, -1}, 96, 64);
                 s.camera.farPlane = 100;
                 for (int i = 0; i < 24; ++i)
                     s.lights.push_back(light("far_" + std::to_string(i), {-60 + 5.0 * i, 20 - 2.0 * i, -100}, 0.5 + 0.25 * (i % 4)));
                 return s;
             },
             SphereTest::Exact, 32, Slicing::Linear, "", 0, checkHasGeometry});
        add({"radius_zero", "lights whose radius is 0 (black colour): they can never be needed",
             [] {
                 Scene s = room();
                 for (int i = 0; i < 8; ++i) {
                     PointLight l;
                     l.name = "black_" + std::to_string(i);
                     l.position = {-6 + 1.5 * i, 1.0, -7.0};
                     l.color = glm::dvec3(0.0);
                     l.intensity = 5;
                     s.lights.push_back(l);
                 }
                 // Exactly on the surface of a box face, radius 0.
                 PointLight on;
                 on.name = "black_on_surface";
                 on.position = {-5, 1.5, -6};
                 on.color = glm::dvec3(0.0);
                 s.lights.push_back(on);
                 return s;
             },
             SphereTest::Exact});
        add({"radius_1e6", "lights of radius 1e6 around a small scene: every tile holds every such light",
             [] {
                 Scene s = room();
                 s.lights.push_back(light("huge_inside", {0, 2, -10}, 1e6));
                 s.lights.push_back(light("huge_offset", {5e5, 3e5, -2e5}, 1e6));
                 s.lights.push_back(light("huge_behind", {0, 0, 9e5}, 1e6));
                 return s;
             },
             SphereTest::PlanesAabb});
        add({"tiny_min_intensity", "I_min of 1e-12 and 1e-300: radii 1e6 and ~1e150 (beyond float range on the GPU)",
             [] {
                 Scene s = room();
                 PointLight a;
                 a.name = "imin_1e-12";
                 a.position = {1, 2, -5};
                 a.intensity = 1;
                 a.minIntensity = 1e-12;
                 PointLight b = a;
                 b.name = "imin_1e-300";
                 b.position = {-2, 1, -15};
                 b.minIntensity = 1e-300;
                 s.lights.push_back(a);
                 s.lights.push_back(b);
                 return s;
             },
             SphereTest::Exact});
        add({"zero_intensity", "lights of intensity 0 (radius 0) among ordinary ones",
             [] {
                 Scene s = room();
                 for (std::size_t i = 0; i < s.lights.size(); i += 3) s.lights[i].intensity = 0;
                 return s;
             },
             SphereTest::Planes});
        add({"wall_min_equals_max", "a wall perpendicular to the view axis: every tile has min == max (zero-depth chunks)",
             [] {
                 Scene s = makeBuiltinScene("wall");
                 s.camera.width = 80;
                 s.camera.height = 48;
                 return s;
             },
             SphereTest::Exact, 32, Slicing::Log, "", 0, checkAllTilesMinEqualsMax});
        add({"empty_tiles_and_one_pixel", "one tile whose only geometry is a single pixel, every other tile empty",
             [] {
                 Scene s;
                 s.camera = camera({0, 0, 10}, {0, 0, 0}, 64, 64);
                 s.camera.projection = ProjectionKind::Orthographic;
                 s.camera.orthoHeight = 64; // one world unit per pixel
                 // Pixel (20, 37) has its centre at x = 20.5 - 32, y = 32 - 37.5.
                 Mesh m;
                 m.name = "speck";
                 const double cx = -11.5, cy = -5.5;
                 addTriangle(m, {cx - 0.3, cy - 0.3, 0}, {cx + 0.3, cy - 0.3, 0}, {cx, cy + 0.3, 0});
                 s.meshes.push_back(std::move(m));
                 s.lights.push_back(light("on_speck", {cx, cy, 0.2}, 0.5));
                 s.lights.push_back(light("near_speck", {cx + 3, cy, 0}, 2.9));
                 s.lights.push_back(light("big", {0, 0, 0}, 20));
                 s.lights.push_back(light("in_empty", {20, 20, 0}, 5));
                 return s;
             },
             SphereTest::Exact, 16, Slicing::Log, "", 0,
             [](const RunOutput& run) -> std::string {
                 if (run.depth.geometryPixelCount() != 1)
                     return "expected exactly one geometry pixel, got " + std::to_string(run.depth.geometryPixelCount());
                 if (!run.depth.hasGeometry(20, 37)) return "the geometry pixel is not (20, 37)";
                 return checkSomeEmptyTiles(run);
             }});
        add({"resolution_1x1", "a 1x1 framebuffer: one partial tile, one pixel",
             [] { return room(1, 1); }, SphereTest::Exact, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"resolution_17x9", "17x9 pixels: partial tiles in both directions",
             [] { return room(17, 9, 8); }, SphereTest::PlanesAabb, 16, Slicing::Linear, "", 0, checkHasGeometry});
        add({"resolution_1366x768", "1366x768: 85 full tiles and a 6-pixel column, 48 rows",
             [] {
                 Scene s = room(1366, 768);
                 s.lights.resize(24);
                 return s;
             },
             SphereTest::Planes, 8, Slicing::Log, "", 0, checkHasGeometry});
        add({"tile_8", "8-pixel tiles", [] { return room(96, 64, 8); }, SphereTest::Exact, 16});
        add({"tile_32", "32-pixel tiles (partial bottom row)", [] { return room(96, 80, 32); }, SphereTest::PlanesAabb, 32});
        add({"tile_64", "64-pixel tiles larger than the 50-pixel-high image", [] { return room(100, 50, 64); },
             SphereTest::Planes, 4});
        add({"fov_0_5", "vertical FOV of 0.5 degrees: nearly parallel tile planes",
             [] {
                 Scene s = room();
                 s.camera.fovYDeg = 0.5;
                 s.camera.position = {0, 3, 200};
                 s.camera.target = {1, 2.5, -10};
                 s.camera.farPlane = 500;
                 s.lights.push_back(light("centre", {1, 2.5, -10}, 0.3));
                 return s;
             },
             SphereTest::Exact, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"fov_170", "vertical FOV of 170 degrees: extreme plane slopes at the edges",
             [] {
                 Scene s = room();
                 s.camera.fovYDeg = 170;
                 s.camera.position = {0, 4, -10};
                 s.camera.target = {0, 3.9, -20};
                 return s;
             },
             SphereTest::PlanesAabb, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"grazing_floor", "a huge floor seen at a grazing angle: tiles spanning a vast depth range",
             [] {
                 Scene s;
                 Mesh m;
                 m.name = "floor";
                 addQuad(m, {-5000, 0, 100}, {5000, 0, 100}, {5000, 0, -5000}, {-5000, 0, -5000});
                 s.meshes.push_back(std::move(m));
                 s.camera = camera({0, 0.05, 0}, {0, 0.04, -100}, 96, 64);
                 s.camera.farPlane = 6000;
                 s.lights = lightsIn({-200, 0, -3000}, {200, 1, -1}, 128, 3, 1, 10, 0.05);
                 for (int i = 0; i < 8; ++i)
                     s.lights.push_back(light("on_floor_" + std::to_string(i), {0.0, 0.0, -std::pow(4.0, i)}, 0.01 * std::pow(4.0, i)));
                 return s;
             },
             SphereTest::Exact, 32, Slicing::Log, "", 0, checkSomeEmptyTiles});
        add({"lights_touching_bounds", "a wall whose stored depth is exact in float (orthographic, 0.5): lights exactly touching a tile side plane or its near/far depth bound",
             [] {
                 Scene s = makeBuiltinScene("wall");
                 s.camera.width = 96;
                 s.camera.height = 64;
                 // Orthographic with near 2, far 18: the wall's window depth
                 // (10 - 2) / 16 = 0.5 is exact in float, so both rasterisers
                 // store the same depth and the tiles' bounds are exactly 10
                 // on both backends (with a perspective camera the two round
                 // the stored depth differently, by ~6e-5 in view depth).
                 s.camera.projection = ProjectionKind::Orthographic;
                 s.camera.orthoHeight = 12;
                 s.camera.nearPlane = 2;
                 s.camera.farPlane = 18;
                 s.lights.clear();
                 const Projection proj(s.camera);
                 const TileGrid grid = TileGrid::make(96, 64, 16);
                 // The tiles' real bounds from the rasterised wall.
                 const DepthImage depth = rasterizeDepthCpu(s, proj);
                 CullSettings mm;
                 mm.algorithm = Algorithm::MinMax;
                 const CullResult bounds = makeCpuBackend()->cull(depth, proj, grid, ViewLights{}, mm);
                 const double r = 0.37;
                 for (std::uint32_t ty = 0; ty < grid.tilesY; ++ty)
                     for (std::uint32_t tx = 0; tx < grid.tilesX; ++tx) {
                         const std::uint32_t t = grid.tileIndex(tx, ty);
                         const auto rect = grid.tileRect(tx, ty);
                         const glm::dvec2 centre(0.5 * (rect.x0 + rect.x1), 0.5 * (rect.y0 + rect.y1));
                         const double dmin = bounds.tileDepthMin[t], dmax = bounds.tileDepthMax[t];
                         const std::string id = std::to_string(tx) + "_" + std::to_string(ty);
                         // Behind the wall, touching the tile's far bound.
                         s.lights.push_back(light("behind_" + id,
                                                  worldFromViewPoint(s.camera, proj.viewPositionAt(centre, dmax + r)), r));
                         // In front, touching the tile's near bound.
                         s.lights.push_back(light("front_" + id,
                                                  worldFromViewPoint(s.camera, proj.viewPositionAt(centre, dmin - r)), r));
                         // On the wall, left of the tile's left side plane by exactly r.
                         const glm::dvec3 edge = proj.viewPositionAt({double(rect.x0), centre.y}, dmax);
                         s.lights.push_back(light("left_" + id, worldFromViewPoint(s.camera, edge - glm::dvec3(r, 0, 0)), r));
                     }
                 return s;
             },
             SphereTest::Exact, 32, Slicing::Log, "", 0, checkAllTilesMinEqualsMax});
        add({"lights_65536_at_one_point", "65,536 identical lights at one point: every list is long and equal",
             [] {
                 Scene s = room(48, 32);
                 s.lights.assign(65536, light("", {0.5, 1.5, -9}, 4.0));
                 return s;
             },
             SphereTest::Planes, 8});
        add({"world_offset_1e5", "the whole scene and camera translated by (1e5, 1e5, -1e5)",
             [] {
                 Scene s = room();
                 const glm::dvec3 off(1e5, 1e5, -1e5);
                 for (Mesh& m : s.meshes)
                     for (std::size_t i = 0; i < m.positions.size(); i += 3) {
                         m.positions[i] = float(m.positions[i] + off.x);
                         m.positions[i + 1] = float(m.positions[i + 1] + off.y);
                         m.positions[i + 2] = float(m.positions[i + 2] + off.z);
                     }
                 for (PointLight& l : s.lights) l.position += off;
                 s.camera.position += off;
                 s.camera.target += off;
                 return s;
             },
             SphereTest::Exact, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"maize_32_log_cells", "the maize asset (thin open leaves, depth discontinuities), 32 log cells",
             [] {
                 Scene s;
                 s.meshes.push_back(loadAsset("maize/maize_single2.obj"));
                 frame(s, {0.6, 0.25, 1.0}, 0.9);
                 s.camera.width = 160;
                 s.camera.height = 120;
                 const auto [lo, hi] = s.bounds();
                 s.lights = lightsIn(lo, hi, 256, 5, 1, 10, 0.05);
                 const double size = glm::length(hi - lo);
                 for (PointLight& l : s.lights) l.explicitRadius = size * 0.03;
                 return s;
             },
             SphereTest::Exact, 32, Slicing::Log, "", 0, checkSomeEmptyTiles});
        add({"buildings_zero_area_faces", "the buildings asset: 400k triangles, zero-area faces, near/far jumps",
             [] {
                 Scene s;
                 s.meshes.push_back(loadAsset("buildings/buildings.obj"));
                 frame(s, {0.5, 0.6, 1.0}, 0.7);
                 s.camera.width = 192;
                 s.camera.height = 108;
                 const auto [lo, hi] = s.bounds();
                 s.lights = lightsIn(lo, hi, 384, 9, 1, 10, 0.05);
                 const double size = glm::length(hi - lo);
                 for (PointLight& l : s.lights) l.explicitRadius = size * 0.02;
                 return s;
             },
             SphereTest::PlanesAabb, 16, Slicing::Log, "", 0, checkHasGeometry});
        // ---- The shapes of engines' own limit bugs (issue 37; docs/ENGINES.md
        // says which presets lose lights on each and why). The built-in
        // algorithms have no limits and must miss nothing on them.
        add({"lights_past_scene_limit",
             "600 lights in the room: past Godot's 512, HDRP's 512 on screen, URP's and Filament's 256, "
             "WebGL2 Bevy's 204 (Godot #56591, #61747; Filament #7493)",
             [] {
                 Scene s = room(128, 72);
                 s.lights = lightsIn({-9, 0.2, -29}, {9, 7.5, 1}, 600, 37);
                 return s;
             }});
        add({"dense_cluster_4k",
             "3840x2160, 160 small lights packed round one box: tile and cluster lists past a cap (Bevy #3915; "
             "HDRP's 23, later 63)",
             [] {
                 Scene s = room(3840, 2160);
                 s.lights.clear();
                 for (int i = 0; i < 160; ++i) {
                     const double a = 0.61 * i, r = 0.3 + 0.01 * (i % 40);
                     s.lights.push_back(light("c" + std::to_string(i),
                                              {3.5 + r * std::cos(a), 2.5 + 0.02 * (i % 50), -12.5 + r * std::sin(a)},
                                              1.5 + 0.01 * (i % 30)));
                 }
                 return s;
             },
             SphereTest::Planes, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"wide_spots_short_far",
             "spot lights at the widest the model holds (90 degree half-angle: a hemisphere) under a far "
             "plane of 12, cones cut by it",
             [] {
                 Scene s = room(96, 64);
                 s.camera.farPlane = 12;
                 s.lights.clear();
                 for (int i = 0; i < 24; ++i) {
                     PointLight l = light("spot" + std::to_string(i), {-8 + 0.7 * i, 6, -2 - 0.9 * i}, 6 + 0.2 * (i % 7));
                     l.kind = LightKind::Spot;
                     l.direction = {std::sin(0.5 * i), -1, std::cos(0.7 * i)};
                     l.outerAngleDeg = 90 - (i % 3) * 10;
                     s.lights.push_back(l);
                 }
                 return s;
             },
             SphereTest::PlanesAabb, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"lights_seen_from_far",
             "the room seen from 2,000 units away through a 2 degree lens: every light a few pixels wide, "
             "log slices stretched over a far plane of 5,000",
             [] {
                 Scene s = room(128, 72);
                 s.camera.position = {0, 800, 1900};
                 s.camera.target = {0, 3, -14};
                 s.camera.fovYDeg = 2;
                 s.camera.nearPlane = 1;
                 s.camera.farPlane = 5000;
                 return s;
             },
             SphereTest::Planes, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"orthographic_far_cut",
             "an orthographic camera whose far plane (18) cuts the room: lights and walls beyond it",
             [] {
                 Scene s = room(96, 64);
                 s.camera.projection = ProjectionKind::Orthographic;
                 s.camera.orthoHeight = 12;
                 s.camera.farPlane = 18;
                 return s;
             },
             SphereTest::Planes, 16, Slicing::Log, "", 0, checkHasGeometry});
        add({"near_gap_first_slice",
             "geometry and lights from 0.2 to 4 in front of a near plane of 0.05: all of it inside the "
             "first slice of engines whose first slice ends at 5 (Filament, Bevy), many log slices here",
             [] {
                 Scene s = room(96, 64);
                 s.camera.position = {0, 1, 1.5};
                 s.camera.target = {0, 1, -3};
                 s.camera.nearPlane = 0.05;
                 Mesh& m = s.meshes[0];
                 addBox(m, {-0.4, 0.8, 0.8}, {-0.1, 1.1, 1.1}); // 0.4..0.7 in front of the eye
                 addBox(m, {0.2, 0.6, -1.5}, {0.8, 1.4, -0.9});
                 for (int i = 0; i < 24; ++i)
                     s.lights.push_back(light("near" + std::to_string(i),
                                              {-0.6 + 0.05 * i, 0.7 + 0.03 * (i % 9), 1.3 - 0.18 * i}, 0.15 + 0.02 * (i % 6)));
                 return s;
             },
             SphereTest::Planes, 32, Slicing::Log, "", 0, checkHasGeometry});
        add({"nan_light_position", "a NaN in a light's position: LightError naming the light",
             [] {
                 Scene s = room(32, 16);
                 s.lights.resize(5);
                 s.lights[3].name = "bad_lamp";
                 s.lights[3].position.y = std::nan("");
                 return s;
             },
             SphereTest::Planes, 16, Slicing::Log, "light 3 'bad_lamp': position: must be finite", 3});
        add({"infinite_light_radius", "an infinite explicit radius: LightError naming the light",
             [] {
                 Scene s = room(32, 16);
                 s.lights.resize(2);
                 s.lights[1].name = "";
                 s.lights[1].explicitRadius = kInf;
                 return s;
             },
             SphereTest::Planes, 16, Slicing::Log, "light 1: radius: must be finite", 1});
        return v;
    }();
    return cases;
}

} // namespace lc::hardcase
