// The hunt (issue 35) on the Vulkan backend, on lavapipe with the validation
// layer: every built-in algorithm hunts a fixed budget with no
// counterexample, and a trial judges, besides false negatives, that the
// Vulkan lists hold every entry the CPU reference lists over the same depth
// image (what test_vulkan_cull checks on its hand-picked frames).
#include "gpu_test_env.hpp"

#include "../support/box_mesh.hpp"
#include "culling/core/params.hpp"
#include "culling/diagnostics/hunt.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

std::string describe(const HuntResult& r, const HuntOptions& o) {
    if (!r.failure) return {};
    return huntVerdictText(*r.failure, o) + "\nshrunk scene:\n" + serializeScene(r.failure->shrunk);
}

// The real Vulkan backend with one light taken out of every list it returns:
// the slip of a culling that drops a light its reference keeps.
class DropsALight : public CullBackend {
public:
    DropsALight(CullBackend& inner, std::uint32_t light) : inner_(inner), light_(light) {}
    std::string name() const override { return inner_.name(); }
    std::string deviceName() const override { return inner_.deviceName(); }
    std::string timingMethod() const override { return inner_.timingMethod(); }
    DepthImage renderDepth(const Scene& scene, const Projection& proj) override {
        DepthImage d = inner_.renderDepth(scene, proj);
        lastDepthMs_ = inner_.lastDepthMs();
        return d;
    }
    CullResult cull(const DepthImage& depth, const Projection& proj, const TileGrid& grid, const ViewLights& lights,
                    const CullSettings& settings) override {
        CullResult r = inner_.cull(depth, proj, grid, lights, settings);
        std::vector<std::uint32_t> kept;
        for (std::size_t l = 0; l < r.listCount.size(); ++l) {
            const std::uint32_t begin = r.listOffset[l], n = r.listCount[l];
            r.listOffset[l] = std::uint32_t(kept.size());
            for (std::uint32_t k = 0; k < n; ++k)
                if (r.lightIndices[begin + k] != light_) kept.push_back(r.lightIndices[begin + k]);
            r.listCount[l] = std::uint32_t(kept.size()) - r.listOffset[l];
        }
        r.lightIndices = std::move(kept);
        return r;
    }

private:
    CullBackend& inner_;
    std::uint32_t light_;
};

} // namespace

// A false negative or a list short of the CPU reference's found here is a
// bug to fix, with its repro as a new hard case: never a reason to shrink
// the budget.
TEST_F(GpuTest, EveryBuiltinAlgorithmOnVulkanHasNoCounterexample) {
    for (const std::string& name : cullParam("algorithm").choices) {
        HuntOptions o;
        o.settings.algorithm = algorithmFromString(name);
        o.seed = 36;
        o.maxTrials = 60;
        const HuntResult r = hunt(o, gputest::vulkan());
        EXPECT_FALSE(r.failure) << name << ": " << describe(r, o);
        EXPECT_EQ(r.coverage.trials, 60u) << name;
        EXPECT_GT(r.coverage.orthographic, 0u) << name;
        EXPECT_GT(r.coverage.reversedZ, 0u) << name;
        EXPECT_GT(r.coverage.wideSpots, 0u) << name;
    }
}

// A wall at z = -40 lit by light 0; light 1 floats at z = -10, far in front
// of it, inside the tiles' frustums but touching no geometry: `naive` lists
// it (tile planes, camera near and far), no pixel needs it. A culling that
// drops light 1 has no false negative, yet lacks the reference's entries:
// the hunt's Vulkan property says so, names the light, and the repro's
// verdict explains it.
TEST_F(GpuTest, ListsShortOfTheCpuReferenceFailTheHunt) {
    Scene s;
    Mesh wall;
    wall.name = "wall";
    lctest::addBox(wall, {-30, -30, -41}, {30, 30, -40});
    s.meshes.push_back(wall);
    s.camera.position = {0, 0, 0};
    s.camera.target = {0, 0, -1};
    s.camera.width = 96;
    s.camera.height = 64;
    s.camera.tileSize = 16;
    PointLight onWall, floating;
    onWall.name = "on the wall";
    onWall.position = {0, 0, -38};
    onWall.explicitRadius = 5;
    floating.name = "floating";
    floating.position = {1, 0, -10};
    floating.explicitRadius = 2;
    s.lights = {onWall, floating};

    HuntOptions o;
    o.settings.algorithm = Algorithm::Naive;
    const HuntVerdict honest = judgeHuntTrial(s, o, gputest::vulkan());
    EXPECT_FALSE(honest.fails) << honest.property;
    EXPECT_EQ(honest.missingReferenceEntries, 0u);

    DropsALight dropping(gputest::vulkan(), 1);
    const HuntVerdict v = judgeHuntTrial(s, o, dropping);
    EXPECT_TRUE(v.fails);
    EXPECT_EQ(v.falseNegatives, 0u) << "no pixel needs the floating light";
    EXPECT_EQ(v.property, "lists lack the CPU reference's entries");
    EXPECT_GT(v.missingReferenceEntries, 0u);
    EXPECT_EQ(v.referenceLight, 1u);

    HuntFailure f;
    f.original = f.shrunk = s;
    f.verdict = v;
    f.varied = "nothing";
    const std::string text = huntVerdictText(f, o);
    EXPECT_NE(text.find("lack"), std::string::npos) << text;
    EXPECT_NE(text.find("light 1"), std::string::npos) << text;
}
