// Bring your own culling (docs/CUSTOM_CULLING.md): the example shaders of
// resources/culling-examples/ run on lavapipe with the validation layer on.
// The correct ones report false negatives 0 and lists equal (within float
// widening) to the built-in algorithm of their rule; the flawed one misses
// lights where its tile frustums drift; overflow, invalid indices, a hang and
// a compile error are reported, never followed; an engine's lists read from
// a dump or CSV are judged the same way.
#include "gpu_test_env.hpp"

#include "culling/diagnostics/explain.hpp"

#include "../unit/cli_support.hpp"

#include "culling/custom/custom_cull.hpp"
#include "culling/core/errors.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "culling/diagnostics/report.hpp"
#include "culling/scene/scene_io.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <numeric>
#include <regex>
#include <sstream>

#include <unistd.h>

using namespace lc;
using lc::gputest::GpuTest;
namespace fs = std::filesystem;

namespace {

const std::string kExamples = std::string(LC_SOURCE_DIR) + "/resources/culling-examples/";
const std::string kData = std::string(LC_TEST_DATA_DIR) + "/custom/";

// The atrium with 200 lights (a quarter spots; or `lights`) at a size that is not a whole
// number of tiles, so edge tiles are partial.
Scene atrium(std::uint32_t w = 330, std::uint32_t h = 190, std::uint32_t lights = 200) {
    Scene s = makeBuiltinScene("atrium");
    LightGenSettings g = defaultLightGen(s, lights, 4);
    g.spotFraction = 0.25;
    s.lights = generateLights(g);
    s.camera.width = w;
    s.camera.height = h;
    return s;
}

CustomShaderOptions optionsFor(const std::string& path, const std::string& layout = {}, const std::string& lists = {}) {
    return shaderOptionsFromFile(path, layout, lists);
}

RunOutput runShader(const Scene& s, const CustomShaderOptions& o, CustomCullReport& rep) {
    RunOptions ro;
    ro.truthOptions.imageError = false;
    return runCustomPipeline(s, o, gputest::vulkan(), ro, rep);
}

// Every entry of `ref` is in `got`; returns the extra entries of `got`.
std::uint64_t supersetExtra(const CullResult& ref, const CullResult& got, std::string& firstLost) {
    std::uint64_t extra = 0;
    for (std::size_t l = 0; l < ref.listCount.size(); ++l) {
        const auto rb = ref.lightIndices.begin() + ref.listOffset[l], re = rb + ref.listCount[l];
        const auto gb = got.lightIndices.begin() + got.listOffset[l], ge = gb + got.listCount[l];
        std::vector<std::uint32_t> lost;
        std::set_difference(rb, re, gb, ge, std::back_inserter(lost));
        if (!lost.empty() && firstLost.empty())
            firstLost = "list " + std::to_string(l) + " lacks light " + std::to_string(lost[0]);
        extra += got.listCount[l] - (ref.listCount[l] - lost.size());
    }
    return extra;
}

CullResult cpuReference(const Scene& s, const DepthImage& depth, Algorithm a, std::uint32_t cells = 1,
                        Slicing slicing = Slicing::Log) {
    CullSettings cs;
    cs.algorithm = a;
    cs.cells = cells;
    cs.slicing = slicing;
    cs.skipEmpty = false;
    const Projection proj(s.camera);
    return makeCpuBackend()->cull(depth, proj, TileGrid::make(s.camera.width, s.camera.height, s.camera.tileSize),
                                  makeViewLights(s), cs);
}

void expectCorrect(const RunOutput& out, const CustomCullReport& rep, const CullResult& ref, const std::string& label) {
    EXPECT_EQ(out.truth.metrics.falseNegatives, 0u) << label;
    EXPECT_TRUE(rep.validationMessages.empty()) << label << ": " << rep.validationMessages.front();
    EXPECT_EQ(rep.overflowLists, 0u) << label;
    EXPECT_EQ(rep.invalidIndices, 0u) << label;
    EXPECT_EQ(rep.duplicateIndices, 0u) << label;
    std::string lost;
    const std::uint64_t extra = supersetExtra(ref, out.result, lost);
    EXPECT_TRUE(lost.empty()) << label << ": " << lost;
    // Equal to the built-in lists up to the float widening: at most 0.5% extra.
    EXPECT_LE(extra * 200, ref.entries()) << label << ": " << extra << " extra of " << ref.entries();
    EXPECT_GT(out.result.entries(), 0u) << label;
    EXPECT_GT(rep.passMs, 0.0) << label;
}

} // namespace

TEST_F(GpuTest, GlslTiledExampleMatchesMinMax) {
    const Scene s = atrium();
    CustomCullReport rep;
    const RunOutput out = runShader(s, optionsFor(kExamples + "tiled_fixed.comp"), rep);
    EXPECT_EQ(rep.layout, "fixed:256"); // from the shader's first line
    EXPECT_EQ(rep.lists, "tile");
    expectCorrect(out, rep, cpuReference(s, out.depth, Algorithm::MinMax), "tiled_fixed.comp");
    EXPECT_EQ(rep.builtinAlgorithm, "minmax");
}

// Saved by an editor with a UTF-8 byte order mark: the first line's settings
// still apply and glslang does not see the mark.
TEST_F(GpuTest, AByteOrderMarkIsNotPartOfTheShader) {
    const Scene s = atrium(64, 64);
    const fs::path dir = fs::temp_directory_path() / ("lc_bom_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    std::ifstream in(kExamples + "tiled_fixed.comp", std::ios::binary);
    std::ofstream(dir / "bom.comp", std::ios::binary) << "\xEF\xBB\xBF" << in.rdbuf();
    std::ofstream(dir / "lightcull.glsl") << std::ifstream(std::string(LC_SOURCE_DIR) + "/shaders/custom/lightcull.glsl").rdbuf();
    CustomCullReport rep;
    const RunOutput out = runShader(s, optionsFor((dir / "bom.comp").string()), rep);
    EXPECT_EQ(rep.layout, "fixed:256");
    EXPECT_EQ(out.truth.metrics.falseNegatives, 0u);
    fs::remove_all(dir);
}

TEST_F(GpuTest, HlslTiledExampleMatchesMinMax) {
    const Scene s = atrium();
    CustomCullReport rep;
    CustomShaderOptions o = optionsFor(kExamples + "tiled_fixed.hlsl");
    EXPECT_EQ(o.entry, "CSMain");
    const RunOutput out = runShader(s, o, rep);
    expectCorrect(out, rep, cpuReference(s, out.depth, Algorithm::MinMax), "tiled_fixed.hlsl");
}

TEST_F(GpuTest, BitmaskLayoutGivesTheSameListsAsFixed) {
    const Scene s = atrium();
    CustomCullReport a, b;
    const RunOutput fixed = runShader(s, optionsFor(kExamples + "tiled_fixed.comp"), a);
    const RunOutput mask = runShader(s, optionsFor(kExamples + "tiled_fixed.comp", "bitmask"), b);
    EXPECT_EQ(b.layout, "bitmask");
    EXPECT_EQ(fixed.result.listCount, mask.result.listCount);
    EXPECT_EQ(fixed.result.lightIndices, mask.result.lightIndices);
}

TEST_F(GpuTest, TwoPointFiveDExampleIsConservativeAndTighterThanMinMax) {
    // The forest: foliage in front of far hills, depth gaps in most tiles.
    Scene s = makeBuiltinScene("forest");
    s.lights = generateLights(defaultLightGen(s, 1000, 4));
    s.camera.width = 330;
    s.camera.height = 190;
    CustomCullReport rep;
    const RunOutput out = runShader(s, optionsFor(kExamples + "twofived_fixed.comp"), rep);
    EXPECT_EQ(out.truth.metrics.falseNegatives, 0u);
    EXPECT_TRUE(rep.validationMessages.empty());
    const CullResult minmax = cpuReference(s, out.depth, Algorithm::MinMax);
    EXPECT_LT(out.result.entries(), minmax.entries()); // the cells reject lights in depth gaps
    // Never tighter than the exact built-in 2.5d of the same cells (32, linear).
    const CullResult exact = cpuReference(s, out.depth, Algorithm::TwoPointFiveD, 32, Slicing::Linear);
    std::string lost;
    supersetExtra(exact, out.result, lost);
    EXPECT_TRUE(lost.empty()) << lost;
}

TEST_F(GpuTest, ClusteredCompactExampleMatchesClustered) {
    const Scene s = atrium();
    CustomCullReport rep;
    const RunOutput out = runShader(s, optionsFor(kExamples + "clustered_compact.comp"), rep);
    EXPECT_EQ(rep.layout, "compact");
    EXPECT_EQ(rep.lists, "froxel:16:log");
    expectCorrect(out, rep, cpuReference(s, out.depth, Algorithm::Clustered, 16, Slicing::Log), "clustered_compact.comp");
    // The same shader with linear froxels, chosen on the command line.
    CustomCullReport lin;
    const RunOutput outLin = runShader(s, optionsFor(kExamples + "clustered_compact.comp", "", "froxel:8:linear"), lin);
    expectCorrect(outLin, lin, cpuReference(s, outLin.depth, Algorithm::Clustered, 8, Slicing::Linear),
                  "clustered_compact.comp froxel:8:linear");
    // A crowd: 700 lights in the same froxels. The example once gathered a
    // froxel's lights in a shared array of 512 and dropped the rest unsaid.
    Scene crowd = atrium(96, 64, 0);
    for (int i = 0; i < 700; ++i) {
        PointLight l;
        l.name = "crowd" + std::to_string(i);
        l.position = crowd.camera.target + glm::dvec3(0.001 * i, 0.0, 0.0);
        l.explicitRadius = 0.4;
        crowd.lights.push_back(l);
    }
    CustomCullReport many;
    const RunOutput outMany = runShader(crowd, optionsFor(kExamples + "clustered_compact.comp"), many);
    expectCorrect(outMany, many, cpuReference(crowd, outMany.depth, Algorithm::Clustered, 16, Slicing::Log),
                  "clustered_compact.comp, 700 lights in a froxel");
    std::uint32_t longest = 0;
    for (const std::uint32_t c : outMany.result.listCount) longest = std::max(longest, c);
    EXPECT_EQ(longest, 700u);
}

TEST_F(GpuTest, CellListsOverTheTileDepthRange) {
    const Scene s = atrium();
    for (const char* rule : {"cells:8:linear", "cells:4:log"}) {
        CustomCullReport rep;
        const RunOutput out = runShader(s, optionsFor(kData + "cells_bitmask.comp", "", rule), rep);
        EXPECT_EQ(rep.lists, std::string(rule));
        EXPECT_TRUE(out.result.cellLists);
        EXPECT_EQ(out.result.listsPerTile, std::string(rule) == "cells:8:linear" ? 8u : 4u);
        EXPECT_EQ(out.truth.metrics.falseNegatives, 0u) << rule;
        EXPECT_TRUE(rep.validationMessages.empty()) << rule;
        // A pixel's list is its cell's: the shading work can only shrink
        // against one list per tile (minmax).
        const CullResult minmax = cpuReference(s, out.depth, Algorithm::MinMax);
        const GroundTruth mt = computeGroundTruth(out.depth, Projection(s.camera), out.lights, minmax);
        EXPECT_LE(out.truth.metrics.shadingWork, mt.metrics.shadingWork) << rule;
        // The overlays draw the cells with their own lists.
        const auto cells = tileCells(out.result, Projection(s.camera), 30);
        for (const DepthCell& c : cells) EXPECT_EQ(c.list, 30 * out.result.listsPerTile + c.cell);
    }
}

TEST_F(GpuTest, FlawedExampleMissesLightsWhereItsFrustumsDrift) {
    // 650 px = 40.6 tiles: the flawed frustum of column tx spans pixels
    // [tx, tx + 1] * 650 / 41 instead of [16 tx, 16 tx + 16]; 368 rows are
    // exactly 23 tiles, so only the columns drift.
    const Scene s = atrium(650, 368, 3000);
    CustomCullReport rep;
    // Bitmask lists: 3,000 lights would overflow fixed:256 lists, and only
    // the drift may cause misses here.
    const RunOutput out = runShader(s, optionsFor(kExamples + "flawed_tile_edges.comp", "bitmask"), rep);
    EXPECT_EQ(rep.overflowLists, 0u);
    ASSERT_GT(out.truth.metrics.falseNegatives, 0u);
    const auto missed = locateFalseNegatives(out, Projection(s.camera));
    ASSERT_FALSE(missed.empty());
    const TileGrid& g = out.result.grid;
    // A tile can miss only where some pixel centre of it lies outside its
    // drifted frustum; every other tile's lights are all found.
    auto hasUncoveredPixel = [&](std::uint32_t tx) {
        const double left = double(tx) * g.width / g.tilesX, right = double(tx + 1) * g.width / g.tilesX;
        const TileGrid::Rect r = g.tileRect(tx, 0);
        for (std::uint32_t x = r.x0; x < r.x1; ++x)
            if (x + 0.5 < left || x + 0.5 > right) return true;
        return false;
    };
    std::uint64_t pixels = 0;
    std::uint32_t driftingColumns = 0;
    for (std::uint32_t tx = 0; tx < g.tilesX; ++tx) driftingColumns += hasUncoveredPixel(tx);
    ASSERT_GT(driftingColumns, 0u);
    ASSERT_LT(driftingColumns, g.tilesX);
    for (const MissedLight& m : missed) {
        EXPECT_TRUE(hasUncoveredPixel(m.tile % g.tilesX)) << "light " << m.light << " missed in tile " << m.tile;
        // Each located miss is real: the list lacks the light.
        const auto b = out.result.lightIndices.begin() + out.result.listOffset[m.list];
        EXPECT_FALSE(std::binary_search(b, b + out.result.listCount[m.list], m.light));
        pixels += m.pixels;
    }
    EXPECT_EQ(pixels, out.truth.metrics.falseNegatives); // every false negative is located
    // The correct shader at the same size misses nothing.
    CustomCullReport ok;
    EXPECT_EQ(runShader(s, optionsFor(kExamples + "tiled_fixed.comp", "bitmask"), ok).truth.metrics.falseNegatives, 0u);
}

TEST_F(GpuTest, OverflowingFixedListsAreReportedNotHidden) {
    const Scene s = atrium();
    CustomCullReport rep;
    const RunOutput out = runShader(s, optionsFor(kExamples + "tiled_fixed.comp", "fixed:2"), rep);
    EXPECT_GT(rep.overflowLists, 0u);
    EXPECT_GT(rep.overflowEntries, 0u);
    EXPECT_GT(out.truth.metrics.falseNegatives, 0u); // the lights that did not fit are missed
    EXPECT_LE(out.truth.metrics.maxList, 2u);
    // Each miss is labelled: a miss in a list that overflowed is "list full",
    // and this correct shader has no miss of its own test.
    EXPECT_EQ(rep.overflowedListIds.size(), rep.overflowLists);
    const std::vector<MissedLight> missed = locateFalseNegatives(out, Projection(s.camera));
    ASSERT_FALSE(missed.empty());
    for (const MissedLight& m : missed) {
        EXPECT_EQ(m.cause, MissCause::ListFull) << "list " << m.list;
        EXPECT_TRUE(std::binary_search(rep.overflowedListIds.begin(), rep.overflowedListIds.end(), m.list));
    }
    // Explain says so for such a light, not "the tests keep it".
    const Explanation e = explainLight(out, Projection(s.camera), missed[0].list, missed[0].light);
    EXPECT_EQ(e.verdict.rfind("MISSING", 0), 0u) << e.verdict;
    EXPECT_NE(e.verdict.find("dropped: list full, layout fixed:2"), std::string::npos) << e.verdict;
    // The metrics split the misses the same way (they once called them all
    // the culling test's), and tiles.csv marks the lists over-full.
    EXPECT_EQ(out.truth.metrics.falseNegativesListFull, out.truth.metrics.falseNegatives);
    EXPECT_EQ(out.truth.metrics.falseNegativesCullingTest(), 0u);
    const std::string csv = tilesCsv(out);
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line); // header
    std::uint64_t overRows = 0;
    for (std::uint32_t l = 0; std::getline(lines, line); ++l) {
        // tile_x,tile_y,cell,min,max,mask,count,fn,fn_list_full,fn_light_limit,overflow,...
        std::vector<std::string> f;
        std::istringstream cells(line);
        for (std::string c; std::getline(cells, c, ',');) f.push_back(c);
        ASSERT_GE(f.size(), 11u) << line;
        const bool over = std::binary_search(rep.overflowedListIds.begin(), rep.overflowedListIds.end(), l);
        EXPECT_EQ(f[10], over ? "1" : "0") << "list " << l;
        EXPECT_EQ(f[8], f[7]) << "list " << l; // every miss here is the list being full
        overRows += over;
    }
    EXPECT_EQ(overRows, rep.overflowLists);
}

TEST_F(GpuTest, InvalidAndDuplicateIndicesAreReportedNeverFollowed) {
    const Scene s = atrium(96, 64);
    CustomCullReport rep;
    const RunOutput out = runShader(s, optionsFor(kData + "out_of_range.comp"), rep);
    const std::uint64_t tiles = out.result.grid.tileCount();
    EXPECT_EQ(rep.invalidIndices, tiles);
    EXPECT_EQ(rep.duplicateIndices, tiles);
    for (std::uint32_t i : out.result.lightIndices) EXPECT_LT(i, s.lights.size());
    EXPECT_EQ(out.result.entries(), tiles); // light 0 once per tile
    // summary.json says where: every list held an invalid index here,
    const auto j = nlohmann::json::parse(summaryJson(s, out.result.settings, out));
    ASSERT_EQ(j["custom"]["invalid_index_lists"].size(), std::min<std::uint64_t>(tiles, 1000));
    EXPECT_EQ(j["custom"]["invalid_index_lists"][1]["list"], 1);
    EXPECT_EQ(j["custom"]["invalid_index_lists"][1]["tile_x"], 1);
    EXPECT_EQ(j["custom"]["overflowed_lists"].size(), 0u);
    // And every list held light 0 twice.
    ASSERT_EQ(j["custom"]["duplicate_index_lists"].size(), std::min<std::uint64_t>(tiles, 1000));
    EXPECT_EQ(j["custom"]["duplicate_index_lists"][2]["list"], 2);
    EXPECT_EQ(j["custom"]["duplicate_index_lists"][2]["tile_x"], 2);
}

TEST_F(GpuTest, AHangIsATimeoutAndTheNextRunWorks) {
    const Scene s = atrium(320, 180);
    CustomShaderOptions o = optionsFor(kData + "hang.comp");
    o.timeoutMs = 300;
    CustomCullReport rep;
    try {
        runShader(s, o, rep);
        FAIL() << "no timeout";
    } catch (const DeviceError& e) {
        EXPECT_NE(std::string(e.what()).find("did not finish within 300 ms"), std::string::npos) << e.what();
        // A slow shader is not called an endless loop: the limit and how to raise it.
        EXPECT_NE(std::string(e.what()).find("raise it with --timeout-ms"), std::string::npos) << e.what();
    }
    // The hung device is abandoned, never handed to the next run: it opens one.
    const std::uint64_t opened = customShaderDevices().devicesOpened;
    CustomCullReport ok;
    EXPECT_EQ(runShader(s, optionsFor(kExamples + "tiled_fixed.comp"), ok).truth.metrics.falseNegatives, 0u);
    EXPECT_EQ(customShaderDevices().devicesOpened, opened + 1);
}

TEST_F(GpuTest, RunsOfAShaderShareOneDeviceAndItsPipelines) {
    // A hunt or a report runs one shader hundreds of times: a finished run
    // leaves its device, and the pipelines compiled on it, to the next run
    // with the same device options.
    const CustomShaderOptions o = optionsFor(kExamples + "tiled_fixed.comp");
    CustomCullReport a, b, c, d;
    const RunOutput first = runShader(atrium(96, 64), o, a);
    const CustomShaderDeviceCount before = customShaderDevices();
    const RunOutput second = runShader(atrium(96, 64), o, b);
    EXPECT_EQ(customShaderDevices().devicesOpened, before.devicesOpened);
    EXPECT_EQ(customShaderDevices().pipelinesMade, before.pipelinesMade);
    EXPECT_EQ(second.result.listCount, first.result.listCount);
    EXPECT_EQ(second.result.lightIndices, first.result.lightIndices);
    EXPECT_TRUE(b.validationMessages.empty()) << b.validationMessages.front();
    // Another screen, the same defines (tile size, light count, layout): the
    // same pipeline, the lists of this screen.
    const RunOutput wide = runShader(atrium(250, 130), o, c);
    EXPECT_EQ(customShaderDevices().pipelinesMade, before.pipelinesMade);
    EXPECT_EQ(wide.result.grid.width, 250u);
    EXPECT_EQ(wide.truth.metrics.falseNegatives, 0u);
    EXPECT_GT(wide.result.entries(), 0u);
    // 8-pixel tiles: another TILE_SIZE, another pipeline, on the same device.
    Scene small = atrium(250, 130, 40);
    small.camera.tileSize = 8;
    const RunOutput fine = runShader(small, o, d);
    EXPECT_EQ(customShaderDevices().pipelinesMade, before.pipelinesMade + 1);
    EXPECT_EQ(customShaderDevices().devicesOpened, before.devicesOpened);
    EXPECT_EQ(fine.result.grid.tileSize, 8u);
    EXPECT_EQ(fine.truth.metrics.falseNegatives, 0u);
    EXPECT_EQ(fine.result.validate(40), "");
    // Other device options (the layer off) are another device, kept in its place.
    CustomShaderOptions quiet = o;
    quiet.validation = false;
    CustomCullReport e, f;
    runShader(atrium(96, 64), quiet, e);
    EXPECT_EQ(customShaderDevices().devicesOpened, before.devicesOpened + 1);
    runShader(atrium(96, 64), quiet, f);
    EXPECT_EQ(customShaderDevices().devicesOpened, before.devicesOpened + 1);
}

TEST_F(GpuTest, AKeptPipelinesValidationMessagesAreSaidAtEveryRun) {
    // A double without the shaderFloat64 feature: the layer objects when the
    // module is made, which a run that reuses the pipeline does not repeat.
    lc_test::ScratchDir tmp;
    std::string text = lc_test::slurp(kExamples + "tiled_fixed.comp");
    text.replace(text.find("void main() {"), 13,
                 "void main() {\n    if (double(lc.counts.x) < -1.0) lcOut[0] = 7u;");
    const std::string path = (tmp.path / "doubles.comp").string();
    std::ofstream(path) << text;
    const CustomShaderOptions o = optionsFor(path);
    CustomCullReport first, second;
    runShader(atrium(96, 64), o, first);
    const std::uint64_t made = customShaderDevices().pipelinesMade;
    runShader(atrium(96, 64), o, second);
    ASSERT_EQ(customShaderDevices().pipelinesMade, made); // the kept pipeline
    ASSERT_FALSE(first.validationMessages.empty());
    EXPECT_EQ(second.validationMessages, first.validationMessages);
}

TEST_F(GpuTest, CompileErrorsNameFileAndLine) {
    const Scene s = atrium(64, 64);
    CustomCullReport rep;
    try {
        runShader(s, optionsFor(kData + "syntax_error.comp"), rep);
        FAIL() << "no compile error";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 6);
        EXPECT_NE(std::string(e.what()).find("syntax_error.comp:6: compile error: 'undeclaredThing'"), std::string::npos)
            << e.what();
    }
}

TEST_F(GpuTest, SpirvFromTheCompilerRunsToo) {
    // Compile the GLSL example with glslangValidator as a build would, with
    // the tool's defines, then hand the tool the .spv.
    const Scene s = atrium();
    const fs::path dir = fs::temp_directory_path() / ("lc_spv_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    fs::copy_file(kExamples + "tiled_fixed.comp", dir / "t.comp", fs::copy_options::overwrite_existing);
    std::ofstream(dir / "lightcull.glsl") << std::ifstream(std::string(LC_SOURCE_DIR) + "/shaders/custom/lightcull.glsl").rdbuf();
    const std::string cmd = "glslangValidator -V --target-env vulkan1.1 -DTILE_SIZE=16 -DMAX_LIGHTS_PER_TILE=256 "
                            "-DLC_LAYOUT=0 -DLC_LISTS=0 -DLC_LISTS_PER_TILE=1 -DLC_MASK_WORDS=7 -DLC_COMPACT_ENTRIES=0 -o " +
                            (dir / "t.spv").string() + " " + (dir / "t.comp").string() + " > /dev/null";
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    CustomShaderOptions o;
    o.path = (dir / "t.spv").string();
    o.layout = parseLayout("fixed:256");
    CustomCullReport rep;
    const RunOutput out = runShader(s, o, rep);
    expectCorrect(out, rep, cpuReference(s, out.depth, Algorithm::MinMax), "t.spv");
    // An entry point the module lacks is named before the device sees it
    // (with validation on, the layer crashed creating the pipeline).
    o.entry = "nope";
    try {
        runShader(s, o, rep);
        FAIL() << "no error for a missing entry point";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("t.spv: no compute entry point 'nope' (the module has 'main'"),
                  std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

// What the contract fixes is checked before the device sees the shader: a
// binding outside it (which crashed the validation layer), push constants, an
// HLSL entry point that is not in the file (glslang only warns, and emits an
// empty function that writes no list).
TEST_F(GpuTest, InterfaceMistakesAreOneLineErrors) {
    const Scene s = atrium(64, 64);
    const fs::path dir = fs::temp_directory_path() / ("lc_iface_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string head = "#version 450\nlayout(local_size_x = 64) in;\n"
                             "layout(set = 0, binding = 0, std140) uniform P { uvec4 size; uvec4 counts; } lc;\n"
                             "layout(set = 0, binding = 4, std430) buffer O { uint outw[]; };\n";
    const std::string body = "void main() { if (gl_LocalInvocationIndex == 0u) outw[0] = X; }\n";
    struct Case {
        std::string file, text, entry, expected;
    };
    const std::vector<Case> cases = {
        {"binding5.comp", head + "layout(set = 0, binding = 5, std430) readonly buffer L { vec4 l[]; };\n" +
                              std::regex_replace(body, std::regex("X"), "uint(l[0].w)"),
         "", "binding5.comp: declares set 0 binding 5, which the contract does not bind"},
        {"set1.comp", head + "layout(set = 1, binding = 0, std430) readonly buffer L { vec4 l[]; };\n" +
                          std::regex_replace(body, std::regex("X"), "uint(l[0].w)"),
         "", "set1.comp: declares set 1 binding 0"},
        // The right binding, the wrong kind of resource: it would read nothing.
        {"texture_as_buffer.comp", head + "layout(set = 0, binding = 1, std430) readonly buffer D { float d[]; };\n" +
                                       std::regex_replace(body, std::regex("X"), "uint(d[0])"),
         "", "texture_as_buffer.comp: declares binding 1 as a storage buffer; the contract binds a texture or sampler"},
        {"lists_as_uniform.comp",
         "#version 450\nlayout(local_size_x = 64) in;\n"
         "layout(set = 0, binding = 4, std140) uniform O { uvec4 outw[4]; };\n"
         "layout(set = 0, binding = 3, std430) buffer L { vec4 l[]; };\n"
         "void main() { l[0].x = float(outw[0].x); }\n",
         "", "lists_as_uniform.comp: declares binding 4 as a uniform buffer; the contract binds a storage buffer"},
        {"push.comp", head + "layout(push_constant) uniform PC { uint k; } pc;\n" +
                          std::regex_replace(body, std::regex("X"), "pc.k"),
         "", "push.comp: declares push constants"},
        {"tiled.hlsl", "", "NoSuchFn", "tiled.hlsl: no function 'NoSuchFn' to use as the entry point"},
    };
    for (const Case& c : cases) {
        const fs::path p = dir / c.file;
        if (c.text.empty())
            fs::copy_file(kExamples + "tiled_fixed.hlsl", p, fs::copy_options::overwrite_existing);
        else
            std::ofstream(p) << c.text;
        CustomShaderOptions o = optionsFor(p.string());
        if (!c.entry.empty()) o.entry = c.entry;
        CustomCullReport rep;
        try {
            runShader(s, o, rep);
            ADD_FAILURE() << c.file << ": no error";
        } catch (const InputError& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(c.expected), std::string::npos) << msg;
            EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
        }
    }
    fs::remove_all(dir);
}

// Engines differ on whether an empty froxel keeps its lights: a dump of
// either built-in variant is judged equal to it, and named so.
TEST_F(GpuTest, FroxelDumpsAreComparedWithTheNearerSkipEmptyVariant) {
    const Scene s = atrium();
    const Projection proj(s.camera);
    const DepthImage depth = gputest::vulkan().renderDepth(s, proj);
    const fs::path dir = fs::temp_directory_path() / ("lc_froxels_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    RunOptions ro;
    ro.truthOptions.imageError = false;
    for (const bool skip : {false, true}) {
        CullSettings cs;
        cs.algorithm = Algorithm::Clustered;
        cs.cells = 16;
        cs.slicing = Slicing::Log;
        cs.skipEmpty = skip;
        const CullResult ref = makeCpuBackend()->cull(
            depth, proj, TileGrid::make(s.camera.width, s.camera.height, s.camera.tileSize), makeViewLights(s), cs);
        {
            std::ofstream csv(dir / "froxels.csv");
            for (std::size_t l = 0; l < ref.listCount.size(); ++l) {
                csv << l;
                for (std::uint32_t k = 0; k < ref.listCount[l]; ++k) csv << "," << ref.lightIndices[ref.listOffset[l] + k];
                csv << "\n";
            }
        }
        CustomCullReport rep;
        const RunOutput out = checkListDump(s, (dir / "froxels.csv").string(), parseLayout("fixed:64"),
                                            parseListSpec("froxel:16:log"), depth, ro, rep);
        SCOPED_TRACE(skip ? "skip-empty true" : "skip-empty false");
        EXPECT_EQ(out.truth.metrics.falseNegatives, 0u);
        EXPECT_EQ(rep.listsDifferingFromBuiltin, 0u);
        EXPECT_EQ(rep.builtinEntries, ref.entries());
        EXPECT_EQ(rep.builtinAlgorithm, skip ? "clustered, skip-empty true" : "clustered, skip-empty false");
    }
    fs::remove_all(dir);
}

TEST_F(GpuTest, EngineListDumpsAreJudgedLikeShaders) {
    const Scene s = atrium();
    const Projection proj(s.camera);
    const DepthImage depth = gputest::vulkan().renderDepth(s, proj);
    const CullResult ref = cpuReference(s, depth, Algorithm::MinMax);
    const fs::path dir = fs::temp_directory_path() / ("lc_dump_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    // As a GPU debugger exports a fixed:N buffer: count + N indices per tile.
    const std::uint32_t n = *std::max_element(ref.listCount.begin(), ref.listCount.end());
    const std::string fixedN = "fixed:" + std::to_string(n);
    std::vector<std::uint32_t> words(ref.listCount.size() * (n + 1), 0);
    for (std::size_t l = 0; l < ref.listCount.size(); ++l) {
        words[l * (n + 1)] = ref.listCount[l];
        for (std::uint32_t k = 0; k < ref.listCount[l]; ++k)
            words[l * (n + 1) + 1 + k] = ref.lightIndices[ref.listOffset[l] + k];
    }
    std::ofstream(dir / "lists.bin", std::ios::binary)
        .write(reinterpret_cast<const char*>(words.data()), std::streamsize(words.size() * 4));
    RunOptions ro;
    ro.truthOptions.imageError = false;
    CustomCullReport rep;
    const RunOutput out =
        checkListDump(s, (dir / "lists.bin").string(), parseLayout(fixedN), parseListSpec("tile"), depth, ro, rep);
    EXPECT_EQ(out.truth.metrics.falseNegatives, 0u);
    EXPECT_EQ(rep.listsDifferingFromBuiltin, 0u);
    EXPECT_EQ(out.result.lightIndices, ref.lightIndices);
    EXPECT_TRUE(rep.warnings.empty());
    // The same dump read as fixed:(N-1): longer than that layout needs, so
    // read, but with a warning naming the words used (a wrong N otherwise
    // looks like a broken engine).
    {
        CustomCullReport wrongRep;
        const std::string wrongN = "fixed:" + std::to_string(n - 1);
        checkListDump(s, (dir / "lists.bin").string(), parseLayout(wrongN), parseListSpec("tile"), depth, ro, wrongRep);
        ASSERT_EQ(wrongRep.warnings.size(), 1u);
        EXPECT_NE(wrongRep.warnings[0].find("reads the first " + std::to_string(ref.listCount.size() * n)),
                  std::string::npos)
            << wrongRep.warnings[0];
    }

    // CSV with one light dropped from the busiest list, as a broken engine
    // would: exactly that miss. The light dropped is one some pixel of the
    // tile needs (asserted, not hoped for: a dropped false positive would
    // miss nothing and the miss checks would never run); dropping a false
    // positive instead misses nothing.
    std::size_t busiest = 0;
    for (std::size_t l = 0; l < ref.listCount.size(); ++l)
        if (ref.listCount[l] > ref.listCount[busiest]) busiest = l;
    ASSERT_EQ(ref.listsPerTile, 1u); // minmax: list == tile
    const auto needingInBusiest =
        pixelsNeedingLights(depth, proj, out.lights, out.result.grid, std::uint32_t(busiest));
    ASSERT_FALSE(needingInBusiest.empty()) << "the busiest tile needs no light: nothing to drop";
    const std::uint32_t dropped = needingInBusiest[0].first;
    const std::uint64_t needing = needingInBusiest[0].second;
    ASSERT_GT(needing, 0u);
    std::uint32_t droppedFalsePositive = 0;
    bool haveFalsePositive = false;
    for (std::uint32_t k = 0; k < ref.listCount[busiest] && !haveFalsePositive; ++k) {
        const std::uint32_t light = ref.lightIndices[ref.listOffset[busiest] + k];
        if (std::none_of(needingInBusiest.begin(), needingInBusiest.end(),
                         [&](const auto& n) { return n.first == light; }))
            droppedFalsePositive = light, haveFalsePositive = true;
    }
    ASSERT_TRUE(haveFalsePositive) << "minmax lists a false positive in the busiest atrium tile";
    const auto writeCsvWithout = [&](const fs::path& file, std::uint32_t drop) {
        std::ofstream csv(file);
        csv << "list,lights\n";
        bool droppedOne = false;
        for (std::size_t l = 0; l < ref.listCount.size(); ++l) {
            csv << l;
            for (std::uint32_t k = 0; k < ref.listCount[l]; ++k) {
                const std::uint32_t light = ref.lightIndices[ref.listOffset[l] + k];
                if (l == busiest && light == drop) {
                    droppedOne = true;
                    continue;
                }
                csv << "," << light;
            }
            csv << "\n";
        }
        ASSERT_TRUE(droppedOne) << "light " << drop << " is not in list " << busiest;
    };
    writeCsvWithout(dir / "lists.csv", dropped);
    writeCsvWithout(dir / "lists_fp.csv", droppedFalsePositive);
    // Judged on the engine's own depth, written as raw float32.
    std::ofstream(dir / "depth.f32", std::ios::binary)
        .write(reinterpret_cast<const char*>(depth.depth.data()), std::streamsize(depth.depth.size() * 4));
    const DepthImage engineDepth = loadDepthFile((dir / "depth.f32").string(), proj);
    EXPECT_EQ(engineDepth.depth, depth.depth);
    CustomCullReport csvRep;
    const RunOutput csvOut = checkListDump(s, (dir / "lists.csv").string(), parseLayout("fixed:32"), parseListSpec("tile"),
                                           engineDepth, ro, csvRep);
    EXPECT_EQ(csvOut.truth.metrics.falseNegatives, needing);
    const auto missed = locateFalseNegatives(csvOut, proj);
    ASSERT_EQ(missed.size(), 1u);
    EXPECT_EQ(missed[0].tile, busiest);
    EXPECT_EQ(missed[0].light, dropped);
    EXPECT_EQ(missed[0].pixels, needing);
    {
        CustomCullReport fpRep;
        const RunOutput fpOut = checkListDump(s, (dir / "lists_fp.csv").string(), parseLayout("fixed:32"),
                                              parseListSpec("tile"), engineDepth, ro, fpRep);
        EXPECT_EQ(fpOut.truth.metrics.falseNegatives, 0u);
        EXPECT_TRUE(locateFalseNegatives(fpOut, proj).empty()); // a false positive was dropped: nothing missed
        EXPECT_EQ(fpOut.result.entries(), ref.entries() - 1);
    }
    // Bad dumps: one line naming the file and the line.
    std::ofstream(dir / "bad.csv") << "0,1,2\n99999,3\n";
    try {
        checkListDump(s, (dir / "bad.csv").string(), parseLayout("fixed:32"), parseListSpec("tile"), depth, ro, csvRep);
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("bad.csv:2: list 99999 is outside"), std::string::npos) << e.what();
    }
    // A first line is a header only when it has a letter: "-1,0" is a bad
    // list, not a header to skip; an empty file is no dump.
    for (const auto& [text, expect] : {std::pair<std::string, std::string>{"-1,0\n", "bad.csv:1: '-1' is not a list index"},
                                       {" \n", "bad.csv: empty"}}) {
        std::ofstream(dir / "bad.csv") << text;
        try {
            checkListDump(s, (dir / "bad.csv").string(), parseLayout("fixed:32"), parseListSpec("tile"), depth, ro, csvRep);
            ADD_FAILURE() << "no error for " << text;
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
        }
    }
    std::ofstream(dir / "short.bin", std::ios::binary) << "abcd";
    EXPECT_THROW(checkListDump(s, (dir / "short.bin").string(), parseLayout("fixed:32"), parseListSpec("tile"), depth, ro,
                               csvRep),
                 InputError);
    fs::remove_all(dir);
}

TEST(CustomSpecs, LayoutsListsAndFirstLineSettings) {
    EXPECT_EQ(toString(parseLayout("fixed:64")), "fixed:64");
    EXPECT_EQ(toString(parseLayout("compact")), "compact");
    EXPECT_EQ(toString(parseLayout("compact:1000")), "compact:1000");
    EXPECT_EQ(toString(parseLayout("bitmask")), "bitmask");
    EXPECT_THROW(parseLayout("fixed"), SettingsError);
    EXPECT_THROW(parseLayout("fixed:0"), SettingsError);
    EXPECT_THROW(parseLayout("list"), SettingsError);
    EXPECT_EQ(toString(parseListSpec("froxel:24")), "froxel:24:log");
    EXPECT_EQ(toString(parseListSpec("froxel:8:linear")), "froxel:8:linear");
    EXPECT_THROW(parseListSpec("froxel:33"), SettingsError);
    EXPECT_THROW(parseListSpec("cells"), SettingsError);
    EXPECT_EQ(toString(parseListSpec("cells:6")), "cells:6:log");
    EXPECT_THROW(parseListSpec("cells:0"), SettingsError);
    EXPECT_EQ(layoutWords(parseLayout("fixed:4"), 10, 100), 50u);
    EXPECT_EQ(layoutWords(parseLayout("bitmask"), 10, 33), 20u);
    EXPECT_EQ(layoutWords(parseLayout("compact:7"), 10, 100), 1u + 20u + 7u);

    CustomShaderOptions o;
    applyShaderHeader("// lightcull: --layout bitmask --lists halfz --entry CS\n", "x.comp", o, false, false, false);
    EXPECT_EQ(toString(o.layout), "bitmask");
    EXPECT_EQ(toString(o.lists), "halfz");
    EXPECT_EQ(o.entry, "CS");
    CustomShaderOptions given;
    given.layout = parseLayout("fixed:8");
    applyShaderHeader("// lightcull: --layout bitmask\n", "x.comp", given, true, false, false); // the flag wins
    EXPECT_EQ(toString(given.layout), "fixed:8");
    EXPECT_THROW(applyShaderHeader("// lightcull: --layout nonsense\n", "x.comp", o, false, false, false), InputError);
    EXPECT_THROW(applyShaderHeader("// lightcull: --frobnicate 3\n", "x.comp", o, false, false, false), InputError);

    // After a licence header and #version: still the settings (they were
    // silently ignored, and a ported shader ran with the defaults).
    CustomShaderOptions licensed;
    applyShaderHeader("/*\n * Copyright (c) 2016 Someone\n * MIT licence\n */\n// Tiled culling\n#version 450\n\n"
                      "// lightcull: --layout bitmask --lists halfz\nlayout(local_size_x = 16) in;\nvoid main() {}\n",
                      "x.comp", licensed, false, false, false);
    EXPECT_EQ(toString(licensed.layout), "bitmask");
    EXPECT_EQ(toString(licensed.lists), "halfz");
    CustomShaderOptions inBlock;
    applyShaderHeader("/* Licence\n * lightcull: --layout fixed:32\n */\nvoid main() {}\n", "x.comp", inBlock, false,
                      false, false);
    EXPECT_EQ(toString(inBlock.layout), "fixed:32");
    // After code: refused with the line, not ignored.
    try {
        CustomShaderOptions late;
        applyShaderHeader("#version 450\nlayout(local_size_x = 16) in;\n// lightcull: --layout bitmask\n", "late.comp",
                          late, false, false, false);
        FAIL() << "a settings line after code was ignored";
    } catch (const InputError& e) {
        EXPECT_EQ(e.line(), 3);
        EXPECT_NE(std::string(e.what()).find("must be in the comment block at the top of the file, before the first "
                                             "line of code (line 2)"),
                  std::string::npos)
            << e.what();
    }
    // A code line that merely mentions the word is not a settings line.
    CustomShaderOptions mention;
    applyShaderHeader("void main() {} // see lightcull: docs\n", "x.comp", mention, false, false, false);
    EXPECT_EQ(toString(mention.layout), "fixed:64");
    EXPECT_THROW(applyShaderHeader("// lightcull: --layout bitmask\n// lightcull: --lists halfz\n", "x.comp", mention,
                                   false, false, false),
                 InputError);

    // Written as the CLI takes it: --layout=VALUE.
    CustomShaderOptions joined;
    applyShaderHeader("// lightcull: --layout=bitmask --lists=halfz\n", "x.comp", joined, false, false, false);
    EXPECT_EQ(toString(joined.layout), "bitmask");
    EXPECT_EQ(toString(joined.lists), "halfz");
    // Mistyped settings lines were skipped and the shader ran with the
    // defaults: each is refused, with its line and how to write it.
    auto refusal = [](const std::string& text) -> std::string {
        try {
            CustomShaderOptions x;
            applyShaderHeader(text, "x.comp", x, false, false, false);
        } catch (const InputError& e) {
            return std::to_string(e.line()) + ": " + e.what();
        }
        return "accepted";
    };
    for (const char* near : {"// LightCull: --layout fixed:256\n", "// lightcull --layout fixed:256\n",
                             "// lightcull : --layout fixed:256\n", "/*\n * LIGHTCULL --lists halfz\n */\n"}) {
        const std::string why = refusal(std::string("// Tiled culling\n") + near + "void main() {}\n");
        EXPECT_NE(why.find("write this line as '// lightcull: --layout"), std::string::npos) << near << why;
        EXPECT_NE(why.find(near[1] == '*' ? "3: " : "2: "), std::string::npos) << why;
    }
    // Ordinary comments naming the tool stay comments.
    EXPECT_EQ(refusal("// LightCull Studio example: run it with --shader\nvoid main() {}\n"), "accepted");
    EXPECT_NE(refusal("// lightcull: layout=fixed:256\n").find("unknown flag 'layout=fixed:256'"), std::string::npos);
    EXPECT_NE(refusal("// lightcull: --layout fixed:256 --layout bitmask\n").find("--layout given twice"),
              std::string::npos);
}

TEST(CustomSpecs, ValidationMessagesAreCutToWhatIsWrong) {
    const std::string layer =
        "error: VUID-VkComputePipelineCreateInfo-layout-00703: Validation Error: [ "
        "VUID-VkComputePipelineCreateInfo-layout-00703 ] Object 0: handle = 0x120000000012, name = "
        "lc.custom.custom.shader, type = VK_OBJECT_TYPE_SHADER_MODULE; Object 1: handle = 0x50000000005, name = "
        "lc.custom.custom.pipelineLayout, type = VK_OBJECT_TYPE_PIPELINE_LAYOUT; | MessageID = 0xe63c2d8b | Set 0 "
        "Binding 1 type mismatch on descriptor slot in shader (VK_SHADER_STAGE_COMPUTE_BIT), uses type "
        "VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER but expected VK_DESCRIPTOR_TYPE_STORAGE_BUFFER The Vulkan spec "
        "states: layout must be consistent (https://www.khronos.org/registry/vulkan/specs/...)";
    EXPECT_EQ(validationGist(layer),
              "error: VUID-VkComputePipelineCreateInfo-layout-00703: Set 0 Binding 1 type mismatch on descriptor slot "
              "in shader (VK_SHADER_STAGE_COMPUTE_BIT), uses type VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER but "
              "expected VK_DESCRIPTOR_TYPE_STORAGE_BUFFER");
    EXPECT_EQ(validationGist("a message of another shape"), "a message of another shape");
}

TEST(CustomDecode, EveryLayoutDecodesCountsOverflowAndBadIndices) {
    CullResult r;
    r.listOffset.assign(3, 0);
    CustomCullReport rep;
    // fixed:2 -> 3 lists: {1, 0}, count 3 (overflow 1) {2, 2}, {9 (invalid)}
    decodeLists({2, 1, 0, 3, 2, 2, 1, 9, 0}, parseLayout("fixed:2"), 5, r, rep);
    EXPECT_EQ(r.listCount, (std::vector<std::uint32_t>{2, 1, 0}));
    EXPECT_EQ(r.lightIndices, (std::vector<std::uint32_t>{0, 1, 2}));
    EXPECT_EQ(rep.overflowLists, 1u);
    EXPECT_EQ(rep.overflowEntries, 1u);
    EXPECT_EQ(rep.duplicateIndices, 1u);
    EXPECT_EQ(rep.invalidIndices, 1u);
    EXPECT_EQ(rep.overflowedListIds, (std::vector<std::uint32_t>{1}));
    EXPECT_EQ(rep.invalidIndexListIds, (std::vector<std::uint32_t>{2}));
    // bitmask with 40 lights: 2 words per list.
    CustomCullReport b;
    decodeLists({0b101, 1u << 7, 0, 0, 0xFFFFFFFFu, 0}, parseLayout("bitmask"), 40, r, b);
    EXPECT_EQ(r.listCount, (std::vector<std::uint32_t>{3, 0, 32}));
    EXPECT_EQ(r.lightIndices[2], 39u);
    // compact:4: counter, (offset, count) x 3, 4 entries; list 2 runs past the array.
    CustomCullReport c;
    decodeLists({6, 0, 2, 2, 0, 3, 3, 4, 1, 3, 0}, parseLayout("compact:4"), 5, r, c);
    EXPECT_EQ(r.listCount, (std::vector<std::uint32_t>{2, 0, 1}));
    EXPECT_EQ(c.overflowLists, 1u);
    EXPECT_EQ(c.overflowEntries, 2u);
    // Too few words for the layout is an error, not a read past the end.
    EXPECT_THROW(decodeLists({1, 2}, parseLayout("fixed:2"), 5, r, c), Error);
}

// A report of few rows on one backend: 16-pixel tiles, one cell, the plane
// test, one timed run each.
ReportOptions oneRunReport(const std::string& backend) {
    ReportOptions o;
    o.backends = {backend};
    o.tileSizes = {16};
    o.cellCounts = {1};
    o.fixed["test"] = "planes";
    o.repeat = 1;
    o.warmup = 0;
    return o;
}

TEST_F(GpuTest, ReportNamesShadersOfOneFileNameByTheirPaths) {
    // Two versions of one engine's shader, each in its own folder: two rows
    // a reader can tell apart (both were once `custom:cull.comp ...`).
    lc_test::ScratchDir tmp;
    std::vector<std::string> paths;
    for (const char* dir : {"old", "new"}) {
        fs::create_directories(tmp.path / dir);
        fs::copy_file(kExamples + "tiled_fixed.comp", tmp.path / dir / "cull.comp");
        paths.push_back((tmp.path / dir / "cull.comp").string());
    }
    ReportOptions o = oneRunReport("cpu");
    o.fixed["algorithm"] = "minmax";
    o.shaders = {optionsFor(paths[0]), optionsFor(paths[1]), optionsFor(kExamples + "tiled_fixed.comp"),
                 optionsFor(kData + "duplicate_light.comp")};
    const Report rep = runReport(atrium(96, 64, 20), o);
    // A light twice in a list fails `run`: the report says it in a note.
    ASSERT_EQ(rep.rows.back().config.customLabel.rfind("custom:duplicate_light.comp ", 0), 0u);
    const std::string notes = std::accumulate(rep.notes.begin(), rep.notes.end(), std::string(),
                                              [](std::string a, const std::string& b) { return a + b + "\n"; });
    EXPECT_NE(notes.find("custom:duplicate_light.comp"), std::string::npos) << notes;
    EXPECT_EQ(notes.find(" 0 duplicate indices"), std::string::npos) << notes;
    EXPECT_NE(notes.find(" duplicate ind"), std::string::npos) << notes;
    std::vector<std::string> labels;
    for (const ReportRow& r : rep.rows)
        if (!r.config.customLabel.empty()) labels.push_back(r.config.customLabel);
    ASSERT_EQ(labels.size(), 4u);
    EXPECT_EQ(labels[0].rfind("custom:" + paths[0] + " ", 0), 0u) << labels[0];
    EXPECT_EQ(labels[1].rfind("custom:" + paths[1] + " ", 0), 0u) << labels[1];
    // A file name no other shader has stays short.
    EXPECT_EQ(labels[2].rfind("custom:tiled_fixed.comp ", 0), 0u) << labels[2];

    // With --tile the shader runs at each size given (TILE_SIZE), its rows
    // named by the size.
    o.shaders = {optionsFor(kExamples + "tiled_fixed.comp")};
    o.fixed["tile"] = "8,16";
    const Report tiles = runReport(atrium(96, 64, 20), o);
    std::map<std::string, const ReportRow*> byLabel;
    for (const ReportRow& r : tiles.rows)
        if (!r.config.customLabel.empty()) byLabel[r.config.customLabel] = &r;
    ASSERT_EQ(byLabel.size(), 2u);
    const ReportRow* at8 = byLabel["custom:tiled_fixed.comp fixed:256 tile tile=8"];
    const ReportRow* at16 = byLabel["custom:tiled_fixed.comp fixed:256 tile tile=16"];
    ASSERT_TRUE(at8 && at16);
    EXPECT_EQ(at8->config.tileSize, 8u);
    EXPECT_EQ(at16->config.tileSize, 16u);
    EXPECT_EQ(at8->falseNegatives, 0u);
    EXPECT_EQ(at16->falseNegatives, 0u);
    EXPECT_GT(at16->meanList, at8->meanList); // larger tiles, longer lists
}

TEST_F(GpuTest, ReportPutsCustomShadersBesideTheBuiltinRows) {
    Scene s = atrium(330, 190, 1500); // partial edge tiles: the flawed shader drifts
    ReportOptions o = oneRunReport("vulkan");
    o.fixed["spot-test"] = "apex-sphere";
    o.shaders = {optionsFor(kExamples + "tiled_fixed.comp", "bitmask"),
                 optionsFor(kExamples + "flawed_tile_edges.comp", "bitmask")};
    setenv("LIGHTCULL_VALIDATION", "1", 1);
    const Report rep = runReport(s, o);
    const ReportRow* good = nullptr;
    const ReportRow* flawed = nullptr;
    for (const ReportRow& r : rep.rows) {
        if (r.config.customLabel.rfind("custom:tiled_fixed.comp", 0) == 0) good = &r;
        if (r.config.customLabel.rfind("custom:flawed_tile_edges.comp", 0) == 0) flawed = &r;
    }
    ASSERT_TRUE(good && flawed);
    EXPECT_EQ(good->config.backend, "vulkan");
    EXPECT_EQ(good->falseNegatives, 0u);
    EXPECT_GT(good->cullMs, 0.0);
    ASSERT_GT(flawed->falseNegatives, 0u);
    EXPECT_FALSE(flawed->paretoEfficiency); // false negatives keep it off the front
    EXPECT_GT(good->optimalWork, 0u);
    EXPECT_LE(good->efficiencyVsOptimal, 1.0);
    const std::string csv = reportCsv(rep);
    EXPECT_NE(csv.find(",custom:tiled_fixed.comp,"), std::string::npos);
    // The reading names the shaders as themselves, never as the built-in
    // algorithm whose default settings their rows carry, and names the row
    // with false negatives.
    const std::string md = reportMarkdown(rep);
    const auto best = md.find("- Best total per algorithm on vulkan:");
    ASSERT_NE(best, std::string::npos) << md;
    const std::string bestLine = md.substr(best, md.find('\n', best) - best);
    EXPECT_NE(bestLine.find("`custom:tiled_fixed.comp bitmask tile`"), std::string::npos) << bestLine;
    double best25d = 1e300;
    for (const ReportRow& r : rep.rows)
        if (r.config.customLabel.empty() && r.config.settings.algorithm == Algorithm::TwoPointFiveD)
            best25d = std::min(best25d, r.totalMs);
    char want[64];
    std::snprintf(want, sizeof want, "2.5d %.3f ms", best25d); // the built-in rows' best, not a shader's
    EXPECT_NE(bestLine.find(want), std::string::npos) << want << " in " << bestLine;
    EXPECT_NE(md.find("1 configuration has false negatives** (lights missing where they matter): "
                      "`custom:flawed_tile_edges.comp"),
              std::string::npos) << md;

    // Swept on the CPU only, the shaders still ran on a Vulkan device: the
    // header says which.
    o.backends = {"cpu", "cpu"}; // and a backend named twice is swept once
    o.shaders.pop_back();
    const Report cpuRep = runReport(s, o);
    std::size_t cpuRows = 0;
    for (const ReportRow& r : cpuRep.rows) cpuRows += r.config.backend == "cpu";
    EXPECT_EQ(cpuRows, reportConfigs(o, "cpu", false).size());
    const std::string cpuMd = reportMarkdown(cpuRep);
    EXPECT_NE(cpuMd.find("- backend `vulkan`: " + good->device + " (the custom shaders)"), std::string::npos) << cpuMd;
    EXPECT_NE(cpuMd.find("Best total per algorithm on vulkan: `custom:tiled_fixed.comp"), std::string::npos) << cpuMd;
}

// --layout over a shader's own settings line: when the lists then read
// wrong, run says which layout the shader states.
TEST_F(GpuTest, ALayoutFlagOverTheShadersOwnIsNamedWhenTheListsReadWrong) {
    lc_test::ScratchDir d;
    lc_test::CliResult r = lc_test::runCli({"run", "--builtin", "atrium", "--width", "96", "--height", "64", "--shader",
                                            kExamples + "tiled_fixed.comp", "--layout", "compact", "--no-image-error",
                                            "--out", (d.path / "wrong").string()},
                                           d.path);
    EXPECT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.out.find("note: the shader's settings line says --layout fixed:256; --layout compact overrides it"),
              std::string::npos)
        << r.out;
    // Its own layout given again: nothing to say.
    r = lc_test::runCli({"run", "--builtin", "atrium", "--width", "96", "--height", "64", "--shader",
                         kExamples + "tiled_fixed.comp", "--layout", "fixed:256", "--no-image-error", "--out",
                         (d.path / "right").string()},
                        d.path);
    EXPECT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(r.out.find("note: the shader's settings line"), std::string::npos) << r.out;
}

TEST_F(GpuTest, CliRunShaderAndCheckWriteTheDiagnostics) {
    lc_test::ScratchDir d;
    const fs::path out = d.path / "mine";
    auto r = lc_test::runCli({"run", "--builtin", "atrium", "--width", "330", "--height", "190", "--lights", "150",
                              "--no-image-error", "--shader", kExamples + "flawed_tile_edges.comp", "--layout", "bitmask",
                              "--out", out.string()},
                             d.path);
    // The shader misses lights: the outputs are written and the exit code
    // says so (docs/CLI.md: 3), for a CI job to fail on.
    ASSERT_EQ(r.code, 3) << r.err;
    EXPECT_NE(r.err.find("lightcull: the culling fails: "), std::string::npos) << r.err;
    EXPECT_NE(r.out.find("algorithm custom"), std::string::npos) << r.out;
    const auto j = nlohmann::json::parse(lc_test::slurp(out / "summary.json"));
    EXPECT_EQ(j["algorithm"], "custom");
    EXPECT_EQ(j["custom"]["layout"], "bitmask"); // the flag beat the first line's fixed:256
    EXPECT_EQ(j["custom"]["lists"], "tile");
    // No built-in setting made these lists: none is reported as if it had.
    for (const char* k : {"test", "cells", "slicing", "skip_empty", "spot_test", "bins"})
        EXPECT_TRUE(j[k].is_null()) << k;
    EXPECT_TRUE(j["custom"]["validation_messages"].empty());
    const auto fn = j["metrics"]["false_negatives"].get<std::uint64_t>();
    std::uint64_t located = 0;
    for (const auto& m : j["custom"]["missed"]) located += m["pixels"].get<std::uint64_t>();
    EXPECT_EQ(located, fn); // every missed pixel-light is located
    // 330 px is 20.6 tiles: the flawed frustums drift at this width (not a
    // precondition to hope for: the test's point).
    ASSERT_GT(fn, 0u);
    EXPECT_NE(r.out.find("FALSE NEGATIVES " + std::to_string(fn)), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("MISSING light"), std::string::npos) << r.out;
    // Its misses are the test's own (bitmask lists never overflow).
    EXPECT_NE(r.out.find("cause: culling test"), std::string::npos) << r.out;
    EXPECT_EQ(j["custom"]["missed_pairs_by_cause"]["culling_test"], j["custom"]["missed_pairs"]);
    for (const auto& m : j["custom"]["missed"]) EXPECT_EQ(m["cause"], "culling_test");
    // The depth was drawn by the default backend's pre-pass, not by "custom".
    EXPECT_EQ(j["depth_source"].get<std::string>().rfind("pre-pass on vulkan (", 0), 0u) << j["depth_source"];
    r = lc_test::runCli({"run", "--builtin", "atrium", "--width", "64", "--height", "48", "--lights", "40", "--backend", "cpu",
                         "--shader", kExamples + "tiled_fixed.comp", "--out", (d.path / "cpu-depth").string()},
                        d.path);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto cj = nlohmann::json::parse(lc_test::slurp(d.path / "cpu-depth" / "summary.json"));
    EXPECT_EQ(cj["depth_source"].get<std::string>().rfind("pre-pass on cpu (", 0), 0u) << cj["depth_source"];
    EXPECT_TRUE(fs::exists(out / "tiles.csv") && fs::exists(out / "heatmap.png") && fs::exists(out / "overlays.vtm"));

    // A compile error: one line with file and line, exit 1, nothing written.
    r = lc_test::runCli({"run", "--builtin", "atrium", "--shader", kData + "syntax_error.comp", "--out",
                         (d.path / "bad").string()},
                        d.path);
    EXPECT_EQ(r.code, 1);
    EXPECT_NE(r.err.find("syntax_error.comp:6: compile error"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(d.path / "bad"));

    // check: an engine's CSV lists, here every light in every tile (no misses).
    {
        std::ofstream csv(d.path / "all.csv");
        for (int t = 0; t < 21 * 12; ++t) {
            csv << t;
            for (int l = 0; l < 150; ++l) csv << "," << l;
            csv << "\n";
        }
    }
    r = lc_test::runCli({"check", "--builtin", "atrium", "--width", "330", "--height", "190", "--lights", "150", "--lists",
                         (d.path / "all.csv").string(), "--rule", "tile", "--out", (d.path / "engine").string()},
                        d.path);
    ASSERT_EQ(r.code, 0) << r.err;
    const auto c = nlohmann::json::parse(lc_test::slurp(d.path / "engine" / "summary.json"));
    EXPECT_EQ(c["metrics"]["false_negatives"], 0);
    EXPECT_EQ(c["backend"], "dump");
    // The lists were judged on the default backend's pre-pass: said, timed
    // and counted, not "no pre-pass ran".
    EXPECT_EQ(c["depth_source"].get<std::string>().rfind("pre-pass on vulkan (", 0), 0u) << c["depth_source"];
    EXPECT_GE(c["timings_ms"]["depth"].get<double>(), 0.0);
    EXPECT_EQ(c["depth_triangles"]["scene"], 11880);
    EXPECT_NE(r.out.find("pre-pass on vulkan ("), std::string::npos) << r.out;
    EXPECT_EQ(r.out.find("--no-image-error"), std::string::npos) << r.out; // not a flag of check

    // Culling flags that would change nothing are refused, not recorded.
    r = lc_test::runCli({"check", "--builtin", "atrium", "--width", "330", "--height", "190", "--lights", "150", "--lists",
                         (d.path / "all.csv").string(), "--algorithm", "clustered", "--out", (d.path / "e2").string()},
                        d.path);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--algorithm: has no effect on check"), std::string::npos) << r.err;
    r = lc_test::runCli({"run", "--builtin", "atrium", "--width", "64", "--height", "64", "--shader",
                         kExamples + "tiled_fixed.comp", "--cells", "4", "--out", (d.path / "e3").string()},
                        d.path);
    EXPECT_EQ(r.code, 2);
    EXPECT_NE(r.err.find("--cells: has no effect with --shader"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(d.path / "e2") || fs::exists(d.path / "e3"));
}
