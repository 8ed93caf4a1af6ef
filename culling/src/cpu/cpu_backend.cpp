// The CPU reference backend: the depth pre-pass (raster_cpu.cpp) and every
// culling algorithm of DESIGN.md in double precision.
//
// Work layout: each light gets a conservative screen-space rectangle of tiles
// (lightTileRange); tile rows are handed to worker threads, and a row's tiles
// test only the lights whose rectangle covers them, in ascending light order,
// so every list comes out sorted without a sort. Memory is the lists
// themselves, never tiles x lights.
#include "culling/core/backend.hpp"

#include "culling/core/errors.hpp"
#include "culling/cpu/fine_prune.hpp"
#include "culling/math/light_proxy.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <fstream>
#include <limits>
#include <thread>

namespace lc {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct TileRange {
    std::uint32_t tx0 = 1, tx1 = 0, ty0 = 1, ty1 = 0; // empty when tx0 > tx1
    bool empty() const { return tx0 > tx1 || ty0 > ty1; }
};

// Tiles whose frustum the sphere (view-space centre c, radius r) may touch.
// Perspective: when the sphere reaches within half the near distance of the eye
// plane its projection is unbounded or huge: every tile. Otherwise the sphere's
// view-space AABB lies in front of the eye, and x/v, y/v (linear-fractional)
// reach their extremes over that box at its corners, so projecting the 8
// corners bounds the sphere's projection. One pixel of margin absorbs rounding.
TileRange lightTileRange(const Projection& proj, const TileGrid& grid, const glm::dvec3& c, double r) {
    TileRange all{0, grid.tilesX - 1, 0, grid.tilesY - 1};
    if (grid.tilesX == 0 || grid.tilesY == 0) return TileRange{};
    double x0 = kInf, x1 = -kInf, y0 = kInf, y1 = -kInf;
    if (proj.orthographic()) {
        for (int i = 0; i < 4; ++i) {
            const glm::dvec2 p =
                proj.pixelFromView(c + glm::dvec3((i & 1) ? r : -r, (i & 2) ? r : -r, 0.0));
            x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
            y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
        }
    } else {
        if (-c.z - r <= 0.5 * proj.nearPlane()) return all;
        for (int i = 0; i < 8; ++i) {
            const glm::dvec3 k = c + glm::dvec3((i & 1) ? r : -r, (i & 2) ? r : -r, (i & 4) ? r : -r);
            const glm::dvec2 p = proj.pixelFromView(k);
            x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
            y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
        }
    }
    if (!(x0 == x0) || !(x1 == x1) || !(y0 == y0) || !(y1 == y1)) return all; // NaN: be safe
    x0 -= 1, y0 -= 1, x1 += 1, y1 += 1;
    if (x1 < 0 || y1 < 0 || x0 > double(grid.width) || y0 > double(grid.height)) return TileRange{};
    // Clamp in double before converting (no out-of-range float->int cast).
    auto tileOf = [&](double p, std::uint32_t count) {
        const double t = std::floor(std::clamp(p, 0.0, double(count) * grid.tileSize) / grid.tileSize);
        return std::min<std::uint32_t>(std::uint32_t(t), count - 1);
    };
    return {tileOf(x0, grid.tilesX), tileOf(x1, grid.tilesX), tileOf(y0, grid.tilesY),
            tileOf(y1, grid.tilesY)};
}

std::string cpuModelName() {
    std::ifstream f("/proc/cpuinfo");
    std::string line;
    while (std::getline(f, line)) {
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos) {
                std::string s = line.substr(colon + 1);
                const auto b = s.find_first_not_of(" \t");
                return b == std::string::npos ? "cpu" : s.substr(b);
            }
        }
    }
    return "cpu";
}

unsigned workerCount(std::uint32_t jobs) {
    const unsigned hw = std::max(1u, std::thread::hardware_concurrency());
    return std::max(1u, std::min({hw, 8u, jobs}));
}

// Runs fn(row) for row in [0, rows) on a few threads; rethrows the first error.
template <class Fn> void parallelRows(std::uint32_t rows, Fn fn) {
    const unsigned n = workerCount(rows);
    std::atomic<std::uint32_t> next{0};
    std::vector<std::exception_ptr> errors(n);
    auto work = [&](unsigned t) {
        try {
            for (std::uint32_t row; (row = next.fetch_add(1)) < rows;) fn(row);
        } catch (...) {
            errors[t] = std::current_exception();
            next = rows;
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < n; ++t) pool.emplace_back(work, t);
    work(0);
    for (auto& th : pool) th.join();
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
}

} // namespace

namespace {

// The inputs every part of a CPU cull reads: the frame, the depth as view
// depth per pixel (NaN: no geometry), each light's culling sphere.
struct CpuCull {
    const CullFrame& frame;
    const DepthImage& depth;
    const Projection& proj;
    const ViewLights& lights;
    const CullSettings& settings;
    std::vector<double> viewDepth;
    std::vector<glm::dvec3> sphereCenter;
    std::vector<double> sphereRadius;
};

// Per pixel view depth and per tile bounds, in double from the float depth.
void tileBounds(CpuCull& c, CullResult& res) {
    const DepthImage& depth = c.depth;
    const TileGrid& grid = c.frame.grid;
    std::vector<double>& viewDepth = c.viewDepth;
    viewDepth.assign(depth.depth.size(), std::nan(""));
    for (std::uint32_t y = 0; y < depth.height; ++y) {
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            const std::size_t i = std::size_t(y) * depth.width + x;
            if (depth.depth[i] == depth.clearDepth) continue;
            const double v = c.proj.viewDepthFromWindowDepth(double(depth.depth[i]));
            if (!std::isfinite(v)) continue;
            viewDepth[i] = v;
            const std::uint32_t t = grid.tileOfPixel(x, y);
            res.tileDepthMin[t] = std::min(res.tileDepthMin[t], v);
            res.tileDepthMax[t] = std::max(res.tileDepthMax[t], v);
        }
    }
}

// 2.5d's occupied cells and clustered's occupied slices per tile.
void cellMasks(const CpuCull& c, CullResult& res) {
    const DepthImage& depth = c.depth;
    const TileGrid& grid = c.frame.grid;
    const std::uint32_t cells = c.settings.cells;
    res.cellMask.assign(grid.tileCount(), 0);
    // sliceOfDepth's answers, the boundaries worked out once per range.
    const std::vector<SliceLocator> slices = cellSlices(res, cells);
    for (std::uint32_t y = 0; y < depth.height; ++y) {
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            const double v = c.viewDepth[std::size_t(y) * depth.width + x];
            if (std::isnan(v)) continue;
            const std::uint32_t t = grid.tileOfPixel(x, y);
            const std::uint32_t k = slices[c.settings.clusterLists() ? 0 : t](v);
            res.cellMask[t] |= 1u << k;
        }
    }
}

// Every algorithm but `all`: each light against each tile's (or cell's)
// volume in its screen range, tile rows on several threads; the lists in
// `lists`, the tests counted into res.volumeTests.
void cullTiles(const CpuCull& cc, CullResult& res, std::vector<std::vector<std::uint32_t>>& lists) {
    const CullFrame& frame = cc.frame;
    const DepthImage& depth = cc.depth;
    const Projection& proj = cc.proj;
    const ViewLights& lights = cc.lights;
    const CullSettings& settings = cc.settings;
    const TileGrid& grid = frame.grid;
    const Algorithm algo = settings.algorithm;
    const std::uint32_t cells = settings.cells;
    const std::size_t n = lights.size();
    const std::vector<double>& viewDepth = cc.viewDepth;
    const std::vector<glm::dvec3>& sphereCenter = cc.sphereCenter;
    const std::vector<double>& sphereRadius = cc.sphereRadius;
    const bool coneRefines =
        settings.spotTest == SpotTest::ConeSphere || settings.spotTest == SpotTest::ConePlanes;
    const double camNear = frame.cameraNear, naiveFar = frame.cameraFar;
    auto tileEmpty = [&](std::uint32_t t) { return !(res.tileDepthMin[t] <= res.tileDepthMax[t]); };
    std::vector<TileRange> ranges(n);
    std::vector<std::uint32_t> clusterMask(algo == Algorithm::Clustered ? n : 0);
    for (std::size_t l = 0; l < n; ++l) {
        ranges[l] = lightTileRange(proj, grid, sphereCenter[l], sphereRadius[l]);
        if (algo == Algorithm::Clustered) {
            const double cd = -sphereCenter[l].z, r = sphereRadius[l];
            clusterMask[l] = sliceRangeMask(settings.slicing, res.clusterNear, res.clusterFar,
                                            cells, cd - r, cd + r);
        }
    }
    const SphereTest test = settings.test;
    // fptl's fine test: any geometry pixel of the tile inside the light's
    // volume (fine_prune.hpp), from the same per-pixel positions.
    auto tilePixelKeeps = [&](const TileGrid::Rect& rect, std::uint32_t l) {
        for (std::uint32_t y = rect.y0; y < rect.y1; ++y)
            for (std::uint32_t x = rect.x0; x < rect.x1; ++x) {
                const double v = viewDepth[std::size_t(y) * depth.width + x];
                if (std::isnan(v)) continue;
                if (fptlPixelKeeps(lights, l, proj.viewPositionFromDepth(x, y, double(depth.at(x, y)))))
                    return true;
            }
        return false;
    };
    // The one per-chunk test: the culling sphere, then for a spot light
    // under a cone test the cone refinement (spot_tests.hpp).
    // Counted into the tile row's counter (the rows run on several
    // threads), summed below.
    std::vector<std::uint64_t> rowTests(grid.tilesY, 0);
    auto intersects = [&](const FrustumChunk& chunk, std::uint32_t l, std::uint64_t& tests) {
        ++tests;
        if (!sphereIntersectsChunk(test, chunk, sphereCenter[l], sphereRadius[l])) return false;
        if (!coneRefines || !lights.isSpot(l)) return true;
        return spotIntersectsChunk(settings.spotTest, test, lights.spotCone(l), chunk);
    };
    parallelRows(grid.tilesY, [&](std::uint32_t ty) {
        std::uint64_t& tests = rowTests[ty];
        std::vector<std::uint32_t> candidates;
        for (std::size_t l = 0; l < n; ++l)
            if (!ranges[l].empty() && ranges[l].ty0 <= ty && ty <= ranges[l].ty1)
                candidates.push_back(std::uint32_t(l));
        std::vector<FrustumChunk> sliceChunk(cells);
        std::vector<char> sliceBuilt(cells);
        for (std::uint32_t tx = 0; tx < grid.tilesX; ++tx) {
            const std::uint32_t t = grid.tileIndex(tx, ty);
            const TileGrid::Rect rect = grid.tileRect(tx, ty);
            const bool empty = tileEmpty(t);
            // naive's and zbin's screen-space volumes do not depend on the depth.
            if (empty && algo != Algorithm::Naive && algo != Algorithm::ZBin &&
                !(algo == Algorithm::Clustered && !settings.skipEmpty))
                continue;
            const double tmin = res.tileDepthMin[t], tmax = res.tileDepthMax[t];
            FrustumChunk chunkA, chunkB;
            switch (algo) {
            case Algorithm::ZBin:
            case Algorithm::Naive: chunkA = makeFrustumChunk(proj, rect, camNear, naiveFar); break;
            case Algorithm::Fptl:
            case Algorithm::MinMax:
            case Algorithm::TwoPointFiveD: chunkA = makeFrustumChunk(proj, rect, tmin, tmax); break;
            case Algorithm::HalfZ:
                chunkA = makeFrustumChunk(proj, rect, tmin, res.halfzSplit[t]);
                chunkB = makeFrustumChunk(proj, rect, res.halfzSplit[t], tmax);
                break;
            default: std::fill(sliceBuilt.begin(), sliceBuilt.end(), 0); break;
            }
            for (std::uint32_t l : candidates) {
                const TileRange& rg = ranges[l];
                if (tx < rg.tx0 || tx > rg.tx1) continue;
                const glm::dvec3& c = sphereCenter[l];
                const double r = sphereRadius[l];
                switch (algo) {
                case Algorithm::Naive:
                case Algorithm::ZBin: // the tile's mask: the screen-space test
                case Algorithm::MinMax:
                    if (intersects(chunkA, l, tests)) lists[t].push_back(l);
                    break;
                case Algorithm::Fptl:
                    // Coarse: minmax's test; fine: a pixel of the tile the light could reach.
                    if (intersects(chunkA, l, tests) && tilePixelKeeps(rect, l)) lists[t].push_back(l);
                    break;
                case Algorithm::HalfZ:
                    if (intersects(chunkA, l, tests)) lists[2 * t].push_back(l);
                    if (intersects(chunkB, l, tests)) lists[2 * t + 1].push_back(l);
                    break;
                case Algorithm::TwoPointFiveD: {
                    const double cd = -c.z;
                    const std::uint32_t m =
                        sliceRangeMask(settings.slicing, tmin, tmax, cells, cd - r, cd + r);
                    if ((m & res.cellMask[t]) && intersects(chunkA, l, tests))
                        lists[t].push_back(l);
                    break;
                }
                case Algorithm::Clustered: {
                    std::uint32_t m = clusterMask[l];
                    if (settings.skipEmpty) m &= res.cellMask[t];
                    for (; m; m &= m - 1) {
                        const std::uint32_t k = std::uint32_t(std::countr_zero(m));
                        if (!sliceBuilt[k]) {
                            sliceChunk[k] = makeFrustumChunk(
                                proj, rect,
                                sliceBoundary(settings.slicing, res.clusterNear, res.clusterFar, cells, k),
                                sliceBoundary(settings.slicing, res.clusterNear, res.clusterFar, cells, k + 1));
                            sliceBuilt[k] = 1;
                        }
                        if (intersects(sliceChunk[k], l, tests))
                            lists[std::size_t(t) * cells + k].push_back(l);
                    }
                    break;
                }
                default: break;
                }
            }
        }
    });
    for (std::uint64_t t : rowTests) res.volumeTests += t;
}

// raster: each light's proxy (light_proxy.hpp) drawn at one pixel per tile.
// A tile lists the light when one of the proxy's triangles covers it, the
// tile holds geometry, and the proxy's depth extent reaches the tile's
// min/max (widened by the tests' slack). Lights in index order, so every
// list comes out sorted.
void rasterTiles(const CpuCull& c, CullResult& res, std::vector<std::vector<std::uint32_t>>& lists) {
    const TileGrid& grid = c.frame.grid;
    const ViewLights& lights = c.lights;
    std::vector<std::uint32_t> seen(grid.tileCount(), std::numeric_limits<std::uint32_t>::max());
    const SliceLocator clusterSlices(c.settings.slicing, res.clusterNear, res.clusterFar,
                                     std::min<std::uint32_t>(c.settings.cells, 32));
    for (std::uint32_t l = 0; l < lights.size(); ++l) {
        const LightProxy p = makeLightProxy(lights, l, c.settings);
        if (c.settings.proxySlices) {
            // Clusters: per covered tile the depths the covering triangles
            // span there, then the light's slices (LightProxy::sliceMask).
            res.volumeTests += proxySliceTiles(c.proj, grid, p, c.settings.conservative,
                                               [&](std::uint32_t t, double lo, double hi) {
                                                   for (std::uint32_t m = p.sliceMask(clusterSlices,
                                                                                      c.settings.skipEmpty, lo, hi,
                                                                                      res.cellMask[t]);
                                                        m; m &= m - 1)
                                                       lists[std::size_t(t) * res.listsPerTile +
                                                             std::uint32_t(std::countr_zero(m))]
                                                           .push_back(l);
                                               });
            continue;
        }
        auto mark = [&](std::uint32_t tx, std::uint32_t ty) {
            const std::uint32_t t = grid.tileIndex(tx, ty);
            if (seen[t] == l) return;
            seen[t] = l;
            if (res.tileDepthMin[t] <= res.tileDepthMax[t] && p.depthReaches(res.tileDepthMin[t], res.tileDepthMax[t]))
                lists[t].push_back(l);
        };
        for (const auto& tri : p.mesh->triangles)
            res.volumeTests += proxyTriangleTiles(c.proj, grid, {p.vertex(tri[0]), p.vertex(tri[1]), p.vertex(tri[2])},
                                                  c.settings.conservative, mark);
    }
    res.coverage = c.settings.conservative ? "every tile a proxy triangle overlaps (exact, double precision)"
                                           : "every tile whose centre a proxy triangle covers (double precision)";
}

// zbin: the lights sorted by the view depth of their culling sphere's
// centre; per linear bin of [near, far] the range of sorted positions whose
// depth extent (with the tests' slack) reaches it.
void zbinBins(const CpuCull& c, CullResult& res) {
    const std::size_t n = c.lights.size();
    res.zbinNear = c.frame.cameraNear;
    res.zbinFar = c.frame.cameraFar;
    std::vector<double> centreDepth(n);
    for (std::size_t l = 0; l < n; ++l) centreDepth[l] = -c.sphereCenter[l].z;
    zbinSortLights(centreDepth, res.zbinOrder, res.zbinRank);
    res.zbinLo.assign(c.settings.bins, std::numeric_limits<std::uint32_t>::max());
    res.zbinHi.assign(c.settings.bins, 0);
    for (std::uint32_t k = 0; k < n; ++k) {
        const std::uint32_t l = res.zbinOrder[k];
        const double slack = sphereTestSlack(c.sphereCenter[l], c.sphereRadius[l]);
        const double a = centreDepth[l] - c.sphereRadius[l] - slack, b = centreDepth[l] + c.sphereRadius[l] + slack;
        if (b < res.zbinNear || a > res.zbinFar) continue;
        for (std::uint32_t bin = res.zbinOf(a), last = res.zbinOf(b); bin <= last; ++bin) {
            res.zbinLo[bin] = std::min(res.zbinLo[bin], k);
            res.zbinHi[bin] = std::max(res.zbinHi[bin], k);
        }
    }
}

// The lists compacted: offsets, counts and one index array.
void compactLists(const std::vector<std::vector<std::uint32_t>>& lists, CullResult& res) {
    const std::size_t listTotal = lists.size();
    res.listOffset.resize(listTotal);
    res.listCount.resize(listTotal);
    std::size_t total = 0;
    for (std::size_t i = 0; i < listTotal; ++i) {
        res.listOffset[i] = std::uint32_t(total);
        res.listCount[i] = std::uint32_t(lists[i].size());
        total += lists[i].size();
    }
    if (total > std::numeric_limits<std::uint32_t>::max())
        throw Error("culling produced more than 2^32 list entries");
    res.lightIndices.resize(total);
    for (std::size_t i = 0; i < listTotal; ++i)
        std::copy(lists[i].begin(), lists[i].end(), res.lightIndices.begin() + res.listOffset[i]);
}

} // namespace

// The culling pass itself (the CPU backend's cullFrame() without the timing).
static CullResult cullCpu(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                          const ViewLights& lights, const CullSettings& settings) {
    const TileGrid& grid = frame.grid;
    const Algorithm algo = settings.algorithm;
    const std::uint32_t tiles = grid.tileCount();
    const std::size_t n = lights.size();

    CullResult res;
    res.algorithm = algo;
    res.settings = settings;
    res.grid = grid;
    res.listsPerTile = frame.listsPerTile;
    res.tileDepthMin.assign(tiles, kInf);
    res.tileDepthMax.assign(tiles, -kInf);
    CpuCull c{frame, depth, proj, lights, settings, {}, {}, {}};
    tileBounds(c, res);
    // Each light's culling sphere (the frame's: its range sphere, or for a
    // spot light the sphere its spot test uses); spot tests may refine it per
    // chunk. The camera's and the clusters' depth ranges are the frame's too
    // (an infinite far plane replaced by the farthest depth any light reaches).
    c.sphereCenter.resize(n);
    c.sphereRadius.resize(n);
    for (std::size_t l = 0; l < n; ++l) {
        c.sphereCenter[l] = frame.cullSpheres[l].center;
        c.sphereRadius[l] = frame.cullSpheres[l].radius;
    }
    if (settings.clusterLists()) {
        res.clusterNear = frame.clusterNear;
        res.clusterFar = frame.clusterFar;
    }
    if (algo == Algorithm::HalfZ) {
        res.halfzSplit.assign(tiles, kInf);
        for (std::uint32_t t = 0; t < tiles; ++t)
            if (res.tileDepthMin[t] <= res.tileDepthMax[t])
                res.halfzSplit[t] = 0.5 * (res.tileDepthMin[t] + res.tileDepthMax[t]);
    }
    if (algo == Algorithm::TwoPointFiveD || settings.clusterLists()) cellMasks(c, res);

    const std::size_t listTotal = algo == Algorithm::All ? 1 : std::size_t(tiles) * res.listsPerTile;
    std::vector<std::vector<std::uint32_t>> lists(listTotal);
    if (algo == Algorithm::All) {
        lists[0].resize(n);
        for (std::size_t l = 0; l < n; ++l) lists[0][l] = std::uint32_t(l);
    } else if (algo == Algorithm::Raster) {
        if (tiles > 0) rasterTiles(c, res, lists);
    } else if (tiles > 0) {
        cullTiles(c, res, lists);
    }
    if (algo == Algorithm::ZBin) zbinBins(c, res);
    compactLists(lists, res);
    return res;
}

namespace {

class CpuBackend final : public CullBackend {
public:
    CpuBackend() : device_(cpuModelName()) {}
    std::string name() const override { return "cpu"; }
    std::string deviceName() const override { return device_; }
    std::string timingMethod() const override { return "cpu-wall-clock (steady_clock)"; }

protected:
    DepthPass renderDepthPass(const Scene& scene, const Projection& proj) override {
        DepthPass d;
        const auto t0 = std::chrono::steady_clock::now();
        d.image = rasterizeDepthCpu(scene, proj);
        d.ms = d.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        d.triangles = d.trianglesDrawn = scene.triangleCount();
        return d;
    }

    CullResult cullFrame(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                         const ViewLights& lights, const CullSettings& settings) override {
        const auto t0 = std::chrono::steady_clock::now();
        CullResult r = cullCpu(frame, depth, proj, lights, settings);
        r.timings.cullMs =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        lastCullWallMs_ = r.timings.cullMs;
        r.backend = name();
        r.device = device_;
        r.timingMethod = timingMethod();
        return r;
    }

private:
    std::string device_;
};

} // namespace

std::unique_ptr<CullBackend> makeCpuBackend() { return std::make_unique<CpuBackend>(); }

} // namespace lc
