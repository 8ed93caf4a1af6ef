// The raster algorithm's Vulkan pass (a graphics pipeline drawing light
// proxies, validation layer on) against the CPU reference on a built-in
// scene: with conservative coverage the GPU lists hold the reference's,
// with centre sampling they are the reference's up to a rounding at an
// edge; the misses of an inscribed proxy show on both.
#include "gpu_test_env.hpp"

#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/ground_truth.hpp"

#include <algorithm>
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
