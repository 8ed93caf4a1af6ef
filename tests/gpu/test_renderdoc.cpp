// RenderDoc captures, for real (Debian's librenderdoc and python3-renderdoc,
// on lavapipe with the validation layer): `run --renderdoc-capture` writes a
// capture of the tool's own passes, and `check --capture` reads the lists,
// depth, lights and camera back from it and gives the verdict the run gave:
// for every example shader of resources/culling-examples/ and a built-in
// algorithm, the same lists, the same false negatives and the same located
// misses. Bad captures and descriptions get one line each; without RenderDoc
// the commands say what to install.
#include "../unit/cli_support.hpp"

#include "culling/custom/custom_cull.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <tuple>

namespace fs = std::filesystem;
using lc_test::CliResult;
using lc_test::runCli;
using lc_test::ScratchDir;
using lc_test::slurp;
using nlohmann::json;

namespace {

const std::string kExamples = std::string(LC_SOURCE_DIR) + "/resources/culling-examples/";

void writeText(const fs::path& p, const std::string& text) {
    std::ofstream out(p);
    out << text;
}

// The custom-culling contract (docs/CUSTOM_CULLING.md) as a capture
// description: its bindings by number (GLSL and HLSL name them differently).
std::string contractDescription(const std::string& layout, const std::string& lists) {
    return R"({"lights": {"binding": "0.3", "stride": 32, "position": 0, "radius": 12, "spot_axis": 16, "spot_angle": 28},
 "camera": {"binding": "0.0", "projection": 96}, "depth": {"binding": "0.1"},
 "lists": {"layout": ")" + layout + R"(", "binding": "0.4", "rule": ")" + lists + R"("}})";
}

// Each list's count and lights (tiles.csv without the metrics a view-space
// float camera rounds differently: depth bounds, false negative pixels).
std::vector<std::string> listColumns(const fs::path& tilesCsv) {
    std::vector<std::string> rows;
    std::istringstream in(slurp(tilesCsv));
    std::string line;
    while (std::getline(in, line)) {
        std::vector<std::string> f;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) f.push_back(cell);
        if (f.size() < 13) f.resize(13);
        rows.push_back(f[0] + "," + f[1] + "," + f[2] + "," + f[6] + "," + f[12]);
    }
    return rows;
}

using Miss = std::tuple<std::uint32_t, std::uint32_t, std::uint32_t, std::uint64_t, std::string>;
std::set<Miss> misses(const json& summary) {
    std::set<Miss> out;
    for (const json& m : summary["custom"]["missed"])
        out.insert({m["list"].get<std::uint32_t>(), m["tile"][0].get<std::uint32_t>(), m["light"].get<std::uint32_t>(),
                    m["pixels"].get<std::uint64_t>(), m["cause"].get<std::string>()});
    return out;
}

class RenderDoc : public ::testing::Test {
protected:
    void SetUp() override { setenv("LIGHTCULL_VALIDATION", "1", 1); }
    ScratchDir dir;
};

struct Example {
    const char* file;
    std::vector<std::string> runFlags; // beside --builtin atrium
    std::string layout;                // empty: the shader's first line
    bool misses;                       // the run has false negatives
};

void PrintTo(const Example& e, std::ostream* os) { *os << e.file; }

class RoundTrip : public RenderDoc, public ::testing::WithParamInterface<Example> {};

} // namespace

// The tool's own run of a custom shader, captured, read back: the same
// verdict. flawed_tile_edges on a screen of 20.6 tiles misses lights; the
// capture's check locates the same misses.
TEST_P(RoundTrip, CheckCaptureGivesTheRunsVerdict) {
    const Example& e = GetParam();
    const std::string shader = kExamples + e.file;
    const lc::CustomShaderOptions header = lc::shaderOptionsFromFile(shader, e.layout);
    const fs::path capture = dir.path / "frame.rdc", run = dir.path / "run", check = dir.path / "check";
    std::vector<std::string> args{"run", "--builtin", "atrium", "--no-image-error", "--shader", shader,
                                  "--renderdoc-capture", capture.string(), "--out", run.string()};
    args.insert(args.end(), e.runFlags.begin(), e.runFlags.end());
    if (!e.layout.empty()) args.insert(args.end(), {"--layout", e.layout});
    const CliResult r = runCli(args, dir.path);
    ASSERT_EQ(r.code, e.misses ? 3 : 0) << r.err;
    EXPECT_NE(r.err.find("RenderDoc capture written to " + capture.string()), std::string::npos) << r.err;
    ASSERT_TRUE(fs::exists(capture));

    writeText(dir.path / "describe.json", contractDescription(lc::toString(header.layout), lc::toString(header.lists)));
    const CliResult c = runCli({"check", "--capture", capture.string(), "--dispatch", "custom.cull", "--describe",
                                (dir.path / "describe.json").string(), "--out", check.string()},
                               dir.path);
    ASSERT_EQ(c.code, r.code) << c.out << c.err;
    const json a = json::parse(slurp(run / "summary.json")), b = json::parse(slurp(check / "summary.json"));
    // Every field read is echoed.
    EXPECT_NE(c.out.find("read lights: " + std::to_string(a["lights"].get<int>()) + " ("), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("read camera: perspective, fov y 60 deg"), std::string::npos) << c.out;
    EXPECT_NE(c.out.find("read depth: "), std::string::npos) << c.out;

    EXPECT_EQ(b["metrics"]["false_negatives"], a["metrics"]["false_negatives"]);
    EXPECT_EQ(b["custom"]["overflow_lists"], a["custom"]["overflow_lists"]);
    EXPECT_EQ(misses(b), misses(a));
    if (e.misses) EXPECT_FALSE(misses(a).empty());
    EXPECT_EQ(listColumns(check / "tiles.csv"), listColumns(run / "tiles.csv"));
    EXPECT_EQ(b["depth_source"].get<std::string>().rfind("capture " + capture.string() + " event ", 0), 0u)
        << b["depth_source"];
}

INSTANTIATE_TEST_SUITE_P(
    Examples, RoundTrip,
    ::testing::Values(Example{"tiled_fixed.comp", {}, "", false}, Example{"tiled_fixed.hlsl", {}, "", false},
                      Example{"twofived_fixed.comp", {}, "", false}, Example{"clustered_compact.comp", {}, "", false},
                      Example{"flawed_reversed_z.comp", {}, "", false},
                      Example{"flawed_silent_cap.comp", {}, "", false},
                      Example{"flawed_wide_spot.comp", {}, "", false},
                      Example{"flawed_tile_edges.comp", {"--width", "330", "--height", "190", "--lights", "150"},
                              "bitmask", true}),
    [](const ::testing::TestParamInfo<Example>& i) {
        std::string n = i.param.file;
        for (char& ch : n)
            if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
        return n;
    });

// A built-in algorithm's own lists (2.5d: counts, prefix-sum offsets and an
// index array in three buffers; depth in a float buffer; lights as view-space
// vec4s; no matrix in the frame, so the lens is given).
TEST_F(RenderDoc, BuiltInRunRoundTripsThroughRangesLayout) {
    const fs::path capture = dir.path / "builtin.rdc", run = dir.path / "run", check = dir.path / "check";
    const CliResult r = runCli({"run", "--builtin", "atrium", "--backend", "vulkan", "--no-image-error",
                                "--renderdoc-capture", capture.string(), "--out", run.string()},
                               dir.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("(depth pre-pass, culling and shading)"), std::string::npos) << r.err;

    // capture-info: the passes' marker regions and the write pass's bindings.
    const CliResult all = runCli({"capture-info", capture.string()}, dir.path);
    ASSERT_EQ(all.code, 0) << all.err;
    EXPECT_NE(all.out.find("draw  vkCmdDrawIndexed()  [lc.depth.commands]"), std::string::npos) << all.out;
    EXPECT_NE(all.out.find("[lc.cull.commands.count / tile bounds]"), std::string::npos) << all.out;
    const CliResult info = runCli({"capture-info", capture.string(), "--dispatch", "commands.write"}, dir.path);
    ASSERT_EQ(info.code, 0) << info.err;
    EXPECT_NE(info.out.find("0.6  buffer ReadWriteBuffer"), std::string::npos) << info.out;
    EXPECT_NE(info.out.find("lc.cull.indices  (shader: IndexBuf_var)"), std::string::npos) << info.out;

    writeText(dir.path / "describe.json", R"({
  "lights": {"binding": "lc.cull.lights", "stride": 16, "position": 0, "radius": 12},
  "camera": {"fov_y_deg": 60, "near": 0.1, "far": 200},
  "depth": {"binding": "0.1", "width": 1280, "height": 720},
  "lists": {"layout": "ranges", "offsets": "OffsetBuf_var", "counts": "CountBuf_var", "indices": "IndexBuf_var"}
})");
    const CliResult c = runCli({"check", "--capture", capture.string(), "--dispatch", "commands.write", "--describe",
                                (dir.path / "describe.json").string(), "--out", check.string()},
                               dir.path);
    ASSERT_EQ(c.code, 0) << c.out << c.err;
    const json a = json::parse(slurp(run / "summary.json")), b = json::parse(slurp(check / "summary.json"));
    EXPECT_EQ(b["metrics"]["false_negatives"], 0);
    EXPECT_EQ(b["metrics"]["list_entries"], a["metrics"]["list_entries"]);
    EXPECT_EQ(b["metrics"]["shading_work"], a["metrics"]["shading_work"]);
    EXPECT_EQ(listColumns(check / "tiles.csv"), listColumns(run / "tiles.csv"));
    // The depth the culling read is the run's: the same exact work within
    // what a float view-space light moves (a few pixel-light pairs).
    const double wa = a["metrics"]["exact_work"].get<double>(), wb = b["metrics"]["exact_work"].get<double>();
    EXPECT_NEAR(wb, wa, wa * 1e-4);
}

TEST_F(RenderDoc, BadCapturesAndDescriptionsGetOneLine) {
    // A capture to read from.
    const fs::path capture = dir.path / "frame.rdc";
    ASSERT_EQ(runCli({"run", "--builtin", "atrium", "--width", "160", "--height", "96", "--no-image-error", "--shader",
                      kExamples + "tiled_fixed.comp", "--renderdoc-capture", capture.string(), "--out",
                      (dir.path / "run").string()},
                     dir.path)
                  .code,
              0);
    // A capture inside the output folder, which each run replaces, is refused.
    const CliResult inside = runCli({"run", "--builtin", "atrium", "--renderdoc-capture",
                                     (dir.path / "run" / "frame.rdc").string(), "--out", (dir.path / "run").string()},
                                    dir.path);
    EXPECT_EQ(inside.code, 2) << inside.err;
    EXPECT_NE(inside.err.find("is inside --out"), std::string::npos) << inside.err;
    EXPECT_TRUE(fs::exists(dir.path / "run" / "summary.json")) << "the earlier output is untouched";
    writeText(dir.path / "good.json", contractDescription("fixed:256", "tile"));
    const auto check = [&](const std::string& cap, const std::string& dispatch, const std::string& describe) {
        fs::remove_all(dir.path / "out");
        return runCli({"check", "--capture", cap, "--dispatch", dispatch, "--describe", describe, "--out",
                       (dir.path / "out").string()},
                      dir.path);
    };
    const auto oneLine = [&](const CliResult& r, int code, const std::string& has) {
        EXPECT_EQ(r.code, code) << r.out << r.err;
        EXPECT_EQ(lc_test::lineCount(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find(has), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(dir.path / "out")) << "nothing written on an error";
    };
    // Not a capture.
    writeText(dir.path / "notes.rdc", "these are not the frames you are looking for\n");
    oneLine(check((dir.path / "notes.rdc").string(), "1", (dir.path / "good.json").string()), 1,
            "notes.rdc: not a RenderDoc capture");
    oneLine(runCli({"capture-info", (dir.path / "missing.rdc").string()}, dir.path), 1, "missing.rdc: no such file");
    // No such dispatch; an event that is not a dispatch.
    oneLine(check(capture.string(), "shadow pass", (dir.path / "good.json").string()), 1,
            "no compute dispatch named 'shadow pass' (dispatches: ");
    oneLine(check(capture.string(), "9", (dir.path / "good.json").string()), 1, "event 9 is not a compute dispatch");
    // No such binding.
    std::string text = contractDescription("fixed:256", "tile");
    text.replace(text.find("\"0.3\""), 5, "\"LightBuffer\"");
    writeText(dir.path / "nobinding.json", text);
    oneLine(check(capture.string(), "custom", (dir.path / "nobinding.json").string()), 1,
            "binds nothing named 'LightBuffer' (its bindings: 0.0 lc.custom.custom.params");
    // A buffer smaller than the description needs.
    writeText(dir.path / "toomany.json", R"({"lights": {"binding": "0.3", "stride": 32, "position": 0, "radius": 12, "count": 100000},
 "camera": {"binding": "0.0", "projection": 96}, "depth": {"binding": "0.1"},
 "lists": {"layout": "fixed:256", "binding": "0.4"}})");
    oneLine(check(capture.string(), "custom", (dir.path / "toomany.json").string()), 1,
            "100000 lights of 32 bytes at byte 0 needs 3200000 bytes, but the binding holds");
    // Overlapping fields: the description's JSON path.
    writeText(dir.path / "overlap.json", R"({"lights": {"binding": "0.3", "stride": 32, "position": 0, "radius": 4},
 "camera": {"binding": "0.0", "projection": 96}, "depth": {"binding": "0.1"},
 "lists": {"layout": "fixed:256", "binding": "0.4"}})");
    oneLine(check(capture.string(), "custom", (dir.path / "overlap.json").string()), 1, "lights.radius");
    // The wrong matrix offset reads something that is no projection.
    text = contractDescription("fixed:256", "tile");
    text.replace(text.find("\"projection\": 96"), 16, "\"projection\": 32");
    writeText(dir.path / "badmatrix.json", text);
    oneLine(check(capture.string(), "custom", (dir.path / "badmatrix.json").string()), 1,
            "neither perspective (0, 0, -1, 0) nor orthographic");
}

TEST_F(RenderDoc, WithoutRenderDocTheCommandsSayWhatToInstall) {
    const fs::path capture = dir.path / "frame.rdc";
    setenv("LIGHTCULL_RENDERDOC_LIBRARY", "/nonexistent/librenderdoc.so", 1);
    const CliResult r = runCli({"run", "--builtin", "atrium", "--no-image-error", "--renderdoc-capture",
                                capture.string(), "--out", (dir.path / "run").string()},
                               dir.path);
    unsetenv("LIGHTCULL_RENDERDOC_LIBRARY");
    EXPECT_EQ(r.code, 1);
    EXPECT_EQ(lc_test::lineCount(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("apt-get install librenderdoc"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path / "run"));

    // A python3 without the renderdoc module (site-packages off).
    writeText(dir.path / "python-without-renderdoc", "#!/bin/sh\nexec /usr/bin/python3 -S \"$@\"\n");
    fs::permissions(dir.path / "python-without-renderdoc", fs::perms::owner_all);
    writeText(capture, "RDOC");
    setenv("LIGHTCULL_PYTHON", (dir.path / "python-without-renderdoc").c_str(), 1);
    const CliResult i = runCli({"capture-info", capture.string()}, dir.path);
    unsetenv("LIGHTCULL_PYTHON");
    EXPECT_EQ(i.code, 1);
    EXPECT_EQ(lc_test::lineCount(i.err), 1u) << i.err;
    EXPECT_NE(i.err.find("apt-get install python3-renderdoc"), std::string::npos) << i.err;
}

namespace {

// list -> its lights, from the mini engine's CSV or a tiles.csv.
std::map<std::uint32_t, std::set<std::uint32_t>> engineLists(const fs::path& csv) {
    std::map<std::uint32_t, std::set<std::uint32_t>> out;
    std::istringstream in(slurp(csv));
    std::string line;
    std::getline(in, line); // header
    while (std::getline(in, line)) {
        std::stringstream ss(line);
        std::string cell;
        std::getline(ss, cell, ',');
        auto& l = out[std::uint32_t(std::stoul(cell))];
        while (std::getline(ss, cell, ',')) l.insert(std::uint32_t(std::stoul(cell)));
    }
    return out;
}

std::map<std::uint32_t, std::set<std::uint32_t>> checkedLists(const fs::path& tilesCsv, std::uint32_t tilesX) {
    std::map<std::uint32_t, std::set<std::uint32_t>> out;
    std::istringstream in(slurp(tilesCsv));
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
        std::vector<std::string> f;
        std::stringstream ss(line);
        std::string cell;
        while (std::getline(ss, cell, ',')) f.push_back(cell);
        f.resize(13);
        auto& l = out[std::uint32_t(std::stoul(f[1]) * tilesX + std::stoul(f[0]))];
        std::stringstream lights(f[12]);
        std::string id;
        while (lights >> id) l.insert(std::uint32_t(std::stoul(id)));
    }
    return out;
}

const char* kMiniEngineDescription = R"({
  "lights": {"binding": "LightBuffer", "stride": 32, "position": 16, "radius": 28, "space": "world",
             "count": {"binding": "FrameConstants", "offset": 140}},
  "camera": {"binding": "FrameConstants", "view": 0, "projection": 64, "order": "row-major"},
  "depth": {"binding": "SceneDepth"},
  "lists": {"layout": "counts+indices:32", "counts": "TileLightCounts", "indices": "TileLightIndices", "tile": 16}
})";

} // namespace

// The issue's "done when": a renderer that is not this tool captures its
// frame in RenderDoc; capture-info shows its culling dispatch's bindings; a
// ten-line description of its light struct and layout gets the verdict on
// its own lists, depth and lights, on standard and reversed-Z cameras.
TEST_F(RenderDoc, AMinimalEnginesOwnCaptureIsJudgedFromATenLineDescription) {
    writeText(dir.path / "engine.json", kMiniEngineDescription);
    for (const std::string mode : {"standard", "reversed"}) {
        SCOPED_TRACE(mode);
        const fs::path capture = dir.path / (mode + ".rdc"), lists = dir.path / (mode + ".csv"),
                       out = dir.path / (mode + "-check");
        const std::string cmd = std::string(LC_MINI_ENGINE_PATH) + " '" + capture.string() + "' '" + lists.string() +
                                "'" + (mode == "reversed" ? " --reversed" : "") + " > '" +
                                (dir.path / "engine.log").string() + "' 2>&1";
        ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(dir.path / "engine.log");

        const CliResult info = runCli({"capture-info", capture.string(), "--dispatch", "light culling"}, dir.path);
        ASSERT_EQ(info.code, 0) << info.err;
        EXPECT_NE(info.out.find("0.2  image ImageSampler  250x140 D32  SceneDepth"), std::string::npos) << info.out;
        EXPECT_NE(info.out.find("0.3  buffer ReadWriteBuffer  576 bytes at offset 0 of 576  TileLightCounts"),
                  std::string::npos)
            << info.out;

        const CliResult c = runCli({"check", "--capture", capture.string(), "--dispatch", "Forward+ light culling",
                                    "--describe", (dir.path / "engine.json").string(), "--out", out.string()},
                                   dir.path);
        ASSERT_EQ(c.code, 0) << c.out << c.err;
        EXPECT_NE(c.out.find(mode == "reversed" ? "read camera: reversed_z, fov y 55 deg, near 0.3"
                                                : "read camera: perspective, fov y 55 deg, near 0.3"),
                  std::string::npos)
            << c.out;
        EXPECT_NE(c.out.find("read lights: 64 (read at byte 140 of set 0 binding 0"), std::string::npos) << c.out;
        EXPECT_NE(c.out.find("custom: " + capture.string() + " event "), std::string::npos) << c.out;
        EXPECT_NE(c.out.find("layout counts+indices:32"), std::string::npos) << c.out;
        const json s = json::parse(slurp(out / "summary.json"));
        EXPECT_EQ(s["metrics"]["false_negatives"], 0);
        EXPECT_EQ(s["width"], 250);
        EXPECT_EQ(s["tiles_x"], 16);
        // The lists judged are the ones the engine read back.
        const auto mine = engineLists(lists);
        const auto judged = checkedLists(out / "tiles.csv", 16);
        ASSERT_EQ(judged.size(), 144u);
        std::size_t entries = 0;
        for (const auto& [list, lights] : mine) {
            EXPECT_EQ(judged.at(list), lights) << "list " << list;
            entries += lights.size();
        }
        EXPECT_GT(entries, 100u) << "the engine's frame lists lights (a test of something)";
    }
}

// The same engine with a bug (it tests every light with half its range):
// the verdict names the lights it missed, in which tiles, and they are the
// ones its lists lack.
TEST_F(RenderDoc, AMinimalEnginesBugIsLocatedInItsOwnLists) {
    writeText(dir.path / "engine.json", kMiniEngineDescription);
    const fs::path capture = dir.path / "bug.rdc", lists = dir.path / "bug.csv", out = dir.path / "check";
    const std::string cmd = std::string(LC_MINI_ENGINE_PATH) + " '" + capture.string() + "' '" + lists.string() +
                            "' --bug > '" + (dir.path / "engine.log").string() + "' 2>&1";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << slurp(dir.path / "engine.log");
    const CliResult c = runCli({"check", "--capture", capture.string(), "--dispatch", "light culling", "--describe",
                                (dir.path / "engine.json").string(), "--out", out.string()},
                               dir.path);
    ASSERT_EQ(c.code, 3) << c.out << c.err;
    EXPECT_NE(c.err.find("lightcull: the culling fails: "), std::string::npos) << c.err;
    const json s = json::parse(slurp(out / "summary.json"));
    const auto fn = s["metrics"]["false_negatives"].get<std::uint64_t>();
    ASSERT_GT(fn, 0u);
    const auto mine = engineLists(lists);
    std::uint64_t located = 0;
    for (const json& m : s["custom"]["missed"]) {
        located += m["pixels"].get<std::uint64_t>();
        EXPECT_EQ(m["cause"], "culling_test");
        EXPECT_EQ(mine.at(m["list"].get<std::uint32_t>()).count(m["light"].get<std::uint32_t>()), 0u)
            << "a missed light is one the engine's list lacks";
    }
    EXPECT_EQ(located, fn);
}
