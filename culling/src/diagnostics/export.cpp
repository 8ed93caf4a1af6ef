// Diagnostics exporters: summary.json, tiles.csv, heatmap.png, and the atomic
// folder write that the CLI's `run --out` and the studio share. The formats are
// documented in docs/CLI.md.

#include "culling/diagnostics/export.hpp"
#include "culling/math/light_proxy.hpp"
#include "culling/scene/gltf_io.hpp"

#include "culling/custom/custom_cull.hpp"
#include "culling/core/file_io.hpp"
#include "culling/core/presets.hpp"
#include "culling/diagnostics/overlays.hpp"

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/shade.hpp"
#include "diagnostics/font5x7.hpp"

#include <nlohmann/json.hpp>
#include <png.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <set>

#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

namespace lc {

namespace fs = std::filesystem;

namespace {

// Shortest text that reads back as the same double.
std::string roundTrip(double v) {
    std::array<char, 64> buf{};
    const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), v);
    return std::string(buf.data(), r.ptr);
}

nlohmann::ordered_json msOrNull(double ms) {
    return ms >= 0 ? nlohmann::ordered_json(ms) : nlohmann::ordered_json(nullptr);
}

bool tileHasDepth(const CullResult& r, std::size_t t) {
    return t < r.tileDepthMin.size() && t < r.tileDepthMax.size() &&
           std::isfinite(r.tileDepthMin[t]) && std::isfinite(r.tileDepthMax[t]) &&
           r.tileDepthMin[t] <= r.tileDepthMax[t];
}

// ---- colour -----------------------------------------------------------------

// Viridis (matplotlib), sampled at 9 evenly spaced points, interpolated
// linearly in sRGB. Perceptually ordered: light = more lights per list.
glm::dvec3 viridis(double t) {
    static constexpr double k[9][3] = {{68, 1, 84},    {71, 44, 122},  {59, 81, 139},
                                       {44, 113, 142}, {33, 144, 141}, {39, 173, 129},
                                       {92, 200, 99},  {170, 220, 50}, {253, 231, 37}};
    t = std::clamp(std::isfinite(t) ? t : 0.0, 0.0, 1.0) * 8.0;
    const int i = std::min(int(t), 7);
    const double f = t - i;
    return glm::dvec3(k[i][0] + f * (k[i + 1][0] - k[i][0]), k[i][1] + f * (k[i + 1][1] - k[i][1]),
                      k[i][2] + f * (k[i + 1][2] - k[i][2])) / 255.0;
}

struct Canvas {
    RgbImage& img;
    void set(int x, int y, glm::dvec3 c) {
        if (x < 0 || y < 0 || x >= int(img.width) || y >= int(img.height)) return;
        std::uint8_t* p = &img.rgb[(std::size_t(y) * img.width + x) * 3];
        for (int i = 0; i < 3; ++i) p[i] = std::uint8_t(std::lround(std::clamp(c[i], 0.0, 1.0) * 255.0));
    }
    void fill(int x0, int y0, int x1, int y1, glm::dvec3 c) {
        for (int y = y0; y < y1; ++y)
            for (int x = x0; x < x1; ++x) set(x, y, c);
    }
    int textWidth(const std::string& s, int scale) const {
        return s.empty() ? 0 : int(s.size()) * detail::kGlyphAdvance * scale - scale;
    }
    void text(int x, int y, const std::string& s, int scale, glm::dvec3 c) {
        for (char ch : s) {
            const auto& g = detail::glyph5x7(ch);
            for (int r = 0; r < detail::kGlyphHeight; ++r)
                for (int b = 0; b < 5; ++b)
                    if (g.rows[r] & (0x10 >> b)) fill(x + b * scale, y + r * scale, x + (b + 1) * scale, y + (r + 1) * scale, c);
            x += detail::kGlyphAdvance * scale;
        }
    }
};

std::string fixed2(double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.2f", v);
    return buf;
}

// ---- files ------------------------------------------------------------------


// libpng reports errors by longjmp; this function holds no C++ object with a
// destructor between setjmp and the libpng calls, so the jump is safe. Returns
// an empty string on success, else libpng's message.
const char* writePngRaw(FILE* f, const RgbImage& img, png_bytep* rows, char* errBuf) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, errBuf, [](png_structp p, png_const_charp msg) {
        char* buf = static_cast<char*>(png_get_error_ptr(p));
        std::snprintf(buf, 256, "%s", msg);
        png_longjmp(p, 1);
    }, nullptr);
    if (!png) return "png_create_write_struct failed";
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        return "png_create_info_struct failed";
    }
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        return errBuf[0] ? errBuf : "libpng error";
    }
    png_init_io(png, f);
    png_set_IHDR(png, info, img.width, img.height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return nullptr;
}

} // namespace

namespace {

// What reproduces a run: the file and its version, the glTF choices that
// shaped the scene, the command, and whether it was edited since (then the
// edited scene is beside summary.json as scene.json).
nlohmann::ordered_json sceneSourceJson(const Scene& scene) {
    const SceneOrigin& o = scene.origin;
    nlohmann::ordered_json src;
    src["file"] = o.file.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.file);
    src["content_hash_fnv1a64"] =
        o.contentHash.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.contentHash);
    src["builtin"] = o.builtin.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.builtin);
    src["gltf_camera"] = o.gltfCamera.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.gltfCamera);
    src["gltf_min_intensity"] =
        o.gltfMinIntensity > 0 ? nlohmann::ordered_json(o.gltfMinIntensity) : nlohmann::ordered_json(nullptr);
    // How many lights that cut-off sized (those without a glTF range): 0
    // says the cut-off changed nothing.
    src["gltf_cutoff_lights"] = o.gltfMinIntensity > 0 ? nlohmann::ordered_json(gltfCutoffLights(scene).size())
                                                       : nlohmann::ordered_json(nullptr);
    src["command"] = o.command.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(o.command);
    src["edited"] = o.edited;
    src["edited_scene"] = o.edited ? nlohmann::ordered_json("scene.json") : nlohmann::ordered_json(nullptr);
    return src;
}

// The engine limits a run culled under, and what they took.
nlohmann::ordered_json limitsJson(const CullSettings& settings, const RunOutput& run) {
    const CullResult& r = run.result;
    const Metrics& m = run.truth.metrics;
    const ListLimits& lim = r.limits;
    nlohmann::ordered_json lj;
    lj["cap"] = settings.cap;
    lj["max_lights"] = settings.maxLights;
    lj["max_entries"] = settings.maxEntries;
    lj["overflow_policy"] = toString(settings.overflow);
    lj["limit_keep"] = toString(settings.limitKeep);
    lj["overflow_lists"] = lim.overflowLists.size();
    lj["dropped_entries"] = lim.droppedLights.size();
    lj["lights_over_limit"] = lim.lightsOverLimit;
    // The longest list the test made: the smallest cap that never overflows.
    lj["longest_list_uncapped"] = settings.hasLimits() ? lim.longestUncapped : m.maxList;
    lj["entries_uncapped"] = settings.hasLimits() ? lim.entriesUncapped : r.entries();
    nlohmann::ordered_json over = nlohmann::ordered_json::array();
    for (std::size_t k = 0; k < lim.overflowLists.size() && k < 1000; ++k) {
        const std::uint32_t l = lim.overflowLists[k];
        const std::uint32_t t = r.tileOfList(l);
        nlohmann::ordered_json e;
        e["list"] = l;
        e["tile"] = {t % std::max(r.grid.tilesX, 1u), t / std::max(r.grid.tilesX, 1u)};
        e["kept"] = r.listCount[l];
        e["dropped"] = lim.droppedOffset[k + 1] - lim.droppedOffset[k];
        over.push_back(std::move(e));
    }
    lj["overflowed"] = std::move(over);
    return lj;
}

// docs/CUSTOM_CULLING.md: what a user's culling did beside its lists.
// Every false negative located: tile, list, light and the pixels that
// needed it (the first 1,000, cause by cause and most pixels first within
// a cause; the total is in metrics), as
// "missed", "missed_pairs" and "missed_pairs_by_cause" of `j`.
void addMissed(nlohmann::ordered_json& j, const Scene& scene, const RunOutput& run) {
    const TileGrid& grid = run.result.grid;
    const Projection proj(scene.camera);
    nlohmann::ordered_json missed = nlohmann::ordered_json::array();
    const std::vector<MissedLight> located = locateFalseNegatives(run, proj);
    nlohmann::ordered_json byCause;
    for (MissCause c : {MissCause::CullingTest, MissCause::ListFull, MissCause::LightLimit, MissCause::InvalidIndex})
        byCause[jsonName(c)] = std::count_if(located.begin(), located.end(),
                                             [&](const MissedLight& m) { return m.cause == c; });
    for (std::size_t i = 0; i < located.size() && i < 1000; ++i) {
        const MissedLight& ml = located[i];
        nlohmann::ordered_json e;
        e["tile"] = {ml.tile % grid.tilesX, ml.tile / grid.tilesX};
        e["list"] = ml.list;
        // The list within its tile (halfz's half, a cluster's slice), as
        // explain's --cell takes it; null where a tile has one list.
        const int cell = run.result.cellOfList(ml.list);
        e["cell"] = cell >= 0 ? nlohmann::ordered_json(cell) : nlohmann::ordered_json(nullptr);
        e["light"] = ml.light;
        e["light_name"] = ml.light < scene.lights.size() ? scene.lights[ml.light].name : std::string();
        e["pixels"] = ml.pixels;
        e["cause"] = jsonName(ml.cause);
        missed.push_back(std::move(e));
    }
    j["missed"] = std::move(missed);
    j["missed_pairs"] = located.size();
    j["missed_pairs_by_cause"] = std::move(byCause);
}

nlohmann::ordered_json customJson(const Scene& scene, const RunOutput& run) {
    const CustomCullReport& c = *run.custom;
    nlohmann::ordered_json cj;
    cj["source"] = c.source;
    cj["layout"] = c.layout;
    cj["lists"] = c.lists;
    cj["pass_ms"] = c.passMs >= 0 ? nlohmann::ordered_json(c.passMs) : nlohmann::ordered_json(nullptr);
    cj["overflow_lists"] = c.overflowLists;
    cj["overflow_entries"] = c.overflowEntries;
    cj["invalid_indices"] = c.invalidIndices;
    cj["duplicate_indices"] = c.duplicateIndices;
    // Where: the lists (and their tiles) that overflowed, held an index past
    // the light count or a light twice, the first 1,000 of each.
    const auto where = [&](const std::vector<std::uint32_t>& lists) {
        nlohmann::ordered_json a = nlohmann::ordered_json::array();
        for (std::size_t k = 0; k < lists.size() && k < 1000; ++k) {
            const std::uint32_t t = run.result.tileOfList(lists[k]);
            const std::uint32_t tilesX = std::max(run.result.grid.tilesX, 1u);
            a.push_back({{"list", lists[k]}, {"tile_x", t % tilesX}, {"tile_y", t / tilesX}});
        }
        return a;
    };
    cj["overflowed_lists"] = where(c.overflowedListIds);
    cj["invalid_index_lists"] = where(c.invalidIndexListIds);
    cj["duplicate_index_lists"] = where(c.duplicateIndexListIds);
    cj["validation_messages"] = c.validationMessages;
    cj["warnings"] = c.warnings;
    cj["builtin_algorithm"] = c.builtinAlgorithm;
    cj["builtin_entries"] = c.builtinEntries;
    cj["lists_differing_from_builtin"] = c.listsDifferingFromBuiltin;
    addMissed(cj, scene, run);
    return cj;
}

} // namespace

std::string summaryJson(const Scene& scene, const CullSettings& settings, const RunOutput& run) {
    const CullResult& r = run.result;
    const Metrics& m = run.truth.metrics;
    nlohmann::ordered_json j;
    j["scene"] = scene.name;
    j["scene_source"] = sceneSourceJson(scene);
    j["algorithm"] = run.custom ? std::string("custom") : std::string(toString(settings.algorithm));
    j["test"] = toString(settings.test);
    j["backend"] = r.backend;
    j["device"] = r.device;
    j["timing_method"] = r.timingMethod;
    j["width"] = r.grid.width;
    j["height"] = r.grid.height;
    j["tile_size"] = r.grid.tileSize;
    j["tiles_x"] = r.grid.tilesX;
    j["tiles_y"] = r.grid.tilesY;
    j["cells"] = settings.cells;
    j["slicing"] = toString(settings.slicing);
    j["skip_empty"] = settings.skipEmpty;
    j["spot_test"] = toString(settings.spotTest);
    j["bins"] = settings.bins;
    // raster: the proxies and how their coverage was made.
    if (!run.custom && settings.algorithm == Algorithm::Raster) {
        nlohmann::ordered_json p;
        p["level"] = settings.proxyLevel;
        p["triangles"] = unitIcosphere(settings.proxyLevel).triangles.size();
        p["segments"] = settings.proxySegments;
        p["cone_angle_deg"] = settings.proxyConeAngle;
        p["overfit"] = settings.proxyOverfit > 0 ? nlohmann::ordered_json(settings.proxyOverfit)
                                                 : nlohmann::ordered_json("auto");
        p["sphere_overfit_applied"] = settings.proxyOverfit > 0 ? settings.proxyOverfit
                                                                : icosphereEnclosingOverfit(settings.proxyLevel);
        p["cone_overfit_applied"] = settings.proxyOverfit > 0 ? settings.proxyOverfit
                                                              : coneEnclosingOverfit(settings.proxySegments);
        p["conservative"] = settings.conservative;
        p["depth"] = settings.proxySlices ? "slices" : "tile";
        p["coverage"] = r.coverage;
        j["proxy"] = p;
    }
    // Lists from a custom shader or an engine's dump were made by none of
    // the built-in settings: they are not reported as if they were.
    if (run.custom)
        for (const char* k : {"test", "cells", "slicing", "skip_empty", "spot_test", "bins"}) j[k] = nullptr;
    // The engine preset these settings are (docs/ENGINES.md), null when they
    // equal none (none was picked, or a parameter was changed after it).
    const EnginePreset* preset = run.custom ? nullptr : presetMatching(settings, scene.camera, scene.lights.size());
    j["preset"] = preset ? nlohmann::ordered_json(preset->name) : nlohmann::ordered_json(nullptr);
    j["lights"] = run.lights.size();
    std::size_t spots = 0;
    for (std::size_t i = 0; i < run.lights.size(); ++i) spots += run.lights.isSpot(i);
    j["spot_lights"] = spots;
    // A run on a depth image it was given (an engine's, or the previous run's
    // for a Live light edit) ran no pre-pass: no depth time, no triangles.
    j["timings_ms"] = {{"depth", msOrNull(run.depthReused ? -1.0 : r.timings.depthMs)},
                       {"cull", msOrNull(r.timings.cullMs)},
                       {"ground_truth", msOrNull(r.timings.groundTruthMs)},
                       {"shade", msOrNull(r.timings.shadeMs)}};
    if (run.depthFrom.empty())
        j["depth_source"] = run.depthReused ? "given" : "pre-pass on " + r.backend;
    else
        j["depth_source"] = run.depthFrom;
    if (run.depthReused)
        j["depth_triangles"] = nullptr;
    else
        j["depth_triangles"] = {{"scene", r.depthTriangles}, {"drawn", r.depthTrianglesDrawn}};
    nlohmann::ordered_json mj;
    mj["false_negatives"] = m.falseNegatives;
    // By cause (docs/ALGORITHMS.md, "Caps and limits"): the engine limits'
    // drops apart from the culling test's own misses. A custom culling's
    // over-full lists are counted by pairs in custom.missed_pairs_by_cause.
    mj["false_negatives_by_cause"] = {{"culling_test", m.falseNegativesCullingTest()},
                                      {"list_full", m.falseNegativesListFull},
                                      {"light_limit", m.falseNegativesLightLimit}};
    mj["shading_work"] = m.shadingWork;
    mj["exact_work"] = m.exactWork;
    mj["efficiency"] = m.efficiency;
    mj["optimal_work"] = m.optimalWork;
    mj["efficiency_vs_optimal"] = m.efficiencyVsOptimal;
    mj["mean_list"] = m.meanList;
    mj["max_list"] = m.maxList;
    mj["result_bytes"] = m.resultBytes;
    mj["list_entries"] = r.entries();
    mj["lists"] = r.listCountTotal();
    mj["geometry_pixels"] = m.geometryPixels;
    mj["image_rmse"] = m.imageErrorComputed ? nlohmann::ordered_json(m.imageRmse) : nlohmann::ordered_json(nullptr);
    mj["image_max_error"] =
        m.imageErrorComputed ? nlohmann::ordered_json(m.imageMaxError) : nlohmann::ordered_json(nullptr);
    j["metrics"] = mj;
    // Which lights were missed where (a custom run has them under "custom").
    if (!run.custom && run.truthComputed) addMissed(j, scene, run);
    if (!run.custom) j["limits"] = limitsJson(settings, run);
    if (run.custom) j["custom"] = customJson(scene, run);
    return j.dump(2) + "\n";
}

std::string tilesCsv(const RunOutput& run) {
    const CullResult& r = run.result;
    std::string out = "tile_x,tile_y,cell,view_depth_min,view_depth_max,cell_mask,count,false_negatives,"
                      "fn_list_full,fn_light_limit,overflow,dropped,lights\n";
    const GroundTruth& gt = run.truth;
    const bool truth = run.truthComputed && gt.listFalseNegatives.size() == r.listCount.size();
    const std::size_t lists = r.listCount.size();
    const std::uint32_t per = std::max(r.listsPerTile, 1u);
    for (std::size_t l = 0; l < lists; ++l) {
        std::string row;
        if (r.algorithm == Algorithm::All) {
            // The one list of `all` belongs to no tile: tile -1,-1, no depth range.
            row = "-1,-1,0,,,0,";
        } else {
            const std::size_t t = r.tileOfList(std::uint32_t(l));
            const std::uint32_t sub = std::uint32_t(l % per);
            const std::uint32_t tx = r.grid.tilesX ? std::uint32_t(t % r.grid.tilesX) : 0;
            const std::uint32_t ty = r.grid.tilesX ? std::uint32_t(t / r.grid.tilesX) : 0;
            row = std::to_string(tx) + "," + std::to_string(ty) + "," + std::to_string(sub) + ",";
            if (tileHasDepth(r, t)) {
                // The view-depth interval the list serves: the tile's geometry
                // bounds; halfz halves at the split; clustered: its slice.
                double lo = r.tileDepthMin[t], hi = r.tileDepthMax[t];
                if (r.algorithm == Algorithm::HalfZ && t < r.halfzSplit.size())
                    (sub == 0 ? hi : lo) = r.halfzSplit[t];
                else if (r.layout() == Algorithm::Clustered) {
                    lo = sliceBoundary(r.settings.slicing, r.clusterNear, r.clusterFar, per, sub);
                    hi = sliceBoundary(r.settings.slicing, r.clusterNear, r.clusterFar, per, sub + 1);
                }
                row += roundTrip(lo) + "," + roundTrip(hi) + ",";
            } else {
                row += ",,";
            }
            row += std::to_string(t < r.cellMask.size() ? r.cellMask[t] : 0u) + ",";
        }
        const std::uint32_t off = r.listOffset[l], cnt = r.listCount[l];
        row += std::to_string(cnt) + ",";
        // Misses by cause (empty without ground truth), then the engine
        // limits: whether the list was over-full and how many lights it lost.
        if (truth)
            row += std::to_string(gt.listFalseNegatives[l]) + "," + std::to_string(gt.listFalseNegativesListFull[l]) +
                   "," + std::to_string(gt.listFalseNegativesLightLimit[l]) + ",";
        else
            row += ",,,";
        const auto [d0, d1] = r.limits.droppedFrom(std::uint32_t(l));
        // A custom shader's list over its layout's capacity is over-full too
        // (which lights it lost is not known: dropped stays 0).
        const bool over = r.limits.overflowIndex(std::uint32_t(l)) >= 0 ||
                          (run.custom && std::binary_search(run.custom->overflowedListIds.begin(),
                                                            run.custom->overflowedListIds.end(), std::uint32_t(l)));
        row += std::string(over ? "1," : "0,") + std::to_string(d1 - d0) + ",";
        for (std::uint32_t k = 0; k < cnt; ++k) {
            if (k) row += ' ';
            row += std::to_string(r.lightIndices[off + k]);
        }
        out += row;
        out += '\n';
    }
    return out;
}

namespace {
// Per pixel a grey from depth, near bright, histogram-equalised: 1 - (the
// fraction of geometry pixels nearer than it), mapped to [0.3, 1]; background
// 0.12. Window depth is monotonic in view depth for every projection kind, so
// this needs no linearisation, and perspective depth (bunched near 1) still
// shows detail.
std::vector<double> depthGrey(const DepthImage& depth) {
    const bool reversed = depth.clearDepth == 0.0f; // reversed-Z: larger is nearer
    std::vector<float> sorted;
    sorted.reserve(depth.depth.size());
    for (float d : depth.depth)
        if (d != depth.clearDepth) sorted.push_back(reversed ? -d : d);
    std::sort(sorted.begin(), sorted.end());
    std::vector<double> grey(std::size_t(depth.width) * depth.height, 0.12);
    for (std::uint32_t y = 0; y < depth.height; ++y)
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            if (!depth.hasGeometry(x, y)) continue;
            const float key = reversed ? -depth.at(x, y) : depth.at(x, y);
            const double rank = double(std::lower_bound(sorted.begin(), sorted.end(), key) - sorted.begin());
            const double farness = sorted.size() > 1 ? rank / double(sorted.size() - 1) : 0.0;
            grey[std::size_t(y) * depth.width + x] = 0.3 + 0.7 * (1.0 - farness);
        }
    return grey;
}

// The heat map pictures' common part: each pixel `shade(tile, grey)` (the
// pixel's tile, 0 without a grid, and its depthGrey), a faint tile grid over
// it, and a dark band of `legendH` rows under the image for the legend.
template <class Shade>
RgbImage tintedTiles(const RunOutput& run, int legendH, Shade shade) {
    const DepthImage& depth = run.depth;
    const CullResult& r = run.result;
    const std::uint32_t W = depth.width, H = depth.height;
    RgbImage img;
    img.width = W;
    img.height = H + std::uint32_t(legendH);
    img.rgb.assign(std::size_t(img.width) * img.height * 3, 0);
    Canvas cv{img};
    const std::vector<double> grey = depthGrey(depth);
    const std::uint32_t ts = std::max(r.grid.tileSize, 1u);
    const bool tiled = r.grid.tileCount() > 0;
    for (std::uint32_t y = 0; y < H; ++y)
        for (std::uint32_t x = 0; x < W; ++x) {
            const std::size_t t = tiled ? r.grid.tileOfPixel(x, y) : 0;
            glm::dvec3 c = shade(t, grey[std::size_t(y) * W + x]);
            if (x % ts == 0 || y % ts == 0) c = c * 0.8 + glm::dvec3(0.2); // faint tile grid
            cv.set(int(x), int(y), c);
        }
    cv.fill(0, int(H), int(W), int(H) + legendH, glm::dvec3(0.1));
    return img;
}

// Per tile: 1 when one of its lists was over-full under the engine limits.
std::vector<char> tilesOverflowing(const CullResult& r) {
    std::vector<char> over(std::max<std::size_t>(r.grid.tileCount(), 1), 0);
    for (std::uint32_t l : r.limits.overflowLists) {
        const std::uint32_t t = r.tileOfList(l);
        if (r.algorithm == Algorithm::All) std::fill(over.begin(), over.end(), 1);
        else if (t < over.size()) over[t] = 1;
    }
    return over;
}

// The colour that marks over-full lists (the heat map's frames, the misses a
// cap or record buffer caused) and the light limit's misses, everywhere.
const glm::dvec3 kOverflowColour(1.0, 0.55, 0.0);
const glm::dvec3 kLightLimitColour(0.75, 0.3, 1.0);

// A frame `width` pixels wide inside each flagged tile.
void frameTiles(Canvas& cv, const TileGrid& g, const std::vector<char>& flagged, int width, glm::dvec3 c) {
    for (std::uint32_t t = 0; t < g.tileCount() && t < flagged.size(); ++t) {
        if (!flagged[t]) continue;
        const TileGrid::Rect rc = g.tileRect(t % g.tilesX, t / g.tilesX);
        const int x0 = int(rc.x0), y0 = int(rc.y0), x1 = int(rc.x1), y1 = int(rc.y1);
        cv.fill(x0, y0, x1, std::min(y1, y0 + width), c);
        cv.fill(x0, std::max(y0, y1 - width), x1, y1, c);
        cv.fill(x0, y0, std::min(x1, x0 + width), y1, c);
        cv.fill(std::max(x0, x1 - width), y0, x1, y1, c);
    }
}

} // namespace

RgbImage heatmapImage(const RunOutput& run) {
    const DepthImage& depth = run.depth;
    const CullResult& r = run.result;
    const std::uint32_t W = depth.width, H = depth.height;
    const int scale = std::max(1, int(W) / 480);
    const bool overflow = !r.limits.overflowLists.empty();
    const int legendH = scale * (overflow ? 39 : 29);

    // List-length range over all lists, for the colour scale.
    std::uint32_t minList = std::numeric_limits<std::uint32_t>::max(), maxList = 0;
    for (std::uint32_t c : r.listCount) minList = std::min(minList, c), maxList = std::max(maxList, c);
    if (r.listCount.empty()) minList = 0;
    // The legend's mean in the tint's unit: the list length a geometry pixel
    // loops over, on average (shading work / geometry pixels). The mean over
    // lists would count clustered's many empty froxels and read 20x lower
    // than the colours around it. Without ground truth, the mean over lists.
    const Metrics& gm = run.truth.metrics;
    const bool perPixel = run.truthComputed && gm.geometryPixels > 0;
    const double mean = perPixel ? double(gm.shadingWork) / double(gm.geometryPixels)
                        : r.listCount.empty() ? 0.0
                                              : double(r.entries()) / double(r.listCount.size());
    auto colourOf = [&](double count) {
        return viridis(maxList > minList ? (count - minList) / double(maxList - minList) : 0.0);
    };

    // Per tile, the list length its pixels loop over: for one list per tile
    // the list's count; with several (halfz, clustered) the mean over the
    // tile's geometry pixels, from the ground truth's per-list shading work
    // (sum of |listed| over the pixels using the list). Tiles without geometry
    // (or without ground truth) show their longest list.
    const std::uint32_t per = std::max(r.listsPerTile, 1u);
    const std::size_t tiles = r.grid.tileCount();
    std::vector<double> tileValue(std::max<std::size_t>(tiles, 1), 0.0);
    const GroundTruth& gt = run.truth;
    for (std::size_t t = 0; t < tileValue.size(); ++t) {
        if (r.algorithm == Algorithm::All) {
            tileValue[t] = r.listCount.empty() ? 0 : r.listCount[0];
            continue;
        }
        std::uint32_t longest = 0;
        std::uint64_t work = 0;
        for (std::uint32_t s = 0; s < per && t * per + s < r.listCount.size(); ++s) {
            longest = std::max(longest, r.listCount[t * per + s]);
            if (t * per + s < gt.listShadingWork.size()) work += gt.listShadingWork[t * per + s];
        }
        const std::uint32_t px = t < gt.tileGeometryPixels.size() ? gt.tileGeometryPixels[t] : 0;
        tileValue[t] = px ? double(work) / px : longest;
    }

    RgbImage img = tintedTiles(run, legendH, [&](std::size_t t, double grey) {
        return colourOf(t < tileValue.size() ? tileValue[t] : 0.0) * grey;
    });
    Canvas cv{img};

    // Legend band: colour bar from the shortest to the longest list, a white
    // tick above it at the mean, and the three numbers.
    const int y0 = int(H), m = 4 * scale;
    const int bx0 = int(W) > 2 * m + 1 ? m : 0, bx1 = int(W) > 2 * m + 1 ? int(W) - m : int(W);
    for (int x = bx0; x < bx1; ++x) {
        const double t = bx1 - bx0 > 1 ? double(x - bx0) / double(bx1 - bx0 - 1) : 0.0;
        cv.fill(x, y0 + m, x + 1, y0 + m + 10 * scale, viridis(t));
    }
    if (maxList > minList) {
        const int mx = bx0 + int(std::lround((mean - minList) / double(maxList - minList) * (bx1 - bx0 - 1)));
        // Above the bar only, so that the bar itself stays a clean scale.
        cv.fill(mx - scale, y0 + scale, mx + scale, y0 + m, glm::dvec3(1.0));
    }
    const int ty = y0 + m + 10 * scale + 3 * scale;
    const std::string left = "MIN " + std::to_string(minList);
    const std::string right = "MAX " + std::to_string(maxList);
    const std::string centre = "MEAN " + fixed2(mean) + (perPixel ? " LIGHTS/PIXEL" : " LIGHTS/LIST");
    cv.text(bx0, ty, left, scale, glm::dvec3(1.0));
    cv.text(bx1 - cv.textWidth(right, scale), ty, right, scale, glm::dvec3(1.0));
    const int cw = cv.textWidth(centre, scale);
    const int cx = (int(W) - cw) / 2;
    // Only when it fits between the other two labels.
    if (cx > bx0 + cv.textWidth(left, scale) + 2 * scale &&
        cx + cw < bx1 - cv.textWidth(right, scale) - 2 * scale)
        cv.text(cx, ty, centre, scale, glm::dvec3(1.0));
    if (overflow) {
        // Over-full lists (engine limits): an orange frame in their tiles,
        // lined in black inside so that it reads on viridis's yellow too.
        const std::vector<char> over = tilesOverflowing(r);
        frameTiles(cv, r.grid, over, 2 * scale, glm::dvec3(0.0));
        frameTiles(cv, r.grid, over, scale, kOverflowColour);
        std::uint64_t tilesOver = 0;
        for (char f : over) tilesOver += f;
        const std::string lists = std::to_string(r.limits.overflowLists.size()),
                          dropped = std::to_string(r.limits.droppedLights.size());
        // The longest wording that fits the image's width.
        for (const std::string& t : {"OVER-FULL LISTS " + lists + " IN " + std::to_string(tilesOver) + " TILES, " +
                                         dropped + " ENTRIES DROPPED",
                                     "OVER-FULL " + lists + ", DROPPED " + dropped, "OVER-FULL " + lists,
                                     "FULL " + lists})
            if (cv.textWidth(t, scale) <= bx1 - bx0 || t.rfind("FULL ", 0) == 0) {
                cv.text(bx0, ty + 10 * scale, t, scale, kOverflowColour);
                break;
            }
    }
    return img;
}

RgbImage missHeatmapImage(const RunOutput& run) {
    const std::uint32_t W = run.depth.width, H = run.depth.height;
    const int scale = std::max(1, int(W) / 480);
    const Metrics& split = run.truth.metrics;
    const int legendH = scale * (split.falseNegativesListFull || split.falseNegativesLightLimit ? 26 : 16);
    const std::vector<double> fn = tileHeat(run, HeatMode::FalseNegatives);
    double most = 0;
    std::size_t tilesMissing = 0;
    for (double v : fn)
        if (v > 0) most = std::max(most, v), ++tilesMissing;
    // Grey depth; a tile with misses red, brighter with more (log scale, so
    // that a tile missing one light at a few pixels still stands out).
    // The cause of most of a tile's misses picks its hue: red for the
    // culling test, orange for a list the engine limits left full, violet
    // for lights past the light limit.
    const CullResult& r = run.result;
    const GroundTruth& gt = run.truth;
    const bool byCause = gt.listFalseNegativesListFull.size() == r.listCount.size() && r.algorithm != Algorithm::All;
    auto hueOf = [&](std::size_t t) {
        if (!byCause) return glm::dvec3(1.0, 0.08, 0.08);
        std::uint64_t all = 0, full = 0, limit = 0;
        const auto [first, count] = r.tileLists(std::uint32_t(t));
        for (std::uint32_t l = first; l < first + count; ++l)
            all += gt.listFalseNegatives[l], full += gt.listFalseNegativesListFull[l],
                limit += gt.listFalseNegativesLightLimit[l];
        const std::uint64_t test = all - full - limit;
        if (full > test && full >= limit) return kOverflowColour;
        if (limit > test && limit > full) return kLightLimitColour;
        return glm::dvec3(1.0, 0.08, 0.08);
    };
    RgbImage img = tintedTiles(run, legendH, [&](std::size_t t, double g) {
        const double v = t < fn.size() && fn[t] > 0 ? fn[t] : 0.0;
        if (!(v > 0)) return glm::dvec3(g * 0.6);
        const double k = most > 1 ? 0.45 + 0.55 * std::log(v) / std::log(most) : 1.0;
        return hueOf(t) * (0.35 + 0.65 * k) * (0.55 + 0.45 * g);
    });
    Canvas cv{img};
    const int y0 = int(H), m = 4 * scale;
    const std::string text =
        !run.truthComputed ? "NO GROUND TRUTH: MISSES NOT COUNTED"
        : tilesMissing == 0
            ? "NO FALSE NEGATIVES"
            : "FALSE NEGATIVES " + std::to_string(run.truth.metrics.falseNegatives) + " IN " +
                  std::to_string(tilesMissing) + " TILES, MOST " + std::to_string(std::uint64_t(most)) + " IN ONE";
    // A narrow image (a hunt's shrunk repro) gets the short form.
    const std::string shortText = "FN " + std::to_string(run.truth.metrics.falseNegatives) + " IN " +
                                  std::to_string(tilesMissing) + " TILES";
    cv.text(m, y0 + m, tilesMissing && cv.textWidth(text, scale) > int(W) - 2 * m ? shortText : text, scale,
            tilesMissing ? glm::dvec3(1.0, 0.45, 0.45) : glm::dvec3(1.0));
    const Metrics& mt = run.truth.metrics;
    if (tilesMissing && (mt.falseNegativesListFull || mt.falseNegativesLightLimit)) {
        // The split, each in its own colour, on a second line: long labels
        // where they fit, else short ones.
        const std::string t = std::to_string(mt.falseNegativesCullingTest()),
                          f = std::to_string(mt.falseNegativesListFull), l = std::to_string(mt.falseNegativesLightLimit);
        const bool roomy = cv.textWidth("TEST " + t + "   LIST FULL " + f + "   LIGHT LIMIT " + l, scale) <= int(W) - 2 * m;
        int x = m;
        const auto part = [&](const std::string& s, glm::dvec3 c) {
            cv.text(x, y0 + m + 10 * scale, s, scale, c);
            x += cv.textWidth(s + "   ", scale) + scale; // three spaces between the parts
        };
        part((roomy ? "TEST " : "T ") + t, glm::dvec3(1.0, 0.45, 0.45));
        part((roomy ? "LIST FULL " : "F ") + f, kOverflowColour);
        part((roomy ? "LIGHT LIMIT " : "L ") + l, kLightLimitColour);
    }
    return img;
}

void writePng(const RgbImage& img, const std::string& path) {
    if (img.width == 0 || img.height == 0 || img.rgb.size() != std::size_t(img.width) * img.height * 3)
        throw Error("cannot write " + path + ": image is empty or its size is inconsistent");
    std::vector<png_bytep> rows(img.height);
    for (std::uint32_t y = 0; y < img.height; ++y)
        rows[y] = const_cast<png_bytep>(&img.rgb[std::size_t(y) * img.width * 3]);
    FILE* f = std::fopen(path.c_str(), "wb");
    if (!f) throw Error("cannot create " + path + ": " + std::strerror(errno));
    char errBuf[256] = {0};
    const char* err = writePngRaw(f, img, rows.data(), errBuf);
    const std::string message = err ? err : "";
    const bool flushed = std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
    const int closeErr = std::fclose(f);
    if (err || !flushed || closeErr != 0) {
        std::remove(path.c_str());
        throw Error("cannot write " + path + ": " + (err ? message : std::string(std::strerror(errno))));
    }
}

ShadedPictures shadedPictures(const RunOutput& run) {
    const DepthImage& d = run.depth;
    const std::size_t n = std::size_t(d.width) * d.height * 3;
    if (run.shadedCulled.size() != n || run.shadedAll.size() != n)
        throw Error("cannot write the shaded images: they do not match the " + std::to_string(d.width) + "x" +
                    std::to_string(d.height) + " depth image");
    // One exposure for both shaded images so they compare by eye; the
    // difference is scaled so that the largest error is white.
    ShadedPictures p;
    p.exposure = exposureFor(d, run.shadedAll);
    p.error = compareShadedImages(d, run.shadedCulled, run.shadedAll);
    p.culled = {d.width, d.height, shadedPicture(run.shadedCulled, p.exposure)};
    p.all = {d.width, d.height, shadedPicture(run.shadedAll, p.exposure)};
    p.difference = {d.width, d.height, differencePicture(run.shadedCulled, run.shadedAll, p.error.maxAbs)};
    return p;
}

void writeShadedImages(const RunOutput& run, const std::string& dir) {
    const ShadedPictures p = shadedPictures(run);
    const fs::path base(dir);
    writePng(p.culled, (base / "shaded_culled.png").string());
    writePng(p.all, (base / "shaded_all.png").string());
    writePng(p.difference, (base / "shaded_diff.png").string());
}

namespace {
// What an export folder may hold: an older export is replaced, anything else
// is refused (writeFolderAtomic).
const std::set<std::string>& diagnosticsOutputs() {
    static const std::set<std::string> k = {"summary.json", "tiles.csv", "heatmap.png", "heatmap_misses.png",
                                            "overlays.vtm", "overlays", kExportViewImages[0],
                                            kExportViewImages[1],
                                            // writeShadedImages
                                            "shaded_culled.png", "shaded_all.png", "shaded_diff.png",
                                            // the edited scene (SceneOrigin::edited)
                                            "scene.json"};
    return k;
}
} // namespace

void checkDiagnosticsFolder(const std::string& dir) {
    checkFolderTarget(dir, diagnosticsOutputs(), "export diagnostics", "diagnostics output");
}

void exportDiagnostics(const Scene& scene, const CullSettings& settings, const RunOutput& run,
                       const std::string& dir, const std::vector<NamedImage>& viewImages) {
    for (const NamedImage& v : viewImages)
        if (std::find(std::begin(kExportViewImages), std::end(kExportViewImages), v.fileName) ==
            std::end(kExportViewImages))
            throw Error("cannot export diagnostics image '" + v.fileName + "': not a view image name");
    writeFolderAtomic(dir, diagnosticsOutputs(), "export diagnostics", "diagnostics output", [&](const std::string& out) {
        const fs::path tmp = out;
        writeFileSynced((tmp / "summary.json").string(), summaryJson(scene, settings, run));
        // Mesh paths relative to `dir`, where it will live (a sibling of tmp).
        if (scene.origin.edited) writeFileSynced((tmp / "scene.json").string(), serializeScene(scene, dir));
        writeFileSynced((tmp / "tiles.csv").string(), tilesCsv(run));
        writePng(heatmapImage(run), (tmp / "heatmap.png").string());
        writePng(missHeatmapImage(run), (tmp / "heatmap_misses.png").string());
        if (!run.shadedAll.empty()) writeShadedImages(run, tmp.string());
        writeOverlaysVtm(scene, run, tmp.string());
        for (const NamedImage& v : viewImages) writePng(v.image, (tmp / v.fileName).string());
    });
}

} // namespace lc
