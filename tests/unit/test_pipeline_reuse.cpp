// RunOptions::reuseDepth: a run that moved only lights may reuse the depth
// image of an earlier run (the studio's Live drags do). The result must be the
// one a fresh run gives, and a depth image of the wrong size is refused.
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

using namespace lc;

namespace {

Scene smallAtrium() {
    Scene s = makeBuiltinScene("atrium");
    s.camera.width = 320;
    s.camera.height = 180;
    s.lights.resize(64);
    return s;
}

} // namespace

TEST(PipelineReuse, ReusedDepthGivesTheResultOfAFreshRun) {
    auto cpu = makeCpuBackend();
    Scene scene = smallAtrium();
    CullSettings settings;
    const RunOutput first = runPipeline(scene, settings, *cpu);
    EXPECT_FALSE(first.depthReused);

    // Move a listed light a long way: its lists change, the depth does not.
    ASSERT_FALSE(first.result.lightIndices.empty());
    scene.lights[first.result.lightIndices[0]].position += glm::dvec3(3.0, -1.0, 2.5);
    RunOptions reuse;
    reuse.reuseDepth = &first.depth;
    const RunOutput reused = runPipeline(scene, settings, *cpu, reuse);
    const RunOutput fresh = runPipeline(scene, settings, *cpu);
    EXPECT_TRUE(reused.depthReused);
    EXPECT_EQ(reused.result.timings.depthMs, 0.0);
    EXPECT_EQ(reused.depth.depth, fresh.depth.depth);
    EXPECT_EQ(reused.result.lightIndices, fresh.result.lightIndices);
    EXPECT_EQ(reused.result.listOffset, fresh.result.listOffset);
    EXPECT_EQ(reused.result.listCount, fresh.result.listCount);
    EXPECT_EQ(reused.truth.metrics.falseNegatives, 0u);
    EXPECT_EQ(reused.truth.metrics.shadingWork, fresh.truth.metrics.shadingWork);
    // And the move really changed the lists (so the comparison above means something).
    EXPECT_NE(first.result.lightIndices, fresh.result.lightIndices);
}

TEST(PipelineReuse, DepthOfAnotherSizeIsRefused) {
    auto cpu = makeCpuBackend();
    Scene scene = smallAtrium();
    const RunOutput first = runPipeline(scene, CullSettings{}, *cpu);
    scene.camera.width = 160;
    RunOptions reuse;
    reuse.reuseDepth = &first.depth;
    try {
        runPipeline(scene, CullSettings{}, *cpu, reuse);
        FAIL() << "a 320x180 depth image was accepted for a 160x180 camera";
    } catch (const Error& e) {
        EXPECT_STREQ(e.what(), "the reused depth image is 320x180 but the camera is 160x180");
    }
}
