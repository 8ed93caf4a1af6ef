// The `lightcull` CLI as a user runs it: listing scenes, help, a run from a
// scene file, and every kind of bad input -> a one-line error naming the
// thing, a non-zero exit, and no output folder.
#include "cli_support.hpp"

#include "culling/core/params.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/gltf_io.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include <sys/stat.h>
#include <nlohmann/json.hpp>

using lc_test::CliResult;
using lc_test::lineCount;
using lc_test::runCli;
using lc_test::ScratchDir;
namespace fs = std::filesystem;

TEST(Cli, ScenesListsEveryBuiltin) {
    ScratchDir s;
    const CliResult r = runCli({"scenes"}, s.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(lineCount(r.out), lc::builtinScenes().size());
    for (const auto& b : lc::builtinScenes()) {
        EXPECT_NE(r.out.find(b.name + " "), std::string::npos) << b.name;
        EXPECT_NE(r.out.find(b.description), std::string::npos) << b.name;
    }
}

TEST(Cli, HelpDocumentsEveryFlagAndVersionPrints) {
    ScratchDir s;
    const CliResult r = runCli({"run", "--help"}, s.path);
    ASSERT_EQ(r.code, 0) << r.err;
    for (const auto& p : lc::cullParams()) {
        EXPECT_NE(r.out.find("--" + p.name + " "), std::string::npos) << p.name;
        EXPECT_NE(r.out.find(p.help), std::string::npos) << p.name;
    }
    for (const char* f : {"--scene", "--builtin", "--lights", "--seed", "--backend", "--device",
                          "--no-image-error", "--out"})
        EXPECT_NE(r.out.find(f), std::string::npos) << f;
    const CliResult top = runCli({"--help"}, s.path);
    EXPECT_EQ(top.code, 0);
    EXPECT_NE(top.out.find("scenes"), std::string::npos);
    const CliResult v = runCli({"--version"}, s.path);
    EXPECT_EQ(v.code, 0);
    EXPECT_EQ(v.out.rfind("lightcull ", 0), 0u) << v.out;
}

TEST(Cli, RunFromASceneFileWritesTheDiagnostics) {
    ScratchDir s;
    lc::Scene scene = lc::makeBuiltinScene("wall");
    scene.name = "wall-from-file";
    lc::saveSceneFile(scene, (s.path / "scene.json").string());
    const fs::path out = s.path / "out";
    const CliResult r = runCli({"run", "--scene", (s.path / "scene.json").string(), "--width", "80",
                                "--height", "48", "--tile", "8", "--algorithm", "halfz", "--lights",
                                "50", "--seed", "9", "--backend", "cpu", "--out", out.string()},
                               s.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("false negatives 0"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find(out.string()), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(lc_test::slurp(out / "summary.json"));
    EXPECT_EQ(j["scene"], "wall-from-file");
    EXPECT_EQ(j["algorithm"], "halfz");
    EXPECT_EQ(j["width"], 80);
    EXPECT_EQ(j["height"], 48);
    EXPECT_EQ(j["tile_size"], 8);
    EXPECT_EQ(j["lights"], 50);
    EXPECT_EQ(j["backend"], "cpu");
    EXPECT_EQ(j["metrics"]["lists"], 10 * 6 * 2);
    // The metrics are the run's own: the same scene, lights and settings run
    // here give the same figures (CPU backend: deterministic; the summary's
    // doubles read back exactly).
    {
        lc::Scene same = lc::loadSceneFile((s.path / "scene.json").string());
        same.lights = lc::generateLights(lc::defaultLightGen(same, 50, 9));
        lc::CullSettings cs;
        lc::setParam(cs, same.camera, "width", "80");
        lc::setParam(cs, same.camera, "height", "48");
        lc::setParam(cs, same.camera, "tile", "8");
        lc::setParam(cs, same.camera, "algorithm", "halfz");
        auto cpu = lc::makeBackend("cpu");
        const lc::Metrics m = lc::runPipeline(same, cs, *cpu).truth.metrics;
        ASSERT_TRUE(m.imageErrorComputed);
        const auto& jm = j["metrics"];
        EXPECT_EQ(jm["false_negatives"].get<std::uint64_t>(), m.falseNegatives);
        EXPECT_EQ(jm["shading_work"].get<std::uint64_t>(), m.shadingWork);
        EXPECT_EQ(jm["exact_work"].get<std::uint64_t>(), m.exactWork);
        EXPECT_EQ(jm["optimal_work"].get<std::uint64_t>(), m.optimalWork);
        EXPECT_EQ(jm["efficiency"].get<double>(), m.efficiency);
        EXPECT_EQ(jm["image_rmse"].get<double>(), m.imageRmse);
        EXPECT_EQ(jm["image_max_error"].get<double>(), m.imageMaxError);
        EXPECT_GT(m.exactWork, 0u); // the lights reach the wall: the comparison is not of zeros
    }
    EXPECT_TRUE(fs::is_regular_file(out / "tiles.csv"));
    EXPECT_TRUE(fs::is_regular_file(out / "heatmap.png"));
    // The folder gets the permissions mkdir would give it (not mkdtemp's 0700).
    {
        const mode_t mask = ::umask(0);
        ::umask(mask);
        struct stat st {};
        ASSERT_EQ(::stat(out.c_str(), &st), 0);
        EXPECT_EQ(st.st_mode & 0777, 0777 & ~mask);
    }

    // --lights with the same seed is deterministic; another seed differs.
    const CliResult again = runCli({"run", "--scene", (s.path / "scene.json").string(), "--width", "80",
                                    "--height", "48", "--tile", "8", "--algorithm", "halfz", "--lights",
                                    "50", "--seed", "9", "--backend", "cpu", "--no-image-error",
                                    "--out", (s.path / "out2").string()},
                                   s.path);
    ASSERT_EQ(again.code, 0) << again.err;
    EXPECT_EQ(lc_test::slurp(out / "tiles.csv"), lc_test::slurp(s.path / "out2" / "tiles.csv"));
    EXPECT_TRUE(nlohmann::json::parse(lc_test::slurp(s.path / "out2" / "summary.json"))["metrics"]["image_rmse"].is_null());
}

namespace {

// Runs a command expected to fail: non-zero exit, exactly one line on stderr
// mentioning `needle`, nothing on stdout, and the output folder not created.
// `code`: the exit status expected (docs/CLI.md: 2 for a bad command line,
// 1 for a failed run); -1: any failure.
void expectCleanFailure(std::vector<std::string> args, const std::string& needle, int code = -1) {
    ScratchDir s;
    const fs::path out = s.path / "out";
    bool hasOut = false;
    for (auto& a : args) {
        if (a == "OUT") a = out.string(), hasOut = true;
    }
    const CliResult r = runCli(args, s.path);
    std::string joined;
    for (const auto& a : args) joined += a + " ";
    EXPECT_NE(r.code, 0) << joined;
    if (code >= 0) EXPECT_EQ(r.code, code) << joined << "\nstderr: " << r.err;
    EXPECT_EQ(lineCount(r.err), 1u) << joined << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find(needle), std::string::npos) << joined << "\nstderr: " << r.err;
    EXPECT_EQ(r.err.find("terminate"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    if (hasOut) EXPECT_FALSE(fs::exists(out)) << joined;
    // Nothing at all besides what the harness itself made.
    for (const auto& e : fs::directory_iterator(s.path))
        ADD_FAILURE() << joined << ": left behind " << e.path();
}

} // namespace

TEST(Cli, BadCommandLinesFailWithOneLineNamingTheProblem) {
    const std::vector<std::string> base = {"run", "--builtin", "wall", "--width", "32", "--height", "24",
                                           "--backend", "cpu", "--out", "OUT"};
    auto with = [&](std::vector<std::string> extra) {
        std::vector<std::string> a = base;
        a.insert(a.end(), extra.begin(), extra.end());
        return a;
    };
    // A bad value on the command line: exit 2, whichever layer finds it
    // (the parser, the parameter table, the light generator).
    expectCleanFailure(with({"--bogus", "3"}), "--bogus", 2);
    expectCleanFailure(with({"--cells", "99"}), "--cells", 2);
    expectCleanFailure(with({"--cells", "many"}), "--cells", 2);
    expectCleanFailure(with({"--algorithm", "quadtree"}), "--algorithm", 2);
    expectCleanFailure(with({"--test", "sphere"}), "--test", 2);
    expectCleanFailure(with({"--slicing", "cubic"}), "--slicing", 2);
    expectCleanFailure(with({"--skip-empty", "maybe"}), "--skip-empty", 2);
    expectCleanFailure(with({"--tile", "0"}), "--tile", 2);
    expectCleanFailure(with({"--width", "-5"}), "--width", 2);
    expectCleanFailure(with({"--width", "0"}), "--width", 2);
    expectCleanFailure(with({"--lights", "-3"}), "--lights", 2);
    expectCleanFailure(with({"--lights", "1000001"}), "--lights", 2);
    expectCleanFailure({"run", "--builtin", "wall", "--backend", "metal", "--out", "OUT"}, "metal");
    expectCleanFailure({"run", "--builtin", "nowhere", "--out", "OUT"}, "nowhere");
    expectCleanFailure({"run", "--scene", "/nonexistent/scene.json", "--out", "OUT"}, "/nonexistent/scene.json");
    expectCleanFailure({"run", "--builtin", "wall", "--scene", "x.json", "--out", "OUT"}, "--scene");
    expectCleanFailure({"run", "--builtin", "wall"}, "--out");
    expectCleanFailure({"run", "--out", "OUT"}, "--builtin");
    expectCleanFailure({"frobnicate"}, "frobnicate", 2);
    // glTF's --camera and --min-intensity with a scene JSON would be ignored.
    {
        const fs::path scene = fs::path(LC_SOURCE_DIR) / "resources" / "scenes" / "stele_courtyard.json";
        expectCleanFailure({"run", "--scene", scene.string(), "--camera", "Main", "--out", "OUT"},
                           "--camera: applies to glTF scenes", 2);
        expectCleanFailure({"run", "--scene", scene.string(), "--min-intensity", "0.5", "--out", "OUT"},
                           "--min-intensity: applies to glTF scenes", 2);
    }
    expectCleanFailure({}, "subcommand");
}

// run's header names the settings the algorithm reads, not every one.
TEST(Cli, RunHeaderNamesOnlyTheSettingsTheAlgorithmReads) {
    ScratchDir s;
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"minmax", "algorithm minmax, test planes, backend cpu"},
        {"2.5d", "algorithm 2.5d, test planes, cells 32, slicing log, backend cpu"},
        {"zbin", "algorithm zbin, test planes, bins 1024, backend cpu"},
    };
    for (const auto& [algorithm, header] : cases) {
        const CliResult r = runCli({"run", "--builtin", "wall", "--width", "32", "--height", "24", "--backend", "cpu",
                                    "--algorithm", algorithm, "--test", "planes", "--no-image-error", "--out",
                                    (s.path / algorithm).string()},
                                   s.path);
        ASSERT_EQ(r.code, 0) << r.err;
        EXPECT_NE(r.out.find(header), std::string::npos) << r.out;
    }
}

// raster's proxy line counts the proxies drawn: under a light limit, the
// lights it keeps (it counted every light of the scene).
TEST(Cli, RasterProxiesAreTheLightsTheLimitKeeps) {
    ScratchDir s;
    const CliResult r = runCli({"run", "--builtin", "wall", "--width", "64", "--height", "48", "--backend", "cpu",
                                "--lights", "20", "--algorithm", "raster", "--max-lights", "8", "--no-image-error",
                                "--out", (s.path / "o").string()},
                               s.path);
    ASSERT_TRUE(r.code == 0 || r.code == 3) << r.err; // the limit may miss lights
    EXPECT_NE(r.out.find("12 lights past the limit"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("proxies: 8 icospheres of level"), std::string::npos) << r.out;
}

// The parser's own complaints, worded as the rest: the flag, what it takes,
// what it got (they read "Value abc not in range 1 to 1000" and "Could not
// convert: --lights = x").
TEST(Cli, ParserErrorsNameTheFlagAndWhatItGot) {
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"report", "--builtin", "sky", "--repeat", "abc", "--out", "OUT"},
         "--repeat: expected a number from 1 to 1000, got 'abc'"},
        {{"run", "--builtin", "sky", "--lights", "x", "--out", "OUT"}, "--lights: 'x' is not a number"},
        {{"hunt", "--shader", "x.comp", "--timeout-ms", "0", "--out", "OUT"},
         "--timeout-ms: expected a number from 1 to 3600000, got '0'"},
        {{"report", "--builtin", "sky", "extra", "--out", "OUT"},
         "'extra' is not an option or argument here (see lightcull report --help)"},
        {{"bench", "--builtin", "sky", "--nope"},
         "'--nope' is not an option or argument here (see lightcull bench --help)"},
    };
    ScratchDir s;
    for (const auto& [args, message] : cases) {
        const CliResult r = runCli(args, s.path);
        EXPECT_EQ(r.code, 2) << args[0];
        EXPECT_EQ(r.err, "lightcull: error: " + message + "\n");
    }
}

// A view with no geometry scores as a perfect culler: the CLI says so. A
// scene JSON without a camera frames its meshes (as a glTF does) instead of
// looking at the origin from a fixed place.
// The docs' `--out out/frame` in a fresh folder: missing parent folders are
// made; a parent that is a file is refused before the run, in one line.
TEST(Cli, OutMakesMissingParentFoldersAndRefusesAFileOnItsPath) {
    ScratchDir s;
    const CliResult ok = runCli({"run", "--builtin", "wall", "--width", "64", "--height", "32", "--backend", "cpu",
                                 "--no-image-error", "--out", (s.path / "out" / "deep" / "wall").string()},
                                s.path);
    EXPECT_EQ(ok.code, 0) << ok.err;
    EXPECT_TRUE(fs::exists(s.path / "out" / "deep" / "wall" / "summary.json"));
    std::ofstream(s.path / "afile") << "x";
    const CliResult bad = runCli({"run", "--builtin", "wall", "--width", "64", "--height", "32", "--backend", "cpu",
                                  "--out", (s.path / "afile" / "sub" / "out").string()},
                                 s.path);
    EXPECT_NE(bad.code, 0);
    EXPECT_NE(bad.err.find((s.path / "afile").string() + " is not a folder"), std::string::npos) << bad.err;
    EXPECT_EQ(lineCount(bad.err), 1u) << bad.err;
    EXPECT_FALSE(fs::exists(s.path / "afile" / "sub"));
}

TEST(Cli, AnEmptyViewIsSaidAndAMissingCameraFramesTheMeshes) {
    ScratchDir s;
    const std::string mesh = R"("meshes": [{"positions": [40, 0, 40, 44, 0, 40, 40, 4, 40], "indices": [0, 1, 2]}],
        "lights": [{"name": "a", "position": [41, 1, 39], "radius": 3}])";
    std::ofstream(s.path / "away.json") << R"({"format": "lightcull-scene", "version": 1,
        "camera": {"position": [0, 0, 0], "target": [0, 0, 5], "width": 64, "height": 64}, )" << mesh << "}";
    std::ofstream(s.path / "nocam.json") << R"({"format": "lightcull-scene", "version": 1, )" << mesh << "}";
    CliResult r = runCli({"run", "--scene", (s.path / "away.json").string(), "--backend", "cpu", "--out",
                          (s.path / "o1").string()},
                         s.path);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("warning: the camera sees no geometry"), std::string::npos) << r.err;
    r = runCli({"run", "--scene", (s.path / "nocam.json").string(), "--backend", "cpu", "--width", "64", "--height",
                "64", "--out", (s.path / "o2").string()},
               s.path);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
    const auto j = nlohmann::json::parse(lc_test::slurp(s.path / "o2" / "summary.json"));
    EXPECT_GT(j["metrics"]["geometry_pixels"].get<std::uint64_t>(), 200u);
}

// --min-intensity sizes the glTF lights without a range; summary.json says
// how many, and a cut-off that sizes none is warned about (it changed
// nothing, though the summary would otherwise record it as if it had).
TEST(Cli, MinIntensityCountsTheLightsItSizedAndWarnsWhenItSizedNone) {
    ScratchDir s;
    lc::Scene scene = lc::makeBuiltinScene("wall");
    scene.lights.resize(2);
    for (auto& l : scene.lights) {
        l.kind = lc::LightKind::Point;
        l.explicitRadius = 2.0;
    }
    auto j = nlohmann::json::parse(lc::serializeGltf(scene, false));
    std::ofstream(s.path / "ranged.gltf") << j.dump();
    auto& light = j["extensions"]["KHR_lights_punctual"]["lights"][0];
    light.erase("range");
    light.erase("extras");
    std::ofstream(s.path / "one_without.gltf") << j.dump();
    for (const auto& [file, sized] : {std::pair{"ranged.gltf", 0}, std::pair{"one_without.gltf", 1}}) {
        const fs::path out = s.path / (std::string("out_") + file);
        const CliResult r = runCli({"run", "--scene", (s.path / file).string(), "--min-intensity", "0.5", "--backend",
                                    "cpu", "--width", "64", "--height", "36", "--no-image-error", "--out", out.string()},
                                   s.path);
        ASSERT_EQ(r.code, 0) << r.err;
        const bool warned = r.err.find("--min-intensity applies to no light") != std::string::npos;
        EXPECT_EQ(warned, sized == 0) << file << ": " << r.err;
        const auto summary = nlohmann::json::parse(lc_test::slurp(out / "summary.json"));
        EXPECT_EQ(summary["scene_source"]["gltf_min_intensity"].get<double>(), 0.5) << file;
        EXPECT_EQ(summary["scene_source"]["gltf_cutoff_lights"].get<int>(), sized) << file;
    }
}

// An output the command could not write is a bad command line, said before
// any work (a large run took minutes to end in 'refusing to replace'), with
// nothing on stdout and no temporary names in the message.
TEST(Cli, OutputsThatCannotBeWrittenAreRefusedFirst) {
    ScratchDir s;
    fs::create_directory(s.path / "mine");
    std::ofstream(s.path / "mine" / "notes.txt") << "keep";
    std::ofstream(s.path / "afile") << "x";
    fs::create_directory(s.path / "adir");
    struct Case {
        std::vector<std::string> args;
        std::string expected;
    };
    const std::vector<Case> cases = {
        {{"run", "--builtin", "wall", "--out", (s.path / "mine").string()}, "--out: refusing to replace"},
        {{"run", "--builtin", "wall", "--out", (s.path / "afile").string()}, "--out: cannot export diagnostics into"},
        {{"report", "--builtin", "wall", "--backend", "cpu", "--out", (s.path / "mine").string()},
         "--out: refusing to replace"},
        {{"bench", "--builtin", "wall", "--backend", "cpu", "--repeat", "1", "--warmup", "0", "--json",
          (s.path / "adir").string()},
         "--json: cannot write " + (s.path / "adir").string() + ": it is a folder"},
        {{"convert", std::string(LC_SOURCE_DIR) + "/resources/scenes/stele_courtyard.json",
          (s.path / "nodir" / "x.glb").string()},
         "OUT: cannot write"},
    };
    for (const Case& c : cases) {
        const CliResult r = runCli(c.args, s.path);
        EXPECT_EQ(r.code, 2) << c.args[0] << ": " << r.err;
        EXPECT_NE(r.err.find(c.expected), std::string::npos) << r.err;
        EXPECT_EQ(r.err.find(".tmp"), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty()) << r.out;
    }
    EXPECT_EQ(lc_test::slurp(s.path / "mine" / "notes.txt"), "keep");
}

TEST(Cli, BadSceneFileFailsNamingTheFileAndNothingIsWritten) {
    ScratchDir s;
    {
        std::ofstream(s.path / "broken.json") << "{ \"version\": 1, \"lights\": [ { \"position\": [0, 1";
    }
    const fs::path out = s.path / "out";
    const CliResult r = runCli({"run", "--scene", (s.path / "broken.json").string(), "--out", out.string()}, s.path);
    EXPECT_NE(r.code, 0);
    EXPECT_EQ(lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("broken.json"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out));
}
