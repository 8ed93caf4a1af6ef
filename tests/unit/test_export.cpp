// Exporters: summary.json, tiles.csv and heatmap.png from real pipeline runs,
// read back and checked against the run; the atomic folder write on success
// and on failure.
#include "culling/core/errors.hpp"
#include "culling/core/presets.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <png.h>

#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

using namespace lc;
namespace fs = std::filesystem;

namespace {

std::string readText(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::vector<std::string> split(const std::string& s, char sep) {
    std::vector<std::string> out;
    std::string cur;
    for (char c : s) {
        if (c == sep) out.push_back(cur), cur.clear();
        else cur += c;
    }
    out.push_back(cur);
    return out;
}

// A fresh, empty folder under the system temp dir, removed at the end.
struct TempDir {
    fs::path path;
    TempDir() {
        std::string t = (fs::temp_directory_path() / "lc_export_XXXXXX").string();
        path = ::mkdtemp(t.data());
    }
    ~TempDir() { fs::remove_all(path); }
    std::vector<std::string> entries() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(path)) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
};

struct PipelineRun {
    Scene scene;
    CullSettings settings;
    RunOutput out;
};

PipelineRun runBuiltin(const std::string& name, Algorithm alg, std::uint32_t w = 96, std::uint32_t h = 64,
               bool imageError = true) {
    PipelineRun r;
    r.scene = makeBuiltinScene(name);
    r.scene.camera.width = w;
    r.scene.camera.height = h;
    r.scene.camera.tileSize = 16;
    r.settings.algorithm = alg;
    r.settings.cells = 8;
    auto backend = makeCpuBackend();
    RunOptions opt;
    opt.truthOptions.imageError = imageError;
    r.out = runPipeline(r.scene, r.settings, *backend, opt);
    return r;
}

struct Png {
    std::uint32_t width = 0, height = 0;
    std::vector<std::uint8_t> rgb;
};

// Reads an 8-bit RGB PNG through libpng's simplified API.
Png readPng(const fs::path& p) {
    png_image img{};
    img.version = PNG_IMAGE_VERSION;
    EXPECT_TRUE(png_image_begin_read_from_file(&img, p.c_str())) << img.message;
    img.format = PNG_FORMAT_RGB;
    Png out;
    out.width = img.width, out.height = img.height;
    out.rgb.resize(PNG_IMAGE_SIZE(img));
    EXPECT_TRUE(png_image_finish_read(&img, nullptr, out.rgb.data(), 0, nullptr)) << img.message;
    return out;
}

} // namespace

// A run on a depth image it was given ran no pre-pass: null, not 0 ms and
// 0 of 0 triangles.
TEST(Export, ARunOnAGivenDepthImageHasNoDepthTimeOrTriangles) {
    const PipelineRun first = runBuiltin("atrium", Algorithm::MinMax);
    auto backend = makeCpuBackend();
    RunOptions opt;
    opt.truthOptions.imageError = false;
    opt.reuseDepth = &first.out.depth;
    const RunOutput again = runPipeline(first.scene, first.settings, *backend, opt);
    ASSERT_TRUE(again.depthReused);
    const auto j = nlohmann::json::parse(summaryJson(first.scene, first.settings, again));
    EXPECT_TRUE(j["timings_ms"]["depth"].is_null());
    EXPECT_TRUE(j["depth_triangles"].is_null());
    EXPECT_GE(j["timings_ms"]["cull"].get<double>(), 0.0);
}

// summary.json names the engine preset the settings are, and none once a
// parameter differs from it (the preset's own derived values, not its name
// passed along, so an override is never reported as the engine's choice).
TEST(Export, SummaryJsonNamesThePresetTheSettingsAre) {
    PipelineRun r = runBuiltin("atrium", Algorithm::TwoPointFiveD);
    EXPECT_TRUE(nlohmann::json::parse(summaryJson(r.scene, r.settings, r.out))["preset"].is_null());
    for (const char* name : {"urp", "hdrp-fptl", "unreal-5", "godot-4", "bevy"}) {
        CullSettings s;
        Camera cam = r.scene.camera;
        applyPreset(enginePreset(name), s, cam, r.scene.lights.size());
        Scene scene = r.scene;
        scene.camera = cam;
        const auto j = nlohmann::json::parse(summaryJson(scene, s, r.out));
        ASSERT_TRUE(j["preset"].is_string()) << name;
        EXPECT_EQ(j["preset"].get<std::string>(), name);
        CullSettings changed = s;
        changed.cap = s.cap + 1;
        EXPECT_TRUE(nlohmann::json::parse(summaryJson(scene, changed, r.out))["preset"].is_null()) << name;
    }
}

TEST(Export, SummaryJsonHasEveryKeyConsistentWithTheRun) {
    const PipelineRun r = runBuiltin("atrium", Algorithm::TwoPointFiveD);
    const auto j = nlohmann::json::parse(summaryJson(r.scene, r.settings, r.out));
    for (const char* k : {"scene", "algorithm", "test", "backend", "device", "timing_method", "width",
                          "height", "tile_size", "tiles_x", "tiles_y", "cells", "slicing", "lights",
                          "timings_ms", "metrics"})
        EXPECT_TRUE(j.contains(k)) << k;
    for (const char* k : {"depth", "cull", "ground_truth"}) {
        ASSERT_TRUE(j["timings_ms"].contains(k)) << k;
        EXPECT_GE(j["timings_ms"][k].get<double>(), 0.0) << k;
    }
    const auto& m = j["metrics"];
    for (const char* k : {"false_negatives", "shading_work", "exact_work", "efficiency", "mean_list",
                          "max_list", "result_bytes", "list_entries", "lists", "geometry_pixels",
                          "image_rmse", "image_max_error"})
        EXPECT_TRUE(m.contains(k)) << k;

    const CullResult& res = r.out.result;
    EXPECT_EQ(j["scene"], r.scene.name);
    EXPECT_EQ(j["algorithm"], "2.5d");
    EXPECT_EQ(j["backend"], "cpu");
    EXPECT_EQ(j["width"], 96);
    EXPECT_EQ(j["height"], 64);
    EXPECT_EQ(j["tile_size"], 16);
    EXPECT_EQ(j["tiles_x"], 6);
    EXPECT_EQ(j["tiles_y"], 4);
    EXPECT_EQ(j["cells"], 8);
    EXPECT_EQ(j["lights"], r.scene.lights.size());
    const std::size_t triangles = r.scene.triangleCount();
    ASSERT_GT(triangles, 0u);
    EXPECT_EQ(j["depth_triangles"]["scene"], triangles); // the CPU rasteriser draws every one
    EXPECT_EQ(j["depth_triangles"]["drawn"], triangles);
    EXPECT_EQ(m["false_negatives"], 0);
    const auto W = m["shading_work"].get<std::uint64_t>(), E = m["exact_work"].get<std::uint64_t>();
    EXPECT_GT(W, 0u);
    EXPECT_EQ(m["efficiency"].get<double>(), double(E) / double(W)); // round-trips exactly
    EXPECT_EQ(m["lists"], res.listCount.size());
    EXPECT_EQ(m["list_entries"], res.lightIndices.size());
    EXPECT_EQ(m["mean_list"].get<double>(), double(res.lightIndices.size()) / double(res.listCount.size()));
    EXPECT_EQ(m["max_list"], *std::max_element(res.listCount.begin(), res.listCount.end()));
    EXPECT_EQ(m["result_bytes"], res.bytes());
    EXPECT_EQ(m["geometry_pixels"], r.out.depth.geometryPixelCount());
    // The run's own figures, not figures recomputed from the same JSON: an
    // image error that ignored a light's range passed "is a number" checks.
    const Metrics& run = r.out.truth.metrics;
    ASSERT_TRUE(run.imageErrorComputed);
    EXPECT_EQ(m["image_rmse"].get<double>(), run.imageRmse);
    EXPECT_EQ(m["image_max_error"].get<double>(), run.imageMaxError);
    EXPECT_EQ(W, run.shadingWork);
    EXPECT_EQ(E, run.exactWork);
    EXPECT_EQ(m["false_negatives"].get<std::uint64_t>(), run.falseNegatives);
    EXPECT_EQ(m["optimal_work"].get<std::uint64_t>(), run.optimalWork);
    EXPECT_EQ(m["efficiency"].get<double>(), run.efficiency);
    EXPECT_EQ(m["efficiency_vs_optimal"].get<double>(), run.efficiencyVsOptimal);
    EXPECT_EQ(m["mean_list"].get<double>(), run.meanList);
    EXPECT_EQ(m["max_list"].get<std::uint64_t>(), run.maxList);
    EXPECT_EQ(m["result_bytes"].get<std::uint64_t>(), run.resultBytes);
    EXPECT_EQ(m["geometry_pixels"].get<std::uint64_t>(), run.geometryPixels);
    EXPECT_GT(run.imageRmse, 0.0); // inverse-square lights: the cut-off's error

    const PipelineRun noImg = runBuiltin("wall", Algorithm::MinMax, 48, 32, false);
    const auto j2 = nlohmann::json::parse(summaryJson(noImg.scene, noImg.settings, noImg.out));
    EXPECT_TRUE(j2["metrics"]["image_rmse"].is_null());
    EXPECT_TRUE(j2["metrics"]["image_max_error"].is_null());
}

TEST(Export, TilesCsvHasOneRowPerListMatchingTheResult) {
    for (Algorithm alg : {Algorithm::All, Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD,
                          Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin}) {
        const PipelineRun r = runBuiltin("sky", alg, 100, 70); // partial edge tiles, many empty tiles
        const CullResult& res = r.out.result;
        const std::string csv = tilesCsv(r.out);
        std::vector<std::string> lines = split(csv, '\n');
        ASSERT_EQ(lines.back(), ""); // ends with a newline
        lines.pop_back();
        ASSERT_EQ(lines[0], "tile_x,tile_y,cell,view_depth_min,view_depth_max,cell_mask,count,false_negatives,"
                            "fn_list_full,fn_light_limit,overflow,dropped,lights");
        ASSERT_EQ(lines.size() - 1, res.listCount.size()) << toString(alg);
        std::size_t emptyDepthRows = 0;
        for (std::size_t l = 0; l < res.listCount.size(); ++l) {
            const auto f = split(lines[l + 1], ',');
            ASSERT_EQ(f.size(), 13u) << lines[l + 1];
            EXPECT_EQ(std::stoul(f[6]), res.listCount[l]);
            EXPECT_EQ(std::stoull(f[7]), r.out.truth.listFalseNegatives[l]);
            EXPECT_EQ(f[10], "0"); // no limits: never over-full
            EXPECT_EQ(f[11], "0");
            std::vector<std::uint32_t> listed;
            if (!f[12].empty())
                for (const auto& tok : split(f[12], ' ')) listed.push_back(std::uint32_t(std::stoul(tok)));
            EXPECT_EQ(listed, std::vector<std::uint32_t>(res.lightIndices.begin() + res.listOffset[l],
                                                         res.lightIndices.begin() + res.listOffset[l] + res.listCount[l]));
            if (alg == Algorithm::All) {
                EXPECT_EQ(f[0], "-1");
                EXPECT_EQ(f[1], "-1");
                continue;
            }
            const std::uint32_t t = std::uint32_t(l / res.listsPerTile);
            EXPECT_EQ(std::stoul(f[0]), t % res.grid.tilesX);
            EXPECT_EQ(std::stoul(f[1]), t / res.grid.tilesX);
            EXPECT_EQ(std::stoul(f[2]), l % res.listsPerTile);
            const bool empty = !(res.tileDepthMin[t] <= res.tileDepthMax[t]);
            if (empty) {
                ++emptyDepthRows;
                EXPECT_EQ(f[3], "");
                EXPECT_EQ(f[4], "");
            } else if (alg == Algorithm::MinMax || alg == Algorithm::TwoPointFiveD) {
                // Round-trip precision: the text reads back as the same double.
                EXPECT_EQ(std::strtod(f[3].c_str(), nullptr), res.tileDepthMin[t]);
                EXPECT_EQ(std::strtod(f[4].c_str(), nullptr), res.tileDepthMax[t]);
            } else if (alg == Algorithm::HalfZ) {
                const double split_ = res.halfzSplit[t];
                EXPECT_EQ(std::strtod(f[l % 2 ? 3 : 4].c_str(), nullptr), split_);
            }
            if (alg == Algorithm::TwoPointFiveD || alg == Algorithm::Clustered)
                EXPECT_EQ(std::stoul(f[5]), res.cellMask[t]);
        }
        if (alg != Algorithm::All) EXPECT_GT(emptyDepthRows, 0u) << "sky should have empty tiles";
    }
}

TEST(Export, HeatmapPngIsReadableWithImageSizeAndLegend) {
    TempDir tmp;
    const PipelineRun r = runBuiltin("atrium", Algorithm::MinMax, 160, 90);
    const RgbImage img = heatmapImage(r.out);
    EXPECT_EQ(img.width, 160u);
    EXPECT_GT(img.height, 90u); // the legend band below the image
    const fs::path p = tmp.path / "h.png";
    writePng(img, p.string());
    const Png back = readPng(p);
    ASSERT_EQ(back.width, img.width);
    ASSERT_EQ(back.height, img.height);
    EXPECT_EQ(back.rgb, img.rgb);
    // The colour bar runs from viridis' dark purple (left) to its yellow (right).
    const std::uint32_t barY = 90 + 8;
    const std::uint8_t* left = &back.rgb[(std::size_t(barY) * 160 + 4) * 3];
    const std::uint8_t* right = &back.rgb[(std::size_t(barY) * 160 + 155) * 3];
    EXPECT_LT(left[1], 20);
    EXPECT_GT(left[2], left[0]);
    EXPECT_GT(right[0], 200);
    EXPECT_GT(right[1], 200);
    EXPECT_LT(right[2], 80);
    EXPECT_THROW(writePng(img, (tmp.path / "missing" / "h.png").string()), Error);

    // The tick above the bar marks the mean in the tint's unit, lights per
    // geometry pixel, not the mean over clustered's mostly empty froxel lists.
    const PipelineRun c = runBuiltin("atrium", Algorithm::Clustered, 320, 180);
    const RgbImage ci = heatmapImage(c.out);
    const Metrics& m = c.out.truth.metrics;
    const CullResult& res = c.out.result;
    const auto [lo, hi] = std::minmax_element(res.listCount.begin(), res.listCount.end());
    const double perPixel = double(m.shadingWork) / double(m.geometryPixels);
    const double perList = double(res.entries()) / double(res.listCount.size());
    ASSERT_GT(perPixel, 2 * perList); // the two differ here
    const int bx0 = 4, bx1 = 320 - 4;
    const auto tickAt = [&](double v) { return bx0 + int(std::lround((v - *lo) / double(*hi - *lo) * (bx1 - bx0 - 1))); };
    int tick = -1;
    const std::uint32_t tickY = 180 + 2;
    for (int x = 0; x < 320; ++x) {
        const std::uint8_t* p = &ci.rgb[(std::size_t(tickY) * 320 + std::size_t(x)) * 3];
        if (p[0] == 255 && p[1] == 255 && p[2] == 255) tick = x;
    }
    EXPECT_LE(std::abs(tick - tickAt(perPixel)), 2) << tick << " vs " << tickAt(perPixel);
}

TEST(Export, DiagnosticsFolderIsWrittenAndReplacedAtomically) {
    TempDir tmp;
    const PipelineRun r = runBuiltin("wall", Algorithm::TwoPointFiveD, 64, 48);
    const fs::path out = tmp.path / "diag";
    exportDiagnostics(r.scene, r.settings, r.out, out.string());
    EXPECT_EQ(tmp.entries(), std::vector<std::string>{"diag"});
    EXPECT_EQ(readText(out / "summary.json"), summaryJson(r.scene, r.settings, r.out));
    EXPECT_EQ(readText(out / "tiles.csv"), tilesCsv(r.out));
    EXPECT_EQ(readPng(out / "heatmap.png").width, 64u);

    // A second export replaces the first; nothing else stays beside it.
    PipelineRun r2 = runBuiltin("wall", Algorithm::Naive, 64, 48);
    exportDiagnostics(r2.scene, r2.settings, r2.out, out.string() + "/");
    EXPECT_EQ(tmp.entries(), std::vector<std::string>{"diag"});
    EXPECT_EQ(readText(out / "summary.json"), summaryJson(r2.scene, r2.settings, r2.out));

    // A writer interrupted mid-export (Ctrl+C: no handler runs) leaves its
    // temporary folders: the next export beside them removes those of
    // writers that are gone, and leaves a live writer's alone.
    pid_t gone = 4194000;
    while (gone > 300 && ::kill(gone, 0) == 0) --gone;
    const fs::path abandoned = tmp.path / (".diag.tmp-" + std::to_string(gone) + "-AbCdEf");
    const fs::path abandonedOld = tmp.path / (".diag.old-" + std::to_string(gone) + "-XyZ123");
    const fs::path live = tmp.path / (".diag.tmp-" + std::to_string(::getppid()) + "-LiVe00");
    for (const fs::path& p : {abandoned, abandonedOld, live}) {
        fs::create_directory(p);
        std::ofstream(p / "summary.json") << "{}";
    }
    exportDiagnostics(r.scene, r.settings, r.out, out.string());
    EXPECT_FALSE(fs::exists(abandoned));
    EXPECT_FALSE(fs::exists(abandonedOld));
    EXPECT_TRUE(fs::exists(live));
    fs::remove_all(live);
    EXPECT_EQ(tmp.entries(), std::vector<std::string>{"diag"});
}

TEST(Export, FailureLeavesNothingBehind) {
    TempDir tmp;
    const PipelineRun r = runBuiltin("wall", Algorithm::MinMax, 32, 32, false);

    // A missing parent folder is made (as the docs' --out out/frame needs).
    exportDiagnostics(r.scene, r.settings, r.out, (tmp.path / "no" / "diag").string());
    EXPECT_TRUE(fs::exists(tmp.path / "no" / "diag" / "summary.json"));
    fs::remove_all(tmp.path / "no");

    // Parent is a regular file.
    { std::ofstream(tmp.path / "file") << "x"; }
    EXPECT_THROW(exportDiagnostics(r.scene, r.settings, r.out, (tmp.path / "file" / "diag").string()), Error);
    EXPECT_EQ(tmp.entries(), std::vector<std::string>{"file"});

    // Target exists as a file, or as a folder holding something else: refused, untouched.
    EXPECT_THROW(exportDiagnostics(r.scene, r.settings, r.out, (tmp.path / "file").string()), Error);
    EXPECT_EQ(readText(tmp.path / "file"), "x");
    fs::create_directory(tmp.path / "mine");
    { std::ofstream(tmp.path / "mine" / "notes.txt") << "keep"; }
    EXPECT_THROW(exportDiagnostics(r.scene, r.settings, r.out, (tmp.path / "mine").string()), Error);
    EXPECT_EQ(readText(tmp.path / "mine" / "notes.txt"), "keep");

    // A failure after the temporary folder was filled halfway (the PNG of an
    // empty image cannot be written): the previous export stays as it was and
    // the temporary folder is gone.
    const fs::path out = tmp.path / "diag";
    exportDiagnostics(r.scene, r.settings, r.out, out.string());
    const std::string before = readText(out / "summary.json");
    RunOutput broken = r.out;
    broken.depth = DepthImage{};
    EXPECT_THROW(exportDiagnostics(r.scene, r.settings, broken, out.string()), Error);
    EXPECT_EQ(readText(out / "summary.json"), before);
    EXPECT_EQ(tmp.entries(), (std::vector<std::string>{"diag", "file", "mine"}));
}

// heatmap_misses.png and the FalseNegatives heat mode: a tile is red exactly
// where its pixels miss lights, and the figure per tile is the ground truth's
// own (sum of listFalseNegatives over the tile's lists).
TEST(Export, MissHeatmapIsRedExactlyWhereTilesMissLights) {
    PipelineRun r = runBuiltin("atrium", Algorithm::HalfZ, 96, 64, false);
    const Projection proj(r.scene.camera);
    // Drop every light from the lists of the left half of the tiles.
    CullResult& res = r.out.result;
    const TileGrid& g = res.grid;
    CullResult cut = res;
    cut.lightIndices.clear();
    for (std::size_t l = 0; l < res.listCount.size(); ++l) {
        const std::uint32_t tile = std::uint32_t(l / res.listsPerTile);
        cut.listOffset[l] = std::uint32_t(cut.lightIndices.size());
        const bool drop = tile % g.tilesX < g.tilesX / 2;
        cut.listCount[l] = drop ? 0 : res.listCount[l];
        if (!drop)
            cut.lightIndices.insert(cut.lightIndices.end(), res.lightIndices.begin() + res.listOffset[l],
                                    res.lightIndices.begin() + res.listOffset[l] + res.listCount[l]);
    }
    res = cut;
    GroundTruthOptions to;
    to.imageError = false;
    r.out.truth = computeGroundTruth(r.out.depth, proj, r.out.lights, res, to);
    ASSERT_GT(r.out.truth.metrics.falseNegatives, 0u);
    // The summary reports the misses this run has, not a 0 from elsewhere.
    {
        const auto sm = nlohmann::json::parse(summaryJson(r.scene, r.settings, r.out))["metrics"];
        EXPECT_EQ(sm["false_negatives"].get<std::uint64_t>(), r.out.truth.metrics.falseNegatives);
        EXPECT_EQ(sm["shading_work"].get<std::uint64_t>(), r.out.truth.metrics.shadingWork);
        EXPECT_EQ(sm["exact_work"].get<std::uint64_t>(), r.out.truth.metrics.exactWork);
    }
    const std::vector<double> fn = tileHeat(r.out, HeatMode::FalseNegatives);
    std::uint64_t sum = 0;
    std::size_t missing = 0;
    for (std::uint32_t t = 0; t < g.tileCount(); ++t) {
        std::uint64_t want = 0;
        for (std::uint32_t k = 0; k < res.listsPerTile; ++k) want += r.out.truth.listFalseNegatives[t * res.listsPerTile + k];
        if (std::isnan(fn[t])) {
            EXPECT_EQ(want, 0u);
            continue;
        }
        EXPECT_EQ(fn[t], double(want)) << "tile " << t;
        if (t % g.tilesX >= g.tilesX / 2) EXPECT_EQ(fn[t], 0.0) << "tile " << t << " kept its lists";
        sum += std::uint64_t(fn[t]);
        missing += fn[t] > 0;
    }
    EXPECT_EQ(sum, r.out.truth.metrics.falseNegatives);
    ASSERT_GT(missing, 0u);

    TempDir tmp;
    const fs::path out = tmp.path / "miss";
    exportDiagnostics(r.scene, r.settings, r.out, out.string());
    const Png png = readPng(out / "heatmap_misses.png");
    ASSERT_EQ(png.width, 96u);
    ASSERT_GT(png.height, 64u); // the legend band below
    // The centre pixel of every tile: red (r well above g and b) iff it misses.
    for (std::uint32_t t = 0; t < g.tileCount(); ++t) {
        const auto rect = g.tileRect(t % g.tilesX, t / g.tilesX);
        const std::uint32_t x = (rect.x0 + rect.x1) / 2, y = (rect.y0 + rect.y1) / 2;
        const std::uint8_t* p = &png.rgb[(std::size_t(y) * png.width + x) * 3];
        const bool red = p[0] > p[1] + 40 && p[0] > p[2] + 40;
        EXPECT_EQ(red, !std::isnan(fn[t]) && fn[t] > 0) << "tile " << t << " rgb " << int(p[0]) << "," << int(p[1])
                                                      << "," << int(p[2]);
    }
}

// A built-in run that misses lights says which, where: summary.json's
// "missed" names each (tile, list, light, pixels, cause), as the ground
// truth counts them; a run without misses has an empty array.
TEST(Export, SummaryJsonLocatesABuiltinRunsMisses) {
    PipelineRun clean = runBuiltin("atrium", Algorithm::MinMax, 160, 96);
    const auto c = nlohmann::json::parse(summaryJson(clean.scene, clean.settings, clean.out));
    ASSERT_TRUE(c["missed"].is_array());
    EXPECT_TRUE(c["missed"].empty());
    EXPECT_EQ(c["missed_pairs"].get<std::uint64_t>(), 0u);

    PipelineRun r;
    r.scene = makeBuiltinScene("atrium");
    r.scene.camera.width = 160;
    r.scene.camera.height = 96;
    r.settings.algorithm = Algorithm::Raster;
    r.settings.proxyLevel = 0;
    r.settings.proxyOverfit = 1.0; // inscribed: misses
    auto backend = makeCpuBackend();
    r.out = runPipeline(r.scene, r.settings, *backend);
    ASSERT_GT(r.out.truth.metrics.falseNegatives, 0u);
    const auto j = nlohmann::json::parse(summaryJson(r.scene, r.settings, r.out));
    ASSERT_FALSE(j["missed"].empty());
    std::uint64_t pixels = 0;
    for (const auto& m : j["missed"]) {
        const std::uint32_t list = m["list"].get<std::uint32_t>(), light = m["light"].get<std::uint32_t>();
        EXPECT_EQ(m["cause"].get<std::string>(), "culling_test");
        EXPECT_EQ(m["tile"][0].get<std::uint32_t>() + m["tile"][1].get<std::uint32_t>() * r.out.result.grid.tilesX,
                  list);
        EXPECT_EQ(m["light_name"].get<std::string>(), r.scene.lights[light].name);
        // The list lacks the light.
        const auto* b = r.out.result.lightIndices.data() + r.out.result.listOffset[list];
        EXPECT_FALSE(std::binary_search(b, b + r.out.result.listCount[list], light));
        pixels += m["pixels"].get<std::uint64_t>();
    }
    // Every missed light-pixel, when the array holds them all.
    if (j["missed_pairs"].get<std::size_t>() == j["missed"].size())
        EXPECT_EQ(pixels, r.out.truth.metrics.falseNegatives);
}
