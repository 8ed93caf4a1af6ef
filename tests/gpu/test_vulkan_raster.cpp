// The raster algorithm's Vulkan pass (a graphics pipeline drawing light
// proxies, validation layer on) against the CPU reference on a built-in
// scene: with conservative coverage the GPU lists hold the reference's,
// with centre sampling they are the reference's up to a rounding at an
// edge; the misses of an inscribed proxy show on both.
#include "gpu_test_env.hpp"
#include "../unit/cli_support.hpp"

#include "culling/core/pipeline.hpp"
#include "culling/diagnostics/explain.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/ground_truth.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <iterator>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

struct Compared {
    std::uint64_t missing = 0, extra = 0, cpuEntries = 0;
    std::uint64_t cpuFalseNegatives = 0, gpuFalseNegatives = 0;
    std::string coverage;
};

Compared compare(const Scene& scene, const CullSettings& st) {
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    const CullResult c = cpu->cull(depth, proj, grid, lights, st);
    const CullResult g = gputest::vulkan().cull(depth, proj, grid, lights, st);
    EXPECT_EQ(g.validate(lights.size()), "");
    Compared out;
    out.coverage = g.coverage;
    out.cpuEntries = c.lightIndices.size();
    for (std::size_t l = 0; l < c.listCount.size(); ++l) {
        const auto cb = c.lightIndices.begin() + c.listOffset[l], ce = cb + c.listCount[l];
        const auto gb = g.lightIndices.begin() + g.listOffset[l], ge = gb + g.listCount[l];
        std::vector<std::uint32_t> lost, more;
        std::set_difference(cb, ce, gb, ge, std::back_inserter(lost));
        std::set_difference(gb, ge, cb, ce, std::back_inserter(more));
        out.missing += lost.size();
        out.extra += more.size();
    }
    GroundTruthOptions o;
    o.imageError = false;
    out.cpuFalseNegatives = computeGroundTruth(depth, proj, lights, c, o).metrics.falseNegatives;
    out.gpuFalseNegatives = computeGroundTruth(depth, proj, lights, g, o).metrics.falseNegatives;
    return out;
}

Scene atrium() {
    Scene s = makeBuiltinScene("atrium");
    s.camera.width = 430; // 27 x 17 tiles, the last column and row partial
    s.camera.height = 270;
    return s;
}

} // namespace

class VulkanRaster : public GpuTest {};

TEST_F(VulkanRaster, ConservativeListsHoldTheCpuReferenceAtEveryLevel) {
    const Scene scene = atrium();
    for (std::uint32_t level : {0u, 1u, 2u, 4u})
        for (double overfit : {0.0, 1.0}) {
            SCOPED_TRACE("level " + std::to_string(level) + " overfit " + std::to_string(overfit));
            CullSettings st;
            st.algorithm = Algorithm::Raster;
            st.proxyLevel = level;
            st.proxyOverfit = overfit;
            const Compared c = compare(scene, st);
            EXPECT_EQ(c.missing, 0u);
            EXPECT_LE(c.extra, 8 + c.cpuEntries / 100);
            if (overfit == 0.0) {
                EXPECT_EQ(c.cpuFalseNegatives, 0u);
                EXPECT_EQ(c.gpuFalseNegatives, 0u);
            } else {
                EXPECT_LE(c.gpuFalseNegatives, c.cpuFalseNegatives);
            }
            // lavapipe has no VK_EXT_conservative_rasterization: the pass says so.
            if (gputest::vulkanIsCpuDevice()) EXPECT_NE(c.coverage.find("pushed"), std::string::npos) << c.coverage;
        }
    // The inscribed icosahedron misses on both backends.
    CullSettings st;
    st.algorithm = Algorithm::Raster;
    st.proxyLevel = 0;
    st.proxyOverfit = 1.0;
    const Compared inscribed = compare(scene, st);
    EXPECT_GT(inscribed.cpuFalseNegatives, 0u);
    EXPECT_GT(inscribed.gpuFalseNegatives, 0u);
}

TEST_F(VulkanRaster, CentreSamplingListsAreTheCpuReferences) {
    const Scene scene = atrium();
    for (std::uint32_t level : {0u, 2u}) {
        SCOPED_TRACE("level " + std::to_string(level));
        CullSettings st;
        st.algorithm = Algorithm::Raster;
        st.proxyLevel = level;
        st.conservative = false;
        const Compared c = compare(scene, st);
        // A tile centre on a triangle's edge may fall either way in float.
        EXPECT_LE(c.missing + c.extra, 4 + c.cpuEntries / 200) << "missing " << c.missing << " extra " << c.extra;
        EXPECT_GT(c.cpuFalseNegatives, 0u) << "centre sampling misses grazed tiles";
        EXPECT_NE(c.coverage.find("centre"), std::string::npos) << c.coverage;
    }
}

TEST_F(VulkanRaster, RunsThroughThePipelineWithTheDepthItRendered) {
    // The pipeline's own path: the Vulkan depth pre-pass left on the device,
    // the bounds pass reading it, the proxies drawn; false negatives 0.
    Scene scene = makeBuiltinScene("forest");
    scene.camera.width = 480;
    scene.camera.height = 270;
    CullSettings st;
    st.algorithm = Algorithm::Raster;
    const RunOutput run = runPipeline(scene, st, gputest::vulkan());
    EXPECT_EQ(run.result.algorithm, Algorithm::Raster);
    EXPECT_EQ(run.truth.metrics.falseNegatives, 0u);
    EXPECT_GT(run.result.entries(), 0u);
    EXPECT_GT(run.truth.metrics.efficiency, 0.0);
}

TEST_F(VulkanRaster, ASceneWithoutLightsHasEmptyLists) {
    // No light: no mask words to clear (a zero-sized fill is invalid Vulkan,
    // which the validation layer reports), every list empty.
    Scene scene = atrium();
    scene.lights.clear();
    CullSettings st;
    st.algorithm = Algorithm::Raster;
    const RunOutput run = runPipeline(scene, st, gputest::vulkan());
    EXPECT_EQ(run.result.entries(), 0u);
    EXPECT_EQ(run.result.listCount.size(), std::size_t(run.result.grid.tileCount()));
}

TEST_F(VulkanRaster, ClusteredSlicesHoldTheCpuReference) {
    // proxy-depth slices: the fragments' depth ranges (float, widened) into
    // the host's slices; the lists hold the CPU reference's, no miss with the
    // enclosing overfit, and the inscribed proxy's misses show on both.
    const Scene scene = atrium();
    for (std::uint32_t level : {0u, 1u})
        for (double overfit : {0.0, 1.0})
            for (Slicing slicing : {Slicing::Log, Slicing::Linear}) {
                SCOPED_TRACE("level " + std::to_string(level) + " overfit " + std::to_string(overfit) + " " +
                             toString(slicing));
                CullSettings st;
                st.algorithm = Algorithm::Raster;
                st.proxySlices = true;
                st.proxyLevel = level;
                st.proxyOverfit = overfit;
                st.slicing = slicing;
                st.cells = 16;
                const Compared c = compare(scene, st);
                EXPECT_EQ(c.missing, 0u);
                EXPECT_LE(c.extra, 8 + c.cpuEntries / 100);
                if (overfit == 0.0) {
                    EXPECT_EQ(c.gpuFalseNegatives, 0u);
                } else {
                    EXPECT_GT(c.cpuFalseNegatives, 0u);
                    EXPECT_GT(c.gpuFalseNegatives, 0u);
                }
            }
    // The built-in wall at 640x360 with 256 generated lights (seed 4): a
    // face at a sphere's silhouette, seen almost edge-on, alone reached a
    // slice there; the GPU once dropped such faces and lost the slice.
    Scene wall = makeBuiltinScene("wall");
    wall.camera.width = 640;
    wall.camera.height = 360;
    wall.lights = generateLights(defaultLightGen(wall, 256, 4));
    CullSettings wallSlices;
    wallSlices.algorithm = Algorithm::Raster;
    wallSlices.proxySlices = true;
    const Compared w = compare(wall, wallSlices);
    EXPECT_EQ(w.missing, 0u) << "the wall's silhouette faces";
    EXPECT_LE(w.extra, 8 + w.cpuEntries / 100);
    EXPECT_EQ(w.gpuFalseNegatives, 0u);

    CullSettings centre;
    centre.algorithm = Algorithm::Raster;
    centre.proxySlices = true;
    centre.conservative = false;
    const Compared c = compare(scene, centre);
    EXPECT_LE(c.missing + c.extra, 8 + c.cpuEntries / 100) << "missing " << c.missing << " extra " << c.extra;
}

TEST_F(VulkanRaster, NearCutAndEdgeOnTrianglesCoverWhatTheCpuReferenceCovers) {
    // An inscribed level-0 proxy (overfit 1) misses; the GPU must show the
    // same misses, not hide them under coverage of its own. Two shapes did:
    // triangles the near plane cuts (trimmed by their bounding box alone,
    // now by the four edges of what is left in front) and, under an
    // orthographic camera, faces seen exactly edge-on (drawn as their
    // bounding box, now dropped as the CPU reference drops them: their
    // neighbours cover their edges). Lights around the camera, across the
    // near plane, wide spots, on a 333x197 screen (partial tiles).
    Scene s;
    s.camera.position = {0, 0, 0};
    s.camera.target = {0, 0, -1};
    s.camera.nearPlane = 0.1;
    s.camera.farPlane = 100;
    s.camera.fovYDeg = 90;
    s.camera.width = 333;
    s.camera.height = 197;
    s.camera.tileSize = 16;
    Mesh wall;
    wall.positions = {-50, -50, -2, 50, -50, -2, 50, 50, -2, -50, 50, -2};
    wall.indices = {0, 1, 2, 0, 2, 3};
    s.meshes.push_back(wall);
    const std::pair<glm::dvec3, double> points[] = {{{0.3, 0.2, 0.05}, 2.2},  {{0.5, 0.3, -0.08}, 2.0},
                                                    {{-1, 0, 1}, 3.1},        {{0, 0, -0.3}, 0.25},
                                                    {{-1.5, 0.5, -0.05}, 2.1}, {{0.8, -0.6, 0.2}, 2.4}};
    for (const auto& [c, r] : points) {
        PointLight l;
        l.position = c;
        l.explicitRadius = r;
        s.lights.push_back(l);
    }
    for (bool ortho : {false, true}) {
        SCOPED_TRACE(ortho ? "orthographic" : "perspective");
        s.camera.projection = ortho ? ProjectionKind::Orthographic : ProjectionKind::Perspective;
        s.camera.orthoHeight = 4;
        for (bool slices : {false, true}) {
            CullSettings st;
            st.algorithm = Algorithm::Raster;
            st.proxyLevel = 0;
            st.proxyOverfit = 1.0;
            st.proxySlices = slices;
            const Compared c = compare(s, st);
            EXPECT_EQ(c.missing, 0u);
            EXPECT_LE(c.extra, 4 + c.cpuEntries / 100) << (slices ? "slices" : "tile");
            EXPECT_EQ(c.gpuFalseNegatives, c.cpuFalseNegatives) << (slices ? "slices" : "tile");
        }
    }
}

// Settings past a device's limit (raster's slices at one-pixel tiles: 7.5 GB
// of depth ranges, more than any device binds) are refused by the cull, not
// the command line. A bench sweep keeps going: the refused configuration is
// a row saying why, the others are measured and written, and the command
// fails (exit 1) naming the first refusal; alone, it is exit 2 as before.
TEST_F(GpuTest, ABenchSweepKeepsItsRowsPastADeviceRefusal) {
    lc_test::ScratchDir d;
    const std::string json = (d.path / "bench.json").string();
    const std::vector<std::string> common = {"bench", "--builtin", "wall", "--backend", "vulkan", "--width", "1280",
                                             "--height", "720", "--lights", "1024", "--algorithm", "raster",
                                             "--proxy-depth", "slices", "--repeat", "1", "--warmup", "0"};
    std::vector<std::string> sweep = common;
    for (const char* a : {"--sweep", "tile=32,1,64", "--json"}) sweep.push_back(a);
    sweep.push_back(json);
    const lc_test::CliResult r = lc_test::runCli(sweep, d.path);
    EXPECT_EQ(r.code, 1) << r.out << r.err;
    EXPECT_EQ(lc_test::lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("1 of 3 configurations refused by the device (the first: tile=1: proxy-depth:"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.out.find("tile=1: refused: proxy-depth:"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("tile=32: depth "), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("tile=64: depth "), std::string::npos) << r.out;
    const nlohmann::json doc = nlohmann::json::parse(lc_test::slurp(json));
    ASSERT_EQ(doc["configs"].size(), 3u);
    EXPECT_GT(doc["configs"][0]["list_entries"].get<std::uint64_t>(), 0u);
    EXPECT_NE(doc["configs"][1]["refused"].get<std::string>().find("binds at once"), std::string::npos);
    EXPECT_EQ(doc["configs"][1]["params"]["tile"], "1");
    EXPECT_FALSE(doc["configs"][1].contains("cull_ms"));
    EXPECT_GT(doc["configs"][2]["list_entries"].get<std::uint64_t>(), 0u);

    std::vector<std::string> alone = common;
    for (const char* a : {"--tile", "1"}) alone.push_back(a);
    const lc_test::CliResult one = lc_test::runCli(alone, d.path);
    EXPECT_EQ(one.code, 2) << one.out << one.err;
    EXPECT_TRUE(one.out.empty()) << "an error prints nothing on stdout: " << one.out;
    EXPECT_NE(one.err.find("--proxy-depth: raster's slices need two depths per tile and light"), std::string::npos)
        << one.err;
}

// The GPU's rasteriser covers tiles the exact reference does not (edges
// pushed out by half a tile's diagonal): Explain of such an entry says the
// reference's tests reject the light and the list holds it, and now why,
// instead of leaving the two side by side.
TEST_F(GpuTest, ExplainSaysWhyTheGpuListedALightItsTestsReject) {
    Scene scene = atrium();
    scene.lights = generateLights(defaultLightGen(scene, 96, 7));
    CullSettings s;
    s.algorithm = Algorithm::Raster;
    RunOptions o;
    o.truthOptions.imageError = false;
    const RunOutput run = runPipeline(scene, s, gputest::vulkan(), o);
    const RunOutput ref = runPipeline(scene, s, *makeCpuBackend(), o);
    const Projection proj(scene.camera);
    const CullResult& g = run.result;
    std::size_t explained = 0;
    for (std::uint32_t l = 0; l < g.listCount.size() && explained < 3; ++l) {
        const auto cb = ref.result.lightIndices.begin() + ref.result.listOffset[l];
        const auto ce = cb + ref.result.listCount[l];
        for (std::uint32_t k = 0; k < g.listCount[l] && explained < 3; ++k) {
            const std::uint32_t light = g.lightIndices[g.listOffset[l] + k];
            if (std::binary_search(cb, ce, light)) continue; // the reference lists it too
            const Explanation e = explainLight(run, proj, l, light);
            if (e.testsPass) continue; // the depth pre-passes differ here, not the coverage
            ++explained;
            const std::string text = e.text();
            EXPECT_NE(text.find("tests: reject it; the list holds it\n  why listed: the rasteriser's coverage"),
                      std::string::npos)
                << text;
            // On the CPU's own lists the reference agrees: nothing to explain away.
            EXPECT_TRUE(explainLight(ref, proj, l, light).listedAnyway.empty());
        }
    }
    EXPECT_GT(explained, 0u) << "no entry the GPU alone listed";
}
