// The hunt (issue 35) on the CPU backend: every built-in algorithm (and every
// spot test) hunts a fixed number of trials with no counterexample, a trial
// is a pure function of its seed and index, and `lightcull hunt` reports,
// writes its verdict and refuses bad flags like the other commands.
#include "cli_support.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/params.hpp"
#include "culling/diagnostics/hunt.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

using namespace lc;
using lc_test::CliResult;
using lc_test::runCli;
using lc_test::ScratchDir;

namespace {

// What a counterexample says, so that a failure of these tests is a repro.
std::string describe(const HuntResult& r, const HuntOptions& o) {
    if (!r.failure) return {};
    return huntVerdictText(*r.failure, o) + "\nshrunk scene:\n" + serializeScene(r.failure->shrunk);
}

} // namespace

// A built-in algorithm's false negative found here is a bug to fix, with its
// repro as a new hard case: never a reason to shrink the budget.
TEST(Hunt, EveryBuiltinAlgorithmOnTheCpuBackendHasNoCounterexample) {
    auto cpu = makeCpuBackend();
    for (const std::string& name : cullParam("algorithm").choices) {
        HuntOptions o;
        o.settings.algorithm = algorithmFromString(name);
        o.seed = 35;
        o.maxTrials = 500;
        const HuntResult r = hunt(o, *cpu);
        EXPECT_FALSE(r.failure) << name << ": " << describe(r, o);
        EXPECT_EQ(r.coverage.trials, r.failure ? r.failure->trial + 1 : 500u) << name;
        EXPECT_GT(r.coverage.orthographic, 0u) << name;
        EXPECT_GT(r.coverage.reversedZ, 0u) << name;
        EXPECT_GT(r.coverage.nonMultipleScreens, 0u) << name;
        EXPECT_GT(r.coverage.wideSpots, 0u) << name;
        EXPECT_GT(r.coverage.crowds, 0u) << name;
        EXPECT_LT(r.coverage.emptyViews, r.coverage.trials / 2) << name << ": most trials must see geometry";
    }
}

TEST(Hunt, EverySpotTestOnTheCpuBackendHasNoCounterexample) {
    auto cpu = makeCpuBackend();
    for (const std::string& algorithm : {"minmax", "2.5d", "clustered"})
        for (const std::string& test : cullParam("spot-test").choices) {
            HuntOptions o;
            Camera unused;
            setParam(o.settings, unused, "algorithm", algorithm);
            setParam(o.settings, unused, "spot-test", test);
            o.seed = 8;
            o.maxTrials = 150;
            const HuntResult r = hunt(o, *cpu);
            EXPECT_FALSE(r.failure) << algorithm << " " << test << ": " << describe(r, o);
        }
}

TEST(Hunt, GivenSceneKeepsItsMeshesAndVariesTheRest) {
    auto cpu = makeCpuBackend();
    const Scene atrium = makeBuiltinScene("atrium");
    HuntOptions o;
    o.baseScene = &atrium;
    o.maxTrials = 30;
    o.seed = 3;
    const Scene t = makeHuntTrial(&atrium, 3, 4, HuntAll);
    EXPECT_EQ(t.triangleCount(), atrium.triangleCount());
    EXPECT_LE(t.camera.width, 400u);
    const HuntResult r = hunt(o, *cpu);
    EXPECT_FALSE(r.failure) << describe(r, o);
    EXPECT_EQ(r.coverage.generatedScenes, 0u);
    // Only lights varied: the camera is the scene's.
    const Scene l = makeHuntTrial(&atrium, 3, 4, HuntLights);
    EXPECT_EQ(l.camera, atrium.camera);
    EXPECT_NE(serializeScene(l), serializeScene(atrium));
}

TEST(Hunt, TheSameSeedGivesTheSameTrialsAndResult) {
    for (std::uint64_t i : {0u, 1u, 17u, 99u}) {
        EXPECT_EQ(serializeScene(makeHuntTrial(nullptr, 5, i, HuntAll)), serializeScene(makeHuntTrial(nullptr, 5, i, HuntAll)))
            << i;
        EXPECT_NE(serializeScene(makeHuntTrial(nullptr, 5, i, HuntAll)), serializeScene(makeHuntTrial(nullptr, 6, i, HuntAll)))
            << i;
    }
    EXPECT_NE(serializeScene(makeHuntTrial(nullptr, 5, 1, HuntAll)), serializeScene(makeHuntTrial(nullptr, 5, 2, HuntAll)));
    auto cpu = makeCpuBackend();
    HuntOptions o;
    o.settings.algorithm = Algorithm::HalfZ;
    o.seed = 11;
    o.maxTrials = 40;
    const HuntResult a = hunt(o, *cpu), b = hunt(o, *cpu);
    EXPECT_EQ(a.coverage.text(), b.coverage.text());
    EXPECT_EQ(a.coverage.trials, 40u);
    EXPECT_EQ(bool(a.failure), bool(b.failure));
}

TEST(Hunt, VaryParsesItsDimensionsAndRefusesUnknownOnes) {
    EXPECT_EQ(parseHuntDims("all"), unsigned(HuntAll));
    EXPECT_EQ(parseHuntDims("camera,screen"), unsigned(HuntCamera | HuntScreen));
    EXPECT_EQ(huntDimsToString(HuntLights | HuntSpots), "lights,spots");
    EXPECT_THROW(parseHuntDims("camera,colour"), SettingsError);
}

// --preset: every trial is culled with the engine's settings for that trial's
// screen and light count (here URP mobile's light limit and derived tile
// size), and the repro names them one by one with the preset's tile size in
// its scene, so that it runs as the trial did.
TEST(Hunt, APresetIsDerivedForEachTrial) {
    auto cpu = makeCpuBackend();
    const EnginePreset& urpMobile = enginePreset("urp-mobile");
    Scene many = makeBuiltinScene("atrium");
    many.camera.width = 208;
    many.camera.height = 92;
    HuntOptions plain, engine;
    engine.preset = &urpMobile;
    Scene derived = many;
    const CullSettings s = huntSettings(engine, derived);
    CullSettings expect;
    Camera expectCamera = many.camera;
    applyPreset(urpMobile, expect, expectCamera, many.lights.size());
    EXPECT_EQ(getParam(s, derived.camera, "max-lights"), getParam(expect, expectCamera, "max-lights"));
    EXPECT_EQ(derived.camera.tileSize, expectCamera.tileSize);
    ASSERT_LT(s.maxLights, many.lights.size()); // atrium's 512 lights are past a mobile light limit
    // The same scene over the engine's light limit; without the preset, not.
    EXPECT_TRUE(judgeHuntTrial(many, engine, *cpu).overCapacity);
    EXPECT_FALSE(judgeHuntTrial(many, plain, *cpu).overCapacity);
    EXPECT_EQ(huntSettings(plain, many).algorithm, plain.settings.algorithm);

    // Over capacity as the failure: found, shrunk and written as the engine runs it.
    engine.overflowIsFailure = true;
    engine.seed = 1;
    engine.maxTrials = 40;
    const HuntResult r = hunt(engine, *cpu);
    ASSERT_TRUE(r.failure) << r.coverage.text();
    EXPECT_NE(huntVerdictText(*r.failure, engine).find("engine preset urp-mobile"), std::string::npos);
    ScratchDir dir;
    const std::string command = writeHuntRepro(r, engine, *cpu, (dir.path / "repro").string(), "");
    Scene shrunk = r.failure->shrunk;
    const CullSettings forShrunk = huntSettings(engine, shrunk);
    EXPECT_NE(command.find("--max-lights " + std::to_string(forShrunk.maxLights)), std::string::npos) << command;
    EXPECT_EQ(loadSceneFile((dir.path / "repro" / "scene.json").string()).camera.tileSize, shrunk.camera.tileSize);
    EXPECT_NE(lc_test::slurp(dir.path / "repro" / "summary.json").find("\"preset\": \"urp-mobile\""),
              std::string::npos);
}

TEST(HuntCli, NoCounterexampleExitsZeroWithCoverage) {
    ScratchDir s;
    const auto out = s.path / "hunt";
    const CliResult r = runCli({"hunt", "--backend", "cpu", "--algorithm", "minmax", "--trials", "40", "--seed", "2",
                                "--out", out.string()},
                               s.path);
    ASSERT_EQ(r.code, 0) << r.err << r.out;
    EXPECT_NE(r.out.find("no miss in 40 trials"), std::string::npos) << r.out;
    EXPECT_NE(r.err.find("trials/s"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("orthographic"), std::string::npos) << r.err;
    EXPECT_NE(lc_test::slurp(out / "verdict.txt").find("no miss"), std::string::npos);
    EXPECT_FALSE(std::filesystem::exists(out / "repro.sh"));
}

TEST(HuntCli, BadFlagsExitTwo) {
    ScratchDir s;
    EXPECT_EQ(runCli({"hunt", "--backend", "cpu", "--vary", "colour", "--out", (s.path / "h").string()}, s.path).code, 2);
    std::ofstream(s.path / "afile") << "x"; // a file where a parent folder would be
    EXPECT_EQ(runCli({"hunt", "--backend", "cpu", "--out", (s.path / "afile" / "such" / "h").string()}, s.path).code, 2);
    std::ofstream(s.path / "keep.txt") << "mine";
    const CliResult r = runCli({"hunt", "--backend", "cpu", "--trials", "1", "--out", s.path.string()}, s.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_TRUE(std::filesystem::exists(s.path / "keep.txt"));
    EXPECT_EQ(runCli({"hunt", "--shader", "x.comp", "--algorithm", "naive", "--out", (s.path / "h").string()}, s.path).code,
              2);
    const CliResult unknown = runCli({"hunt", "--preset", "quake", "--out", (s.path / "h").string()}, s.path);
    EXPECT_EQ(unknown.code, 2);
    EXPECT_NE(unknown.err.find("unknown preset 'quake' (known: urp"), std::string::npos) << unknown.err;
    EXPECT_EQ(runCli({"hunt", "--preset", "urp", "--shader", "x.comp", "--out", (s.path / "h").string()}, s.path).code,
              2);
    // Numbers that CLI11 would wrap or clamp, and nothing to vary.
    for (const std::vector<std::string>& bad :
         {std::vector<std::string>{"--trials", "-1"}, {"--trials", "0"}, {"--trials", "1.5"}, {"--seed", "-1"},
          {"--seed", "18446744073709551616"}, {"--budget", "0"}, {"--budget", "nan"}, {"--vary", ""}}) {
        std::vector<std::string> args{"hunt", "--backend", "cpu", "--out", (s.path / "n").string()};
        args.insert(args.end(), bad.begin(), bad.end());
        const CliResult r2 = runCli(args, s.path);
        EXPECT_EQ(r2.code, 2) << bad[0] << " " << bad[1] << ": " << r2.err;
        EXPECT_NE(r2.err.find(bad[0]), std::string::npos) << r2.err;
    }
}

// --out never replaces what a hunt did not write: a folder of the user's
// holding a scene.json (the very scene hunted, say) or a run/ is refused and
// left as it was; a folder a hunt wrote is reused.
TEST(HuntCli, OutNeverReplacesTheUsersFiles) {
    ScratchDir s;
    const auto mine = s.path / "myproj";
    std::filesystem::create_directories(mine / "run" / "deep");
    std::ofstream(mine / "run" / "deep" / "notes.txt") << "mine";
    const CliResult r = runCli({"hunt", "--builtin", "atrium", "--backend", "cpu", "--trials", "2", "--out",
                                mine.string()},
                               s.path);
    EXPECT_EQ(r.code, 2) << r.err;
    EXPECT_NE(r.err.find("no hunt wrote them"), std::string::npos) << r.err;
    EXPECT_TRUE(std::filesystem::exists(mine / "run" / "deep" / "notes.txt"));

    const auto again = s.path / "again";
    for (int k = 0; k < 2; ++k) {
        const CliResult a = runCli({"hunt", "--backend", "cpu", "--trials", "3", "--out", again.string()}, s.path);
        EXPECT_EQ(a.code, 0) << k << ": " << a.err;
    }
}

// A shader that does not compile is the user's file, not a trial's failure:
// one line naming the file and line, exit 1, no repro folder.
TEST(HuntCli, AShaderThatDoesNotCompileIsAnErrorNotACounterexample) {
    ScratchDir s;
    std::ofstream(s.path / "broken.comp") << "// lightcull: --layout fixed:8 --lists tile\n#version 450\n"
                                              "layout(local_size_x = 1) in;\nvoid main() { nope(); }\n";
    const CliResult r = runCli({"hunt", "--shader", (s.path / "broken.comp").string(), "--backend", "cpu",
                                "--trials", "3", "--out", (s.path / "h").string()},
                               s.path);
    EXPECT_EQ(r.code, 1) << r.err;
    EXPECT_NE(r.err.find("broken.comp:4"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("compile error"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(s.path / "h"));
}

namespace {
// A JSON camera path (docs/FORMATS.md, "Camera paths"): `n` cameras panning
// along x past the atrium's own camera, each keeping the scene's other values.
std::filesystem::path writePanPath(const std::filesystem::path& dir, int n, const std::string& extra = {}) {
    const Camera c = makeBuiltinScene("atrium").camera;
    std::ostringstream o;
    o << "{\"cameras\": [";
    for (int k = 0; k < n; ++k)
        o << (k ? ", " : "") << "{\"position\": [" << c.position.x + 0.4 * k << ", " << c.position.y << ", "
          << c.position.z << "], \"target\": [" << c.target.x + 0.4 * k << ", " << c.target.y << ", " << c.target.z
          << "]" << extra << "}";
    o << "]}";
    const auto p = dir / "pan.json";
    std::ofstream(p) << o.str();
    return p;
}
} // namespace

// --path: every frame judged; a CSV row per frame and the plot; a built-in
// algorithm misses nothing along the path (exit 0).
TEST(HuntCli, CameraPathJudgesEveryFrame) {
    ScratchDir s;
    const auto out = s.path / "path";
    const CliResult r = runCli({"hunt", "--builtin", "atrium", "--backend", "cpu", "--algorithm", "minmax", "--path",
                                writePanPath(s.path, 6).string(), "--out", out.string()},
                               s.path);
    ASSERT_EQ(r.code, 0) << r.err << r.out;
    EXPECT_NE(r.out.find("no miss in 6 frames of"), std::string::npos) << r.out;
    std::ifstream csv(out / "path.csv");
    std::string line;
    std::getline(csv, line);
    EXPECT_EQ(line.rfind("frame,time,false_negatives,geometry_pixels,", 0), 0u) << line;
    int rows = 0;
    while (std::getline(csv, line)) {
        EXPECT_EQ(line.rfind(std::to_string(rows) + ",", 0), 0u) << line;
        EXPECT_NE(line.find(",0,"), std::string::npos) << line; // no false negatives
        ++rows;
    }
    EXPECT_EQ(rows, 6);
    const std::string svg = lc_test::slurp(out / "path.svg");
    EXPECT_NE(svg.find("<polyline"), std::string::npos);
    EXPECT_NE(svg.find("no frame misses a light"), std::string::npos);
}

TEST(HuntCli, CameraPathRefusesTheSearchFlagsAndNeedsAScene) {
    ScratchDir s;
    const std::string path = writePanPath(s.path, 2).string();
    const CliResult trials = runCli(
        {"hunt", "--builtin", "atrium", "--path", path, "--trials", "5", "--out", (s.path / "a").string()}, s.path);
    EXPECT_EQ(trials.code, 2);
    EXPECT_NE(trials.err.find("--trials: has no effect with --path"), std::string::npos) << trials.err;
    const CliResult noScene = runCli({"hunt", "--path", path, "--out", (s.path / "b").string()}, s.path);
    EXPECT_EQ(noScene.code, 2);
    EXPECT_NE(noScene.err.find("give the scene"), std::string::npos) << noScene.err;
    const CliResult fps = runCli({"hunt", "--fps", "10", "--out", (s.path / "c").string()}, s.path);
    EXPECT_EQ(fps.code, 2) << "--fps needs --path";
}

// Ctrl+C during a hunt writes what it covered and exits 130, not 0: an
// interrupted hunt is no clean pass for a CI job. One SIGINT, as a terminal
// sends it: without --foreground, timeout signals the child and then its own
// process group, and a second SIGINT rightly ends the hunt at once.
TEST(HuntCli, AnInterruptedHuntWritesWhatItCoveredAndExits130) {
    ScratchDir s;
    const auto out = s.path / "int";
    const std::string cmd = "timeout --foreground --preserve-status -s INT 3 '" + std::string(LC_CLI_PATH) +
                            "' hunt --backend cpu --budget 120 --out '" + out.string() + "' >'" +
                            (s.path / "log").string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    ASSERT_TRUE(WIFEXITED(status)) << lc_test::slurp(s.path / "log");
    EXPECT_EQ(WEXITSTATUS(status), 130) << lc_test::slurp(s.path / "log");
    const std::string verdict = lc_test::slurp(out / "verdict.txt");
    EXPECT_EQ(verdict.rfind("cancelled: no miss in ", 0), 0u) << verdict;
    EXPECT_NE(lc_test::slurp(s.path / "log").find("interrupted"), std::string::npos);
}
