// The Lambert shading pass's CPU reference and the image error (shade.hpp).
// View space throughout: right-handed, Y up, camera looking down -Z.
//
// Cost: pixels x (lights per list); the all-lights image is pixels x lights,
// about 20 float operations per pixel-light pair, vectorised over pixels with
// SSE, over row bands on every core.

#include "culling/truth/shade.hpp"

#include "culling/core/errors.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <optional>
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

// Runs fn(y0, y1) over row bands on every worker thread; the first exception
// of any worker is rethrown here.
template <class Fn> void forEachRowBand(std::uint32_t height, std::uint32_t bandRows, Fn&& fn) {
    bandRows = std::max(bandRows, 1u);
    const std::uint32_t bands = (height + bandRows - 1) / bandRows;
    const unsigned workers = std::max(1u, std::min<unsigned>(workerCount(), std::max(bands, 1u)));
    std::atomic<std::uint32_t> next{0};
    std::atomic<bool> stop{false};
    std::exception_ptr error;
    std::mutex errorMutex;
    auto body = [&] {
        try {
            for (;;) {
                if (stop.load(std::memory_order_relaxed)) return;
                const std::uint32_t b = next.fetch_add(1);
                if (b >= bands) return;
                const std::uint32_t y0 = b * bandRows;
                fn(y0, std::min(height, y0 + bandRows));
            }
        } catch (...) {
            std::lock_guard<std::mutex> lock(errorMutex);
            if (!error) error = std::current_exception();
            stop = true;
        }
    };
    std::vector<std::thread> threads;
    for (unsigned w = 1; w < workers; ++w) threads.emplace_back(body);
    body();
    for (auto& t : threads) t.join();
    if (error) std::rethrow_exception(error);
}

// Light data for the shading kernel, float SoA. A spot light's cone is its
// axis (ax, ay, az) and cos(outer angle); a point light has axis 0 and cos -2,
// so that the one cone test below always passes for it. invRange2 is
// 1 / range^2 for a light with a shading range, 0 (no window) otherwise.
struct LightSoA {
    std::vector<float> x, y, z, r, g, b, ax, ay, az, cosA, invRange2;
    explicit LightSoA(const ViewLights& l) {
        const std::size_t n = l.size();
        x.resize(n), y.resize(n), z.resize(n), r.resize(n), g.resize(n), b.resize(n);
        ax.assign(n, 0.0f), ay.assign(n, 0.0f), az.assign(n, 0.0f), cosA.assign(n, -2.0f), invRange2.assign(n, 0.0f);
        for (std::size_t i = 0; i < n; ++i) {
            x[i] = float(l.centers[i].x), y[i] = float(l.centers[i].y), z[i] = float(l.centers[i].z);
            r[i] = float(l.power[i].x), g[i] = float(l.power[i].y), b[i] = float(l.power[i].z);
            invRange2[i] = shadingInvRange2(l.shadingRange(i));
            if (l.isSpot(i)) {
                ax[i] = float(l.spotAxes[i].x), ay[i] = float(l.spotAxes[i].y), az[i] = float(l.spotAxes[i].z);
                cosA[i] = float(std::cos(l.spotAngles[i]));
            }
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
// times, for a spot light, 1 inside its cone and 0 outside (a hard cone, no
// penumbra): inside when (P - c).axis >= |P - c| cos(outer angle), and, for a
// light with a shading range r, times KHR_lights_punctual's window
//   w = max(0, 1 - (d^2/r^2)^2)^2,
// which is 1 at the light and falls to 0 at d = r (with no range the factor
// is computed with 1/r^2 = 0 and is exactly 1, so such lights shade bitwise as
// without it).
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
        const float sx = L.ax[i], sy = L.ay[i], sz = L.az[i], cosA = L.cosA[i];
        const float invR2 = L.invRange2[i];
        std::size_t p = begin;
#if defined(__SSE2__)
        const __m128 vlx = _mm_set1_ps(lx), vly = _mm_set1_ps(ly), vlz = _mm_set1_ps(lz);
        const __m128 vcr = _mm_set1_ps(cr), vcg = _mm_set1_ps(cg), vcb = _mm_set1_ps(cb);
        const __m128 tiny = _mm_set1_ps(1e-30f), floor2 = _mm_set1_ps(1e-4f), zero = _mm_setzero_ps();
        const __m128 vsx = _mm_set1_ps(sx), vsy = _mm_set1_ps(sy), vsz = _mm_set1_ps(sz), vcos = _mm_set1_ps(cosA);
        const __m128 vinvR2 = _mm_set1_ps(invR2), one = _mm_set1_ps(1.0f);
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
            // Cone: -(axis.d) >= len cos a, d = c - P (negation is exact).
            const __m128 axial = _mm_sub_ps(zero, _mm_add_ps(_mm_add_ps(_mm_mul_ps(vsx, dx), _mm_mul_ps(vsy, dy)),
                                                             _mm_mul_ps(vsz, dz)));
            const __m128 inCone = _mm_cmpge_ps(axial, _mm_mul_ps(len, vcos));
            const __m128 t = _mm_mul_ps(d2, vinvR2);
            const __m128 w = _mm_max_ps(_mm_sub_ps(one, _mm_mul_ps(t, t)), zero);
            const __m128 f = _mm_mul_ps(_mm_and_ps(inCone, _mm_div_ps(_mm_max_ps(ndl, zero), _mm_max_ps(d2, floor2))),
                                        _mm_mul_ps(w, w));
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
            const float axial = 0.0f - ((sx * dx + sy * dy) + sz * dz);
            const float t = d2 * invR2;
            const float w0 = 1.0f - t * t;
            const float w = w0 > 0.0f ? w0 : 0.0f;
            const float f =
                (axial >= len * cosA ? (ndl > 0.0f ? ndl : 0.0f) / (d2 > 1e-4f ? d2 : 1e-4f) : 0.0f) * (w * w);
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


// Every list of `culled` in range of the index array and of the lights.
void checkLists(const CullResult& culled, std::size_t lightCount) {
    if (culled.listOffset.size() != culled.listCount.size())
        throw Error("shading: cull result has " + std::to_string(culled.listOffset.size()) + " offsets for " +
                    std::to_string(culled.listCount.size()) + " lists");
    for (std::size_t l = 0; l < culled.listCount.size(); ++l) {
        const std::uint32_t off = culled.listOffset[l], cnt = culled.listCount[l];
        if (std::size_t(off) + cnt > culled.lightIndices.size())
            throw Error("shading: list " + std::to_string(l) + " overruns the index array");
    }
    for (std::uint32_t i : culled.lightIndices)
        if (i >= lightCount)
            throw Error("shading: a list names light " + std::to_string(i) + " of " + std::to_string(lightCount));
}

} // namespace

namespace {

void checkShadeSizes(const DepthImage& depth, const Projection& proj, const CullResult* culled) {
    if (depth.depth.size() != std::size_t(depth.width) * depth.height)
        throw Error("shading: depth image holds " + std::to_string(depth.depth.size()) + " values, expected " +
                    std::to_string(depth.width) + "x" + std::to_string(depth.height));
    if (depth.width != proj.width() || depth.height != proj.height())
        throw Error("shading: depth image is " + std::to_string(depth.width) + "x" + std::to_string(depth.height) +
                    " but the camera is " + std::to_string(proj.width()) + "x" + std::to_string(proj.height()));
    if (culled && (culled->grid.width != depth.width || culled->grid.height != depth.height))
        throw Error("shading: cull result grid is " + std::to_string(culled->grid.width) + "x" +
                    std::to_string(culled->grid.height) + ", depth image " + std::to_string(depth.width) + "x" +
                    std::to_string(depth.height));
}

} // namespace

ShadeInputs makeShadeInputs(const DepthImage& depth, const Projection& proj, const CullResult* culled) {
    checkShadeSizes(depth, proj, culled);
    ShadeInputs in;
    in.width = depth.width;
    in.height = depth.height;
    const std::size_t n = std::size_t(depth.width) * depth.height;
    in.position.assign(n * 3, 0.0f);
    in.normal.assign(n * 3, 0.0f);
    in.viewDepth.assign(n, 0.0);
    static std::atomic<std::uint64_t> made{0};
    in.gbufferId = ++made;
    forEachRowBand(depth.height, 16, [&](std::uint32_t y0, std::uint32_t y1) {
        for (std::uint32_t y = y0; y < y1; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const std::size_t i = std::size_t(y) * depth.width + x;
                const double v = proj.viewDepthFromWindowDepth(depth.at(x, y));
                in.viewDepth[i] = v;
                const glm::dvec3 p = proj.viewPositionAt({x + 0.5, y + 0.5}, v);
                const glm::dvec3 nrm = shadingNormal(depth, proj, x, y, p);
                for (int c = 0; c < 3; ++c) {
                    in.position[3 * i + c] = float(p[c]);
                    in.normal[3 * i + c] = float(nrm[c]);
                }
            }
    });
    setShadeLists(in, depth, proj, culled);
    return in;
}

void setShadeLists(ShadeInputs& in, const DepthImage& depth, const Projection& proj, const CullResult* culled) {
    checkShadeSizes(depth, proj, culled);
    if (in.width != depth.width || in.height != depth.height)
        throw Error("shading: inputs are " + std::to_string(in.width) + "x" + std::to_string(in.height) +
                    ", depth image " + std::to_string(depth.width) + "x" + std::to_string(depth.height));
    in.perPixelLists.reset();
    if (culled && culled->algorithm == Algorithm::ZBin && culled->pixelList.empty()) {
        // What a zbin pixel loops over: its tile's mask within its bin's range.
        in.perPixelLists = std::make_shared<const CullResult>(zbinPixelLists(*culled, depth, proj));
        culled = in.perPixelLists.get();
    }
    in.list.assign(std::size_t(depth.width) * depth.height, ShadeInputs::kNoList);
    std::optional<PixelListLookup> listOf;
    if (culled) listOf.emplace(*culled);
    const bool known = in.viewDepth.size() == in.list.size();
    forEachRowBand(depth.height, 16, [&](std::uint32_t y0, std::uint32_t y1) {
        for (std::uint32_t y = y0; y < y1; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const std::size_t i = std::size_t(y) * depth.width + x;
                if (!listOf) {
                    in.list[i] = 0u;
                    continue;
                }
                const double v = known ? in.viewDepth[i] : proj.viewDepthFromWindowDepth(depth.at(x, y));
                in.list[i] = (*listOf)(x, y, v);
            }
    });
}

namespace {

// Sorts a band's (list, pixel) pairs, given in pixel order, by list and then
// pixel. A band's lists are one tile row's (times its cells), a narrow range:
// counted into place in two passes (stable, so pixels stay ascending) instead
// of a comparison sort, which took a tenth of `lightcull report`'s time.
// Lists spread wider than the pairs (a custom layout's) take std::sort.
void sortByList(std::vector<std::pair<std::uint32_t, std::uint32_t>>& order, std::uint32_t lo, std::uint32_t hi) {
    if (order.size() < 2) return;
    const std::size_t span = std::size_t(hi - lo) + 1;
    if (span > 4 * order.size() + 4096) {
        std::sort(order.begin(), order.end());
        return;
    }
    std::vector<std::uint32_t> start(span + 1, 0);
    for (const auto& p : order) ++start[p.first - lo + 1];
    for (std::size_t k = 1; k <= span; ++k) start[k] += start[k - 1];
    std::vector<std::pair<std::uint32_t, std::uint32_t>> sorted(order.size());
    for (const auto& p : order) sorted[start[p.first - lo]++] = p;
    order.swap(sorted);
}

} // namespace

std::vector<float> shadeCpu(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled) {
    if (in.perPixelLists && culled) culled = in.perPixelLists.get();
    const std::uint32_t W = in.width;
    const std::size_t n = std::size_t(W) * in.height;
    if (in.position.size() != 3 * n || in.normal.size() != 3 * n || in.list.size() != n)
        throw Error("shading: inconsistent shading inputs");
    if (culled) checkLists(*culled, lights.size());
    const std::size_t listTotal = culled ? culled->listCount.size() : 1;
    std::vector<float> rgb(n * 3, 0.0f);
    const LightSoA L(lights);
    // Band height: a tile row, so that pixels sharing a tile list form groups
    // of a whole tile (long vectorisable inner loops).
    const std::uint32_t band = culled ? std::max(culled->grid.tileSize, 4u) : 16u;
    forEachRowBand(in.height, band, [&](std::uint32_t y0, std::uint32_t y1) {
        // (list, pixel) pairs of this band, sorted by list and, within a
        // list, by pixel: each run of equal lists is shaded light-outer,
        // pixel-inner.
        std::vector<std::pair<std::uint32_t, std::uint32_t>> order;
        order.reserve(std::size_t(W) * (y1 - y0));
        std::uint32_t lo = ~0u, hi = 0;
        for (std::uint32_t y = y0; y < y1; ++y)
            for (std::uint32_t x = 0; x < W; ++x) {
                const std::uint32_t i = y * W + x;
                const std::uint32_t l = in.list[i];
                if (l == ShadeInputs::kNoList) continue;
                if (l >= listTotal) throw Error("shading: pixel (" + std::to_string(x) + ", " + std::to_string(y) +
                                                ") uses list " + std::to_string(l) + " of " +
                                                std::to_string(listTotal));
                order.emplace_back(l, i);
                lo = std::min(lo, l);
                hi = std::max(hi, l);
            }
        if (culled) sortByList(order, lo, hi);
        PixelGroup g;
        g.resize(order.size());
        for (std::size_t k = 0; k < order.size(); ++k) {
            const std::size_t i = order[k].second;
            g.px[k] = in.position[3 * i], g.py[k] = in.position[3 * i + 1], g.pz[k] = in.position[3 * i + 2];
            g.nx[k] = in.normal[3 * i], g.ny[k] = in.normal[3 * i + 1], g.nz[k] = in.normal[3 * i + 2];
        }
        for (std::size_t begin = 0; begin < order.size();) {
            std::size_t end = begin + 1;
            while (end < order.size() && order[end].first == order[begin].first) ++end;
            if (culled) {
                const std::uint32_t l = order[begin].first;
                shadeGroup(g, begin, end, L, culled->lightIndices.data() + culled->listOffset[l],
                           culled->listCount[l]);
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

std::vector<float> shadeLambertCpu(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                                   const CullResult* culled) {
    return shadeCpu(makeShadeInputs(depth, proj, culled), lights, culled);
}

ImageError compareShadedImages(const DepthImage& depth, const std::vector<float>& culled,
                               const std::vector<float>& reference) {
    const std::size_t n = std::size_t(depth.width) * depth.height;
    if (culled.size() != 3 * n || reference.size() != 3 * n || depth.depth.size() != n)
        throw Error("image error: images hold " + std::to_string(culled.size()) + " and " +
                    std::to_string(reference.size()) + " values for a " + std::to_string(depth.width) + "x" +
                    std::to_string(depth.height) + " depth image");
    ImageError e;
    double sum2 = 0;
    for (std::size_t i = 0; i < n; ++i) {
        if (depth.depth[i] == depth.clearDepth) continue;
        ++e.pixels;
        for (int c = 0; c < 3; ++c) {
            const double d = double(culled[3 * i + c]) - double(reference[3 * i + c]);
            sum2 += d * d;
            e.maxAbs = std::max(e.maxAbs, std::abs(d));
        }
    }
    e.rmse = e.pixels ? std::sqrt(sum2 / (3.0 * double(e.pixels))) : 0.0;
    return e;
}

namespace {
std::uint8_t srgb8(double v) {
    v = std::clamp(std::isfinite(v) ? v : 0.0, 0.0, 1.0);
    const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return std::uint8_t(std::lround(s * 255.0));
}
} // namespace

double exposureFor(const DepthImage& depth, const std::vector<float>& reference) {
    std::vector<float> lum;
    const std::size_t n = std::min(depth.depth.size(), reference.size() / 3);
    for (std::size_t i = 0; i < n; ++i)
        if (depth.depth[i] != depth.clearDepth)
            lum.push_back(std::max({reference[3 * i], reference[3 * i + 1], reference[3 * i + 2]}));
    if (lum.empty()) return 1.0;
    const std::size_t k = std::min(lum.size() - 1, std::size_t(0.99 * double(lum.size())));
    std::nth_element(lum.begin(), lum.begin() + std::ptrdiff_t(k), lum.end());
    const double p99 = lum[k];
    return p99 > 0 && std::isfinite(p99) ? 0.9 / p99 : 1.0;
}

std::vector<std::uint8_t> shadedPicture(const std::vector<float>& rgb, double exposure) {
    std::vector<std::uint8_t> out(rgb.size());
    for (std::size_t i = 0; i < rgb.size(); ++i) out[i] = srgb8(double(rgb[i]) * exposure);
    return out;
}

std::vector<std::uint8_t> differencePicture(const std::vector<float>& culled, const std::vector<float>& reference,
                                            double maxAbs) {
    if (culled.size() != reference.size()) throw Error("difference image: the two images differ in size");
    std::vector<std::uint8_t> out(culled.size());
    const double scale = maxAbs > 0 ? 1.0 / maxAbs : 0.0;
    for (std::size_t i = 0; i < culled.size(); ++i)
        out[i] = srgb8(std::abs(double(culled[i]) - double(reference[i])) * scale);
    return out;
}

} // namespace lc
