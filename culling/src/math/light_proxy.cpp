// Light proxies of the `raster` algorithm (light_proxy.hpp): the meshes,
// their enclosing overfit and one triangle's tiles.
#include "culling/math/light_proxy.hpp"

#include "culling/core/backend.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>

namespace lc {

namespace {

constexpr double kPi = 3.14159265358979323846;

ProxyMesh icosahedron() {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    ProxyMesh m;
    m.vertices = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                  {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    for (auto& v : m.vertices) v = glm::normalize(v);
    // Counter-clockwise seen from outside.
    m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                   {11, 10, 2}, {10, 7, 6}, {7, 1, 8},  {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                   {3, 8, 9},  {4, 9, 5},  {2, 4, 11}, {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
    return m;
}

// Each triangle split in four at its edges' midpoints, pushed out onto the sphere.
ProxyMesh subdivide(const ProxyMesh& in) {
    ProxyMesh out;
    out.vertices = in.vertices;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoints;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
        const auto key = std::minmax(a, b);
        auto it = midpoints.find(key);
        if (it != midpoints.end()) return it->second;
        out.vertices.push_back(glm::normalize(out.vertices[a] + out.vertices[b]));
        const auto i = std::uint32_t(out.vertices.size() - 1);
        midpoints.emplace(key, i);
        return i;
    };
    for (const auto& t : in.triangles) {
        const std::uint32_t ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
        out.triangles.push_back({t[0], ab, ca});
        out.triangles.push_back({t[1], bc, ab});
        out.triangles.push_back({t[2], ca, bc});
        out.triangles.push_back({ab, bc, ca});
    }
    return out;
}

ProxyMesh cone(std::uint32_t segments) {
    ProxyMesh m;
    m.vertices.push_back({0, 0, 0}); // apex
    for (std::uint32_t k = 0; k < segments; ++k) {
        const double a = 2.0 * kPi * k / segments;
        m.vertices.push_back({std::cos(a), std::sin(a), 1.0});
    }
    m.vertices.push_back({0, 0, 1}); // the base's centre
    const std::uint32_t centre = segments + 1;
    for (std::uint32_t k = 0; k < segments; ++k) {
        const std::uint32_t a = 1 + k, b = 1 + (k + 1) % segments;
        m.triangles.push_back({0, b, a});
        m.triangles.push_back({centre, a, b});
    }
    return m;
}

} // namespace

const ProxyMesh& unitIcosphere(std::uint32_t level) {
    static const std::array<ProxyMesh, 5> levels = [] {
        std::array<ProxyMesh, 5> l;
        l[0] = icosahedron();
        for (std::size_t i = 1; i < l.size(); ++i) l[i] = subdivide(l[i - 1]);
        return l;
    }();
    return levels[std::min<std::uint32_t>(level, 4)];
}

const ProxyMesh& unitCone(std::uint32_t segments) {
    static std::mutex mutex;
    static std::map<std::uint32_t, std::unique_ptr<ProxyMesh>> cones;
    segments = std::clamp<std::uint32_t>(segments, 3, 64);
    std::lock_guard<std::mutex> lock(mutex);
    auto& c = cones[segments];
    if (!c) c = std::make_unique<ProxyMesh>(cone(segments));
    return *c;
}

double icosphereEnclosingOverfit(std::uint32_t level) {
    // Once per level: every light's proxy asks (a level-4 mesh has 5,120 faces).
    static const std::array<double, 5> overfit = [] {
        std::array<double, 5> o{};
        for (std::uint32_t l = 0; l < o.size(); ++l) {
            const ProxyMesh& m = unitIcosphere(l);
            double nearest = 1.0;
            for (const auto& t : m.triangles) {
                const glm::dvec3 a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
                const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
                nearest = std::min(nearest, std::abs(glm::dot(n, a)));
            }
            o[l] = 1.0 / nearest;
        }
        return o;
    }();
    return overfit[std::min<std::uint32_t>(level, 4)];
}

double coneEnclosingOverfit(std::uint32_t segments) {
    return 1.0 / std::cos(kPi / std::clamp<std::uint32_t>(segments, 3, 64));
}

LightProxy makeLightProxy(const glm::dvec3& center, double radius, const glm::dvec3& axis, double spotAngle,
                          const CullSettings& s) {
    LightProxy p;
    p.radius = radius;
    p.cone = spotAngle > 0.0 && spotAngle <= double(s.proxyConeAngle) * kPi / 180.0;
    p.origin = center;
    if (!p.cone) {
        p.overfit = s.proxyOverfit > 0.0 ? s.proxyOverfit : icosphereEnclosingOverfit(s.proxyLevel);
        p.mesh = &unitIcosphere(s.proxyLevel);
        p.basis = glm::dmat3(radius * p.overfit);
        p.depthMin = -center.z - radius * p.overfit;
        p.depthMax = -center.z + radius * p.overfit;
        return p;
    }
    p.overfit = s.proxyOverfit > 0.0 ? s.proxyOverfit : coneEnclosingOverfit(s.proxySegments);
    p.mesh = &unitCone(s.proxySegments);
    // Any two unit vectors perpendicular to the axis and to each other.
    const glm::dvec3 helper = std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0);
    const glm::dvec3 u = glm::normalize(glm::cross(axis, helper));
    const glm::dvec3 v = glm::cross(axis, u);
    const double base = radius * std::tan(spotAngle) * p.overfit;
    p.basis = glm::dmat3(u * base, v * base, axis * radius);
    p.depthMin = std::numeric_limits<double>::infinity();
    p.depthMax = -std::numeric_limits<double>::infinity();
    for (std::uint32_t i = 0; i < p.mesh->vertices.size(); ++i) {
        const double d = -p.vertex(i).z;
        p.depthMin = std::min(p.depthMin, d);
        p.depthMax = std::max(p.depthMax, d);
    }
    return p;
}

LightProxy makeLightProxy(const ViewLights& lights, std::size_t l, const CullSettings& settings) {
    const bool spot = lights.isSpot(l);
    return makeLightProxy(lights.centers[l], lights.radii[l], spot ? lights.spotAxes[l] : glm::dvec3(0, 0, -1),
                          spot ? lights.spotAngles[l] : 0.0, settings);
}

double LightProxy::slack() const { return sphereTestSlack(origin, radius * overfit); }

std::uint32_t LightProxy::sliceMask(const SliceLocator& slices, bool skipEmpty, double lo, double hi,
                                    std::uint32_t occupied) const {
    const double e = slack();
    double a = lo - e, b = hi + e;
    if (depthMin - e <= slices.lo()) a = std::min(a, slices.lo());
    if (depthMax + e >= slices.hi()) b = std::max(b, slices.hi());
    std::uint32_t m = slices.rangeMask(a, b);
    if (skipEmpty) m &= occupied;
    return m;
}

namespace {

// A proxy triangle on the grid (tile units, x in [0, width / tile] across
// the screen), its part nearer than the near plane clipped away: a pixel a
// light reaches has its geometry beyond the near plane, and the ray to it
// leaves the (closed) proxy beyond that geometry, so the proxy's surface
// beyond the near plane covers the pixel whatever lies nearer. (The Vulkan
// pass clips there too, as its depth clip plane.) Counter-clockwise, up to
// four corners; 0 when nothing is left or it is seen edge-on.
std::size_t projectProxyTriangle(const Projection& proj, const TileGrid& grid, const std::array<glm::dvec3, 3>& tri,
                                 std::array<glm::dvec2, 4>& p) {
    const glm::dmat4& m = proj.clipFromView();
    std::array<glm::dvec4, 4> clip;
    std::array<glm::dvec4, 3> in;
    for (int i = 0; i < 3; ++i) in[std::size_t(i)] = m * glm::dvec4(tri[std::size_t(i)], 1.0);
    const double kEyeW = proj.orthographic() ? -1.0 : proj.nearPlane();
    std::size_t n = 0;
    for (std::size_t i = 0; i < 3; ++i) {
        const glm::dvec4& a = in[i];
        const glm::dvec4& b = in[(i + 1) % 3];
        const bool aIn = a.w >= kEyeW, bIn = b.w >= kEyeW;
        if (aIn) clip[n++] = a;
        if (aIn != bIn) clip[n++] = a + (b - a) * ((kEyeW - a.w) / (b.w - a.w));
    }
    if (n < 3) return 0;
    const double sx = double(grid.width) / grid.tileSize, sy = double(grid.height) / grid.tileSize;
    double area = 0;
    for (std::size_t i = 0; i < n; ++i)
        p[i] = {(clip[i].x / clip[i].w + 1.0) * 0.5 * sx, (clip[i].y / clip[i].w + 1.0) * 0.5 * sy};
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec2& a = p[i];
        const glm::dvec2& b = p[(i + 1) % n];
        area += a.x * b.y - b.x * a.y;
    }
    if (!(std::abs(area) > 1e-12)) return 0; // edge-on (or NaN)
    if (area < 0) std::reverse(p.begin(), p.begin() + std::ptrdiff_t(n));
    return n;
}

} // namespace

double proxyTriangleTileGap(const Projection& proj, const TileGrid& grid, const std::array<glm::dvec3, 3>& tri,
                            std::uint32_t tx, std::uint32_t ty) {
    std::array<glm::dvec2, 4> p;
    const std::size_t n = projectProxyTriangle(proj, grid, tri, p);
    if (n == 0) return std::numeric_limits<double>::infinity();
    const double sx = double(grid.width) / grid.tileSize, sy = double(grid.height) / grid.tileSize;
    const double rx0 = tx, rx1 = std::min(double(tx) + 1.0, sx), ry0 = ty, ry1 = std::min(double(ty) + 1.0, sy);
    double x0 = p[0].x, x1 = p[0].x, y0 = p[0].y, y1 = p[0].y;
    for (std::size_t i = 1; i < n; ++i)
        x0 = std::min(x0, p[i].x), x1 = std::max(x1, p[i].x), y0 = std::min(y0, p[i].y), y1 = std::max(y1, p[i].y);
    // The widest separation along an axis of the separating-axis test: the
    // axes x and y, and each edge's unit normal (the tile's nearest corner
    // outside the edge by that much).
    double gap = std::max({rx0 - x1, x0 - rx1, ry0 - y1, y0 - ry1});
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec2& a = p[i];
        const glm::dvec2& b = p[(i + 1) % n];
        const glm::dvec2 nrm = glm::dvec2(-(b.y - a.y), b.x - a.x) / glm::length(b - a);
        const double cx = nrm.x >= 0 ? rx1 : rx0, cy = nrm.y >= 0 ? ry1 : ry0;
        gap = std::max(gap, -(nrm.x * (cx - a.x) + nrm.y * (cy - a.y)));
    }
    return gap;
}

std::uint64_t proxyTriangleTiles(const Projection& proj, const TileGrid& grid, const std::array<glm::dvec3, 3>& tri,
                                 bool conservative, const std::function<void(std::uint32_t, std::uint32_t)>& covered) {
    if (grid.tilesX == 0 || grid.tilesY == 0) return 0;
    std::array<glm::dvec2, 4> p;
    const std::size_t n = projectProxyTriangle(proj, grid, tri, p);
    if (n == 0) return 0;
    const double sx = double(grid.width) / grid.tileSize, sy = double(grid.height) / grid.tileSize;
    // Edge functions, >= 0 inside (counter-clockwise).
    std::array<glm::dvec3, 4> edge;
    double x0 = p[0].x, x1 = p[0].x, y0 = p[0].y, y1 = p[0].y;
    for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec2& a = p[i];
        const glm::dvec2& b = p[(i + 1) % n];
        edge[i] = {-(b.y - a.y), b.x - a.x, 0.0};
        edge[i].z = -(edge[i].x * a.x + edge[i].y * a.y);
        x0 = std::min(x0, p[i].x), x1 = std::max(x1, p[i].x);
        y0 = std::min(y0, p[i].y), y1 = std::max(y1, p[i].y);
    }
    auto inside = [&](std::size_t i, double x, double y) { return edge[i].x * x + edge[i].y * y + edge[i].z >= 0.0; };
    // The tiles of the bounding box (clamped in double before converting).
    auto first = [](double v, std::uint32_t count) {
        return std::uint32_t(std::clamp(std::floor(v), 0.0, double(count - 1)));
    };
    if (x1 < 0.0 || y1 < 0.0 || x0 > double(grid.tilesX) || y0 > double(grid.tilesY)) return 0;
    const std::uint32_t tx0 = first(x0, grid.tilesX), tx1 = first(x1, grid.tilesX);
    const std::uint32_t ty0 = first(y0, grid.tilesY), ty1 = first(y1, grid.tilesY);
    std::uint64_t tested = 0;
    for (std::uint32_t ty = ty0; ty <= ty1; ++ty) {
        for (std::uint32_t tx = tx0; tx <= tx1; ++tx) {
            ++tested;
            bool hit = true;
            if (conservative) {
                // The tile as far as the screen reaches (a partial edge tile
                // is narrower), against the polygon: separated by neither
                // its bounding box nor any edge.
                const double rx0 = tx, rx1 = std::min(double(tx) + 1.0, sx);
                const double ry0 = ty, ry1 = std::min(double(ty) + 1.0, sy);
                hit = x0 <= rx1 && x1 >= rx0 && y0 <= ry1 && y1 >= ry0;
                for (std::size_t i = 0; hit && i < n; ++i)
                    hit = inside(i, edge[i].x >= 0 ? rx1 : rx0, edge[i].y >= 0 ? ry1 : ry0);
            } else {
                for (std::size_t i = 0; hit && i < n; ++i) hit = inside(i, tx + 0.5, ty + 0.5);
            }
            if (hit) covered(tx, ty);
        }
    }
    return tested;
}

std::uint64_t proxySliceTiles(const Projection& proj, const TileGrid& grid, const LightProxy& p, bool conservative,
                              const std::function<void(std::uint32_t, double, double)>& tile) {
    std::unordered_map<std::uint32_t, std::pair<double, double>> range;
    std::uint64_t tested = 0;
    for (const auto& tri : p.mesh->triangles) {
        const std::array<glm::dvec3, 3> v = {p.vertex(tri[0]), p.vertex(tri[1]), p.vertex(tri[2])};
        tested += proxyTriangleTiles(proj, grid, v, conservative, [&](std::uint32_t tx, std::uint32_t ty) {
            const auto [a, b] = proxyTriangleTileDepth(proj, grid, v, conservative, tx, ty);
            const auto [it, fresh] = range.try_emplace(grid.tileIndex(tx, ty), a, b);
            if (!fresh) it->second = {std::min(it->second.first, a), std::max(it->second.second, b)};
        });
    }
    for (const auto& [t, r] : range) tile(t, r.first, r.second);
    return tested;
}

std::pair<double, double> proxyTriangleTileDepth(const Projection& proj, const TileGrid& grid,
                                                 const std::array<glm::dvec3, 3>& tri, bool conservative,
                                                 std::uint32_t tx, std::uint32_t ty) {
    const double d[3] = {-tri[0].z, -tri[1].z, -tri[2].z};
    const double lo = std::min({d[0], d[1], d[2]}), hi = std::max({d[0], d[1], d[2]});
    const bool ortho = proj.orthographic();
    if (!ortho && !(lo >= proj.nearPlane())) return {lo, hi};
    // The plane of f (1 / depth, or depth) over the screen in tile units.
    const glm::dmat4& m = proj.clipFromView();
    const double sx = double(grid.width) / grid.tileSize, sy = double(grid.height) / grid.tileSize;
    glm::dvec2 s[3];
    double f[3];
    for (int i = 0; i < 3; ++i) {
        const glm::dvec4 c = m * glm::dvec4(tri[i], 1.0);
        s[i] = {(c.x / c.w + 1.0) * 0.5 * sx, (c.y / c.w + 1.0) * 0.5 * sy};
        f[i] = ortho ? d[i] : 1.0 / d[i];
    }
    const glm::dvec2 u = s[1] - s[0], v = s[2] - s[0];
    const double det = u.x * v.y - u.y * v.x;
    if (!(std::abs(det) > 1e-12)) return {lo, hi};
    const double fu = f[1] - f[0], fv = f[2] - f[0];
    const double a = (fu * v.y - fv * u.y) / det, b = (fv * u.x - fu * v.x) / det;
    auto at = [&](double x, double y) { return f[0] + a * (x - s[0].x) + b * (y - s[0].y); };
    auto depthOf = [&](double g) { return ortho ? g : 1.0 / g; };
    if (!conservative) {
        const double g = at(tx + 0.5, ty + 0.5);
        if (!ortho && !(g > 0)) return {lo, hi};
        const double z = std::clamp(depthOf(g), lo, hi);
        return {z, z};
    }
    double gmin = at(tx, ty), gmax = gmin;
    for (const auto& [x, y] : {std::pair<double, double>{tx + 1.0, ty}, {tx, ty + 1.0}, {tx + 1.0, ty + 1.0}}) {
        gmin = std::min(gmin, at(x, y));
        gmax = std::max(gmax, at(x, y));
    }
    double zlo = lo, zhi = hi;
    if (ortho) {
        zlo = std::max(lo, gmin), zhi = std::min(hi, gmax);
    } else if (gmax > 0) {
        // f falls as depth grows: its largest value is the nearest depth.
        zlo = std::max(lo, 1.0 / gmax);
        if (gmin > 0) zhi = std::min(hi, 1.0 / gmin);
    }
    if (!(zlo <= zhi)) return {lo, hi}; // rounding at a tile the triangle barely touches (or NaN)
    return {zlo, zhi};
}

} // namespace lc
