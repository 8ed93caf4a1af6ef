// The raster algorithm's light proxies on the CPU reference: the enclosing
// overfit against its closed form and against rays, the misses an inscribed
// proxy or centre sampling gets (located by the ground truth where the
// sphere leaves the proxy), and the cases engines special-case: a light
// across the near plane, around the camera, on a partial edge tile.
#include "culling/core/backend.hpp"
#include "culling/math/light_proxy.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/ground_truth.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <string>

using namespace lc;

namespace {

// The least distance from the mesh's centre to a face's plane, after
// scaling the mesh by `scale`, along unit direction u (the ray's exit).
double exitDistance(const ProxyMesh& m, double scale, const glm::dvec3& u) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& t : m.triangles) {
        const glm::dvec3 a = m.vertices[t[0]] * scale, b = m.vertices[t[1]] * scale, c = m.vertices[t[2]] * scale;
        glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
        double d = glm::dot(n, a);
        if (d < 0) n = -n, d = -d;
        const double along = glm::dot(n, u);
        if (along > 1e-12) best = std::min(best, d / along);
    }
    return best;
}

// A wall facing the camera at depth `wallDepth`, the camera at the origin
// looking down -Z, and point lights (centre, radius).
Scene wallScene(std::uint32_t w, std::uint32_t h, std::uint32_t tile, double wallDepth,
                const std::vector<std::pair<glm::dvec3, double>>& lights) {
    Scene s;
    s.camera.position = {0, 0, 0};
    s.camera.target = {0, 0, -1};
    s.camera.width = w;
    s.camera.height = h;
    s.camera.tileSize = tile;
    s.camera.nearPlane = 0.5;
    s.camera.farPlane = 100;
    s.camera.fovYDeg = 60;
    Mesh m;
    const double e = 200;
    for (const glm::dvec3& p : {glm::dvec3(-e, -e, -wallDepth), glm::dvec3(e, -e, -wallDepth),
                                glm::dvec3(e, e, -wallDepth), glm::dvec3(-e, e, -wallDepth)})
        for (int i = 0; i < 3; ++i) m.positions.push_back(float(p[i]));
    m.indices = {0, 1, 2, 0, 2, 3};
    s.meshes.push_back(m);
    for (std::size_t i = 0; i < lights.size(); ++i) {
        PointLight l;
        l.name = "l" + std::to_string(i);
        l.position = lights[i].first;
        l.explicitRadius = lights[i].second;
        s.lights.push_back(l);
    }
    return s;
}

struct Judged {
    std::uint64_t falseNegatives = 0;
    std::vector<glm::dvec3> missedAt; // view positions of the pixels that miss a light
};

// Every geometry pixel's needed lights against its tile's list.
Judged judge(const Scene& scene, const CullSettings& st) {
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    const CullResult r = cpu->cull(depth, proj, grid, lights, st);
    EXPECT_EQ(r.validate(lights.size()), "");
    Judged j;
    for (std::uint32_t y = 0; y < depth.height; ++y)
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            if (!depth.hasGeometry(x, y)) continue;
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
            const std::uint32_t list = grid.tileOfPixel(x, y);
            const auto* b = r.lightIndices.data() + r.listOffset[list];
            const auto* e = b + r.listCount[list];
            for (std::uint32_t l = 0; l < lights.size(); ++l)
                if (glm::length(p - lights.centers[l]) <= lights.radii[l] && !std::binary_search(b, e, l)) {
                    ++j.falseNegatives;
                    j.missedAt.push_back(p);
                }
        }
    // The pipeline's ground truth agrees.
    EXPECT_EQ(computeGroundTruth(depth, proj, lights, r, {false}).metrics.falseNegatives, j.falseNegatives);
    return j;
}

// 250x190 at 16-pixel tiles (the last column and row partial), a wall at 6;
// lights across the near plane (0), around the camera (1), on the right and
// bottom edges (2, 3), behind the camera (4).
Scene nearPlaneScene() {
    return wallScene(250, 190, 16, 6.0,
                     {{{0.3, 0.2, -0.4}, 1.5},
                      {{0, 0, 0.5}, 8.0},
                      {{2.9, 0.5, -5.6}, 0.7},
                      {{0.1, -2.2, -5.5}, 0.8},
                      {{0, 0, 3.0}, 2.0}});
}

CullSettings raster(std::uint32_t level, double overfit, bool conservative) {
    CullSettings s;
    s.algorithm = Algorithm::Raster;
    s.proxyLevel = level;
    s.proxyOverfit = overfit;
    s.conservative = conservative;
    return s;
}

} // namespace

TEST(LightProxy, EnclosingOverfitIsTheIcosphereInradius) {
    // The icosahedron's inradius over its circumradius, in closed form.
    const double icosahedron = 1.0 / std::sqrt((5.0 + 2.0 * std::sqrt(5.0)) / 15.0);
    EXPECT_NEAR(icosphereEnclosingOverfit(0), icosahedron, 1e-12);
    std::mt19937 rng(7);
    std::normal_distribution<double> g;
    for (std::uint32_t level = 0; level <= 4; ++level) {
        const ProxyMesh& m = unitIcosphere(level);
        EXPECT_EQ(m.triangles.size(), 20u << (2 * level));
        for (const auto& v : m.vertices) EXPECT_NEAR(glm::length(v), 1.0, 1e-12);
        const double f = icosphereEnclosingOverfit(level);
        if (level > 0) EXPECT_LT(f, icosphereEnclosingOverfit(level - 1)) << "finer meshes need less";
        EXPECT_GT(f, 1.0);
        // Scaled by f the mesh holds the unit sphere: every ray from the
        // centre leaves it at distance 1 or more...
        for (int i = 0; i < 400; ++i) {
            const glm::dvec3 u = glm::normalize(glm::dvec3(g(rng), g(rng), g(rng)));
            EXPECT_GE(exitDistance(m, f, u), 1.0 - 1e-9) << "level " << level;
        }
        // ...and 0.1% less leaves the nearest face's middle inside the sphere.
        glm::dvec3 nearest(0.0);
        double nearestDistance = 2.0;
        for (const auto& t : m.triangles) {
            const glm::dvec3 a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
            const double d = std::abs(glm::dot(glm::normalize(glm::cross(b - a, c - a)), a));
            if (d < nearestDistance) nearestDistance = d, nearest = glm::normalize(a + b + c);
        }
        EXPECT_LT(exitDistance(m, f * 0.999, nearest), 1.0) << "level " << level;
    }
}

TEST(LightProxy, MeshesAreClosedAndWoundOutwards) {
    // Counter-clockwise seen from outside: the Vulkan pass draws only the
    // faces turned to the camera for a proxy wholly beyond the near plane.
    auto check = [](const ProxyMesh& m, const glm::dvec3& inside, const std::string& what) {
        std::map<std::pair<std::uint32_t, std::uint32_t>, int> edges;
        for (const auto& t : m.triangles) {
            const glm::dvec3 a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
            EXPECT_GT(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - inside), 0.0) << what;
            for (int k = 0; k < 3; ++k) ++edges[{t[std::size_t(k)], t[std::size_t((k + 1) % 3)]}];
        }
        // Closed: every directed edge once, its reverse once.
        for (const auto& [e, n] : edges) {
            EXPECT_EQ(n, 1) << what;
            EXPECT_EQ(edges.count({e.second, e.first}), 1u) << what;
        }
    };
    for (std::uint32_t level = 0; level <= 4; ++level) check(unitIcosphere(level), {0, 0, 0}, "icosphere " + std::to_string(level));
    for (std::uint32_t n : {3u, 8u, 64u}) check(unitCone(n), {0, 0, 0.5}, "cone " + std::to_string(n));
}

TEST(LightProxy, ConeOverfitWidensThePolygonToItsCircle) {
    for (std::uint32_t n : {3u, 4u, 8u, 64u}) {
        const double f = coneEnclosingOverfit(n);
        EXPECT_NEAR(f, 1.0 / std::cos(3.14159265358979323846 / n), 1e-12);
        // A spot of 40 degrees, range 5, along -Z: the cone proxy holds the
        // points of its volume at the rim and in the middle of a base side.
        CullSettings s;
        s.proxySegments = n;
        const double angle = 40.0 * 3.14159265358979323846 / 180.0;
        const LightProxy p = makeLightProxy({0, 0, -10}, 5.0, {0, 0, -1}, angle, s);
        ASSERT_TRUE(p.cone);
        EXPECT_NEAR(p.overfit, f, 1e-12);
        EXPECT_NEAR(p.depthMin, 10.0, 1e-12);
        EXPECT_NEAR(p.depthMax, 15.0, 1e-12);
        // The base side's middle sits at the cone's radius exactly.
        const glm::dvec3 a = p.vertex(1), b = p.vertex(2);
        const glm::dvec3 sideMid = 0.5 * (a + b);
        EXPECT_NEAR(glm::length(glm::dvec2(sideMid.x, sideMid.y)), 5.0 * std::tan(angle), 1e-9) << n << " sides";
    }
    // Past the cone angle a spot is drawn as its range sphere.
    CullSettings s;
    s.proxyConeAngle = 30;
    EXPECT_FALSE(makeLightProxy({0, 0, -10}, 5.0, {0, 0, -1}, 0.6, s).cone);
    EXPECT_TRUE(makeLightProxy({0, 0, -10}, 5.0, {0, 0, -1}, 0.5, s).cone);
}

TEST(RasterCull, InscribedProxiesMissWhereTheSphereLeavesThemUntilTheEnclosingFactor) {
    // One light of radius 3 cut through its centre by a wall, at 8-pixel
    // tiles: the wall's disc of lit pixels reaches the sphere's rim, past the
    // inscribed icosahedron's faces.
    const glm::dvec3 c(0.4, -0.3, -9.0);
    const double r = 3.0;
    const Scene scene = wallScene(320, 320, 8, 9.0, {{c, r}});
    const Judged inscribed = judge(scene, raster(0, 1.0, true));
    ASSERT_GT(inscribed.falseNegatives, 0u) << "the case no longer shows the inscribed proxy's misses";
    // Each miss is a pixel inside the sphere and outside the proxy: the
    // conservative coverage of a closed proxy lists every pixel inside it.
    const ProxyMesh& ico = unitIcosphere(0);
    for (const glm::dvec3& p : inscribed.missedAt) {
        const glm::dvec3 u = (p - c) / r;
        EXPECT_LE(glm::length(u), 1.0 + 1e-9);
        EXPECT_GT(glm::length(u), exitDistance(ico, 1.0, glm::normalize(u)) - 1e-9)
            << "a miss inside the proxy at " << p.x << "," << p.y << "," << p.z;
    }
    // Growing the proxy drops the misses, to none at the computed factor.
    const double f = icosphereEnclosingOverfit(0);
    std::uint64_t previous = inscribed.falseNegatives;
    std::string sweep = "overfit 1: " + std::to_string(previous);
    for (double overfit : {1.02, 1.05, 1.1, 1.2}) {
        const std::uint64_t fn = judge(scene, raster(0, overfit, true)).falseNegatives;
        EXPECT_LE(fn, previous) << "overfit " << overfit;
        if (overfit == 1.02) EXPECT_GT(fn, 0u) << "1.02 is well short of " << f;
        previous = fn;
        sweep += ", " + std::to_string(overfit).substr(0, 4) + ": " + std::to_string(fn);
    }
    std::printf("[ sweep    ] false negatives by overfit (level 0, conservative): %s, %.4f: 0\n", sweep.c_str(), f);
    EXPECT_EQ(judge(scene, raster(0, f, true)).falseNegatives, 0u);
    EXPECT_EQ(judge(scene, raster(0, 0.0, true)).falseNegatives, 0u) << "auto is the enclosing factor";
    // A finer proxy misses less at overfit 1.
    EXPECT_LT(judge(scene, raster(3, 1.0, true)).falseNegatives, inscribed.falseNegatives);
}

TEST(RasterCull, CentreSamplingMissesTilesAProxyOnlyGrazes) {
    // Small lights against the wall at 32-pixel tiles: their discs of lit
    // pixels overlap tiles whose centres no proxy triangle covers.
    std::vector<std::pair<glm::dvec3, double>> lights;
    for (int i = 0; i < 12; ++i) lights.push_back({{-4.0 + 0.77 * i, 0.37 * (i % 5) - 0.8, -9.7}, 0.45});
    const Scene scene = wallScene(320, 256, 32, 10.0, lights);
    EXPECT_GT(judge(scene, raster(2, 0.0, false)).falseNegatives, 0u);
    EXPECT_EQ(judge(scene, raster(2, 0.0, true)).falseNegatives, 0u);
}

TEST(RasterCull, LightsAcrossTheNearPlaneAroundTheCameraAndOnPartialTiles) {
    // 250x190 at 16-pixel tiles: the last column and row of tiles are
    // partial. Lights: across the near plane, around the camera, on the
    // right and bottom edges, behind the camera.
    const Scene scene = nearPlaneScene();
    for (std::uint32_t level : {0u, 1u, 4u})
        for (bool conservative : {true}) {
            const Judged j = judge(scene, raster(level, 0.0, conservative));
            EXPECT_EQ(j.falseNegatives, 0u) << "level " << level;
        }
    // Every light the wall needs is listed somewhere; the one behind the
    // camera nowhere.
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    const CullResult r = cpu->cull(depth, proj, TileGrid::make(250, 190, 16), lights, raster(1, 0.0, true));
    EXPECT_EQ(std::count(r.lightIndices.begin(), r.lightIndices.end(), 4u), 0) << "the light behind the camera";
    EXPECT_EQ(std::count(r.lightIndices.begin(), r.lightIndices.end(), 1u), std::ptrdiff_t(r.grid.tileCount()))
        << "the light around the camera reaches the wall in every tile";
    EXPECT_FALSE(r.coverage.empty());
}

TEST(LightProxy, TileDepthRangeHoldsTheTrianglesDepthsOverTheTile) {
    // Random triangles (some reaching behind the near plane, some steeply
    // inclined) under a perspective and an orthographic camera, 170x100 at
    // 16-pixel tiles (a partial last column and row): every point of a
    // triangle over a tile it covers has its depth in the range, and the
    // plane narrows the corners' range (it is the tight measure the slices
    // use, not the whole triangle's).
    for (bool ortho : {false, true}) {
        SCOPED_TRACE(ortho ? "orthographic" : "perspective");
        Camera cam;
        cam.width = 170;
        cam.height = 100;
        cam.tileSize = 16;
        cam.nearPlane = 0.5;
        cam.farPlane = 100;
        if (ortho) {
            cam.projection = ProjectionKind::Orthographic;
            cam.orthoHeight = 20;
        }
        const Projection proj(cam);
        const TileGrid grid = TileGrid::make(cam.width, cam.height, cam.tileSize);
        std::mt19937 rng(7);
        std::uniform_real_distribution<double> xy(-12, 12), z(-40, 0.2);
        std::uint64_t checked = 0, tiles = 0;
        double narrowed = 0, corners = 0;
        for (int n = 0; n < 300; ++n) {
            std::array<glm::dvec3, 3> tri;
            for (auto& v : tri) v = {xy(rng), xy(rng), z(rng)};
            proxyTriangleTiles(proj, grid, tri, true, [&](std::uint32_t tx, std::uint32_t ty) {
                const auto [lo, hi] = proxyTriangleTileDepth(proj, grid, tri, true, tx, ty);
                const double vlo = std::min({-tri[0].z, -tri[1].z, -tri[2].z});
                const double vhi = std::max({-tri[0].z, -tri[1].z, -tri[2].z});
                ASSERT_LE(lo, hi);
                EXPECT_GE(lo, vlo);
                EXPECT_LE(hi, vhi);
                ++tiles;
                narrowed += hi - lo;
                corners += vhi - vlo;
                for (int i = 0; i <= 40; ++i)
                    for (int j = 0; i + j <= 40; ++j) {
                        const glm::dvec3 p = tri[0] + (tri[1] - tri[0]) * (i / 40.0) + (tri[2] - tri[0]) * (j / 40.0);
                        if (-p.z < cam.nearPlane) continue; // clipped away
                        const glm::dvec2 t = proj.pixelFromView(p) / double(cam.tileSize);
                        if (t.x < tx || t.x > tx + 1.0 || t.y < ty || t.y > ty + 1.0) continue;
                        const double d = -p.z, e = 1e-9 * std::abs(d) + 1e-12;
                        EXPECT_GE(d, lo - e) << "tile " << tx << "," << ty;
                        EXPECT_LE(d, hi + e) << "tile " << tx << "," << ty;
                        ++checked;
                    }
            });
        }
        EXPECT_GT(checked, 10000u);
        EXPECT_GT(tiles, 1000u);
        EXPECT_LT(narrowed, 0.5 * corners) << "the plane narrows the corners' range";
    }
}

namespace {

// False negatives of `st` on `scene` by the pipeline's ground truth (which
// looks clustered lists up by each pixel's slice), CPU reference.
std::uint64_t truthFalseNegatives(const Scene& scene, const CullSettings& st, std::uint64_t* shading = nullptr) {
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    const CullResult r = cpu->cull(depth, proj, grid, lights, st);
    EXPECT_EQ(r.validate(lights.size()), "");
    EXPECT_EQ(r.listsPerTile, st.proxySlices ? st.cells : 1u);
    const Metrics m = computeGroundTruth(depth, proj, lights, r, {false}).metrics;
    if (shading) *shading = m.shadingWork;
    return m.falseNegatives;
}

} // namespace

TEST(RasterCull, ClusteredSlicesMissNothingAndShadeLessThanTheTilesRange) {
    // proxy-depth slices: each covered tile's triangles' depths mark the
    // light's slices. With the enclosing overfit: no miss, at every level,
    // slicing and skip-empty, and less shading than the tile's min/max rule
    // (a tile spanning a pillar and the far wall no longer lists a light
    // between them); the inscribed proxy misses.
    Scene scene = makeBuiltinScene("atrium");
    scene.camera.width = 330; // partial last column and row
    scene.camera.height = 190;
    for (std::uint32_t level : {0u, 1u, 2u}) {
        CullSettings tile = raster(level, 0.0, true);
        std::uint64_t tileWork = 0;
        ASSERT_EQ(truthFalseNegatives(scene, tile, &tileWork), 0u);
        for (Slicing slicing : {Slicing::Log, Slicing::Linear})
            for (bool skipEmpty : {true, false}) {
                SCOPED_TRACE("level " + std::to_string(level) + " " + toString(slicing) +
                             (skipEmpty ? " skip-empty" : ""));
                CullSettings st = tile;
                st.proxySlices = true;
                st.cells = 16;
                st.slicing = slicing;
                st.skipEmpty = skipEmpty;
                std::uint64_t work = 0;
                EXPECT_EQ(truthFalseNegatives(scene, st, &work), 0u);
                EXPECT_LT(work, tileWork);
            }
    }
    CullSettings inscribed = raster(0, 1.0, true);
    inscribed.proxySlices = true;
    EXPECT_GT(truthFalseNegatives(scene, inscribed), 0u);
    // Centre sampling samples the depth at the tile's centre too: it misses.
    CullSettings centre = raster(1, 0.0, false);
    centre.proxySlices = true;
    EXPECT_GT(truthFalseNegatives(scene, centre), 0u);
}

TEST(RasterCull, ClusteredSlicesAcrossTheNearPlaneAndAroundTheCamera) {
    // The near-plane cases with slices: a proxy the near plane cuts starts at
    // slice 0 (its part in front is clipped away), a camera inside a light
    // lists it in every tile's occupied slice; one behind the camera nowhere.
    const Scene scene = nearPlaneScene();
    for (std::uint32_t level : {0u, 1u, 4u}) {
        CullSettings st = raster(level, 0.0, true);
        st.proxySlices = true;
        EXPECT_EQ(truthFalseNegatives(scene, st), 0u) << "level " << level;
    }
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    CullSettings st = raster(1, 0.0, true);
    st.proxySlices = true;
    const CullResult r = cpu->cull(depth, proj, TileGrid::make(250, 190, 16), lights, st);
    EXPECT_EQ(std::count(r.lightIndices.begin(), r.lightIndices.end(), 4u), 0) << "the light behind the camera";
    EXPECT_EQ(std::count(r.lightIndices.begin(), r.lightIndices.end(), 1u), std::ptrdiff_t(r.grid.tileCount()))
        << "the light around the camera, once per tile: the wall's one occupied slice";
}
