// Engine limits on both backends (core/limits.hpp): every algorithm, every
// overflow policy, the light limit and the record buffer, on lavapipe with the
// validation layer on. The limits are one host rule applied to each backend's
// lists, so wherever the two backends' tests listed the same lights, the
// limits must keep and drop the same lights; and the misses they cause must
// be counted the same.
#include "result_lists.hpp"
#include "gpu_test_env.hpp"

#include "culling/core/limits.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/ground_truth.hpp"

#include <algorithm>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

using test::droppedAt;
using test::listAt;

} // namespace

TEST_F(GpuTest, LimitsKeepAndDropTheSameLightsOnBothBackends) {
    Scene scene = makeBuiltinScene("atrium");
    scene.camera.width = 320;
    scene.camera.height = 180;
    // One depth image for both culls: the lists differ only by the tests' rounding.
    const gputest::Frame f(scene, nullptr);
    auto cpu = makeCpuBackend();
    std::uint64_t overflowsSeen = 0;
    for (const std::string& a : cullParam("algorithm").choices) {
        for (const char* policy : {"index", "nearest", "all-lights"}) {
            CullSettings s;
            Camera cam = scene.camera;
            setParam(s, cam, "algorithm", a);
            setParam(s, cam, "cap", "3");
            setParam(s, cam, "max-lights", "400"); // atrium has 512
            setParam(s, cam, "limit-keep", "nearest");
            setParam(s, cam, "overflow-policy", policy);
            CullSettings open = s;
            open.cap = open.maxLights = 0;
            const CullResult cpuOpen = f.cull(*cpu, open), gpuOpen = f.cull(gputest::vulkan(), open);
            const CullResult cpuCapped = f.cull(*cpu, s), gpuCapped = f.cull(gputest::vulkan(), s);
            ASSERT_EQ(cpuCapped.validate(f.lights.size()), "") << a;
            ASSERT_EQ(gpuCapped.validate(f.lights.size()), "") << a;
            EXPECT_EQ(cpuCapped.limits.overLightLimit, gpuCapped.limits.overLightLimit) << a;
            EXPECT_EQ(cpuCapped.limits.lightsOverLimit, 112u) << a;
            ASSERT_EQ(cpuOpen.listCount.size(), gpuOpen.listCount.size()) << a;
            std::size_t same = 0;
            for (std::uint32_t l = 0; l < cpuOpen.listCount.size(); ++l) {
                if (listAt(cpuOpen, l) != listAt(gpuOpen, l)) continue; // rounding listed another light
                ++same;
                EXPECT_EQ(listAt(cpuCapped, l), listAt(gpuCapped, l)) << a << " " << policy << " list " << l;
                EXPECT_EQ(droppedAt(cpuCapped, l), droppedAt(gpuCapped, l)) << a << " " << policy << " list " << l;
                EXPECT_EQ(cpuCapped.limits.overflowIndex(l) >= 0, gpuCapped.limits.overflowIndex(l) >= 0) << a;
                // The kept list: at most the cap, unless the fallback listed every light.
                if (std::string(policy) != "all-lights") EXPECT_LE(cpuCapped.listCount[l], 3u) << a;
            }
            EXPECT_GE(same, cpuOpen.listCount.size() * 9 / 10) << a << ": too few lists to compare";
            overflowsSeen += cpuCapped.limits.overflowLists.size();
        }
    }
    EXPECT_GT(overflowsSeen, 0u); // the cap bit somewhere
}

// A run through the whole pipeline on Vulkan counts the misses by cause as
// the CPU reference does on the same scene (every light holds every pixel,
// so both backends list them all and the limits decide alone).
TEST_F(GpuTest, MissesByCauseMatchTheCpuReference) {
    Scene scene;
    scene.name = "wall";
    Mesh m;
    m.name = "wall";
    m.positions = {-50, -50, 0, 50, -50, 0, 50, 50, 0, -50, 50, 0};
    m.indices = {0, 1, 2, 0, 2, 3};
    scene.meshes.push_back(m);
    scene.camera.width = 96;
    scene.camera.height = 64;
    for (int i = 0; i < 9; ++i) {
        PointLight l;
        l.name = "l" + std::to_string(i);
        l.position = {0.1 * i, 0, 1 + 0.1 * i};
        l.explicitRadius = 100;
        scene.lights.push_back(l);
    }
    RunOptions o;
    o.truthOptions.imageError = false;
    auto cpu = makeCpuBackend();
    for (const std::string& a : cullParam("algorithm").choices) {
        CullSettings s;
        s.algorithm = algorithmFromString(a);
        s.cap = 4;
        s.maxLights = 7;
        s.maxEntries = 40;
        const RunOutput c = runPipeline(scene, s, *cpu, o);
        const RunOutput g = runPipeline(scene, s, gputest::vulkan(), o);
        EXPECT_EQ(c.truth.metrics.falseNegativesListFull, g.truth.metrics.falseNegativesListFull) << a;
        EXPECT_EQ(c.truth.metrics.falseNegativesLightLimit, g.truth.metrics.falseNegativesLightLimit) << a;
        EXPECT_EQ(c.truth.metrics.falseNegativesLightLimit, 2 * c.truth.metrics.geometryPixels) << a;
        EXPECT_GT(g.truth.metrics.falseNegativesListFull, 0u) << a;
        EXPECT_EQ(g.truth.metrics.falseNegativesCullingTest(), 0u) << a;
        EXPECT_EQ(c.result.limits.overflowLists, g.result.limits.overflowLists) << a;
    }
}
