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

#include "culling/ground_truth.hpp"

#include "culling/errors.hpp"
#include "light_grid.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <exception>
#include <limits>
#include <mutex>
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

// ---- Lambert shading -------------------------------------------------------

// Light data for the shading kernel, float SoA.
struct LightSoA {
    std::vector<float> x, y, z, r, g, b;
    explicit LightSoA(const ViewLights& l) {
        const std::size_t n = l.size();
        x.resize(n), y.resize(n), z.resize(n), r.resize(n), g.resize(n), b.resize(n);
        for (std::size_t i = 0; i < n; ++i) {
            x[i] = float(l.centers[i].x), y[i] = float(l.centers[i].y), z[i] = float(l.centers[i].z);
            r[i] = float(l.power[i].x), g[i] = float(l.power[i].y), b[i] = float(l.power[i].z);
        }
    }
};

// A group of pixels shaded by the same light list, float SoA.
struct PixelGroup {
    std::vector<float> px, py, pz, nx, ny, nz, ar, ag, ab;
    void resize(std::size_t n) {
        for (auto* v : {&px, &py, &pz, &nx, &ny, &nz}) v->resize(n);
        for (auto* v : {&ar, &ag, &ab}) v->assign(n, 0.0f);
    }
};

// The one Lambert kernel, used for both the culled and the all-lights image so
// that the same light list gives bitwise the same sum: per pixel, lights are
// accumulated in the order given, with the same float operations. The inner
// loop runs over pixels and vectorises; light data are loop invariants.
//   contribution = power * max(0, n.l) / max(d^2, 1e-4),  l = (c - P) / |c - P|
// x86-64 always has SSE2: the pixel loop runs 4 pixels per instruction with
// explicit intrinsics (GCC will not vectorise std::sqrt without
// -fno-math-errno). SSE's add/mul/div/sqrt are IEEE-exact like the scalar
// tail's, so every pixel gets bitwise the value the scalar loop would give.
void shadeGroup(PixelGroup& g, std::size_t begin, std::size_t end, const LightSoA& L,
                const std::uint32_t* lightIndex, std::size_t lightCount) {
    float* __restrict ar = g.ar.data();
    float* __restrict ag = g.ag.data();
    float* __restrict ab = g.ab.data();
    const float* __restrict px = g.px.data();
    const float* __restrict py = g.py.data();
    const float* __restrict pz = g.pz.data();
    const float* __restrict nx = g.nx.data();
    const float* __restrict ny = g.ny.data();
    const float* __restrict nz = g.nz.data();
    for (std::size_t k = 0; k < lightCount; ++k) {
        const std::size_t i = lightIndex ? lightIndex[k] : k;
        const float lx = L.x[i], ly = L.y[i], lz = L.z[i];
        const float cr = L.r[i], cg = L.g[i], cb = L.b[i];
        std::size_t p = begin;
#if defined(__SSE2__)
        const __m128 vlx = _mm_set1_ps(lx), vly = _mm_set1_ps(ly), vlz = _mm_set1_ps(lz);
        const __m128 vcr = _mm_set1_ps(cr), vcg = _mm_set1_ps(cg), vcb = _mm_set1_ps(cb);
        const __m128 tiny = _mm_set1_ps(1e-30f), floor2 = _mm_set1_ps(1e-4f), zero = _mm_setzero_ps();
        for (; p + 4 <= end; p += 4) {
            const __m128 dx = _mm_sub_ps(vlx, _mm_loadu_ps(px + p));
            const __m128 dy = _mm_sub_ps(vly, _mm_loadu_ps(py + p));
            const __m128 dz = _mm_sub_ps(vlz, _mm_loadu_ps(pz + p));
            const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            const __m128 len = _mm_sqrt_ps(_mm_max_ps(d2, tiny));
            const __m128 dot = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_loadu_ps(nx + p), dx),
                                                     _mm_mul_ps(_mm_loadu_ps(ny + p), dy)),
                                          _mm_mul_ps(_mm_loadu_ps(nz + p), dz));
            const __m128 ndl = _mm_div_ps(dot, len);
            const __m128 f = _mm_div_ps(_mm_max_ps(ndl, zero), _mm_max_ps(d2, floor2));
            _mm_storeu_ps(ar + p, _mm_add_ps(_mm_loadu_ps(ar + p), _mm_mul_ps(vcr, f)));
            _mm_storeu_ps(ag + p, _mm_add_ps(_mm_loadu_ps(ag + p), _mm_mul_ps(vcg, f)));
            _mm_storeu_ps(ab + p, _mm_add_ps(_mm_loadu_ps(ab + p), _mm_mul_ps(vcb, f)));
        }
#endif
        for (; p < end; ++p) {
            const float dx = lx - px[p], dy = ly - py[p], dz = lz - pz[p];
            const float d2 = (dx * dx + dy * dy) + dz * dz;
            // A light exactly at the pixel has no direction: clamp the length.
            const float len = std::sqrt(d2 > 1e-30f ? d2 : 1e-30f);
            const float ndl = ((nx[p] * dx + ny[p] * dy) + nz[p] * dz) / len;
            const float f = (ndl > 0.0f ? ndl : 0.0f) / (d2 > 1e-4f ? d2 : 1e-4f);
            ar[p] += cr * f;
            ag[p] += cg * f;
            ab[p] += cb * f;
        }
    }
}

// Shading normal at a geometry pixel, from the reconstructed view positions of
// its neighbours. In each of x and y the shorter of the forward and backward
// differences is used, so that a pixel on a silhouette takes its slope from the
// surface it belongs to. Without a valid neighbour in x or in y the normal is
// the direction to the camera. The normal faces the camera.
glm::dvec3 shadingNormal(const DepthImage& depth, const Projection& proj, std::uint32_t x,
                         std::uint32_t y, const glm::dvec3& p) {
    auto pick = [&](bool hasB, std::uint32_t bx, std::uint32_t by, bool hasF, std::uint32_t fx,
                    std::uint32_t fy, glm::dvec3& out) {
        bool ok = false;
        double best = std::numeric_limits<double>::infinity();
        if (hasF && depth.hasGeometry(fx, fy)) {
            const glm::dvec3 d = proj.viewPositionFromDepth(fx, fy, depth.at(fx, fy)) - p;
            best = glm::dot(d, d), out = d, ok = true;
        }
        if (hasB && depth.hasGeometry(bx, by)) {
            const glm::dvec3 d = p - proj.viewPositionFromDepth(bx, by, depth.at(bx, by));
            if (glm::dot(d, d) < best) out = d, ok = true;
        }
        return ok;
    };
    const glm::dvec3 toCamera =
        proj.orthographic() ? glm::dvec3(0, 0, 1) : (glm::dot(p, p) > 0 ? glm::normalize(-p) : glm::dvec3(0, 0, 1));
    glm::dvec3 dx, dy;
    const bool okX = pick(x > 0, x - 1, y, x + 1 < depth.width, x + 1, y, dx);
    const bool okY = pick(y > 0, x, y - 1, y + 1 < depth.height, x, y + 1, dy);
    if (!okX || !okY) return toCamera;
    glm::dvec3 n = glm::cross(dx, dy);
    const double len = glm::length(n);
    if (!(len > 0) || !std::isfinite(len)) return toCamera;
    n /= len;
    return glm::dot(n, toCamera) < 0 ? -n : n;
}

} // namespace

std::vector<float> shadeLambertCpu(const DepthImage& depth, const Projection& proj,
                                   const ViewLights& lights, const CullResult* culled) {
    checkInputs(depth, proj);
    const std::uint32_t W = depth.width;
    std::vector<float> rgb(std::size_t(W) * depth.height * 3, 0.0f);
    if (culled && (culled->grid.width != W || culled->grid.height != depth.height))
        throw Error("shading: cull result grid is " + std::to_string(culled->grid.width) + "x" +
                    std::to_string(culled->grid.height) + ", depth image " + std::to_string(W) +
                    "x" + std::to_string(depth.height));
    const LightSoA L(lights);
    // Band height: a tile row, so that pixels sharing a tile list form groups
    // of a whole tile (long vectorisable inner loops).
    const std::uint32_t band = culled ? std::max(culled->grid.tileSize, 4u) : 16u;
    const unsigned workers = workerCount();
    forEachRowBand(depth.height, band, workers, nullptr, [&](unsigned, std::uint32_t y0, std::uint32_t y1) {
        // (list, pixel) pairs of this band, sorted by list: each run of equal
        // lists is shaded light-outer, pixel-inner.
        std::vector<std::pair<std::uint32_t, std::uint32_t>> order;
        order.reserve(std::size_t(W) * (y1 - y0));
        for (std::uint32_t y = y0; y < y1; ++y)
            for (std::uint32_t x = 0; x < W; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                std::uint32_t list = 0;
                if (culled)
                    list = culled->listOfPixel(x, y, proj.viewDepthFromWindowDepth(depth.at(x, y)));
                order.emplace_back(list, y * W + x);
            }
        if (culled) std::sort(order.begin(), order.end());
        PixelGroup g;
        g.resize(order.size());
        for (std::size_t k = 0; k < order.size(); ++k) {
            const std::uint32_t x = order[k].second % W, y = order[k].second / W;
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
            const glm::dvec3 n = shadingNormal(depth, proj, x, y, p);
            g.px[k] = float(p.x), g.py[k] = float(p.y), g.pz[k] = float(p.z);
            g.nx[k] = float(n.x), g.ny[k] = float(n.y), g.nz[k] = float(n.z);
        }
        for (std::size_t begin = 0; begin < order.size();) {
            std::size_t end = begin + 1;
            while (end < order.size() && order[end].first == order[begin].first) ++end;
            if (culled) {
                const std::uint32_t l = order[begin].first;
                if (l >= culled->listCount.size())
                    throw Error("shading: list " + std::to_string(l) + " out of range");
                const std::uint32_t off = culled->listOffset[l], cnt = culled->listCount[l];
                if (std::size_t(off) + cnt > culled->lightIndices.size())
                    throw Error("shading: list " + std::to_string(l) + " overruns the index array");
                for (std::uint32_t k = 0; k < cnt; ++k)
                    if (culled->lightIndices[off + k] >= lights.size())
                        throw Error("shading: list " + std::to_string(l) + " names light " +
                                    std::to_string(culled->lightIndices[off + k]) + " of " +
                                    std::to_string(lights.size()));
                shadeGroup(g, begin, end, L, culled->lightIndices.data() + off, cnt);
            } else {
                shadeGroup(g, begin, end, L, nullptr, lights.size());
            }
            begin = end;
        }
        for (std::size_t k = 0; k < order.size(); ++k) {
            float* out = &rgb[std::size_t(order[k].second) * 3];
            out[0] = g.ar[k], out[1] = g.ag[k], out[2] = g.ab[k];
        }
    });
    return rgb;
}

GroundTruth computeGroundTruth(const DepthImage& depth, const Projection& proj,
                               const ViewLights& lights, const CullResult& result,
                               const GroundTruthOptions& opt, const CancelToken* cancel) {
    checkInputs(depth, proj);
    if (const std::string bad = result.validate(lights.size()); !bad.empty())
        throw Error("ground truth: inconsistent cull result: " + bad);
    if (result.grid.width != depth.width || result.grid.height != depth.height)
        throw Error("ground truth: cull result grid does not match the depth image");

    const std::size_t lists = result.listCount.size();
    const std::size_t tiles = result.grid.tileCount();
    const unsigned workers = workerCount();

    GroundTruth gt;
    gt.listShadingWork.assign(lists, 0);
    gt.listExactWork.assign(lists, 0);
    gt.listFalseNegatives.assign(lists, 0);
    gt.tileGeometryPixels.assign(tiles, 0);
    Metrics& m = gt.metrics;

    glm::dvec3 bmin, bmax;
    if (geometryBounds(depth, proj, workers, cancel, bmin, bmax)) {
        const detail::LightGrid grid(lights, bmin, bmax);
        struct Acc {
            std::vector<std::uint64_t> w, e, fn;
            std::vector<std::uint32_t> tilePixels;
        };
        std::vector<Acc> acc(workers);
        for (auto& a : acc) {
            a.w.assign(lists, 0), a.e.assign(lists, 0), a.fn.assign(lists, 0);
            a.tilePixels.assign(tiles, 0);
        }
        // Membership of a needed light in the pixel's list: stamp[i] == the
        // current stamp when light i is listed. Neighbouring pixels mostly share
        // a list, so re-stamping on a change costs less than a binary search
        // per needed light.
        std::vector<std::vector<std::uint32_t>> stamps(workers, std::vector<std::uint32_t>(lights.size(), 0));
        std::vector<std::uint32_t> stampNow(workers, 0);
        forEachRowBand(depth.height, 16, workers, cancel, [&](unsigned w, std::uint32_t y0, std::uint32_t y1) {
            Acc& a = acc[w];
            std::vector<std::uint32_t>& stamp = stamps[w];
            std::uint32_t& now = stampNow[w];
            std::uint32_t stampedList = std::numeric_limits<std::uint32_t>::max();
            for (std::uint32_t y = y0; y < y1; ++y)
                for (std::uint32_t x = 0; x < depth.width; ++x) {
                    if (!depth.hasGeometry(x, y)) continue;
                    const double d = depth.at(x, y);
                    const glm::dvec3 p = proj.viewPositionFromDepth(x, y, d);
                    const std::uint32_t l = result.listOfPixel(x, y, proj.viewDepthFromWindowDepth(d));
                    if (l >= lists) throw Error("ground truth: listOfPixel gave list " + std::to_string(l));
                    ++a.tilePixels[result.grid.tileOfPixel(x, y)];
                    if (l != stampedList) {
                        if (++now == 0) { // wrapped: clear old stamps
                            std::fill(stamp.begin(), stamp.end(), 0);
                            now = 1;
                        }
                        const std::uint32_t* first = result.lightIndices.data() + result.listOffset[l];
                        for (std::uint32_t k = 0; k < result.listCount[l]; ++k) stamp[first[k]] = now;
                        stampedList = l;
                    }
                    a.w[l] += result.listCount[l];
                    std::uint64_t needed = 0, missed = 0;
                    grid.forEachContaining(p, [&](std::uint32_t i) {
                        ++needed;
                        missed += stamp[i] != now;
                    });
                    a.e[l] += needed;
                    a.fn[l] += missed;
                }
        });
        for (const Acc& a : acc) {
            for (std::size_t l = 0; l < lists; ++l) {
                gt.listShadingWork[l] += a.w[l];
                gt.listExactWork[l] += a.e[l];
                gt.listFalseNegatives[l] += a.fn[l];
            }
            for (std::size_t t = 0; t < tiles; ++t) gt.tileGeometryPixels[t] += a.tilePixels[t];
        }
    }

    for (std::size_t l = 0; l < lists; ++l) {
        m.shadingWork += gt.listShadingWork[l];
        m.exactWork += gt.listExactWork[l];
        m.falseNegatives += gt.listFalseNegatives[l];
        m.maxList = std::max(m.maxList, result.listCount[l]);
    }
    for (std::uint32_t c : gt.tileGeometryPixels) m.geometryPixels += c;
    m.efficiency = m.shadingWork == 0 ? 1.0 : double(m.exactWork) / double(m.shadingWork);
    m.meanList = lists == 0 ? 0.0 : double(result.entries()) / double(lists);
    m.resultBytes = result.bytes();

    if (opt.imageError) {
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
        double sum2 = 0, maxErr = 0;
        for (std::uint32_t y = 0; y < depth.height; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const std::size_t i = (std::size_t(y) * depth.width + x) * 3;
                for (int c = 0; c < 3; ++c) {
                    const double e = double(cul[i + c]) - double(ref[i + c]);
                    sum2 += e * e;
                    maxErr = std::max(maxErr, std::abs(e));
                }
            }
        m.imageRmse = m.geometryPixels ? std::sqrt(sum2 / (3.0 * double(m.geometryPixels))) : 0.0;
        m.imageMaxError = maxErr;
        m.imageErrorComputed = true;
    }
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
                if (detail::lightContains(lights.centers[i], lights.radii[i], p)) ++count[i];
        }
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    for (std::size_t i = 0; i < count.size(); ++i)
        if (count[i]) out.emplace_back(std::uint32_t(i), count[i]);
    return out;
}

} // namespace lc
