// Ground truth and error metrics (DESIGN.md, "Ground truth and the error
// metrics"). Everything here works in view space: right-handed, Y up, camera
// looking down -Z, view depth = -z_view.
//
// Cost: the needed-light pass visits every geometry pixel once and tests only
// the lights binned in its cell of a uniform 3D grid (light_grid.hpp), so it
// grows with pixels x (lights per cell), not pixels x lights. The Lambert image
// error is pixels x lights by definition (the "all lights" image): about 20
// float operations per pixel-light pair, vectorised over pixels, over row
// bands on every core. At 1920x1080 with 4096 lights that is ~8.5e9 pairs,
// a few seconds on two cores; GroundTruthOptions::imageError = false skips it.

#include "culling/truth/ground_truth.hpp"

#include "culling/core/errors.hpp"
#include "culling/truth/shade.hpp"
#include "truth/light_grid.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
#include <optional>
#include <thread>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace lc {

namespace {

unsigned workerCount() {
    const unsigned hw = std::thread::hardware_concurrency();
    return std::clamp(hw == 0 ? 2u : hw, 1u, 16u);
}

bool isCancelled(const CancelToken* cancel) {
    return cancel && cancel->cancelled.load(std::memory_order_relaxed);
}

// Runs fn(worker, y0, y1) over row bands of `bandRows` rows on every worker
// thread; bands are handed out in order through an atomic counter. Cancellation
// is checked between bands; the first exception of any worker is rethrown here.
template <class Fn>
void forEachRowBand(std::uint32_t height, std::uint32_t bandRows, unsigned workers,
                    const CancelToken* cancel, Fn&& fn) {
    bandRows = std::max(bandRows, 1u);
    const std::uint32_t bands = (height + bandRows - 1) / bandRows;
    workers = std::max(1u, std::min<unsigned>(workers, std::max(bands, 1u)));
    std::atomic<std::uint32_t> next{0};
    std::atomic<bool> stop{false};
    std::exception_ptr error;
    std::mutex errorMutex;
    auto body = [&](unsigned w) {
        try {
            for (;;) {
                if (stop.load(std::memory_order_relaxed) || isCancelled(cancel)) return;
                const std::uint32_t b = next.fetch_add(1);
                if (b >= bands) return;
                const std::uint32_t y0 = b * bandRows;
                fn(w, y0, std::min(height, y0 + bandRows));
            }
        } catch (...) {
            std::lock_guard<std::mutex> lock(errorMutex);
            if (!error) error = std::current_exception();
            stop = true;
        }
    };
    std::vector<std::thread> threads;
    for (unsigned w = 1; w < workers; ++w) threads.emplace_back(body, w);
    body(0);
    for (auto& t : threads) t.join();
    if (error) std::rethrow_exception(error);
    if (isCancelled(cancel)) throw Cancelled();
}

void checkInputs(const DepthImage& depth, const Projection& proj) {
    if (depth.depth.size() != std::size_t(depth.width) * depth.height)
        throw Error("ground truth: depth image holds " + std::to_string(depth.depth.size()) +
                    " values, expected " + std::to_string(depth.width) + "x" +
                    std::to_string(depth.height));
    if (depth.width != proj.width() || depth.height != proj.height())
        throw Error("ground truth: depth image is " + std::to_string(depth.width) + "x" +
                    std::to_string(depth.height) + " but the camera is " +
                    std::to_string(proj.width()) + "x" + std::to_string(proj.height()));
}

// View-space bounds of every geometry pixel's reconstructed position.
// Returns false when no pixel holds geometry.
bool geometryBounds(const DepthImage& depth, const Projection& proj, unsigned workers,
                    const CancelToken* cancel, glm::dvec3& bmin, glm::dvec3& bmax) {
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<glm::dvec3> lo(workers, glm::dvec3(inf)), hi(workers, glm::dvec3(-inf));
    forEachRowBand(depth.height, 32, workers, cancel, [&](unsigned w, std::uint32_t y0, std::uint32_t y1) {
        for (std::uint32_t y = y0; y < y1; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
                lo[w] = glm::min(lo[w], p);
                hi[w] = glm::max(hi[w], p);
            }
    });
    bmin = glm::dvec3(inf);
    bmax = glm::dvec3(-inf);
    for (unsigned w = 0; w < workers; ++w) {
        bmin = glm::min(bmin, lo[w]);
        bmax = glm::max(bmax, hi[w]);
    }
    return bmin.x <= bmax.x;
}

} // namespace

namespace {

// zbin: a pixel loops over its tile's mask within its bin's range, so it is
// judged through the per-(tile, bin) lists, then folded back to the tiles.
GroundTruth zbinTruth(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                      const CullResult& result, const GroundTruthOptions& opt, const CancelToken* cancel) {
    const CullResult perPixel = zbinPixelLists(result, depth, proj);
    GroundTruth sub = computeGroundTruth(depth, proj, lights, perPixel, opt, cancel);
    std::vector<std::uint32_t> tileOf(perPixel.listCount.size(), 0);
    for (std::uint32_t y = 0; y < depth.height; ++y)
        for (std::uint32_t x = 0; x < depth.width; ++x)
            if (const std::uint32_t l = perPixel.pixelList[std::size_t(y) * depth.width + x]; l != 0xffffffffu)
                tileOf[l] = result.grid.tileOfPixel(x, y);
    GroundTruth gt;
    gt.metrics = sub.metrics;
    gt.tileGeometryPixels = std::move(sub.tileGeometryPixels);
    const std::size_t lists = result.listCount.size();
    gt.listShadingWork.assign(lists, 0);
    gt.listExactWork.assign(lists, 0);
    gt.listFalseNegatives.assign(lists, 0);
    gt.listFalseNegativesListFull.assign(lists, 0);
    gt.listFalseNegativesLightLimit.assign(lists, 0);
    for (std::size_t l = 0; l < tileOf.size(); ++l) {
        gt.listShadingWork[tileOf[l]] += sub.listShadingWork[l];
        gt.listExactWork[tileOf[l]] += sub.listExactWork[l];
        gt.listFalseNegatives[tileOf[l]] += sub.listFalseNegatives[l];
        gt.listFalseNegativesListFull[tileOf[l]] += sub.listFalseNegativesListFull[l];
        gt.listFalseNegativesLightLimit[tileOf[l]] += sub.listFalseNegativesLightLimit[l];
    }
    // The masks are the lists the renderer keeps: their lengths and bytes.
    Metrics& m = gt.metrics;
    m.maxList = 0;
    for (std::uint32_t c : result.listCount) m.maxList = std::max(m.maxList, c);
    m.meanList = lists == 0 ? 0.0 : double(result.entries()) / double(lists);
    m.resultBytes = result.bytes();
    return gt;
}

// Every geometry pixel in bands of tile rows on `workers` threads: per list
// the shading work, the exact work and the misses (by cause under limits),
// per tile its geometry pixels, and the optimum's work into gt.metrics.
void countPixels(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                 const CullResult& result, const PixelNeeds* needs, const glm::dvec3& bmin, const glm::dvec3& bmax,
                 unsigned workers, const CancelToken* cancel, GroundTruth& gt) {
    const std::size_t lists = result.listCount.size();
    const std::size_t tiles = result.grid.tileCount();
    const ListLimits& limits = result.limits;
    const bool limited = !limits.empty();
    Metrics& m = gt.metrics;
    const PixelListLookup listOf(result);
    // Each pixel's lights: precomputed, or found through a uniform grid.
    std::optional<detail::LightGrid> grid;
    if (!needs) grid.emplace(lights, bmin, bmax);
    struct Acc {
        std::vector<std::uint64_t> w, e, fn, fnFull, fnLimit;
        std::vector<std::uint32_t> tilePixels;
        // The optimum: per list its pixels and the lights they need
        // together; `all`'s one list spans every band, so it keeps a flag
        // per light instead.
        std::vector<std::uint64_t> listPixels, listUnion;
        std::vector<std::uint32_t> unionTile, unionSubs; // per light: the tile counted, its sub-lists counted
        std::vector<char> neededAnywhere;
    };
    std::vector<Acc> acc(workers);
    const bool oneList = result.algorithm == Algorithm::All;
    // Per-pixel lists (zbin's): the optimum is the per-tile one, so the
    // union is counted per tile (one "sub-list").
    const bool perTileUnion = !result.pixelList.empty();
    const std::size_t unions = perTileUnion ? std::max(lists, tiles) : lists;
    const std::uint32_t per = std::max(result.listsPerTile, 1u); // <= 32: one bit per sub-list
    for (auto& a : acc) {
        a.w.assign(lists, 0), a.e.assign(lists, 0), a.fn.assign(lists, 0);
        if (limited) a.fnFull.assign(lists, 0), a.fnLimit.assign(lists, 0);
        a.tilePixels.assign(tiles, 0);
        if (oneList) {
            a.neededAnywhere.assign(lights.size(), 0);
        } else {
            a.listPixels.assign(unions, 0), a.listUnion.assign(unions, 0);
            a.unionTile.assign(lights.size(), std::numeric_limits<std::uint32_t>::max());
            a.unionSubs.assign(lights.size(), 0);
        }
    }
    // Membership of a needed light in the pixel's list: stamp[i] == the
    // current stamp when light i is listed. Neighbouring pixels mostly share
    // a list, so re-stamping on a change costs less than a binary search
    // per needed light.
    std::vector<std::vector<std::uint32_t>> stamps(workers, std::vector<std::uint32_t>(lights.size(), 0));
    std::vector<std::uint32_t> stampNow(workers, 0);
    // dropStamps[w][i] == the current stamp when the limits dropped light i from the list.
    std::vector<std::vector<std::uint32_t>> dropStamps(limited ? workers : 0,
                                                       std::vector<std::uint32_t>(lights.size(), 0));
    const std::uint32_t ts = result.grid.tileSize;
    // Bands of one tile row, walked tile by tile: a tile's pixels come one
    // after another, so the lights its lists need together are counted
    // with one tile number and one bit per sub-list per light.
    forEachRowBand(depth.height, ts, workers, cancel, [&](unsigned w, std::uint32_t y0, std::uint32_t y1) {
        Acc& a = acc[w];
        std::vector<std::uint32_t>& stamp = stamps[w];
        std::uint32_t& now = stampNow[w];
        std::uint32_t stampedList = std::numeric_limits<std::uint32_t>::max();
        for (std::uint32_t tx0 = 0; tx0 < depth.width; tx0 += ts)
            for (std::uint32_t y = y0; y < y1; ++y)
                for (std::uint32_t x = tx0; x < std::min(depth.width, tx0 + ts); ++x) {
                    if (!depth.hasGeometry(x, y)) continue;
                    const std::size_t pixel = std::size_t(y) * depth.width + x;
                    const double d = depth.at(x, y);
                    const double viewDepth = needs ? needs->viewDepth[pixel] : proj.viewDepthFromWindowDepth(d);
                    const std::uint32_t l = listOf(x, y, viewDepth);
                    if (l >= lists) throw Error("ground truth: listOfPixel gave list " + std::to_string(l));
                    const std::uint32_t t = result.grid.tileOfPixel(x, y);
                    ++a.tilePixels[t];
                    if (l != stampedList) {
                        if (++now == 0) { // wrapped: clear old stamps
                            std::fill(stamp.begin(), stamp.end(), 0);
                            if (limited) std::fill(dropStamps[w].begin(), dropStamps[w].end(), 0);
                            now = 1;
                        }
                        const std::uint32_t* first = result.lightIndices.data() + result.listOffset[l];
                        for (std::uint32_t k = 0; k < result.listCount[l]; ++k) stamp[first[k]] = now;
                        if (limited)
                            for (auto [d, e] = limits.droppedFrom(l); d != e; ++d) dropStamps[w][*d] = now;
                        stampedList = l;
                    }
                    a.w[l] += result.listCount[l];
                    const std::uint32_t subBit = oneList || perTileUnion ? 1u : 1u << (l - t * per);
                    const std::uint32_t u = perTileUnion ? t : l; // where the union counts
                    std::uint64_t needed = 0, missed = 0, missedFull = 0, missedLimit = 0;
                    const auto visit = [&](std::uint32_t i) {
                        ++needed;
                        missed += stamp[i] != now;
                        if (limited && stamp[i] != now) {
                            if (limits.isOverLimit(i)) ++missedLimit;
                            else if (dropStamps[w][i] == now) ++missedFull;
                        }
                        if (oneList) {
                            a.neededAnywhere[i] = 1;
                            return;
                        }
                        if (a.unionTile[i] != t) a.unionTile[i] = t, a.unionSubs[i] = 0;
                        if (!(a.unionSubs[i] & subBit)) {
                            a.unionSubs[i] |= subBit;
                            ++a.listUnion[u];
                        }
                    };
                    if (needs) {
                        const std::uint32_t* it = needs->lights.data() + needs->offset[pixel];
                        const std::uint32_t* end = needs->lights.data() + needs->offset[pixel + 1];
                        for (; it != end; ++it) visit(*it);
                    } else {
                        grid->forEachContaining(proj.viewPositionFromDepth(x, y, d), visit);
                    }
                    a.e[l] += needed;
                    a.fn[l] += missed;
                    if (limited) a.fnFull[l] += missedFull, a.fnLimit[l] += missedLimit;
                    if (!oneList) ++a.listPixels[u];
                }
    });
    if (oneList) {
        std::uint64_t anywhere = 0, pixels = 0;
        for (std::size_t i = 0; i < lights.size(); ++i) {
            bool any = false;
            for (const Acc& a : acc) any = any || a.neededAnywhere[i];
            anywhere += any;
        }
        for (const Acc& a : acc)
            for (std::uint32_t c : a.tilePixels) pixels += c;
        m.optimalWork = anywhere * pixels;
    } else {
        // optimal += pixels of the list x lights its pixels need together
        // (each list lies in one band: one worker has all of it).
        for (const Acc& a : acc)
            for (std::size_t l = 0; l < a.listPixels.size(); ++l) m.optimalWork += a.listPixels[l] * a.listUnion[l];
    }
    for (const Acc& a : acc) {
        for (std::size_t l = 0; l < lists; ++l) {
            gt.listShadingWork[l] += a.w[l];
            gt.listExactWork[l] += a.e[l];
            gt.listFalseNegatives[l] += a.fn[l];
            if (limited) {
                gt.listFalseNegativesListFull[l] += a.fnFull[l];
                gt.listFalseNegativesLightLimit[l] += a.fnLimit[l];
            }
        }
        for (std::size_t t = 0; t < tiles; ++t) gt.tileGeometryPixels[t] += a.tilePixels[t];
    }
}

// The image error: the culled lists' Lambert image against every light's.
void addImageError(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                   const CullResult& result, const CancelToken* cancel, Metrics& m) {
    const std::size_t lists = result.listCount.size();
    const std::vector<float> ref = shadeLambertCpu(depth, proj, lights, nullptr);
    if (isCancelled(cancel)) throw Cancelled();
    // A single list of every light in order (`all`) shades, through the same
    // kernel in the same order, bitwise like the reference: reuse it.
    bool identity = lists == 1 && result.listCount[0] == lights.size();
    for (std::size_t i = 0; identity && i < lights.size(); ++i)
        identity = result.lightIndices[result.listOffset[0] + i] == i;
    const std::vector<float> cul =
        identity ? ref : shadeLambertCpu(depth, proj, lights, &result);
    if (isCancelled(cancel)) throw Cancelled();
    const ImageError e = compareShadedImages(depth, cul, ref);
    m.imageRmse = e.rmse;
    m.imageMaxError = e.maxAbs;
    m.imageErrorComputed = true;
}

} // namespace

std::shared_ptr<const PixelNeeds> computePixelNeeds(const DepthImage& depth, const Projection& proj,
                                                    const ViewLights& lights, std::size_t maxEntries,
                                                    const CancelToken* cancel) {
    checkInputs(depth, proj);
    maxEntries = std::min<std::size_t>(maxEntries, std::numeric_limits<std::uint32_t>::max());
    auto needs = std::make_shared<PixelNeeds>();
    needs->width = depth.width;
    needs->height = depth.height;
    needs->lightCount = lights.size();
    const std::size_t n = std::size_t(depth.width) * depth.height;
    needs->viewDepth.assign(n, 0.0);
    needs->offset.assign(n + 1, 0);
    const unsigned workers = workerCount();
    glm::dvec3 bmin, bmax;
    if (!geometryBounds(depth, proj, workers, cancel, bmin, bmax)) return needs;
    const detail::LightGrid grid(lights, bmin, bmax);
    // Per band of rows its pixels' lights, joined in pixel order after.
    const std::uint32_t bandRows = 16;
    std::vector<std::vector<std::uint32_t>> bandLights((depth.height + bandRows - 1) / bandRows);
    std::atomic<std::size_t> total{0};
    std::atomic<bool> tooMany{false};
    forEachRowBand(depth.height, bandRows, workers, cancel, [&](unsigned, std::uint32_t y0, std::uint32_t y1) {
        if (tooMany.load(std::memory_order_relaxed)) return;
        std::vector<std::uint32_t>& out = bandLights[y0 / bandRows];
        for (std::uint32_t y = y0; y < y1; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                const std::size_t pixel = std::size_t(y) * depth.width + x;
                if (depth.hasGeometry(x, y)) {
                    const double d = depth.at(x, y);
                    needs->viewDepth[pixel] = proj.viewDepthFromWindowDepth(d);
                    const std::size_t before = out.size();
                    grid.forEachContaining(proj.viewPositionFromDepth(x, y, d),
                                           [&](std::uint32_t i) { out.push_back(i); });
                    needs->offset[pixel + 1] = std::uint32_t(out.size() - before); // a count until joined
                }
            }
        if (total += out.size(); total.load() > maxEntries) tooMany = true;
    });
    if (tooMany) return nullptr;
    needs->lights.reserve(total.load());
    for (std::size_t i = 0; i < n; ++i) needs->offset[i + 1] += needs->offset[i];
    for (const auto& band : bandLights) needs->lights.insert(needs->lights.end(), band.begin(), band.end());
    return needs;
}

GroundTruth computeGroundTruth(const DepthImage& depth, const Projection& proj,
                               const ViewLights& lights, const CullResult& result,
                               const GroundTruthOptions& opt, const CancelToken* cancel) {
    checkInputs(depth, proj);
    if (const std::string bad = result.validate(lights.size()); !bad.empty())
        throw Error("ground truth: inconsistent cull result: " + bad);
    if (result.grid.width != depth.width || result.grid.height != depth.height)
        throw Error("ground truth: cull result grid does not match the depth image");
    if (result.algorithm == Algorithm::ZBin && result.pixelList.empty())
        return zbinTruth(depth, proj, lights, result, opt, cancel);

    const std::size_t lists = result.listCount.size();
    const std::size_t tiles = result.grid.tileCount();
    const unsigned workers = workerCount();

    GroundTruth gt;
    gt.listShadingWork.assign(lists, 0);
    gt.listExactWork.assign(lists, 0);
    gt.listFalseNegatives.assign(lists, 0);
    gt.listFalseNegativesListFull.assign(lists, 0);
    gt.listFalseNegativesLightLimit.assign(lists, 0);
    gt.tileGeometryPixels.assign(tiles, 0);
    Metrics& m = gt.metrics;
    if (const PixelNeeds* needs = opt.needs) {
        if (needs->width != depth.width || needs->height != depth.height || needs->lightCount != lights.size())
            throw Error("ground truth: the pixel needs given are of another frame (" + std::to_string(needs->width) +
                        "x" + std::to_string(needs->height) + ", " + std::to_string(needs->lightCount) + " lights)");
        countPixels(depth, proj, lights, result, needs, {}, {}, workers, cancel, gt);
    } else if (glm::dvec3 bmin, bmax; geometryBounds(depth, proj, workers, cancel, bmin, bmax)) {
        countPixels(depth, proj, lights, result, nullptr, bmin, bmax, workers, cancel, gt);
    }

    if (opt.fullLists)
        for (const std::uint32_t l : *opt.fullLists)
            if (l < lists) gt.listFalseNegativesListFull[l] = gt.listFalseNegatives[l] - gt.listFalseNegativesLightLimit[l];
    for (std::size_t l = 0; l < lists; ++l) {
        m.shadingWork += gt.listShadingWork[l];
        m.exactWork += gt.listExactWork[l];
        m.falseNegatives += gt.listFalseNegatives[l];
        m.falseNegativesListFull += gt.listFalseNegativesListFull[l];
        m.falseNegativesLightLimit += gt.listFalseNegativesLightLimit[l];
        m.maxList = std::max(m.maxList, result.listCount[l]);
    }
    for (std::uint32_t c : gt.tileGeometryPixels) m.geometryPixels += c;
    m.efficiency = m.shadingWork == 0 ? 1.0 : double(m.exactWork) / double(m.shadingWork);
    m.efficiencyVsOptimal = m.shadingWork == 0 ? 1.0 : double(m.optimalWork) / double(m.shadingWork);
    m.meanList = lists == 0 ? 0.0 : double(result.entries()) / double(lists);
    m.resultBytes = result.bytes();

    if (opt.imageError) addImageError(depth, proj, lights, result, cancel, m);
    return gt;
}

std::vector<std::pair<std::uint32_t, std::uint32_t>>
pixelsNeedingLights(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                    const TileGrid& grid, std::uint32_t tile) {
    checkInputs(depth, proj);
    if (tile >= grid.tileCount())
        throw Error("tile " + std::to_string(tile) + " out of range (" +
                    std::to_string(grid.tileCount()) + " tiles)");
    const TileGrid::Rect r = grid.tileRect(tile % grid.tilesX, tile / grid.tilesX);
    // One tile is at most tileSize^2 pixels: a direct test of every light is
    // cheap enough here and needs no index.
    std::vector<std::uint32_t> count(lights.size(), 0);
    for (std::uint32_t y = r.y0; y < r.y1 && y < depth.height; ++y)
        for (std::uint32_t x = r.x0; x < r.x1 && x < depth.width; ++x) {
            if (!depth.hasGeometry(x, y)) continue;
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
            for (std::size_t i = 0; i < lights.size(); ++i)
                if (detail::lightNeeds(lights, i, p)) ++count[i]; // a spot light only inside its cone
        }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    for (std::size_t i = 0; i < count.size(); ++i)
        if (count[i]) out.emplace_back(std::uint32_t(i), count[i]);
    return out;
}

} // namespace lc
