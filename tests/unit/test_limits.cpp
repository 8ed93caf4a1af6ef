// Engine limits (core/limits.hpp): the per-list cap, the record buffer and the
// per-view light limit with their policies, the false negatives they cause
// counted by cause, Explain's verdict, the exports, and the engine presets.
#include "result_lists.hpp"
#include "culling/core/errors.hpp"
#include "culling/core/limits.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/core/presets.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/diagnostics/explain.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "culling/diagnostics/report.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <regex>
#include <sstream>

using namespace lc;

namespace {

using test::droppedAt;
using test::listAt;

// A result of `lists` lists with the given entries, over `lights` lights.
CullResult listsOf(const std::vector<std::vector<std::uint32_t>>& lists) {
    CullResult r;
    r.algorithm = Algorithm::MinMax;
    for (const auto& l : lists) {
        r.listOffset.push_back(std::uint32_t(r.lightIndices.size()));
        r.listCount.push_back(std::uint32_t(l.size()));
        r.lightIndices.insert(r.lightIndices.end(), l.begin(), l.end());
    }
    return r;
}

// Lights on the view axis at depths 1 + i (light i is the (i+1)-th nearest)
// unless `farFirst`, then light 0 is the farthest.
ViewLights lightsAtDepths(std::size_t n, bool farFirst = false) {
    ViewLights v;
    for (std::size_t i = 0; i < n; ++i) {
        const double d = farFirst ? double(n - i) : double(i + 1);
        v.centers.push_back({0, 0, -d});
        v.radii.push_back(1);
        v.power.push_back({1, 1, 1});
    }
    return v;
}

} // namespace

TEST(Limits, NoLimitLeavesTheListsAlone) {
    CullResult r = listsOf({{0, 1, 2}, {}, {3}});
    const CullResult before = r;
    applyListLimits(r, lightsAtDepths(4), CullSettings{});
    EXPECT_EQ(r.lightIndices, before.lightIndices);
    EXPECT_TRUE(r.limits.empty());
    EXPECT_EQ(r.limits.longestUncapped, 0u); // not worked out when no limit is set
}

TEST(Limits, CapByIndexKeepsTheLowestIndicesAndRecordsTheRest) {
    CullResult r = listsOf({{0, 1, 2, 5}, {3}, {1, 4, 6}});
    CullSettings s;
    s.cap = 2;
    applyListLimits(r, lightsAtDepths(7), s);
    EXPECT_EQ(listAt(r, 0), (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(listAt(r, 1), (std::vector<std::uint32_t>{3}));
    EXPECT_EQ(listAt(r, 2), (std::vector<std::uint32_t>{1, 4}));
    EXPECT_EQ(r.limits.overflowLists, (std::vector<std::uint32_t>{0, 2}));
    EXPECT_EQ(droppedAt(r, 0), (std::vector<std::uint32_t>{2, 5}));
    EXPECT_EQ(droppedAt(r, 1), std::vector<std::uint32_t>{});
    EXPECT_EQ(droppedAt(r, 2), (std::vector<std::uint32_t>{6}));
    EXPECT_TRUE(r.limits.dropped(0, 5));
    EXPECT_FALSE(r.limits.dropped(0, 1));
    EXPECT_EQ(r.limits.longestUncapped, 4u);
    EXPECT_EQ(r.limits.entriesUncapped, 8u);
    // What an engine with a cap of 2 allocates: a count and 2 indices per list.
    r.settings = s;
    EXPECT_EQ(r.bytes(), 3u * 4u * 3u);
}

TEST(Limits, NearestKeepsTheLightsNearestTheCamera) {
    CullResult r = listsOf({{0, 1, 2, 3}});
    CullSettings s;
    s.cap = 2;
    s.overflow = OverflowPolicy::Nearest;
    applyListLimits(r, lightsAtDepths(4, /*farFirst=*/true), s); // light 3 nearest, then 2
    EXPECT_EQ(listAt(r, 0), (std::vector<std::uint32_t>{2, 3}));
    EXPECT_EQ(droppedAt(r, 0), (std::vector<std::uint32_t>{0, 1}));
}

TEST(Limits, RecordBufferIsHandedOutInListOrder) {
    CullResult r = listsOf({{0, 1}, {2, 3, 4}, {5}, {}, {6}});
    CullSettings s;
    s.maxEntries = 4;
    applyListLimits(r, lightsAtDepths(7), s);
    EXPECT_EQ(listAt(r, 0), (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(listAt(r, 1), (std::vector<std::uint32_t>{2, 3})); // 2 records left
    EXPECT_EQ(listAt(r, 2), std::vector<std::uint32_t>{});       // none left
    EXPECT_EQ(listAt(r, 3), std::vector<std::uint32_t>{});
    EXPECT_EQ(r.limits.overflowLists, (std::vector<std::uint32_t>{1, 2, 4}));
    EXPECT_EQ(r.entries(), 4u);
}

// Filament's Froxelizer: out of records, every later list that holds a light
// points at the all-lights record; an empty one stays empty.
TEST(Limits, AllLightsFallbackOnceTheRecordsRunOut) {
    CullResult r = listsOf({{0, 1}, {2, 3, 4}, {}, {5}});
    CullSettings s;
    s.maxEntries = 3;
    s.overflow = OverflowPolicy::AllLights;
    applyListLimits(r, lightsAtDepths(6), s);
    const std::vector<std::uint32_t> all{0, 1, 2, 3, 4, 5};
    EXPECT_EQ(listAt(r, 0), (std::vector<std::uint32_t>{0, 1}));
    EXPECT_EQ(listAt(r, 1), all);
    EXPECT_EQ(listAt(r, 2), std::vector<std::uint32_t>{});
    EXPECT_EQ(listAt(r, 3), all); // {5} would fit in the one record left, but the buffer ran out
    EXPECT_EQ(r.limits.overflowLists, (std::vector<std::uint32_t>{1, 3}));
    EXPECT_TRUE(r.limits.droppedLights.empty()); // nothing dropped: a fallback lists more
}

TEST(Limits, AllLightsFallbackOnACapDoesNotUseUpTheBuffer) {
    CullResult r = listsOf({{0, 1, 2}, {3}});
    CullSettings s;
    s.cap = 2;
    s.overflow = OverflowPolicy::AllLights;
    applyListLimits(r, lightsAtDepths(4), s);
    EXPECT_EQ(listAt(r, 0), (std::vector<std::uint32_t>{0, 1, 2, 3}));
    EXPECT_EQ(listAt(r, 1), (std::vector<std::uint32_t>{3}));
}

TEST(Limits, LightLimitTakesLightsOutOfEveryListFirst) {
    CullResult r = listsOf({{0, 1, 2, 3}, {1, 3}});
    CullSettings s;
    s.maxLights = 2;
    s.cap = 1;
    applyListLimits(r, lightsAtDepths(4), s); // keeps 0 and 1
    EXPECT_EQ(r.limits.overLightLimit, (std::vector<std::uint8_t>{0, 0, 1, 1}));
    EXPECT_EQ(r.limits.lightsOverLimit, 2u);
    EXPECT_EQ(listAt(r, 0), (std::vector<std::uint32_t>{0})); // {0, 1} under the cap of 1
    EXPECT_EQ(droppedAt(r, 0), (std::vector<std::uint32_t>{1})); // past the limit is not "dropped by the cap"
    EXPECT_EQ(listAt(r, 1), (std::vector<std::uint32_t>{1}));
    EXPECT_TRUE(r.limits.overflowIndex(1) < 0);
    s.limitKeep = LimitKeep::Nearest;
    const std::vector<std::uint8_t> far = lightsOverLimit(lightsAtDepths(4, true), 2, LimitKeep::Nearest);
    EXPECT_EQ(far, (std::vector<std::uint8_t>{1, 1, 0, 0}));
    EXPECT_TRUE(lightsOverLimit(lightsAtDepths(4), 4, LimitKeep::Index).empty()); // not reached
}

TEST(Limits, AHugeFallbackIsASettingsErrorNotGigabytes) {
    // 20,000 lists each over a cap of 1 with 20,000 lights: 4e8 entries.
    CullResult r;
    r.algorithm = Algorithm::MinMax;
    for (int l = 0; l < 20000; ++l) {
        r.listOffset.push_back(std::uint32_t(r.lightIndices.size()));
        r.listCount.push_back(2);
        r.lightIndices.push_back(0);
        r.lightIndices.push_back(1);
    }
    CullSettings s;
    s.cap = 1;
    s.overflow = OverflowPolicy::AllLights;
    EXPECT_THROW(applyListLimits(r, lightsAtDepths(20000), s), Error); // found while running: exit 1, not 2
}

namespace {

// One wall filling the screen and `n` lights whose spheres hold all of it:
// every geometry pixel needs every light, so a pixel misses exactly the
// lights its list lacks, and the misses by cause are known without the
// ground truth's own bookkeeping.
Scene wallScene(std::size_t n, std::uint32_t w = 64, std::uint32_t h = 48) {
    Scene s;
    s.name = "wall";
    Mesh m;
    m.name = "wall";
    m.positions = {-50, -50, 0, 50, -50, 0, 50, 50, 0, -50, 50, 0};
    m.indices = {0, 1, 2, 0, 2, 3};
    s.meshes.push_back(m);
    s.camera.position = {0, 0, 5};
    s.camera.target = {0, 0, 0};
    s.camera.width = w;
    s.camera.height = h;
    s.camera.tileSize = 16;
    for (std::size_t i = 0; i < n; ++i) {
        PointLight l;
        l.name = "l" + std::to_string(i);
        l.position = {0.01 * double(i), 0, 1 + 0.05 * double(i)};
        l.explicitRadius = 100;
        s.lights.push_back(l);
    }
    return s;
}

} // namespace

// Every built-in algorithm on the CPU reference: a cap and a light limit
// make exactly the misses the lists say, each counted under its cause.
TEST(Limits, FalseNegativesAreSplitByCauseExactlyOnEveryAlgorithm) {
    const Scene scene = wallScene(5);
    auto cpu = makeCpuBackend();
    for (const std::string& a : cullParam("algorithm").choices) {
        CullSettings s;
        s.algorithm = algorithmFromString(a);
        s.cap = 2;
        s.maxLights = 4; // keeps lights 0..3
        RunOptions o;
        o.truthOptions.imageError = false;
        const RunOutput run = runPipeline(scene, s, *cpu, o);
        const Projection proj(scene.camera);
        const CullResult lists = zbinPixelLists(run.result, run.depth, proj);
        std::uint64_t pixels = 0, listed = 0;
        for (std::uint32_t y = 0; y < run.depth.height; ++y)
            for (std::uint32_t x = 0; x < run.depth.width; ++x) {
                if (!run.depth.hasGeometry(x, y)) continue;
                ++pixels;
                const double d = proj.viewDepthFromWindowDepth(run.depth.at(x, y));
                listed += lists.listCount[lists.listOfPixel(x, y, d)];
            }
        ASSERT_GT(pixels, 0u) << a;
        const Metrics& m = run.truth.metrics;
        EXPECT_EQ(m.falseNegativesLightLimit, pixels * 1) << a; // light 4
        EXPECT_EQ(m.falseNegativesListFull, pixels * 4 - listed) << a;
        EXPECT_EQ(m.falseNegativesListFull, pixels * 2) << a; // every list holds all 4: 2 kept, 2 dropped
        EXPECT_EQ(m.falseNegativesCullingTest(), 0u) << a;
        EXPECT_EQ(m.falseNegatives, pixels * 3) << a;
        // Located misses carry the same causes.
        const std::vector<MissedLight> located = locateFalseNegatives(run, proj);
        for (const MissedLight& ml : located)
            EXPECT_EQ(ml.cause, ml.light == 4 ? MissCause::LightLimit : MissCause::ListFull) << a << " " << ml.light;
    }
}

// An engine with a light limit keeps max-lights of the view's lights before
// it culls: the cull tests those alone (its time is what the engine pays),
// and zbin sorts and bins those alone. The result is the cull of a scene
// holding only the kept lights, its indices naming the scene's lights.
TEST(Limits, ALightLimitCullsOnlyTheLightsItKeeps) {
    Scene scene = makeBuiltinScene("atrium");
    scene.camera.width = 96;
    scene.camera.height = 64;
    LightGenSettings gen = defaultLightGen(scene, 40, 3);
    gen.spotFraction = 0.3;
    scene.lights = generateLights(gen);
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, 16);
    const ViewLights all = makeViewLights(scene);
    const std::vector<std::uint8_t> over = lightsOverLimit(all, 15, LimitKeep::Nearest);
    ASSERT_EQ(over.size(), 40u);
    std::vector<std::uint32_t> keep;
    Scene kept = scene;
    kept.lights.clear();
    for (std::uint32_t i = 0; i < 40; ++i)
        if (!over[i]) keep.push_back(i), kept.lights.push_back(scene.lights[i]);
    ASSERT_EQ(keep.size(), 15u);
    ASSERT_NE(keep.back(), 14u) << "the nearest 15 are not the first 15";
    const ViewLights keptLights = makeViewLights(kept);
    for (const Algorithm a : {Algorithm::All, Algorithm::MinMax, Algorithm::Clustered, Algorithm::ZBin, Algorithm::Raster}) {
        CullSettings s;
        s.algorithm = a;
        s.maxLights = 15;
        s.limitKeep = LimitKeep::Nearest;
        const CullResult r = cpu->cull(depth, proj, grid, all, s);
        s.maxLights = 0;
        const CullResult alone = cpu->cull(depth, proj, grid, keptLights, s);
        const std::string what = toString(a);
        EXPECT_EQ(r.volumeTests, alone.volumeTests) << what << ": the lights past the limit are never tested";
        std::vector<std::uint32_t> named;
        for (const std::uint32_t i : alone.lightIndices) named.push_back(keep[i]);
        EXPECT_EQ(r.lightIndices, named) << what;
        EXPECT_EQ(r.listCount, alone.listCount) << what;
        EXPECT_EQ(r.limits.lightsOverLimit, 25u) << what;
        EXPECT_TRUE(r.validate(all.size()).empty()) << what << ": " << r.validate(all.size());
        if (a == Algorithm::ZBin) {
            EXPECT_EQ(r.zbinLo, alone.zbinLo) << "the bins hold the kept lights' sorted positions";
            EXPECT_EQ(r.zbinHi, alone.zbinHi);
            for (std::uint32_t k = 0; k < alone.zbinOrder.size(); ++k)
                EXPECT_EQ(r.zbinOrder[k], keep[alone.zbinOrder[k]]) << k;
        }
    }
}

TEST(Limits, ExplainSaysWhichLimitDroppedALight) {
    const Scene scene = wallScene(5);
    CullSettings s;
    s.algorithm = Algorithm::MinMax;
    s.cap = 2;
    s.maxLights = 4;
    RunOptions o;
    o.truthOptions.imageError = false;
    const RunOutput run = runPipeline(scene, s, *makeCpuBackend(), o);
    const Projection proj(scene.camera);
    const std::string full = explainLight(run, proj, 0, 3).verdict;
    EXPECT_NE(full.find("dropped: list full (cap 2)"), std::string::npos) << full;
    const std::string limit = explainLight(run, proj, 0, 4).verdict;
    EXPECT_NE(limit.find("past the light limit, max-lights 4"), std::string::npos) << limit;
    const std::string kept = explainLight(run, proj, 0, 1).verdict;
    EXPECT_EQ(kept.find("dropped"), std::string::npos) << kept;
    // zbin sorts and bins the kept lights alone: one past the limit has no
    // sorted position, and the Z-bin step says why instead of giving one.
    CullSettings z = s;
    z.algorithm = Algorithm::ZBin;
    const RunOutput zrun = runPipeline(scene, z, *makeCpuBackend(), o);
    const std::string past = explainLight(zrun, proj, 0, 4).text();
    EXPECT_NE(past.find("not binned: past the light limit (max-lights 4), only the 4 lights kept"), std::string::npos)
        << past;
    const std::string in = explainLight(zrun, proj, 0, 1).text();
    EXPECT_NE(in.find(" of 4; bins "), std::string::npos) << "positions among the kept lights: " << in;
}

TEST(Limits, ExportsCountOverfullListsAndCauses) {
    const Scene scene = wallScene(5);
    CullSettings s;
    s.algorithm = Algorithm::MinMax;
    s.cap = 3;
    RunOptions o;
    o.truthOptions.imageError = false;
    const RunOutput run = runPipeline(scene, s, *makeCpuBackend(), o);
    const nlohmann::json j = nlohmann::json::parse(summaryJson(scene, s, run));
    const std::uint64_t lists = run.result.listCount.size();
    EXPECT_EQ(j["limits"]["cap"], 3);
    EXPECT_EQ(j["limits"]["overflow_lists"], lists); // 4x3 tiles, each holding 5 lights
    EXPECT_EQ(j["limits"]["dropped_entries"], 2 * lists);
    EXPECT_EQ(j["limits"]["longest_list_uncapped"], 5);
    EXPECT_EQ(j["metrics"]["false_negatives_by_cause"]["list_full"], j["metrics"]["false_negatives"]);
    EXPECT_EQ(j["metrics"]["false_negatives_by_cause"]["culling_test"], 0);
    // The located pairs by cause hold every pair, a light limit's too.
    CullSettings limited = s;
    limited.maxLights = 4;
    const RunOutput lrun = runPipeline(scene, limited, *makeCpuBackend(), o);
    const nlohmann::json lj = nlohmann::json::parse(summaryJson(scene, limited, lrun));
    std::uint64_t pairs = 0;
    for (const auto& [cause, n] : lj["missed_pairs_by_cause"].items()) pairs += n.get<std::uint64_t>();
    EXPECT_EQ(pairs, lj["missed_pairs"].get<std::uint64_t>()) << lj["missed_pairs_by_cause"].dump();
    EXPECT_EQ(lj["missed_pairs_by_cause"]["light_limit"], lists) << "light 4 in every tile";
    EXPECT_GT(lj["missed_pairs_by_cause"]["list_full"].get<std::uint64_t>(), 0u);
    // tiles.csv: every list over-full, 2 dropped, its misses all list full.
    std::istringstream csv(tilesCsv(run));
    std::string line;
    std::getline(csv, line);
    std::size_t rows = 0;
    while (std::getline(csv, line)) {
        std::vector<std::string> f;
        std::stringstream ls(line);
        for (std::string v; std::getline(ls, v, ',');) f.push_back(v);
        ASSERT_GE(f.size(), 12u) << line;
        EXPECT_EQ(f[10], "1") << line;
        EXPECT_EQ(f[11], "2") << line;
        EXPECT_EQ(f[7], f[8]) << line; // false negatives == list full
        ++rows;
    }
    EXPECT_EQ(rows, lists);
    // The overflow heat: the dropped entries of each tile; a tile that did
    // not overflow is not drawn (NaN).
    const std::vector<double> heat = tileHeat(run, HeatMode::Overflow);
    for (double v : heat) EXPECT_EQ(v, 2.0);
    CullSettings none = s;
    none.cap = 0;
    const RunOutput open = runPipeline(scene, none, *makeCpuBackend(), o);
    for (double v : tileHeat(open, HeatMode::Overflow)) EXPECT_TRUE(std::isnan(v));
}

// ---- engine presets -------------------------------------------------------------

// docs/ENGINES.md's preset table is what the code sets: each row's settings
// column, `--name value ...`, equals the preset's parameters in order.
TEST(Presets, EveryPresetMatchesTheDocumentedTable) {
    std::ifstream in(std::string(LC_SOURCE_DIR) + "/docs/ENGINES.md");
    ASSERT_TRUE(in) << "docs/ENGINES.md";
    std::map<std::string, std::string> documented;
    const std::regex row(R"(^\| `([a-z0-9-]+)` \|[^|]*\| `([^`]*)` \|)");
    for (std::string line; std::getline(in, line);) {
        std::smatch m;
        if (std::regex_search(line, m, row)) documented[m[1]] = m[2];
    }
    ASSERT_EQ(documented.size(), enginePresets().size());
    for (const EnginePreset& p : enginePresets()) {
        std::string flags;
        for (const auto& [k, v] : p.params) flags += (flags.empty() ? "--" : " --") + k + " " + v;
        ASSERT_TRUE(documented.count(p.name)) << p.name;
        EXPECT_EQ(documented[p.name], flags) << p.name;
        // Every parameter is one the table knows, with a valid value.
        CullSettings s;
        Camera c;
        EXPECT_NO_THROW(applyPreset(p, s, c, 100)) << p.name;
        EXPECT_EQ(s.validate(), "") << p.name;
    }
    EXPECT_THROW(enginePreset("unity"), SettingsError);
}

TEST(Presets, DerivedSettingsFollowTheEnginesRules) {
    Camera c;
    c.width = 1920;
    c.height = 1080;
    CullSettings s;
    // URP: 256 lights = 8 words per tile; 8 px tiles = 240x135x8 words > 16384,
    // 16: 120x68x8 = 65280 > 16384, 32: 60x34x8 = 16320 fits.
    applyPreset(enginePreset("urp"), s, c, 300);
    EXPECT_EQ(c.tileSize, 32u);
    EXPECT_EQ(s.bins, 4096u / (2 + 8));
    EXPECT_EQ(s.maxLights, 256u);
    // 20 lights: 1 word; 8 px: 240x135 = 32400 > 16384; 16 px: 120x68 = 8160 fits.
    applyPreset(enginePreset("urp"), s, c, 20);
    EXPECT_EQ(c.tileSize, 16u);
    // Unreal: 30x17 cells x 32 slices x 32 entries.
    applyPreset(enginePreset("unreal-5"), s, c, 10);
    EXPECT_EQ(c.tileSize, 64u);
    EXPECT_EQ(s.maxEntries, 30u * 17u * 32u * 32u);
    // Filament: square froxels, a multiple of 8 px, at most 256 per slice.
    applyPreset(enginePreset("filament"), s, c, 10);
    EXPECT_EQ(c.tileSize % 8, 0u);
    EXPECT_LE(((1920 + c.tileSize - 1) / c.tileSize) * ((1080 + c.tileSize - 1) / c.tileSize), 256u);
    EXPECT_GT(((1920 + c.tileSize - 9) / (c.tileSize - 8)) * ((1080 + c.tileSize - 9) / (c.tileSize - 8)), 256u);
    // A light limit given beside the preset re-derives its grid from it:
    // URP mobile raised to 256 lights takes the desktop's budget and tiles.
    applyPreset(enginePreset("urp-mobile"), s, c, 300, {{"max-lights", "256"}});
    EXPECT_EQ(s.maxLights, 256u);
    EXPECT_EQ(c.tileSize, 32u);
    EXPECT_EQ(s.bins, 4096u / (2 + 8));
    // ... and a value given beside it wins over a derived one.
    applyPreset(enginePreset("unreal-5"), s, c, 10, {{"max-entries", "1000"}});
    EXPECT_EQ(s.maxEntries, 1000u);
    // A preset replaces what was set before it.
    CullSettings t;
    t.cap = 5;
    t.cells = 3;
    applyPreset(enginePreset("bevy"), t, c, 10);
    EXPECT_EQ(t.cap, 0u);
    EXPECT_EQ(t.cells, 24u);
}

// Per preset with a limit: a scene past its light limit (or list cap) loses
// exactly the lights the limits dropped, counted by cause; a preset without
// limits loses nothing.
TEST(Presets, EachPresetsLimitDropsLightsCountedByCause) {
    auto cpu = makeCpuBackend();
    for (const EnginePreset& p : enginePresets()) {
        CullSettings probe;
        Camera pc;
        applyPreset(p, probe, pc, 10);
        const std::size_t n = probe.maxLights ? probe.maxLights + 3 : probe.cap ? probe.cap + 3 : 12;
        Scene scene = wallScene(n, 128, 64);
        CullSettings s;
        applyPreset(p, s, scene.camera, scene.lights.size());
        RunOptions o;
        o.truthOptions.imageError = false;
        const RunOutput run = runPipeline(scene, s, *cpu, o);
        const Projection proj(scene.camera);
        const CullResult lists = zbinPixelLists(run.result, run.depth, proj);
        std::uint64_t pixels = 0, listed = 0;
        for (std::uint32_t y = 0; y < run.depth.height; ++y)
            for (std::uint32_t x = 0; x < run.depth.width; ++x) {
                if (!run.depth.hasGeometry(x, y)) continue;
                ++pixels;
                listed += lists.listCount[lists.listOfPixel(x, y, proj.viewDepthFromWindowDepth(run.depth.at(x, y)))];
            }
        const Metrics& m = run.truth.metrics;
        const std::uint64_t over = run.result.limits.lightsOverLimit;
        EXPECT_EQ(over, probe.maxLights ? 3u : 0u) << p.name;
        EXPECT_EQ(m.falseNegativesLightLimit, pixels * over) << p.name;
        EXPECT_EQ(m.falseNegativesListFull, pixels * (n - over) - listed) << p.name;
        EXPECT_EQ(m.falseNegativesCullingTest(), 0u) << p.name;
        if (!probe.hasLimits()) EXPECT_EQ(m.falseNegatives, 0u) << p.name;
        if (probe.cap && !probe.maxLights) EXPECT_GT(m.falseNegativesListFull, 0u) << p.name;
        if (probe.maxLights) EXPECT_GT(m.falseNegativesLightLimit, 0u) << p.name;
    }
}

// report --presets: one row per preset with the first change that keeps
// every light, found by culling again.
TEST(Presets, TheReportFindsTheSmallestLimitThatLosesNothing) {
    Scene scene = wallScene(40, 128, 64);
    ReportOptions o;
    o.backends = {"cpu"};
    o.presets = {"threejs", "urp-mobile", "bevy"};
    o.repeat = 1;
    o.warmup = 0;
    const Report rep = runReport(scene, o);
    ASSERT_EQ(rep.rows.size(), 3u);
    // three.js: cap 8 with 40 lights in every list: a cap of 40 keeps them all.
    EXPECT_EQ(rep.rows[0].config.preset, "threejs");
    EXPECT_GT(rep.rows[0].falseNegativesListFull, 0u);
    EXPECT_EQ(rep.rows[0].fix, "cap 40 (TiledLightsNode's tileLightCount)");
    // URP mobile: 32 lights kept of 40, all needed everywhere.
    // 40 lights all needed everywhere: URP keeps 32, a constant of its mobile path.
    EXPECT_EQ(rep.rows[1].fix, "max-lights 40: no setting reaches it (URP's k_MaxVisibleLightCountMobile is fixed "
                               "at 32): keep fewer lights in view");
    EXPECT_EQ(rep.rows[1].falseNegativesLightLimit, rep.rows[1].falseNegatives);
    EXPECT_EQ(rep.rows[2].fix, "");
    EXPECT_EQ(rep.rows[2].falseNegatives, 0u);
    const std::string md = reportMarkdown(rep);
    EXPECT_NE(md.find("## Engine presets"), std::string::npos);
    EXPECT_NE(md.find("| cap 40 (TiledLightsNode's tileLightCount) |"), std::string::npos) << md;
    // No cap was swept: no Caps section (a preset's cap is not a sweep).
    EXPECT_EQ(md.find("## Caps"), std::string::npos) << md;
}
