// The hunt (issue 35) on the Vulkan backend, on lavapipe with the validation
// layer: every built-in algorithm hunts a fixed budget with no
// counterexample, and a trial judges, besides false negatives, that the
// Vulkan lists hold every entry the CPU reference lists over the same depth
// image (what test_vulkan_cull checks on its hand-picked frames).
#include "gpu_test_env.hpp"

#include "../unit/cli_support.hpp"

#include "../support/box_mesh.hpp"
#include "culling/core/params.hpp"
#include "culling/diagnostics/hunt.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

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
protected:
    DepthPass renderDepthPass(const Scene& scene, const Projection& proj) override {
        return inner_.depthPass(scene, proj);
    }

    CullResult cullFrame(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                         const ViewLights& lights, const CullSettings& settings) override {
        CullResult r = inner_.cull(depth, proj, frame.grid, lights, settings);
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

// A custom shader that never misses a light but lists light 0 twice in every
// tile (a shading pass adds it twice) fails the hunt at its first trial with
// a light, and its repro's `lightcull run` exits 3 as the hunt says.
TEST(HuntCustomProperties, ADuplicateIndexIsAFailureAndRunSaysSoToo) {
    namespace fs = std::filesystem;
    lc_test::ScratchDir s;
    const fs::path out = s.path / "dup";
    const lc_test::CliResult r =
        lc_test::runCli({"hunt", "--shader", std::string(LC_TEST_DATA_DIR) + "/custom/duplicate_light.comp",
                         "--backend", "cpu", "--trials", "10", "--seed", "3", "--out", out.string()},
                        s.path);
    ASSERT_EQ(r.code, 3) << r.out << r.err;
    EXPECT_NE(r.err.find("duplicate indices"), std::string::npos) << r.err;
    const std::string verdict = lc_test::slurp(out / "verdict.txt");
    EXPECT_NE(verdict.find("(duplicate indices)"), std::string::npos) << verdict;
    EXPECT_NE(verdict.find("0 false negatives"), std::string::npos) << verdict;
    EXPECT_EQ(nlohmann::json::parse(lc_test::slurp(out / "scene.json"))["lights"].size(), 1u);
    // scene.glb is the same scene for glTF tools: camera, lights, meshes.
    const Scene json = loadSceneFile((out / "scene.json").string());
    const Scene glb = loadSceneAny((out / "scene.glb").string());
    ASSERT_EQ(glb.lights.size(), 1u);
    EXPECT_NEAR(glm::distance(glb.lights[0].position, json.lights[0].position), 0.0, 1e-9);
    EXPECT_NEAR(glb.lights[0].radius(), json.lights[0].radius(), 1e-9 * json.lights[0].radius());
    EXPECT_EQ(glb.camera.width, json.camera.width);
    EXPECT_EQ(glb.camera.height, json.camera.height);
    EXPECT_EQ(glb.camera.projection, json.camera.projection);
    EXPECT_EQ(glb.triangleCount(), json.triangleCount());
    std::string reproLog;
    EXPECT_EQ(lc_test::runReproScript(out, &reproLog), 3) << reproLog;
    // The shrunk repro's one duplicate, in the singular.
    EXPECT_NE(reproLog.find("1 duplicate index"), std::string::npos) << reproLog;
    // And where it is.
    EXPECT_NE(reproLog.find("duplicates 1 (first: list "), std::string::npos) << reproLog;
}

// --path on the flawed tile-edge shader: the atrium panned past at 650 x 370
// (not whole tiles) misses lights in some frames; the CSV marks them, the
// plot names the worst frame, and its shrunk repro shows the miss (exit 3).
TEST(HuntCustomProperties, ACameraPathFindsTheFramesWhereTheFlawedShaderMisses) {
    namespace fs = std::filesystem;
    lc_test::ScratchDir s;
    const Camera c = makeBuiltinScene("atrium").camera;
    std::ostringstream o;
    o << "{\"cameras\": [";
    for (int k = 0; k < 8; ++k)
        o << (k ? ", " : "") << "{\"position\": [" << c.position.x + 0.5 * k << ", " << c.position.y << ", "
          << c.position.z << "], \"target\": [" << c.target.x + 0.5 * k << ", " << c.target.y << ", " << c.target.z
          << "], \"width\": 650, \"height\": 370}";
    o << "]}";
    std::ofstream(s.path / "pan.json") << o.str();
    const fs::path out = s.path / "path";
    const lc_test::CliResult r = lc_test::runCli(
        {"hunt", "--builtin", "atrium", "--shader", std::string(LC_SOURCE_DIR) +
                                                        "/resources/culling-examples/flawed_tile_edges.comp",
         "--backend", "cpu", "--path", (s.path / "pan.json").string(), "--out", out.string()},
        s.path);
    ASSERT_EQ(r.code, 3) << r.out << r.err;
    std::ifstream csv(out / "path.csv");
    std::string line;
    std::getline(csv, line);
    int rows = 0, failing = 0;
    while (std::getline(csv, line)) {
        ++rows;
        failing += line.find(",1,false negatives") != std::string::npos;
    }
    EXPECT_EQ(rows, 8);
    EXPECT_GT(failing, 0);
    EXPECT_NE(r.out.find("8 frames, " + std::to_string(failing) + " failing"), std::string::npos) << r.out;
    const std::string verdict = lc_test::slurp(out / "verdict.txt");
    EXPECT_NE(verdict.find("at frame "), std::string::npos) << verdict;
    EXPECT_NE(verdict.find("of 8 (8 cameras"), std::string::npos) << verdict;
    EXPECT_NE(lc_test::slurp(out / "path.svg").find("worst frame"), std::string::npos);
    std::string reproLog;
    EXPECT_EQ(lc_test::runReproScript(out, &reproLog), 3) << reproLog;
}
