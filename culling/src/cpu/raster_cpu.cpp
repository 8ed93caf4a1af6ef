// The CPU reference depth rasteriser (depth.hpp).
//
// Pipeline per triangle, in Vulkan clip space (Projection::clipFromView, y down,
// z/w = window depth):
//  1. clip against 0 <= z <= w (near and far; for infinite reversed-Z the z >= 0
//     plane is the far plane at infinity and never cuts) and against a guard
//     band |x|, |y| <= kGuard * w, which keeps the fixed-point edge functions
//     below in range;
//  2. coverage: vertices snapped to 1/256 pixel, integer edge functions
//     evaluated at pixel centres, D3D/Vulkan top-left rule so that triangles
//     sharing an edge cover each pixel exactly once;
//  3. depth: z/w is affine in screen space over a planar triangle, so it is
//     evaluated from the plane through the unsnapped vertices (double), clamped
//     to [0, 1] and stored as float with a LESS (GREATER for reversed-Z) test.
#include "culling/core/depth.hpp"

#include "culling/core/errors.hpp"

#include <algorithm>
#include <cmath>
#include <thread>

namespace lc {

std::size_t DepthImage::geometryPixelCount() const {
    std::size_t n = 0;
    for (float d : depth) n += d != clearDepth;
    return n;
}

namespace {

constexpr double kGuard = 4.0;     // guard band in NDC units
constexpr std::int64_t kSub = 256; // sub-pixel steps per pixel

struct ClipVert {
    glm::dvec4 p;
};

// Signed distances of the 6 clip planes (>= 0 inside).
inline double planeDist(int i, const glm::dvec4& v) {
    switch (i) {
    case 0: return v.z;
    case 1: return v.w - v.z;
    case 2: return v.x + kGuard * v.w;
    case 3: return kGuard * v.w - v.x;
    case 4: return v.y + kGuard * v.w;
    default: return kGuard * v.w - v.y;
    }
}

inline unsigned outcode(const glm::dvec4& v) {
    unsigned c = 0;
    for (int i = 0; i < 6; ++i)
        if (planeDist(i, v) < 0) c |= 1u << i;
    return c;
}

// Sutherland-Hodgman in homogeneous space against the planes in `mask`.
// A triangle cut by 6 planes has at most 9 vertices.
int clipPolygon(glm::dvec4* poly, int n, unsigned mask) {
    glm::dvec4 tmp[12];
    for (int pl = 0; pl < 6 && n > 0; ++pl) {
        if (!(mask & (1u << pl))) continue;
        int m = 0;
        for (int i = 0; i < n; ++i) {
            const glm::dvec4& a = poly[i];
            const glm::dvec4& b = poly[(i + 1) % n];
            const double da = planeDist(pl, a), db = planeDist(pl, b);
            if (da >= 0) tmp[m++] = a;
            if ((da >= 0) != (db >= 0)) {
                const double t = da / (da - db);
                tmp[m++] = a + t * (b - a);
            }
        }
        n = m;
        std::copy(tmp, tmp + n, poly);
    }
    return n;
}

struct Raster {
    const Projection& proj;
    DepthImage& img;
    std::uint32_t rowBegin, rowEnd; // this band's rows [rowBegin, rowEnd)
    bool reversed;

    // Screen-space vertex: unsnapped position and depth, and snapped fixed point.
    struct SV {
        double x, y, z;
        std::int64_t X, Y;
    };

    SV toScreen(const glm::dvec4& c) const {
        SV s;
        const double iw = 1.0 / c.w;
        s.x = (c.x * iw + 1.0) * 0.5 * double(img.width);
        s.y = (c.y * iw + 1.0) * 0.5 * double(img.height);
        s.z = c.z * iw;
        s.X = std::llround(s.x * double(kSub));
        s.Y = std::llround(s.y * double(kSub));
        return s;
    }

    void triangle(SV a, SV b, SV c) {
        std::int64_t area = (b.X - a.X) * (c.Y - a.Y) - (b.Y - a.Y) * (c.X - a.X);
        if (area == 0) return;
        if (area < 0) { // both faces: bring every triangle to one winding
            std::swap(b, c);
            area = -area;
        }
        // Pixel bounds of the snapped triangle, clipped to the band and image.
        const std::int64_t minX = std::min({a.X, b.X, c.X}), maxX = std::max({a.X, b.X, c.X});
        const std::int64_t minY = std::min({a.Y, b.Y, c.Y}), maxY = std::max({a.Y, b.Y, c.Y});
        // Pixel p's centre is at p*kSub + kSub/2: first p with centre >= min.
        auto firstPix = [](std::int64_t v) {
            return (v - kSub / 2 + kSub - 1 >= 0) ? (v - kSub / 2 + kSub - 1) / kSub : 0;
        };
        std::int64_t x0 = std::max<std::int64_t>(0, firstPix(minX));
        std::int64_t y0 = std::max<std::int64_t>(rowBegin, firstPix(minY));
        std::int64_t x1 = std::min<std::int64_t>(img.width - 1, (maxX - kSub / 2) >= 0
                                                                    ? (maxX - kSub / 2) / kSub
                                                                    : -1);
        std::int64_t y1 = std::min<std::int64_t>(std::int64_t(rowEnd) - 1,
                                                 (maxY - kSub / 2) >= 0 ? (maxY - kSub / 2) / kSub : -1);
        if (x0 > x1 || y0 > y1) return;

        // Depth plane z = z0 + dzdx (x - a.x) + dzdy (y - a.y) from unsnapped vertices.
        const double ux = b.x - a.x, uy = b.y - a.y, vx = c.x - a.x, vy = c.y - a.y;
        const double det = ux * vy - uy * vx;
        double dzdx = 0, dzdy = 0;
        if (det != 0.0 && std::isfinite(det)) {
            const double uz = b.z - a.z, vz = c.z - a.z;
            dzdx = (uz * vy - vz * uy) / det;
            dzdy = (vz * ux - uz * vx) / det;
        }

        // Edge function of edge (p -> q) at point s: (q - p) x (s - p); >= 0 inside.
        // Top-left rule for this winding (clockwise on a y-down screen): an edge
        // owns its pixels when it is a top edge (dy == 0, dx > 0) or a left edge
        // (dy < 0); others need a strictly positive value.
        struct Edge {
            std::int64_t stepX, stepY, rowStart, bias;
        };
        auto makeEdge = [&](const SV& p, const SV& q) {
            Edge e;
            const std::int64_t dx = q.X - p.X, dy = q.Y - p.Y;
            const std::int64_t sx = x0 * kSub + kSub / 2, sy = y0 * kSub + kSub / 2;
            e.rowStart = dx * (sy - p.Y) - dy * (sx - p.X);
            e.stepX = -dy * kSub;
            e.stepY = dx * kSub;
            const bool owns = (dy == 0 && dx > 0) || dy < 0;
            e.bias = owns ? 0 : -1;
            return e;
        };
        Edge e0 = makeEdge(a, b), e1 = makeEdge(b, c), e2 = makeEdge(c, a);
        float* buf = img.depth.data();
        for (std::int64_t y = y0; y <= y1; ++y) {
            std::int64_t w0 = e0.rowStart, w1 = e1.rowStart, w2 = e2.rowStart;
            const double cy = double(y) + 0.5 - a.y;
            for (std::int64_t x = x0; x <= x1; ++x) {
                if ((w0 + e0.bias) >= 0 && (w1 + e1.bias) >= 0 && (w2 + e2.bias) >= 0) {
                    double z = a.z + dzdx * (double(x) + 0.5 - a.x) + dzdy * cy;
                    z = std::clamp(z, 0.0, 1.0);
                    const float zf = float(z);
                    float& d = buf[std::size_t(y) * img.width + std::size_t(x)];
                    if (reversed ? zf > d : zf < d) d = zf;
                }
                w0 += e0.stepX;
                w1 += e1.stepX;
                w2 += e2.stepX;
            }
            e0.rowStart += e0.stepY;
            e1.rowStart += e1.stepY;
            e2.rowStart += e2.stepY;
        }
    }

    void clipTriangle(const glm::dvec4& a, const glm::dvec4& b, const glm::dvec4& c) {
        const unsigned ca = outcode(a), cb = outcode(b), cc = outcode(c);
        if (ca & cb & cc) return; // all outside one plane
        const unsigned any = ca | cb | cc;
        if (!any) {
            triangle(toScreen(a), toScreen(b), toScreen(c));
            return;
        }
        glm::dvec4 poly[12] = {a, b, c};
        const int n = clipPolygon(poly, 3, any);
        if (n < 3) return;
        const SV s0 = toScreen(poly[0]);
        SV prev = toScreen(poly[1]);
        for (int i = 2; i < n; ++i) {
            const SV cur = toScreen(poly[i]);
            triangle(s0, prev, cur);
            prev = cur;
        }
    }
};

} // namespace

DepthImage rasterizeDepthCpu(const Scene& scene, const Projection& proj, const CancelToken* cancel) {
    DepthImage img;
    img.width = proj.width();
    img.height = proj.height();
    img.clearDepth = float(proj.clearDepth());
    img.depth.assign(std::size_t(img.width) * img.height, img.clearDepth);

    // Vertices to clip space once per mesh: clip = clipFromView * viewFromWorld * transform.
    const glm::dmat4 viewFromWorld = scene.camera.viewFromWorld();
    std::vector<std::vector<glm::dvec4>> clip(scene.meshes.size());
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
        const Mesh& mesh = scene.meshes[m];
        const glm::dmat4 M = proj.clipFromView() * viewFromWorld * mesh.transform;
        auto& out = clip[m];
        out.resize(mesh.vertexCount());
        for (std::size_t v = 0; v < out.size(); ++v) out[v] = M * glm::dvec4(glm::dvec3(mesh.vertex(v)), 1.0);
    }
    if (cancel) cancel->throwIfCancelled();

    // Row bands, one per thread: each walks every triangle and writes only its rows.
    const unsigned threads = std::max(1u, std::min(std::thread::hardware_concurrency(), img.height));
    std::vector<std::exception_ptr> errors(threads);
    auto band = [&](unsigned t) {
        try {
            Raster r{proj, img, std::uint32_t(std::uint64_t(img.height) * t / threads),
                     std::uint32_t(std::uint64_t(img.height) * (t + 1) / threads),
                     isReversed(proj.kind())};
            std::size_t done = 0;
            for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
                const auto& idx = scene.meshes[m].indices;
                const auto& cv = clip[m];
                for (std::size_t i = 0; i + 2 < idx.size(); i += 3) {
                    if ((++done & 4095) == 0 && cancel) cancel->throwIfCancelled();
                    if (idx[i] >= cv.size() || idx[i + 1] >= cv.size() || idx[i + 2] >= cv.size())
                        continue; // invalid meshes are rejected by Scene::validate
                    r.clipTriangle(cv[idx[i]], cv[idx[i + 1]], cv[idx[i + 2]]);
                }
            }
        } catch (...) {
            errors[t] = std::current_exception();
        }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < threads; ++t) pool.emplace_back(band, t);
    band(0);
    for (auto& th : pool) th.join();
    for (auto& e : errors)
        if (e) std::rethrow_exception(e);
    return img;
}

} // namespace lc
