// Every CPU culling algorithm on small synthetic scenes, checked two ways:
//  - a mini ground truth: at every pixel with geometry, each light whose sphere
//    contains the pixel's reconstructed view-space point must be in the list
//    the pixel uses (no false negatives);
//  - a brute-force re-derivation of every list from the DESIGN rules over all
//    tiles x all lights, which catches lists lost (or gained) by the backend's
//    per-light tile rectangles.
#include "culling/core/backend.hpp"
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/ground_truth.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <random>
#include <tuple>

using namespace lc;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void addTriangle(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const auto base = std::uint32_t(m.vertexCount());
    for (const glm::dvec3& p : {a, b, c})
        for (int i = 0; i < 3; ++i) m.positions.push_back(float(p[i]));
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
}

void addQuad(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d) {
    addTriangle(m, a, b, c);
    addTriangle(m, a, c, d);
}

// Camera at the origin looking down -Z (world == view space).
Camera viewCamera(ProjectionKind kind, std::uint32_t w, std::uint32_t h, std::uint32_t tile) {
    Camera cam;
    cam.position = {0, 0, 0};
    cam.target = {0, 0, -1};
    cam.projection = kind;
    cam.width = w;
    cam.height = h;
    cam.tileSize = tile;
    cam.nearPlane = 0.5;
    cam.farPlane = kind == ProjectionKind::ReversedZ ? kInf : 60.0;
    cam.fovYDeg = 60;
    cam.orthoHeight = 16;
    return cam;
}

// Boxes' front faces at random depths over a partial back wall: depth
// discontinuities inside tiles and empty tiles on the right edge.
Scene syntheticScene(ProjectionKind kind, std::uint32_t w, std::uint32_t h, std::uint32_t tile,
                     std::size_t lights, std::uint32_t seed) {
    Scene s;
    s.camera = viewCamera(kind, w, h, tile);
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0, 1);
    Mesh m;
    addQuad(m, {-40, -40, -30}, {6, -40, -30}, {6, 40, -45}, {-40, 40, -45}); // tilted back wall, left part
    for (int i = 0; i < 12; ++i) {
        const double z = -(2 + 20 * u(rng)), x = -7 + 12 * u(rng), y = -5 + 10 * u(rng), e = 0.5 + 2 * u(rng);
        addQuad(m, {x, y, z}, {x + e, y, z - 0.5 * e}, {x + e, y + e, z}, {x, y + e, z + 0.3 * e});
    }
    s.meshes.push_back(m);
    for (std::size_t i = 0; i < lights; ++i) {
        PointLight l;
        l.name = "l" + std::to_string(i);
        // Some lights straddle the eye plane or sit behind the camera.
        l.position = {-10 + 20 * u(rng), -8 + 16 * u(rng), 3 - 40 * u(rng)};
        l.explicitRadius = 0.3 + 4 * u(rng);
        s.lights.push_back(l);
    }
    return s;
}

struct CullRun {
    Scene scene;
    DepthImage depth;
    ViewLights lights;
    CullResult result;
};

CullRun runCpu(const Scene& scene, const CullSettings& st) {
    auto backend = makeCpuBackend();
    CullRun r{scene, {}, {}, {}};
    const Projection proj(scene.camera);
    r.depth = backend->renderDepth(scene, proj);
    r.lights = makeViewLights(scene);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    r.result = backend->cull(r.depth, proj, grid, r.lights, st);
    return r;
}

std::vector<std::uint32_t> listAt(const CullResult& res, std::uint32_t l) {
    return {res.lightIndices.begin() + res.listOffset[l],
            res.lightIndices.begin() + res.listOffset[l] + res.listCount[l]};
}

// Sum over geometry pixels of lights needed but not listed.
std::uint64_t falseNegatives(const CullRun& r, std::uint64_t* exactWork = nullptr) {
    const Projection proj(r.scene.camera);
    std::uint64_t fn = 0, e = 0;
    for (std::uint32_t y = 0; y < r.depth.height; ++y)
        for (std::uint32_t x = 0; x < r.depth.width; ++x) {
            if (!r.depth.hasGeometry(x, y)) continue;
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, r.depth.at(x, y));
            const std::uint32_t l = r.result.listOfPixel(x, y, -p.z);
            const auto* b = r.result.lightIndices.data() + r.result.listOffset[l];
            const auto* en = b + r.result.listCount[l];
            // zbin: the pixel loops over the mask's lights within its bin's range.
            const bool zbin = r.result.algorithm == Algorithm::ZBin;
            const std::uint32_t bin = zbin ? r.result.zbinOf(-p.z) : 0;
            for (std::size_t i = 0; i < r.lights.size(); ++i) {
                if (glm::length(p - r.lights.centers[i]) > r.lights.radii[i]) continue;
                ++e;
                const bool inBin = !zbin || (r.result.zbinLo[bin] <= r.result.zbinRank[i] &&
                                             r.result.zbinRank[i] <= r.result.zbinHi[bin]);
                fn += !std::binary_search(b, en, std::uint32_t(i)) || !inBin;
            }
        }
    if (exactWork) *exactWork = e;
    return fn;
}

// Every list re-derived from the rules in DESIGN.md / the brief.
std::vector<std::vector<std::uint32_t>> bruteForceLists(const CullRun& r) {
    const CullResult& res = r.result;
    const CullSettings& st = res.settings;
    const Projection proj(r.scene.camera);
    const TileGrid& g = res.grid;
    std::vector<std::vector<std::uint32_t>> out(res.listOffset.size());
    const std::size_t n = r.lights.size();
    if (res.algorithm == Algorithm::All) {
        for (std::size_t i = 0; i < n; ++i) out[0].push_back(std::uint32_t(i));
        return out;
    }
    double lightFar = 0;
    for (std::size_t i = 0; i < n; ++i) lightFar = std::max(lightFar, -r.lights.centers[i].z + r.lights.radii[i]);
    for (std::uint32_t t = 0; t < g.tileCount(); ++t) {
        const auto rect = g.tileRect(t % g.tilesX, t / g.tilesX);
        // Tile depth bounds straight from the pixels.
        double mn = kInf, mx = -kInf;
        for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
            for (std::uint32_t x = rect.x0; x < rect.x1; ++x)
                if (r.depth.hasGeometry(x, y)) {
                    const double v = proj.viewDepthFromWindowDepth(r.depth.at(x, y));
                    mn = std::min(mn, v);
                    mx = std::max(mx, v);
                }
        EXPECT_EQ(res.tileDepthMin[t], mn);
        EXPECT_EQ(res.tileDepthMax[t], mx);
        const bool empty = !(mn <= mx);
        for (std::size_t i = 0; i < n; ++i) {
            const glm::dvec3 c = r.lights.centers[i];
            const double rad = r.lights.radii[i];
            auto hit = [&](double a, double b) {
                return sphereIntersectsChunk(st.test, makeFrustumChunk(proj, rect, a, b), c, rad);
            };
            switch (res.algorithm) {
            case Algorithm::ZBin: // the tile masks: naive's screen-space test
            case Algorithm::Naive: {
                const double f = std::isinf(proj.farPlane()) ? std::max(lightFar, proj.nearPlane()) : proj.farPlane();
                if (hit(proj.nearPlane(), f)) out[t].push_back(std::uint32_t(i));
                break;
            }
            case Algorithm::MinMax:
                if (!empty && hit(mn, mx)) out[t].push_back(std::uint32_t(i));
                break;
            case Algorithm::Fptl: {
                // minmax's test, then a geometry pixel of the tile within the
                // sphere (with the reference's rounding slack).
                if (empty || !hit(mn, mx)) break;
                bool reached = false;
                for (std::uint32_t y = rect.y0; y < rect.y1 && !reached; ++y)
                    for (std::uint32_t x = rect.x0; x < rect.x1 && !reached; ++x)
                        reached = r.depth.hasGeometry(x, y) &&
                                  glm::length(proj.viewPositionFromDepth(x, y, r.depth.at(x, y)) - c) <=
                                      rad + sphereTestSlack(c, rad);
                if (reached) out[t].push_back(std::uint32_t(i));
                break;
            }
            case Algorithm::HalfZ:
                if (empty) break;
                if (hit(mn, (mn + mx) / 2)) out[2 * t].push_back(std::uint32_t(i));
                if (hit((mn + mx) / 2, mx)) out[2 * t + 1].push_back(std::uint32_t(i));
                break;
            case Algorithm::TwoPointFiveD: {
                if (empty) break;
                std::uint32_t cellMask = 0;
                for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
                    for (std::uint32_t x = rect.x0; x < rect.x1; ++x)
                        if (r.depth.hasGeometry(x, y))
                            cellMask |= 1u << sliceOfDepth(st.slicing, mn, mx, st.cells,
                                                           proj.viewDepthFromWindowDepth(r.depth.at(x, y)));
                EXPECT_EQ(res.cellMask[t], cellMask);
                const double cd = -c.z;
                if ((sliceRangeMask(st.slicing, mn, mx, st.cells, cd - rad, cd + rad) & cellMask) && hit(mn, mx))
                    out[t].push_back(std::uint32_t(i));
                break;
            }
            case Algorithm::Clustered: {
                const double lo = proj.nearPlane();
                const double hi = std::isinf(proj.farPlane()) ? std::max(lightFar, 2 * lo) : proj.farPlane();
                EXPECT_EQ(res.clusterNear, lo);
                EXPECT_EQ(res.clusterFar, hi);
                std::uint32_t occupied = 0;
                for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
                    for (std::uint32_t x = rect.x0; x < rect.x1; ++x)
                        if (r.depth.hasGeometry(x, y))
                            occupied |= 1u << sliceOfDepth(st.slicing, lo, hi, st.cells,
                                                           proj.viewDepthFromWindowDepth(r.depth.at(x, y)));
                EXPECT_EQ(res.cellMask[t], occupied);
                for (std::uint32_t k = 0; k < st.cells; ++k) {
                    if (st.skipEmpty && !(occupied & (1u << k))) continue;
                    if (hit(sliceBoundary(st.slicing, lo, hi, st.cells, k),
                            sliceBoundary(st.slicing, lo, hi, st.cells, k + 1)))
                        out[std::size_t(t) * st.cells + k].push_back(std::uint32_t(i));
                }
                break;
            }
            default: break;
            }
        }
    }
    return out;
}

const ProjectionKind kKinds[] = {ProjectionKind::Perspective, ProjectionKind::PerspectiveGL,
                                 ProjectionKind::ReversedZ, ProjectionKind::Orthographic,
                                 ProjectionKind::OrthographicGL};
const Algorithm kAlgorithms[] = {Algorithm::All,   Algorithm::Naive,         Algorithm::MinMax,
                                 Algorithm::HalfZ, Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin};
const SphereTest kTests[] = {SphereTest::Planes, SphereTest::PlanesAabb, SphereTest::Exact};

} // namespace

class CpuCull : public ::testing::TestWithParam<std::tuple<ProjectionKind, Algorithm, SphereTest>> {};

TEST_P(CpuCull, NoFalseNegativesAndListsMatchBruteForce) {
    const auto [kind, algo, test] = GetParam();
    for (std::uint32_t seed : {1u, 2u}) {
        CullSettings st;
        st.algorithm = algo;
        st.test = test;
        st.cells = seed == 1 ? 32 : 5;
        st.slicing = seed == 1 ? Slicing::Log : Slicing::Linear;
        st.skipEmpty = seed == 1;
        const Scene scene = syntheticScene(kind, 67, 45, 8, 80, seed);
        const CullRun r = runCpu(scene, st);
        ASSERT_EQ(r.result.validate(r.lights.size()), "");
        EXPECT_EQ(r.result.backend, "cpu");
        EXPECT_GE(r.result.timings.cullMs, 0.0);
        ASSERT_GT(r.depth.geometryPixelCount(), 1000u);
        std::uint64_t exact = 0;
        EXPECT_EQ(falseNegatives(r, &exact), 0u) << toString(algo) << " " << toString(test);
        EXPECT_GT(exact, 0u); // the scene does exercise lights touching geometry
        const auto expected = bruteForceLists(r);
        for (std::size_t l = 0; l < expected.size(); ++l)
            ASSERT_EQ(listAt(r.result, std::uint32_t(l)), expected[l]) << "list " << l;
        // Every entry came from a test that passed (fptl's fine prune only
        // removes); `all` tests nothing.
        if (algo == Algorithm::All)
            EXPECT_EQ(r.result.volumeTests, 0u);
        else
            EXPECT_GE(r.result.volumeTests, r.result.entries()) << toString(algo);
    }
}

INSTANTIATE_TEST_SUITE_P(KindsAlgorithmsTests, CpuCull,
                         ::testing::Combine(::testing::ValuesIn(kKinds), ::testing::ValuesIn(kAlgorithms),
                                            ::testing::ValuesIn(kTests)),
                         [](const auto& info) {
                             std::string s = std::string(toString(std::get<0>(info.param))) + "_" +
                                             toString(std::get<1>(info.param)) + "_" +
                                             toString(std::get<2>(info.param));
                             for (char& ch : s)
                                 if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                             return s;
                         });

TEST(CpuCull, TighterTestsNeverListMore) {
    for (Algorithm algo : {Algorithm::Naive, Algorithm::MinMax, Algorithm::Clustered}) {
        std::uint64_t entries[3];
        for (int t = 0; t < 3; ++t) {
            CullSettings st;
            st.algorithm = algo;
            st.test = kTests[t];
            entries[t] = runCpu(syntheticScene(ProjectionKind::Perspective, 64, 48, 8, 100, 4), st).result.entries();
        }
        EXPECT_GE(entries[0], entries[1]);
        EXPECT_GE(entries[1], entries[2]);
        EXPECT_GT(entries[0], entries[2]) << toString(algo) << ": exact should cut something";
    }
}

TEST(CpuCull, NaiveIgnoresDepthOthersEmptyTheEmptyTiles) {
    const Scene scene = syntheticScene(ProjectionKind::Perspective, 64, 48, 8, 60, 9);
    Scene bare = scene;
    bare.meshes.clear();
    CullSettings st;
    st.algorithm = Algorithm::Naive;
    const CullRun a = runCpu(scene, st), b = runCpu(bare, st);
    EXPECT_EQ(a.result.listCount, b.result.listCount);
    EXPECT_EQ(a.result.lightIndices, b.result.lightIndices);
    EXPECT_GT(b.result.entries(), 0u);
    for (Algorithm algo : {Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
        st.algorithm = algo;
        st.skipEmpty = true;
        const CullRun e = runCpu(bare, st);
        EXPECT_EQ(e.result.entries(), 0u) << toString(algo);
        for (std::uint32_t t = 0; t < e.result.grid.tileCount(); ++t) {
            EXPECT_EQ(e.result.tileDepthMin[t], kInf);
            EXPECT_EQ(e.result.tileDepthMax[t], -kInf);
        }
    }
    // Clustered without skip-empty lists lights in clusters that hold no geometry.
    st.algorithm = Algorithm::Clustered;
    st.skipEmpty = false;
    EXPECT_GT(runCpu(bare, st).result.entries(), 0u);
}

TEST(CpuCull, LightInTheTopRowsLandsOnlyInTopTiles) {
    for (ProjectionKind kind : kKinds) {
        Scene s;
        s.camera = viewCamera(kind, 64, 48, 8);
        Mesh wall;
        addQuad(wall, {-100, -100, -10}, {100, -100, -10}, {100, 100, -10}, {-100, 100, -10});
        s.meshes.push_back(wall);
        PointLight l;
        l.position = {0.0, 3.0, -9.0}; // above the view axis, touching the wall
        l.explicitRadius = 1.5;
        s.lights.push_back(l);
        for (Algorithm algo : kAlgorithms) {
            if (algo == Algorithm::All) continue;
            CullSettings st;
            st.algorithm = algo;
            const CullRun r = runCpu(s, st);
            ASSERT_GT(r.result.entries(), 0u) << toString(algo);
            for (std::uint32_t list = 0; list < r.result.listCountTotal(); ++list) {
                if (r.result.listCount[list] == 0) continue;
                const std::uint32_t tile = list / r.result.listsPerTile;
                EXPECT_LT(tile / r.result.grid.tilesX, 3u) << toString(algo) << " kind " << int(kind);
            }
            EXPECT_EQ(falseNegatives(r), 0u);
        }
    }
}

TEST(CpuCull, ZeroAndOneLight) {
    for (Algorithm algo : kAlgorithms) {
        CullSettings st;
        st.algorithm = algo;
        const CullRun none = runCpu(syntheticScene(ProjectionKind::Perspective, 40, 30, 16, 0, 3), st);
        EXPECT_EQ(none.result.validate(0), "");
        EXPECT_EQ(none.result.entries(), 0u);
        Scene one = syntheticScene(ProjectionKind::Perspective, 40, 30, 16, 0, 3);
        PointLight l;
        l.position = {0, 0, -4};
        l.explicitRadius = 50;
        one.lights.push_back(l);
        const CullRun r = runCpu(one, st);
        EXPECT_EQ(r.result.validate(1), "");
        EXPECT_EQ(falseNegatives(r), 0u);
        EXPECT_GT(r.result.entries(), 0u);
    }
}

TEST(CpuCull, OddResolutions) {
    for (auto [w, h, t] : {std::tuple{1u, 1u, 16u}, std::tuple{17u, 9u, 4u}, std::tuple{17u, 9u, 16u}}) {
        for (Algorithm algo : kAlgorithms) {
            CullSettings st;
            st.algorithm = algo;
            const CullRun r = runCpu(syntheticScene(ProjectionKind::ReversedZ, w, h, t, 30, 5), st);
            EXPECT_EQ(r.result.validate(30), "");
            EXPECT_EQ(r.result.grid.tilesX, (w + t - 1) / t);
            EXPECT_EQ(falseNegatives(r), 0u) << w << "x" << h;
            const auto expected = bruteForceLists(r);
            for (std::size_t l = 0; l < expected.size(); ++l) EXPECT_EQ(listAt(r.result, std::uint32_t(l)), expected[l]);
        }
    }
}

TEST(CpuCull, Hd1366x768With16PixelTiles) {
    for (Algorithm algo : {Algorithm::Naive, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
        CullSettings st;
        st.algorithm = algo;
        const CullRun r = runCpu(syntheticScene(ProjectionKind::Perspective, 1366, 768, 16, 150, 8), st);
        EXPECT_EQ(r.result.grid.tilesX, 86u);
        EXPECT_EQ(r.result.grid.tilesY, 48u);
        EXPECT_EQ(r.result.validate(150), "");
        EXPECT_EQ(falseNegatives(r), 0u) << toString(algo);
    }
}

TEST(CullResult, BytesListOfPixelAndValidate) {
    CullSettings st;
    st.algorithm = Algorithm::HalfZ;
    CullRun r = runCpu(syntheticScene(ProjectionKind::Perspective, 64, 48, 8, 40, 6), st);
    const CullResult& res = r.result;
    const std::uint64_t tiles = 8 * 6;
    EXPECT_EQ(res.bytes(), 4 * res.entries() + 8 * (2 * tiles));
    EXPECT_EQ(res.diagnosticBytes(), 8 * tiles);
    // halfz: the split decides between the two lists.
    const std::uint32_t t = res.grid.tileOfPixel(20, 20);
    ASSERT_TRUE(std::isfinite(res.halfzSplit[t]));
    EXPECT_EQ(res.listOfPixel(20, 20, res.halfzSplit[t]), 2 * t);
    EXPECT_EQ(res.listOfPixel(20, 20, res.halfzSplit[t] * 1.0001), 2 * t + 1);

    st.algorithm = Algorithm::Clustered;
    st.cells = 8;
    const CullRun c = runCpu(syntheticScene(ProjectionKind::Perspective, 64, 48, 8, 40, 6), st);
    EXPECT_EQ(c.result.bytes(), 4 * c.result.entries() + 8 * (8 * tiles) + 8);
    EXPECT_EQ(c.result.diagnosticBytes(), 8 * tiles + 4 * tiles);
    EXPECT_EQ(c.result.listOfPixel(63, 47, 0.5), (tiles - 1) * 8);
    EXPECT_EQ(c.result.listOfPixel(63, 47, 60.0), (tiles - 1) * 8 + 7);

    // validate() notices broken results.
    ASSERT_GT(r.result.entries(), 1u);
    CullResult bad = r.result;
    EXPECT_NE(bad.validate(39), "") << "index 39 is out of range for 39 lights only if used";
    bad = r.result;
    bad.listCount[0] += 1000000;
    EXPECT_NE(bad.validate(40), "");
    bad = r.result;
    for (std::uint32_t l = 0; l < bad.listCountTotal(); ++l)
        if (bad.listCount[l] >= 2) {
            std::swap(bad.lightIndices[bad.listOffset[l]], bad.lightIndices[bad.listOffset[l] + 1]);
            break;
        }
    EXPECT_NE(bad.validate(40), "");
    bad = r.result;
    bad.listOffset.pop_back();
    EXPECT_NE(bad.validate(40), "");
}

TEST(Backends, RegistryAndViewLights) {
    auto cpu = makeBackend("cpu");
    EXPECT_EQ(cpu->name(), "cpu");
    EXPECT_FALSE(cpu->deviceName().empty());
    EXPECT_EQ(cpu->timingMethod(), "cpu-wall-clock (steady_clock)");
    EXPECT_THROW(makeBackend("metal"), Error);
    const auto names = availableBackends();
    ASSERT_FALSE(names.empty());
    EXPECT_EQ(names[0], "cpu");

    Scene s;
    s.camera.position = {0, 0, 5};
    s.camera.target = {0, 0, 0};
    PointLight l;
    l.position = {1, 2, 0};
    l.intensity = 4;
    l.color = {1, 0.5, 0.25};
    l.minIntensity = 0.01;
    s.lights.push_back(l);
    const ViewLights v = makeViewLights(s);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_NEAR(v.centers[0].x, 1, 1e-12);
    EXPECT_NEAR(v.centers[0].y, 2, 1e-12);
    EXPECT_NEAR(v.centers[0].z, -5, 1e-12);
    EXPECT_NEAR(v.radii[0], std::sqrt(4.0 / 0.01), 1e-9);
    EXPECT_NEAR(v.power[0].y, 2.0, 1e-12);

    s.lights.push_back(l);
    s.lights[1].minIntensity = 0.0;
    s.lights[1].name = "bad";
    try {
        makeViewLights(s);
        FAIL() << "expected LightError";
    } catch (const LightError& e) {
        EXPECT_EQ(e.index(), 1u);
        EXPECT_EQ(e.lightName(), "bad");
    }
}

// zbin: the bins are the ranges of sorted positions whose depth extent
// reaches them, no wider; a pixel's loop (mask within its bin's range) is what
// the ground truth counts as shading work; and the bins cut the masks' work.
TEST(CpuCull, ZBinBinsAreTightAndTheGroundTruthCountsThePixelsLoops) {
    const Scene scene = syntheticScene(ProjectionKind::Perspective, 96, 64, 16, 120, 11);
    CullSettings st;
    st.algorithm = Algorithm::ZBin;
    st.bins = 64;
    const CullRun r = runCpu(scene, st);
    const CullResult& z = r.result;
    ASSERT_EQ(z.validate(r.lights.size()), "");
    ASSERT_EQ(z.zbinLo.size(), 64u);
    // Sorted by centre depth.
    for (std::size_t k = 1; k < z.zbinOrder.size(); ++k)
        EXPECT_LE(-r.lights.centers[z.zbinOrder[k - 1]].z, -r.lights.centers[z.zbinOrder[k]].z);
    const double width = (z.zbinFar - z.zbinNear) / 64;
    std::size_t nonEmpty = 0;
    for (std::uint32_t b = 0; b < 64; ++b) {
        const double lo = z.zbinNear + b * width, hi = lo + width;
        // Brute force: the sorted positions whose extent overlaps [lo, hi].
        std::uint32_t first = ~0u, last = 0;
        for (std::uint32_t k = 0; k < z.zbinOrder.size(); ++k) {
            const std::uint32_t l = z.zbinOrder[k];
            const double d = -r.lights.centers[l].z, rad = r.lights.radii[l];
            if (d + rad >= lo - 1e-9 * hi && d - rad < hi + 1e-9 * hi) first = std::min(first, k), last = std::max(last, k);
        }
        if (first == ~0u) {
            EXPECT_GT(z.zbinLo[b], z.zbinHi[b]) << "bin " << b;
            continue;
        }
        ++nonEmpty;
        EXPECT_EQ(z.zbinLo[b], first) << "bin " << b;
        EXPECT_EQ(z.zbinHi[b], last) << "bin " << b;
    }
    EXPECT_GT(nonEmpty, 10u);
    // Shading work: per pixel, the mask's lights whose rank is in its bin's range.
    const Projection proj(scene.camera);
    std::uint64_t work = 0;
    for (std::uint32_t y = 0; y < r.depth.height; ++y)
        for (std::uint32_t x = 0; x < r.depth.width; ++x) {
            if (!r.depth.hasGeometry(x, y)) continue;
            const std::uint32_t t = z.grid.tileOfPixel(x, y), b = z.zbinOf(-proj.viewPositionFromDepth(x, y, r.depth.at(x, y)).z);
            for (std::uint32_t i = 0; i < z.listCount[t]; ++i) {
                const std::uint32_t k = z.zbinRank[z.lightIndices[z.listOffset[t] + i]];
                work += z.zbinLo[b] <= k && k <= z.zbinHi[b];
            }
        }
    GroundTruthOptions o;
    o.imageError = false;
    const GroundTruth gt = computeGroundTruth(r.depth, proj, r.lights, z, o);
    EXPECT_EQ(gt.metrics.shadingWork, work);
    EXPECT_EQ(gt.metrics.falseNegatives, 0u);
    std::uint64_t perTile = 0;
    for (std::uint64_t w : gt.listShadingWork) perTile += w;
    EXPECT_EQ(perTile, work);
    EXPECT_EQ(gt.listShadingWork.size(), z.listCount.size());
    // The masks are naive's lists; the bins cut the work a pixel loops over.
    st.algorithm = Algorithm::Naive;
    const CullRun naive = runCpu(scene, st);
    EXPECT_EQ(naive.result.lightIndices, z.lightIndices);
    EXPECT_LT(work, computeGroundTruth(naive.depth, proj, naive.lights, naive.result, o).metrics.shadingWork);
    EXPECT_EQ(z.bytes(), 4u * 64 + 4u * z.grid.tileCount() * ((r.lights.size() + 31) / 32));
}

// PixelListLookup (every pixel of a result) names the list listOfPixel
// names, for every algorithm and both slicings, at every pixel's depth.
TEST(CpuCull, PixelListLookupIsListOfPixel) {
    Scene s = makeBuiltinScene("atrium");
    s.lights = generateLights(defaultLightGen(s, 40, 3));
    s.camera.width = 96;
    s.camera.height = 64;
    const Projection proj(s.camera);
    const DepthImage depth = rasterizeDepthCpu(s, proj);
    const ViewLights lights = makeViewLights(s);
    const TileGrid grid = TileGrid::make(s.camera.width, s.camera.height, 16);
    auto backend = makeCpuBackend();
    std::size_t compared = 0;
    for (const Algorithm a : {Algorithm::All, Algorithm::Naive, Algorithm::HalfZ, Algorithm::TwoPointFiveD,
                              Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin})
        for (const Slicing sl : {Slicing::Log, Slicing::Linear}) {
            CullSettings cs;
            cs.algorithm = a;
            cs.cells = 8;
            cs.slicing = sl;
            const CullResult r = backend->cull(depth, proj, grid, lights, cs);
            const PixelListLookup lookup(r);
            for (std::uint32_t y = 0; y < depth.height; ++y)
                for (std::uint32_t x = 0; x < depth.width; ++x) {
                    if (!depth.hasGeometry(x, y)) continue;
                    const double d = proj.viewDepthFromWindowDepth(depth.at(x, y));
                    ASSERT_EQ(lookup(x, y, d), r.listOfPixel(x, y, d)) << toString(a) << " at " << x << "," << y;
                    ++compared;
                }
        }
    EXPECT_GT(compared, 10000u);
}
