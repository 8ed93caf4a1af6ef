// The Vulkan culling passes against the CPU reference on IDENTICAL depth input
// (the CPU rasteriser's depth fed to both culls, and separately the GPU's):
// every GPU list is a superset of the CPU list (the GPU is conservative near
// planes and bounds, within float rounding), the number of extra entries is
// reported and small, and false_negatives = 0 against the ground truth. Also:
// edge tiles, 0 / 1 / 65,536 lights, more lights than a workgroup has
// invocations, and determinism. Validation is on; any message fails.
#include "gpu_test_env.hpp"

#include "culling/core/depth.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

const Algorithm kAlgorithms[] = {Algorithm::All,    Algorithm::Naive,         Algorithm::MinMax,
                                 Algorithm::HalfZ,  Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin};
const SphereTest kTests[] = {SphereTest::Planes, SphereTest::PlanesAabb, SphereTest::Exact};

struct Comparison {
    std::uint64_t cpuEntries = 0, gpuEntries = 0, extra = 0, missing = 0;
    std::string firstMissing;
};

// GPU lists must contain every CPU entry (both sorted ascending).
Comparison compareLists(const CullResult& cpu, const CullResult& gpu) {
    Comparison c;
    c.cpuEntries = cpu.entries();
    c.gpuEntries = gpu.entries();
    const std::size_t lists = std::min(cpu.listCount.size(), gpu.listCount.size());
    for (std::size_t l = 0; l < lists; ++l) {
        const auto cb = cpu.lightIndices.begin() + cpu.listOffset[l], ce = cb + cpu.listCount[l];
        const auto gb = gpu.lightIndices.begin() + gpu.listOffset[l], ge = gb + gpu.listCount[l];
        std::vector<std::uint32_t> lost;
        std::set_difference(cb, ce, gb, ge, std::back_inserter(lost));
        if (!lost.empty() && c.firstMissing.empty())
            c.firstMissing = "list " + std::to_string(l) + " (tile " + std::to_string(l / cpu.listsPerTile) +
                             ") lacks light " + std::to_string(lost[0]);
        c.missing += lost.size();
        c.extra += gpu.listCount[l] - (cpu.listCount[l] - lost.size());
    }
    return c;
}

struct CaseReport {
    std::uint64_t extra = 0, entries = 0;
};

// Culls `depth` on both backends with `settings` and checks everything the
// issue asks; returns the extras for the caller's summary.
CaseReport checkCase(const std::string& label, const DepthImage& depth, const Projection& proj,
                     const TileGrid& grid, const ViewLights& lights, const CullSettings& settings,
                     CullBackend& cpuBackend, CullBackend& gpuBackend = gputest::vulkan()) {
    SCOPED_TRACE(label);
    const CullResult cpu = cpuBackend.cull(depth, proj, grid, lights, settings);
    const CullResult gpu = gpuBackend.cull(depth, proj, grid, lights, settings);
    EXPECT_EQ(gpu.validate(lights.size()), "");
    EXPECT_EQ(gpu.backend, "vulkan");
    EXPECT_FALSE(gpu.timingMethod.empty());
    EXPECT_GE(gpu.timings.cullMs, 0.0);
    EXPECT_EQ(gpu.listsPerTile, cpu.listsPerTile);
    EXPECT_EQ(gpu.listCountTotal(), cpu.listCountTotal());
    if (gpu.listCountTotal() != cpu.listCountTotal()) return {};

    // Per-tile bounds: the same tiles are empty; float bounds within rounding.
    for (std::uint32_t t = 0; t < grid.tileCount(); ++t) {
        const bool ce = !(cpu.tileDepthMin[t] <= cpu.tileDepthMax[t]);
        const bool ge = !(gpu.tileDepthMin[t] <= gpu.tileDepthMax[t]);
        EXPECT_EQ(ce, ge) << "tile " << t;
        if (ce || ge) continue;
        EXPECT_NEAR(gpu.tileDepthMin[t], cpu.tileDepthMin[t], 1e-5 * cpu.tileDepthMin[t] + 1e-6) << "tile " << t;
        EXPECT_NEAR(gpu.tileDepthMax[t], cpu.tileDepthMax[t], 1e-5 * cpu.tileDepthMax[t] + 1e-6) << "tile " << t;
        // Clustered slices share one range: the GPU marks every slice the CPU
        // marks (and, within rounding of a boundary, its neighbour too).
        if (settings.algorithm == Algorithm::Clustered)
            EXPECT_EQ(gpu.cellMask[t] & cpu.cellMask[t], cpu.cellMask[t]) << "tile " << t;
    }
    if (settings.algorithm == Algorithm::Clustered) {
        EXPECT_EQ(gpu.clusterNear, cpu.clusterNear);
        EXPECT_EQ(gpu.clusterFar, cpu.clusterFar);
    }

    const Comparison cmp = compareLists(cpu, gpu);
    EXPECT_EQ(cmp.missing, 0u) << "GPU lists lack " << cmp.missing << " CPU entries; first: " << cmp.firstMissing;
    // "Small": extras only arise where a light touches a plane or bound within
    // float rounding (relative 2e-5 widening), a tiny share of the entries.
    EXPECT_LE(cmp.extra, 8 + cmp.cpuEntries / 200) << "too many extra GPU entries";

    GroundTruthOptions opt;
    opt.imageError = false;
    const GroundTruth truth = computeGroundTruth(depth, proj, lights, gpu, opt);
    EXPECT_EQ(truth.metrics.falseNegatives, 0u);
    return {cmp.extra, cmp.cpuEntries};
}

CaseReport checkCase(const std::string& label, const gputest::Frame& f, const CullSettings& settings,
                     CullBackend& cpuBackend, CullBackend& gpuBackend = gputest::vulkan()) {
    return checkCase(label, f.depth, f.proj, f.grid, f.lights, settings, cpuBackend, gpuBackend);
}

// A Vulkan backend on the GPU work layout even on lavapipe
// (LIGHTCULL_VK_EMULATE_GPU=1 while it is made): device-local buffers
// behind staging copies, a subgroup per tile and list, GPU timestamps.
std::unique_ptr<CullBackend> makeEmulatedGpuBackend() {
    setenv("LIGHTCULL_VK_EMULATE_GPU", "1", 1);
    std::unique_ptr<CullBackend> b = makeVulkanBackend("");
    unsetenv("LIGHTCULL_VK_EMULATE_GPU");
    return b;
}

Scene sized(const std::string& name, std::uint32_t w, std::uint32_t h, std::uint32_t tile = 16) {
    Scene s = makeBuiltinScene(name);
    s.camera.width = w;
    s.camera.height = h;
    s.camera.tileSize = tile;
    return s;
}

class VulkanCullScene : public GpuTest, public ::testing::WithParamInterface<std::string> {};

// Every built-in scene x every algorithm x every sphere test x both depth sources.
TEST_P(VulkanCullScene, SupersetOfCpuAndNoFalseNegatives) {
    const Scene scene = sized(GetParam(), 320, 180);
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    const ViewLights lights = makeViewLights(scene);
    auto cpuBackend = makeCpuBackend();
    const DepthImage depths[2] = {rasterizeDepthCpu(scene, proj), gputest::vulkan().renderDepth(scene, proj)};
    const char* depthNames[2] = {"cpu-depth", "gpu-depth"};
    for (int d = 0; d < 2; ++d) {
        for (Algorithm a : kAlgorithms) {
            for (SphereTest t : kTests) {
                if (a == Algorithm::All && t != SphereTest::Planes) continue; // no test involved
                CullSettings s;
                s.algorithm = a;
                s.test = t;
                s.cells = 16;
                const std::string label = GetParam() + " " + depthNames[d] + " " + toString(a) + " " + toString(t);
                const CaseReport r = checkCase(label, depths[d], proj, grid, lights, s, *cpuBackend);
                std::printf("[ cull     ] %-44s entries %8llu  extra on GPU %5llu\n", label.c_str(),
                            (unsigned long long)r.entries, (unsigned long long)r.extra);
            }
        }
    }
}

INSTANTIATE_TEST_SUITE_P(Builtins, VulkanCullScene,
                         ::testing::Values("atrium", "forest", "mountain", "wall", "sky"));

// Projection kinds other than the default, including reversed-Z with an
// infinite far plane (naive and clustered then use the farthest light reach),
// linear slicing and clustered without skip-empty.
TEST_F(GpuTest, ProjectionKindsAndSlicing) {
    auto cpuBackend = makeCpuBackend();
    struct K {
        ProjectionKind kind;
        double far;
    };
    const K kinds[] = {{ProjectionKind::ReversedZ, std::numeric_limits<double>::infinity()},
                       {ProjectionKind::ReversedZ, 800.0},
                       {ProjectionKind::PerspectiveGL, 1000.0},
                       {ProjectionKind::Orthographic, 1000.0},
                       {ProjectionKind::OrthographicGL, 1000.0}};
    for (const K& k : kinds) {
        Scene scene = sized("mountain", 256, 144);
        scene.camera.projection = k.kind;
        scene.camera.farPlane = k.far;
        if (isOrthographic(k.kind)) scene.camera.orthoHeight = 60.0;
        const gputest::Frame f(scene, nullptr);
        for (Algorithm a : kAlgorithms) {
            for (Slicing sl : {Slicing::Log, Slicing::Linear}) {
                if (sl == Slicing::Linear && a != Algorithm::TwoPointFiveD && a != Algorithm::Clustered) continue;
                for (bool skip : {true, false}) {
                    if (!skip && a != Algorithm::Clustered) continue;
                    CullSettings s;
                    s.algorithm = a;
                    s.test = SphereTest::Exact;
                    s.slicing = sl;
                    s.skipEmpty = skip;
                    s.cells = 32;
                    const std::string label = std::string(toString(k.kind)) + (std::isinf(k.far) ? "-inf " : " ") +
                                              toString(a) + " " + toString(sl) + (skip ? "" : " no-skip");
                    const CaseReport r = checkCase(label, f, s, *cpuBackend);
                    std::printf("[ cull     ] %-44s entries %8llu  extra on GPU %5llu\n", label.c_str(),
                                (unsigned long long)r.entries, (unsigned long long)r.extra);
                }
            }
        }
    }
}

// Partial edge tiles: 1366 = 85*16 + 6 columns; and a size partial both ways.
TEST_F(GpuTest, EdgeTilesOfNonMultipleResolutions) {
    auto cpuBackend = makeCpuBackend();
    for (auto [w, h] : {std::pair<std::uint32_t, std::uint32_t>{1366, 768}, {333, 187}}) {
        const Scene scene = sized("atrium", w, h);
        const gputest::Frame f(scene);
        for (Algorithm a : {Algorithm::MinMax, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
            CullSettings s;
            s.algorithm = a;
            s.test = SphereTest::PlanesAabb;
            const std::string label = std::to_string(w) + "x" + std::to_string(h) + " " + toString(a);
            const CaseReport r = checkCase(label, f, s, *cpuBackend);
            std::printf("[ cull     ] %-44s entries %8llu  extra on GPU %5llu\n", label.c_str(),
                        (unsigned long long)r.entries, (unsigned long long)r.extra);
        }
    }
}

// Lights built to touch a tile's far bound or a side plane within float
// rounding (the sphere reaches it by 1e-7 of its radius): the CPU
// reference keeps them, so the GPU must too. This is where the relative
// widening of the float passes matters (with it off, this test fails).
TEST_F(GpuTest, LightsTouchingBoundsWithinRounding) {
    auto cpuBackend = makeCpuBackend();
    Scene scene = sized("wall", 320, 180);
    scene.lights.clear();
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(320, 180, 16);
    const DepthImage depth = rasterizeDepthCpu(scene, proj);
    CullSettings mm;
    mm.algorithm = Algorithm::MinMax;
    const CullResult bounds = cpuBackend->cull(depth, proj, grid, makeViewLights(scene), mm);
    const glm::dmat4 worldFromView = glm::inverse(scene.camera.viewFromWorld());
    const double r = 0.37, touch = 1.0 - 1e-7;
    for (std::uint32_t ty = 0; ty < grid.tilesY; ty += 2) {
        for (std::uint32_t tx = 0; tx < grid.tilesX; tx += 3) {
            const std::uint32_t t = grid.tileIndex(tx, ty);
            const auto rect = grid.tileRect(tx, ty);
            const glm::dvec2 centre(0.5 * (rect.x0 + rect.x1), 0.5 * (rect.y0 + rect.y1));
            const double dmax = bounds.tileDepthMax[t];
            // Behind the wall, reaching the tile's far bound by a hair.
            const glm::dvec3 behind = proj.viewPositionAt(centre, dmax + r * touch);
            // On the wall, left of the tile's left edge: the nearest point of the
            // (flat, min == max) chunk is on that edge, r * touch away.
            const glm::dvec3 onEdge = proj.viewPositionAt({double(rect.x0), centre.y}, dmax);
            const glm::dvec3 outside = onEdge - glm::dvec3(r * touch, 0.0, 0.0);
            for (const glm::dvec3& v : {behind, outside}) {
                PointLight l;
                l.position = glm::dvec3(worldFromView * glm::dvec4(v, 1.0));
                l.explicitRadius = r;
                scene.lights.push_back(l);
            }
        }
    }
    const ViewLights lights = makeViewLights(scene);
    for (Algorithm a : {Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD, Algorithm::Clustered})
        for (SphereTest t : kTests) {
            CullSettings s;
            s.algorithm = a;
            s.test = t;
            const std::string label = std::string("touching ") + toString(a) + " " + toString(t);
            const CaseReport rep = checkCase(label, depth, proj, grid, lights, s, *cpuBackend);
            std::printf("[ cull     ] %-44s entries %8llu  extra on GPU %5llu\n", label.c_str(),
                        (unsigned long long)rep.entries, (unsigned long long)rep.extra);
        }
}

TEST_F(GpuTest, ZeroLightsGiveEmptyLists) {
    Scene scene = sized("wall", 200, 120);
    scene.lights.clear();
    const gputest::Frame f(scene);
    for (Algorithm a : kAlgorithms) {
        CullSettings s;
        s.algorithm = a;
        const CullResult r = f.cull(gputest::vulkan(), s);
        EXPECT_EQ(r.validate(0), "") << toString(a);
        EXPECT_EQ(r.entries(), 0u) << toString(a);
        EXPECT_EQ(r.listCountTotal(), a == Algorithm::All ? 1u : f.grid.tileCount() * r.listsPerTile);
        // The wall fills the screen: every tile still gets its depth bounds.
        for (std::uint32_t t = 0; t < f.grid.tileCount(); ++t) EXPECT_LE(r.tileDepthMin[t], r.tileDepthMax[t]);
    }
}

TEST_F(GpuTest, OneLight) {
    auto cpuBackend = makeCpuBackend();
    Scene scene = sized("atrium", 320, 180);
    scene.lights.resize(1);
    scene.lights[0].position = 0.5 * (scene.bounds().first + scene.bounds().second);
    scene.lights[0].explicitRadius = 4.0;
    const gputest::Frame f(scene, nullptr);
    std::uint64_t entries = 0;
    for (Algorithm a : kAlgorithms)
        for (SphereTest t : kTests) {
            CullSettings s;
            s.algorithm = a;
            s.test = t;
            entries += checkCase(std::string("one light ") + toString(a) + " " + toString(t), f, s, *cpuBackend)
                           .entries;
        }
    EXPECT_GT(entries, 0u) << "the light should touch some tiles";
}

// 65,536 lights (a small resolution keeps the CPU reference quick).
TEST_F(GpuTest, SixtyFiveThousandLights) {
    auto cpuBackend = makeCpuBackend();
    Scene scene = sized("atrium", 128, 72);
    scene.lights = generateLights(defaultLightGen(scene, 65536, 11));
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(128, 72, 16);
    const ViewLights lights = makeViewLights(scene);
    ASSERT_EQ(lights.size(), 65536u);
    const DepthImage depth = gputest::vulkan().renderDepth(scene, proj);
    for (Algorithm a : {Algorithm::All, Algorithm::MinMax, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
        CullSettings s;
        s.algorithm = a;
        s.cells = 8;
        const std::string label = std::string("65536 lights ") + toString(a);
        const CaseReport r = checkCase(label, depth, proj, grid, lights, s, *cpuBackend);
        std::printf("[ cull     ] %-44s entries %8llu  extra on GPU %5llu\n", label.c_str(),
                    (unsigned long long)r.entries, (unsigned long long)r.extra);
    }
}

// Far more lights than invocations per workgroup, all touching every tile:
// every list must hold all of them, ascending (the classic one-light-per-
// invocation bug keeps only the first workgroup-size lights).
TEST_F(GpuTest, MoreLightsThanWorkgroupInvocations) {
    Scene scene = sized("wall", 96, 64);
    const std::uint32_t n = 1000;
    scene.lights.assign(n, PointLight{});
    for (std::uint32_t i = 0; i < n; ++i) {
        scene.lights[i].position = {0.001 * i, 0.0, 5.0};
        scene.lights[i].explicitRadius = 500.0;
    }
    const gputest::Frame f(scene);
    for (Algorithm a : kAlgorithms) {
        CullSettings s;
        s.algorithm = a;
        const CullResult r = f.cull(gputest::vulkan(), s);
        ASSERT_EQ(r.validate(n), "");
        std::size_t full = 0;
        for (std::size_t l = 0; l < r.listCount.size(); ++l) {
            if (r.listCount[l] == 0) continue; // clustered: slices without geometry
            ASSERT_EQ(r.listCount[l], n) << toString(a) << " list " << l;
            for (std::uint32_t i = 0; i < n; ++i) ASSERT_EQ(r.lightIndices[r.listOffset[l] + i], i);
            ++full;
        }
        EXPECT_GE(full, a == Algorithm::All ? 1u : f.grid.tileCount()) << toString(a);
    }
}

TEST_F(GpuTest, ResultsAreDeterministic) {
    const Scene scene = sized("forest", 240, 136);
    const gputest::Frame f(scene);
    CullSettings s;
    s.algorithm = Algorithm::Clustered;
    const CullResult a = f.cull(gputest::vulkan(), s);
    const CullResult b = f.cull(gputest::vulkan(), s);
    EXPECT_EQ(a.listOffset, b.listOffset);
    EXPECT_EQ(a.listCount, b.listCount);
    EXPECT_EQ(a.lightIndices, b.lightIndices);
    EXPECT_EQ(a.cellMask, b.cellMask);
}

// The GPU work layout (a subgroup per tile and per list, wide scan,
// device-local buffers behind staging copies, timestamps), forced onto
// lavapipe by LIGHTCULL_VK_EMULATE_GPU=1 so that CI runs the code a real GPU
// runs: the same lists as the CPU layout, bit for bit (same float tests, exact
// min/max/or reductions), hence the same superset of the CPU reference.
TEST_F(GpuTest, GpuWorkLayoutEmulatedOnLavapipe) {
    std::unique_ptr<CullBackend> emulated = makeEmulatedGpuBackend();
    // On a GPU (the device tool's H100) both backends take the GPU layout.
    if (gputest::vulkan().timingMethod().find("cpu-wall-clock") != std::string::npos)
        EXPECT_NE(emulated->timingMethod(), gputest::vulkan().timingMethod());
    EXPECT_NE(emulated->timingMethod().find("gpu-timestamps"), std::string::npos);
    auto cpuBackend = makeCpuBackend();
    // 333x187: partial edge tiles both ways; 500 lights: 16 mask words, so
    // lanes hold several words (8 lanes on lavapipe). 332 wide: the bounds
    // pass loads 4 pixels a lane (a width of whole loads), few enough loads a
    // lane that 2.5d's cell walk takes them from registers (tile_bounds.comp,
    // KEEP); 333: a pixel a load, loaded again.
    for (const std::uint32_t width : {333u, 332u})
    for (const char* name : {"forest", "atrium"}) {
        Scene scene = sized(name, width, 187);
        scene.lights = generateLights(defaultLightGen(scene, 500, 5));
        const Projection proj(scene.camera);
        const TileGrid grid = TileGrid::make(width, 187, 16);
        const ViewLights lights = makeViewLights(scene);
        const DepthPass pass = emulated->depthPass(scene, proj);
        const DepthImage& depth = pass.image;
        EXPECT_GE(pass.ms, 0.0);
        const DepthImage cpuLayoutDepth = gputest::vulkan().renderDepth(scene, proj);
        EXPECT_EQ(depth.depth, cpuLayoutDepth.depth) << "staged vertex upload changed the depth";
        for (Algorithm a : kAlgorithms) {
            for (SphereTest t : {SphereTest::Planes, SphereTest::Exact}) {
                if (t == SphereTest::Exact && (width != 333 || (a != Algorithm::TwoPointFiveD && a != Algorithm::Clustered)))
                    continue;
                CullSettings st;
                st.algorithm = a;
                st.test = t;
                st.cells = 16;
                const std::string label = std::string("emulated gpu ") + std::to_string(width) + " wide " + name + " " +
                                          toString(a) + " " + toString(t);
                checkCase(label, depth, proj, grid, lights, st, *cpuBackend, *emulated);
                const CullResult g = emulated->cull(depth, proj, grid, lights, st);
                const CullResult c = gputest::vulkan().cull(depth, proj, grid, lights, st);
                EXPECT_EQ(g.listCount, c.listCount) << label;
                EXPECT_EQ(g.listOffset, c.listOffset) << label;
                EXPECT_EQ(g.lightIndices, c.lightIndices) << label;
                EXPECT_EQ(g.cellMask, c.cellMask) << label;
                EXPECT_EQ(g.tileDepthMin, c.tileDepthMin) << label;
                EXPECT_EQ(g.tileDepthMax, c.tileDepthMax) << label;
                // clustered: lavapipe walks a tile's slices together (tested
                // in ClusteredTileWalkMatchesTheListWalk), so it counts its
                // tests per (light, slice) of a light's slice range.
                if (a != Algorithm::Clustered) EXPECT_EQ(g.volumeTests, c.volumeTests) << label;
                EXPECT_GE(g.timings.cullMs, 0.0) << label;
            }
        }
    }
}

// Staged downloads go back in copy commands of at most 512 KiB each
// (vulkan_backend.cpp, kDownloadRegion). On the emulated GPU layout a depth
// image of 2.4 MB (four whole regions and part of a fifth) and lists of more
// than 512 KiB must come back whole: the same as the CPU layout's, which
// reads its buffers in place.
TEST_F(GpuTest, DownloadsLargerThanOneCopyRegionComeBackWhole) {
    std::unique_ptr<CullBackend> emulated = makeEmulatedGpuBackend();
    Scene scene = sized("atrium", 1000, 600);
    scene.lights = generateLights(defaultLightGen(scene, 2000, 11));
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(1000, 600, 16);
    const ViewLights lights = makeViewLights(scene);
    const DepthImage depth = emulated->renderDepth(scene, proj);
    EXPECT_EQ(depth.depth, gputest::vulkan().renderDepth(scene, proj).depth);
    CullSettings st;
    st.algorithm = Algorithm::Naive; // every light in every tile its sphere covers on screen
    for (int run = 0; run < 2; ++run) { // the second into the buffers the first sized
        const CullResult g = emulated->cull(depth, proj, grid, lights, st);
        const CullResult c = gputest::vulkan().cull(depth, proj, grid, lights, st);
        ASSERT_GT(g.entries() * (emulated->lastDeviceIndexBits() / 8), 3u * 512 * 1024) << run;
        EXPECT_EQ(g.listCount, c.listCount) << run;
        EXPECT_EQ(g.lightIndices, c.lightIndices) << run;
        EXPECT_EQ(g.tileDepthMin, c.tileDepthMin) << run;
    }
}

// clustered on lavapipe walks a tile's slices in one invocation per up to 32
// slices (cull_lists.comp, clusteredTileWalk; fewer where the lights would
// take the walk's loops past the driver's cap); the emulated GPU layout walks
// each list alone. Their lists must be identical wherever the slice range of
// a light could go wrong: log and linear slices, slice counts that are not
// powers of 2, a tile's 32 slices split over two walks (2,000 lights),
// skip-empty on and off, spot cones by sphere and by planes,
// every sphere test, an orthographic and a reversed-Z infinite camera; lists
// longer than the stash (the write pass walks again) and an index array
// sized from a smaller cull (lists left to the second submission).
TEST_F(GpuTest, ClusteredTileWalkMatchesTheListWalk) {
    std::unique_ptr<CullBackend> listWalk = makeEmulatedGpuBackend();
    std::unique_ptr<CullBackend> tileWalk = makeVulkanBackend("");
    auto cpuBackend = makeCpuBackend();
    struct Case {
        const char* scene;
        ProjectionKind projection;
        std::uint32_t lights, cells;
        Slicing slicing;
        bool skipEmpty;
        SpotTest spot;
        SphereTest test;
    };
    const Case cases[] = {
        {"forest", ProjectionKind::Perspective, 600, 32, Slicing::Log, true, SpotTest::ApexSphere, SphereTest::Planes},
        {"atrium", ProjectionKind::Perspective, 600, 13, Slicing::Linear, false, SpotTest::ConeSphere,
         SphereTest::Exact},
        {"atrium", ProjectionKind::ReversedZ, 600, 5, Slicing::Log, true, SpotTest::ConePlanes,
         SphereTest::PlanesAabb},
        {"forest", ProjectionKind::Orthographic, 600, 20, Slicing::Linear, true, SpotTest::ConeSphere,
         SphereTest::Planes},
        // 2,000 lights: 16 slices a walk (vulkan_backend.cpp), two walks a tile.
        {"forest", ProjectionKind::Perspective, 2000, 32, Slicing::Log, true, SpotTest::ApexSphere,
         SphereTest::PlanesAabb},
        // One slice over the whole range: lists far longer than the stash.
        {"atrium", ProjectionKind::Perspective, 1500, 1, Slicing::Log, false, SpotTest::ApexSphere,
         SphereTest::Planes},
    };
    for (const Case& k : cases) {
        Scene scene = sized(k.scene, 333, 187);
        scene.camera.projection = k.projection;
        if (k.projection == ProjectionKind::ReversedZ) scene.camera.farPlane = std::numeric_limits<double>::infinity();
        LightGenSettings gen = defaultLightGen(scene, k.lights, 11);
        gen.spotFraction = 0.5;
        scene.lights = generateLights(gen);
        const gputest::Frame f(scene);
        CullSettings st;
        st.algorithm = Algorithm::Clustered;
        st.cells = k.cells;
        st.slicing = k.slicing;
        st.skipEmpty = k.skipEmpty;
        st.spotTest = k.spot;
        st.test = k.test;
        const std::string label = std::string(k.scene) + " " + toString(k.projection) + " cells " +
                                  std::to_string(k.cells) + " " + toString(k.spot) + " " + toString(k.test);
        checkCase(label, f, st, *cpuBackend, *tileWalk);
        const CullResult w = f.cull(*tileWalk, st), l = f.cull(*listWalk, st);
        EXPECT_EQ(w.listCount, l.listCount) << label;
        EXPECT_EQ(w.lightIndices, l.lightIndices) << label;
        EXPECT_GT(w.entries(), 0u) << label;
        // The same backend, a cull of fewer lights first: the next cull's
        // index array is sized from it and too small.
        Scene fewer = scene;
        fewer.lights.resize(k.lights / 10);
        (void)gputest::Frame(fewer).cull(*tileWalk, st);
        const CullResult again = f.cull(*tileWalk, st);
        EXPECT_EQ(again.lightIndices, l.lightIndices) << label << ", after a smaller cull";
    }
}

// Result bytes follow the entries: bytes() <= 4 x entries + 8 x lists + 4 KiB
// on real scenes for every algorithm and both backends, and the halfz packing
// bytes() assumes (a tile's far list starts where its near list ends) holds.
TEST_F(GpuTest, ResultBytesFollowTheEntries) {
    auto cpuBackend = makeCpuBackend();
    for (const char* name : {"forest", "atrium"}) {
        Scene scene = sized(name, 640, 360);
        scene.lights = generateLights(defaultLightGen(scene, 2048, 3));
        const gputest::Frame f(scene);
        for (Algorithm a : kAlgorithms) {
            CullSettings st;
            st.algorithm = a;
            for (CullBackend* b : {static_cast<CullBackend*>(cpuBackend.get()), &gputest::vulkan()}) {
                const CullResult r = f.cull(*b, st);
                const std::string label = std::string(name) + " " + toString(a) + " " + r.backend;
                const std::uint64_t lists = r.listCountTotal();
                if (a == Algorithm::ZBin) {
                    // The renderer's form: a 32-bit range per bin, a bit per light per tile.
                    EXPECT_EQ(r.bytes(), 4 * std::uint64_t(st.bins) +
                                             4 * std::uint64_t(f.grid.tileCount()) * ((f.lights.size() + 31) / 32))
                        << label;
                } else {
                    EXPECT_LE(r.bytes(), 4 * r.entries() + 8 * lists + 4096) << label;
                    EXPECT_GE(r.bytes(), 4 * r.entries() + 8 * lists) << label;
                }
                EXPECT_EQ(r.diagnosticBytes(), 8 * std::uint64_t(f.grid.tileCount()) + 4 * r.cellMask.size()) << label;
                if (a == Algorithm::HalfZ)
                    for (std::uint32_t t = 0; t < f.grid.tileCount(); ++t)
                        ASSERT_EQ(r.listOffset[2 * t + 1], r.listOffset[2 * t] + r.listCount[2 * t]) << label;
            }
        }
    }
}

// Device memory accounting: the peak of a cull covers the buffers it must
// hold (depth, light bins, counts, offsets, indices), and every byte is given
// back afterwards (live memory before == after). Nothing per tile x light:
// at 65,536 lights the peak stays far below tiles x lights x 4 bytes.
// A rendered depth image whose pixels changed after the render, its id kept
// (a caller that forgot to reset deviceCopy), an older render's image, and
// another backend's: the cull reads the pixels it is given, not the device's
// copy.
TEST_F(GpuTest, TheCullReadsTheDepthItIsGiven) {
    CullBackend& vk = gputest::vulkan();
    Scene scene = sized("atrium", 320, 180);
    scene.lights = generateLights(defaultLightGen(scene, 256, 4));
    const gputest::Frame f(scene, &vk);
    ASSERT_NE(f.depth.deviceCopy, 0u) << "the Vulkan depth is not kept on the device";
    CullSettings st;
    st.algorithm = Algorithm::MinMax;
    DepthImage cleared = f.depth; // every pixel empty, the render's id kept
    std::fill(cleared.depth.begin(), cleared.depth.end(), cleared.clearDepth);
    const CullResult fromCleared = vk.cull(cleared, f.proj, f.grid, f.lights, st);
    EXPECT_EQ(fromCleared.entries(), 0u) << "culled the device's copy instead of the pixels given";
    const CullResult before = f.cull(vk, st);
    ASSERT_GT(before.entries(), 0u);
    Scene other = scene;
    other.camera.position += glm::dvec3(0.0, 0.5, 0.0);
    (void)vk.renderDepth(other, Projection(other.camera)); // replaces the device's copy
    const CullResult after = f.cull(vk, st);
    EXPECT_EQ(after.lightIndices, before.lightIndices);
    EXPECT_EQ(after.tileDepthMax, before.tileDepthMax);
    // Two fresh backends' first renders: their ids differ, so an image one
    // rendered never names the other's copy; each culls the other's pixels.
    std::unique_ptr<CullBackend> a = makeVulkanBackend(""), b = makeVulkanBackend("");
    const DepthImage fromA = a->renderDepth(scene, f.proj);
    const DepthImage fromB = b->renderDepth(other, Projection(other.camera));
    EXPECT_NE(fromA.deviceCopy, fromB.deviceCopy);
    const CullResult bOnA = a->cull(fromB, f.proj, f.grid, f.lights, st);
    const CullResult bOnB = b->cull(fromB, f.proj, f.grid, f.lights, st);
    EXPECT_EQ(bOnA.lightIndices, bOnB.lightIndices);
    EXPECT_EQ(bOnA.tileDepthMax, bOnB.tileDepthMax);
}

// The cull keeps its buffers for the next one (BufferCache): a repeated cull
// of the same frame allocates no device memory, and what it holds is what
// its lists need and at most about four times that, also after a larger
// cull (65,536 lights, then 64).
TEST_F(GpuTest, DeviceMemoryKeptAndBounded) {
    std::unique_ptr<CullBackend> vk = makeVulkanBackend(""); // holds only this test's buffers
    std::size_t beforeCull = 0;
    for (std::uint32_t n : {65536u, 64u}) {
        Scene scene = sized("forest", 480, 270);
        scene.lights = generateLights(defaultLightGen(scene, n, 9));
        const gputest::Frame f(scene, vk.get());
        if (beforeCull == 0) {
            vk->resetPeakDeviceBytes();
            beforeCull = vk->peakDeviceBytes(); // the depth image and the depth pass's buffers
        }
        CullSettings st;
        st.algorithm = Algorithm::TwoPointFiveD;
        // A depth image the backend did not render (this one's pixels, no
        // device copy): the cull uploads it.
        DepthImage uploaded = f.depth;
        uploaded.deviceCopy = 0;
        // The first culls size the buffers (and a CPU device's stash, from
        // the longest list before).
        (void)f.cull(*vk, st);
        (void)vk->cull(uploaded, f.proj, f.grid, f.lights, st);
        vk->resetPeakDeviceBytes();
        const std::size_t held = vk->peakDeviceBytes();
        const std::uint64_t allocations = vk->deviceAllocations();
        const CullResult r = vk->cull(uploaded, f.proj, f.grid, f.lights, st);
        const CullResult resident = f.cull(*vk, st);
        EXPECT_EQ(vk->deviceAllocations(), allocations)
            << n << " lights: a repeated cull allocated device memory";
        EXPECT_EQ(vk->peakDeviceBytes(), held) << n << " lights";
        EXPECT_EQ(resident.lightIndices, r.lightIndices);
        EXPECT_EQ(resident.listCount, r.listCount);
        EXPECT_EQ(resident.tileDepthMin, r.tileDepthMin);
        const std::uint64_t words = (n + 31) / 32;
        const std::uint64_t depthBytes = 480ull * 270 * 4;
        const std::uint64_t needed = depthBytes + 4 * words * (f.grid.tilesX + f.grid.tilesY) +
                                     8ull * r.listCountTotal() + 2 * r.entries();
        // A GPU also keeps the host-visible staging copies of what goes up and comes back.
        const std::uint64_t copies = vk->timingMethod().find("cpu-wall-clock") != std::string::npos ? 1 : 2;
        EXPECT_GE(held - beforeCull, needed) << n << " lights";
        EXPECT_LT(held - beforeCull, 4 * copies * needed + (1u << 20)) << n << " lights";
        if (n == 65536u) EXPECT_LT(held - beforeCull, std::uint64_t(f.grid.tileCount()) * n * 4 / 8);
        EXPECT_GT(r.volumeTests, 0u);
        EXPECT_GE(r.volumeTests, r.entries());
        // The depth pre-pass of the same scene again: nothing allocated either.
        (void)vk->renderDepth(f.scene, f.proj);
        EXPECT_EQ(vk->deviceAllocations(), allocations) << n << " lights: a repeated depth pass allocated";
    }
}

} // namespace

namespace {

// The count pass stashes each list's first entries (vulkan_backend.cpp: 32,
// and on a CPU device such as lavapipe up to 128 after a cull with longer
// lists; fewer for clustered's many lists): when every list fits, the host takes the lists from the stash
// and no write pass runs; otherwise the write pass copies the lists that fit
// and culls the longer ones again. Both paths against the CPU reference, each
// with its precondition checked: 16 lights cannot make a list longer than the
// stash; 12,000 make lists of 1 to 16 entries (stashed whole by any stash
// size used) and lists longer than 128.
TEST_F(GpuTest, StashedAndRecomputedListsMatchTheReference) {
    auto cpuBackend = makeCpuBackend();
    for (std::uint32_t n : {16u, 12000u}) {
        Scene scene = sized("forest", 640, 360);
        scene.lights = generateLights(defaultLightGen(scene, n, 11));
        const gputest::Frame f(scene);
        for (Algorithm a : {Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
            CullSettings st;
            st.algorithm = a;
            const std::string label = std::to_string(n) + " f.lights " + toString(a);
            const CullResult gpu = f.cull(gputest::vulkan(), st);
            const std::uint32_t longest = *std::max_element(gpu.listCount.begin(), gpu.listCount.end());
            const bool anyShort = std::any_of(gpu.listCount.begin(), gpu.listCount.end(),
                                              [](std::uint32_t c) { return c > 0 && c <= 16; });
            ASSERT_TRUE(anyShort) << label;
            if (n == 16u) ASSERT_LE(longest, 16u) << label;
            else ASSERT_GT(longest, 128u) << label << ": no list needs the write pass";
            checkCase(label, f, st, *cpuBackend);
        }
    }
}

// The write pass runs in the cull's one submission into an index array sized
// from the previous cull of as many lists (on a CPU device: once the previous
// cull's lists outgrew the stash). Lists that outgrow it are written again in
// a second submission: 12,000 lights after 16, 24,000 after 12,000. Each
// repeated cull (sized by its twin, in one submission) gives the same lists,
// and the large ones hold the reference's.
TEST_F(GpuTest, ListsThatOutgrowTheIndexArrayAreWrittenAgain) {
    std::unique_ptr<CullBackend> fresh = makeVulkanBackend("");
    auto cpuBackend = makeCpuBackend();
    std::vector<gputest::Frame> frames;
    for (std::uint32_t n : {16u, 12000u, 24000u}) {
        Scene s = sized("forest", 640, 360);
        s.lights = generateLights(defaultLightGen(s, n, 11));
        frames.emplace_back(s, fresh.get());
    }
    for (Algorithm a : {Algorithm::All, Algorithm::MinMax, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
        CullSettings st;
        st.algorithm = a;
        std::uint64_t before = frames[0].cull(*fresh, st).entries();
        for (std::size_t k = 1; k < frames.size(); ++k) {
            const std::string label = std::to_string(frames[k].lights.size()) + " lights, " + toString(a);
            const CullResult outgrown = frames[k].cull(*fresh, st);
            const CullResult sized = frames[k].cull(*fresh, st);
            ASSERT_GT(outgrown.entries(), before + before / 16 + 256) << label << ": nothing outgrew";
            EXPECT_EQ(outgrown.lightIndices, sized.lightIndices) << label;
            EXPECT_EQ(outgrown.listCount, sized.listCount) << label;
            EXPECT_EQ(outgrown.listOffset, sized.listOffset) << label;
            checkCase(label, frames[k], st, *cpuBackend, *fresh);
            before = sized.entries();
        }
    }
}

} // namespace

namespace {

// On a CPU device the stash grows after a cull whose longest list outgrew
// 32 slots (to 64 or 128; vulkan_backend.cpp, kMaxStashSlotsCpu), so the
// next cull of such a scene takes every list from the stash. The first cull
// (32 slots: the write pass) and the second (the grown stash, seen as more
// device memory) must match each other exactly and the CPU reference.
TEST_F(GpuTest, GrownStashHoldsListsOfUpTo128Entries) {
    setenv("LIGHTCULL_VALIDATION", "1", 1);
    std::unique_ptr<CullBackend> fresh = makeVulkanBackend(""); // no earlier cull sized its stash
    auto cpuBackend = makeCpuBackend();
    Scene scene = sized("forest", 640, 360);
    scene.lights = generateLights(defaultLightGen(scene, 2500, 11));
    const gputest::Frame f(scene);
    CullSettings st;
    st.algorithm = Algorithm::TwoPointFiveD;
    fresh->resetPeakDeviceBytes();
    const CullResult first = f.cull(*fresh, st);
    const std::size_t firstPeak = fresh->peakDeviceBytes();
    const std::uint32_t longest = *std::max_element(first.listCount.begin(), first.listCount.end());
    ASSERT_GT(longest, 32u) << "no list outgrows the first cull's stash";
    ASSERT_LE(longest, 128u) << "a list outgrows the grown stash";
    fresh->resetPeakDeviceBytes();
    const CullResult second = f.cull(*fresh, st);
    // (A GPU keeps 32 slots: there the lists must still match.)
    if (fresh->timingMethod().find("cpu-wall-clock") != std::string::npos)
        EXPECT_GT(fresh->peakDeviceBytes(), firstPeak) << "the stash did not grow";
    EXPECT_EQ(second.listCount, first.listCount);
    EXPECT_EQ(second.lightIndices, first.lightIndices);
    // A third cull (the grown stash again) against the CPU reference: the
    // first two are equal, so all three are checked.
    checkCase("grown stash", f, st, *cpuBackend, *fresh);
}

// On lavapipe tile_bounds reads the depth 8 pixels a load where the width
// and the tile size are multiples of 8, else 2 where both are even
// (LC_WIDE_DEPTH_LOADS); the GPU work layout, emulated, reads 4 pixels a
// lane (a vec4) where both are multiples of 4, else single pixels.
// They must agree exactly: the same depth bounds and cell / slice masks,
// the same lists. Partial edge tiles in all: 330 = 20 x 16 + 10 across (pairs;
// single pixels), 328 = 20 x 16 + 8 and 13 x 24 + 16 (8 pixels a load; 4),
// 332 = 27 x 12 + 8 and 16 x 20 + 12 (pairs; 4), 186 = 11 x 16 + 10 down;
// and tile sizes that are not multiples of 8 (10 px: pairs, single pixels;
// 12 and 20 px: pairs, 4).
TEST_F(GpuTest, WideDepthLoadsMatchSinglePixelLoads) {
    std::unique_ptr<CullBackend> emulated = makeEmulatedGpuBackend();
    const std::pair<std::uint32_t, std::uint32_t> cases[] = {{330, 16}, {330, 10}, {328, 16},
                                                             {328, 24}, {332, 12}, {332, 20}};
    for (const auto& [width, tile] : cases) {
        Scene scene = sized("forest", width, 186, tile);
        scene.lights = generateLights(defaultLightGen(scene, 300, 4));
        const Projection proj(scene.camera);
        const TileGrid grid = TileGrid::make(width, 186, tile);
        const ViewLights lights = makeViewLights(scene);
        const DepthImage depth = gputest::vulkan().renderDepth(scene, proj);
        for (Algorithm a : {Algorithm::MinMax, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
            CullSettings st;
            st.algorithm = a;
            st.cells = 16;
            const std::string label =
                "width " + std::to_string(width) + " tile " + std::to_string(tile) + " " + toString(a);
            const CullResult wide = gputest::vulkan().cull(depth, proj, grid, lights, st);
            const CullResult single = emulated->cull(depth, proj, grid, lights, st);
            EXPECT_EQ(wide.tileDepthMin, single.tileDepthMin) << label;
            EXPECT_EQ(wide.tileDepthMax, single.tileDepthMax) << label;
            EXPECT_EQ(wide.cellMask, single.cellMask) << label;
            EXPECT_EQ(wide.listCount, single.listCount) << label;
            EXPECT_EQ(wide.lightIndices, single.lightIndices) << label;
            EXPECT_GT(wide.entries(), 0u) << label;
        }
    }
}

// zbin's lists come back as depth-sorted positions; the host maps them to
// light indices and puts each list in ascending order: lists of more than
// one light in 512 through a bitmask of the lights, shorter ones by a sort.
// A frame with lists of both kinds (several entries each) matches the CPU
// reference: ascending, no false negatives.
TEST_F(GpuTest, ZBinListsComeBackAscendingShortAndLong) {
    auto cpuBackend = makeCpuBackend();
    Scene scene = sized("forest", 320, 180);
    // Small lights (radius 0.14 to 0.45) and a few hundred large ones.
    LightGenSettings gen = defaultLightGen(scene, 20000, 21);
    gen.intensityMin = 0.001;
    gen.intensityMax = 0.01;
    scene.lights = generateLights(gen);
    for (std::size_t i = 0; i < scene.lights.size(); i += 50)
        scene.lights[i].explicitRadius = 4.0;
    const gputest::Frame f(scene);
    CullSettings st;
    st.algorithm = Algorithm::ZBin;
    checkCase("zbin short and long lists", f, st, *cpuBackend);
    const CullResult r = f.cull(gputest::vulkan(), st);
    std::size_t sorted = 0, masked = 0;
    for (std::uint32_t c : r.listCount) {
        if (c >= 2 && std::size_t(c) * 512 <= scene.lights.size()) ++sorted;
        if (std::size_t(c) * 512 > scene.lights.size()) ++masked;
    }
    EXPECT_GT(sorted, 0u) << "no list takes the sort";
    EXPECT_GT(masked, 0u) << "no list takes the bitmask";
}

// A GPU's fused pass writes 16-bit light indices while the lights fit them
// (at most 65,536) and 32-bit ones beyond. On both sides of the bound the
// emulated GPU layout gives the CPU layout's lists bit for bit; the last
// light (index 65,535, then 65,536: written in 16 bits it would come back as
// 0) lights the whole frame, so it is in every list.
TEST_F(GpuTest, SixteenBitIndicesUpTo65536Lights) {
    std::unique_ptr<CullBackend> emulated = makeEmulatedGpuBackend();
    auto cpuBackend = makeCpuBackend();
    for (const std::size_t n : {std::size_t(65536), std::size_t(65537)}) {
        Scene scene = sized("atrium", 96, 64);
        scene.lights = generateLights(defaultLightGen(scene, n, 6));
        ASSERT_EQ(scene.lights.size(), n);
        scene.lights.back().position = 0.5 * (scene.bounds().first + scene.bounds().second);
        scene.lights.back().explicitRadius = 1e3;
        const gputest::Frame f(scene, nullptr);
        for (Algorithm a : {Algorithm::TwoPointFiveD, Algorithm::ZBin}) {
            CullSettings st;
            st.algorithm = a;
            const std::string label = std::to_string(n) + " lights " + toString(a);
            checkCase(label, f, st, *cpuBackend, *emulated);
            const CullResult g = emulated->cull(f.depth, f.proj, f.grid, f.lights, st);
            EXPECT_EQ(emulated->lastDeviceIndexBits(), n <= 65536 ? 16u : 32u) << label;
            const CullResult c = f.cull(gputest::vulkan(), st);
            EXPECT_EQ(g.listCount, c.listCount) << label;
            EXPECT_EQ(g.listOffset, c.listOffset) << label;
            EXPECT_EQ(g.lightIndices, c.lightIndices) << label;
            ASSERT_FALSE(g.lightIndices.empty()) << label;
            EXPECT_EQ(*std::max_element(g.lightIndices.begin(), g.lightIndices.end()), n - 1) << label;
        }
    }
}

// The depth bins (light_bins.comp) spare the count pass the lights in front
// of or behind a list's depth range: on the forest (depths from a few metres
// to the horizon) most candidates of the column and row bins alone miss the
// tile's depth range (measured at 1080p with 1,024 lights: 85,936 tests for
// 13,673 min/max entries without the depth bins, 16,010 with them). Every
// candidate is tested once, so the tests bound the candidates; the lists
// stay a superset of the CPU reference's.
TEST_F(GpuTest, DepthBinsSpareTheCountPassMostCandidates) {
    Scene scene = sized("forest", 480, 270);
    scene.lights = generateLights(defaultLightGen(scene, 1024, 1));
    const gputest::Frame f(scene);
    auto cpuBackend = makeCpuBackend();
    for (Algorithm a : {Algorithm::MinMax, Algorithm::HalfZ, Algorithm::Clustered}) {
        CullSettings st;
        st.algorithm = a;
        const std::string label = std::string("f.depth bins ") + toString(a);
        checkCase(label, f, st, *cpuBackend);
        const CullResult r = f.cull(gputest::vulkan(), st);
        ASSERT_GT(r.entries(), 1000u) << label;
        EXPECT_LT(double(r.volumeTests), 2.0 * double(r.entries())) << label;
        std::printf("[ cull     ] %-44s entries %8llu  tests %8llu\n", label.c_str(),
                    (unsigned long long)r.entries(), (unsigned long long)r.volumeTests);
    }
}

} // namespace

// fptl (fine-pruned tiles): the CPU reference's lists are the per-tile
// optimum itself (optimal work = shading work), a subset of minmax's per
// tile; the Vulkan lists hold them and stay within float widening of them,
// with spot lights among the point lights (the prune tests the cones).
TEST_F(GpuTest, FinePrunedTilesReachThePerTileOptimum) {
    Scene scene = sized("atrium", 320, 180);
    LightGenSettings g = defaultLightGen(scene, 400, 21);
    g.spotFraction = 0.4;
    scene.lights = generateLights(g);
    auto cpuBackend = makeCpuBackend();
    CullSettings st;
    st.algorithm = Algorithm::MinMax;
    const RunOutput minmax = runPipeline(scene, st, *cpuBackend);
    st.algorithm = Algorithm::Fptl;
    const RunOutput cpu = runPipeline(scene, st, *cpuBackend);
    ASSERT_GT(cpu.truth.metrics.shadingWork, 0u);
    EXPECT_EQ(cpu.truth.metrics.falseNegatives, 0u);
    EXPECT_EQ(cpu.truth.metrics.optimalWork, cpu.truth.metrics.shadingWork);
    EXPECT_LT(cpu.result.entries(), minmax.result.entries());
    for (std::uint32_t t = 0; t < cpu.result.grid.tileCount(); ++t) {
        const auto fb = cpu.result.lightIndices.begin() + cpu.result.listOffset[t];
        const auto mb = minmax.result.lightIndices.begin() + minmax.result.listOffset[t];
        EXPECT_TRUE(std::includes(mb, mb + minmax.result.listCount[t], fb, fb + cpu.result.listCount[t])) << "tile " << t;
    }
    const RunOutput gpu = runPipeline(scene, st, gputest::vulkan());
    EXPECT_EQ(gpu.truth.metrics.falseNegatives, 0u);
    EXPECT_GE(gpu.truth.metrics.efficiencyVsOptimal, 0.99);
    EXPECT_LE(gpu.truth.metrics.efficiencyVsOptimal, 1.0);
    const Comparison cmp = compareLists(cpu.result, gpu.result);
    EXPECT_EQ(cmp.missing, 0u) << cmp.firstMissing;
    EXPECT_LE(cmp.extra, 8 + cmp.cpuEntries / 200);
}

// zbin on the GPU: the same depth order, the same masks up to float
// widening, and every bin's range holding the reference's (zbin.comp widens
// each light's depth extent), at several bin counts.
TEST_F(GpuTest, ZBinBinsHoldTheReferenceBins) {
    Scene scene = sized("forest", 320, 180);
    LightGenSettings g = defaultLightGen(scene, 700, 4);
    g.spotFraction = 0.2;
    scene.lights = generateLights(g);
    auto cpuBackend = makeCpuBackend();
    const gputest::Frame f(scene, cpuBackend.get());
    for (std::uint32_t bins : {1u, 100u, 4096u, 16384u}) {
        SCOPED_TRACE(bins);
        CullSettings st;
        st.algorithm = Algorithm::ZBin;
        st.bins = bins;
        const CullResult cpu = f.cull(*cpuBackend, st);
        const CullResult gpu = f.cull(gputest::vulkan(), st);
        ASSERT_EQ(gpu.validate(f.lights.size()), "");
        EXPECT_EQ(gpu.zbinOrder, cpu.zbinOrder);
        EXPECT_EQ(gpu.zbinNear, cpu.zbinNear);
        EXPECT_EQ(gpu.zbinFar, cpu.zbinFar);
        std::size_t wider = 0, used = 0;
        for (std::uint32_t b = 0; b < bins; ++b) {
            if (cpu.zbinLo[b] > cpu.zbinHi[b]) continue;
            ++used;
            ASSERT_LE(gpu.zbinLo[b], cpu.zbinLo[b]) << "bin " << b;
            ASSERT_GE(gpu.zbinHi[b], cpu.zbinHi[b]) << "bin " << b;
            wider += gpu.zbinLo[b] != cpu.zbinLo[b] || gpu.zbinHi[b] != cpu.zbinHi[b];
        }
        EXPECT_GT(used, 0u);
        EXPECT_LE(wider, 2 + used / 50) << "bins widened by more than rounding";
        GroundTruthOptions o;
        o.imageError = false;
        EXPECT_EQ(computeGroundTruth(f.depth, f.proj, f.lights, gpu, o).metrics.falseNegatives, 0u);
    }
}

// A backend keeps the culling pipelines it used last, at most 128 (megabytes
// each on lavapipe; a report sweep makes hundreds): settings culled again
// soon make none, settings whose pipelines went make them again and cull
// the same lists, and a backend's pipelines go with it.
TEST_F(GpuTest, CullPipelinesHeldAreTheLastUsedAndAtMost128) {
    const VulkanPipelineCount before = vulkanCullPipelines(); // other backends' (held, unchanged here)
    auto cpu = makeCpuBackend();
    Scene scene = sized("atrium", 64, 36, 16);
    LightGenSettings gen = defaultLightGen(scene, 12, 5);
    gen.spotFraction = 0.5; // the spot tests are constants of the count pass
    scene.lights = generateLights(gen);
    const gputest::Frame f(scene, cpu.get());
    // (Pipelines are keyed by the constants their shader reads: about one
    // new count pass a setting, the bounds pass one per cells and slicing.)
    std::vector<CullSettings> all;
    for (Algorithm algo : {Algorithm::TwoPointFiveD, Algorithm::Clustered})
        for (std::uint32_t cells : {2u, 4u, 8u, 16u, 32u})
            for (Slicing slicing : {Slicing::Log, Slicing::Linear})
                for (SphereTest test : kTests)
                    for (SpotTest spot : {SpotTest::ApexSphere, SpotTest::ConeSphere, SpotTest::ConePlanes}) {
                        CullSettings s;
                        s.algorithm = algo;
                        s.cells = cells;
                        s.slicing = slicing;
                        s.test = test;
                        s.spotTest = spot;
                        all.push_back(s);
                    }
    {
        std::unique_ptr<CullBackend> gpu = makeVulkanBackend("");
        const auto made = [] { return vulkanCullPipelines().made; };
        const auto held = [&] { return vulkanCullPipelines().held - before.held; };
        std::vector<CullResult> first;
        for (const CullSettings& s : all) {
            first.push_back(gpu->cull(f.depth, f.proj, f.grid, f.lights, s));
            ASSERT_LE(held(), 128u);
        }
        const std::uint64_t afterSweep = made();
        ASSERT_GT(afterSweep - before.made, 128u) << "the sweep must make more pipelines than are kept";
        EXPECT_EQ(held(), 128u);
        // The last settings: their pipelines are still there.
        EXPECT_EQ(gpu->cull(f.depth, f.proj, f.grid, f.lights, all.back()).lightIndices, first.back().lightIndices);
        EXPECT_EQ(made(), afterSweep);
        // The first settings: made again, the same lists.
        const CullResult again = gpu->cull(f.depth, f.proj, f.grid, f.lights, all.front());
        EXPECT_GT(made(), afterSweep);
        EXPECT_EQ(again.lightIndices, first.front().lightIndices);
        EXPECT_EQ(again.listCount, first.front().listCount);
        EXPECT_LE(held(), 128u);
    }
    EXPECT_EQ(vulkanCullPipelines().held, before.held);
}

// A cull makes only the pipelines it runs, keyed by the constants each
// shader reads: another sphere test compiles the list passes again but not
// the bounds and bins passes, and raster (which runs the bounds pass and
// draws) makes that one pipeline alone. On lavapipe a list pass's pipeline
// is 25 to 40 ms of compiling: a report sweep paid it for every pass of
// every configuration, and raster for four passes it never ran.
TEST_F(GpuTest, CullsMakeOnlyThePipelinesTheyRun) {
    auto cpu = makeCpuBackend();
    Scene scene = sized("atrium", 64, 36, 16);
    scene.lights = generateLights(defaultLightGen(scene, 12, 5));
    const gputest::Frame f(scene, cpu.get());
    std::unique_ptr<CullBackend> gpu = makeVulkanBackend("");
    const auto made = [] { return vulkanCullPipelines().made; };
    CullSettings s;
    s.algorithm = Algorithm::Clustered;
    s.cells = 7; // no other test's constants
    std::uint64_t at = made();
    const CullResult planes = gpu->cull(f.depth, f.proj, f.grid, f.lights, s);
    const std::uint64_t first = made() - at;
    s.test = SphereTest::Exact;
    at = made();
    const CullResult exact = gpu->cull(f.depth, f.proj, f.grid, f.lights, s);
    const std::uint64_t second = made() - at;
    EXPECT_GE(first, second + 2) << "the bounds and bins passes are the same pipelines for either test (first "
                                 << first << ", then " << second << ")";
    EXPECT_GE(second, 1u) << "the list pass reads the test";
    EXPECT_EQ(cpu->cull(f.depth, f.proj, f.grid, f.lights, s).lightIndices, exact.lightIndices);

    CullSettings r;
    r.algorithm = Algorithm::Raster;
    r.cells = 7;
    at = made();
    const CullResult raster = gpu->cull(f.depth, f.proj, f.grid, f.lights, r);
    EXPECT_LE(made() - at, 1u) << "raster runs one culling pipeline, the bounds pass";
    r.proxyLevel = 2;
    at = made();
    gpu->cull(f.depth, f.proj, f.grid, f.lights, r);
    EXPECT_EQ(made() - at, 0u) << "the proxy's detail is no constant of the bounds pass";
    GroundTruthOptions o;
    o.imageError = false;
    EXPECT_EQ(computeGroundTruth(f.depth, f.proj, f.lights, raster, o).metrics.falseNegatives, 0u);
    EXPECT_EQ(computeGroundTruth(f.depth, f.proj, f.lights, planes, o).metrics.falseNegatives, 0u);
}
