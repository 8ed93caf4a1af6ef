// Tile grid, tile frustum planes, slicing and sphere-vs-chunk tests (view space,
// double precision). See tile_math.hpp for the contracts.
#include "culling/math/tile_math.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace lc {

TileGrid TileGrid::make(std::uint32_t width, std::uint32_t height, std::uint32_t tileSize) {
    TileGrid g;
    g.width = width;
    g.height = height;
    g.tileSize = std::max<std::uint32_t>(tileSize, 1);
    g.tilesX = (width + g.tileSize - 1) / g.tileSize;
    g.tilesY = (height + g.tileSize - 1) / g.tileSize;
    return g;
}

TileGrid::Rect TileGrid::tileRect(std::uint32_t tx, std::uint32_t ty) const {
    Rect r;
    r.x0 = tx * tileSize;
    r.y0 = ty * tileSize;
    r.x1 = std::min(r.x0 + tileSize, width);
    r.y1 = std::min(r.y0 + tileSize, height);
    return r;
}

// Perspective: a tile edge at NDC x = nx is the plane through the eye holding
// the view-space points (nx * tanHalfX * v, y, -v); with z = -v that is
// x + nx * tanHalfX * z = 0. Horizontal edges likewise with NDC y pointing
// down: view y = -ny * tanHalfY * v = ny * tanHalfY * z. Orthographic edges are
// the axis-aligned planes x = nx * halfW, y = -ny * halfH.
std::array<Plane, 4> tileSidePlanes(const Projection& proj, const TileGrid::Rect& rect) {
    const glm::dvec2 n0 = proj.ndcFromPixel({double(rect.x0), double(rect.y0)});
    const glm::dvec2 n1 = proj.ndcFromPixel({double(rect.x1), double(rect.y1)});
    std::array<Plane, 4> planes;
    if (proj.orthographic()) {
        // Extents of the view volume in view units, from a reference point at depth 1.
        const glm::dvec3 c0 = proj.viewPositionAt({double(rect.x0), double(rect.y0)}, 1.0);
        const glm::dvec3 c1 = proj.viewPositionAt({double(rect.x1), double(rect.y1)}, 1.0);
        planes[0] = {1, 0, 0, -c0.x};  // x >= left edge
        planes[1] = {-1, 0, 0, c1.x};  // x <= right edge
        planes[2] = {0, -1, 0, c0.y};  // y <= top edge (view y up)
        planes[3] = {0, 1, 0, -c1.y};  // y >= bottom edge
        return planes;
    }
    // tanHalfX/Y recovered from a point at view depth 1 on the NDC corner (1, -1).
    const glm::dvec3 corner = proj.viewPositionAt({double(proj.width()), 0.0}, 1.0);
    const double tx = corner.x, ty = corner.y;
    planes[0] = {1, 0, n0.x * tx, 0};   // x - nx0 tX v >= 0
    planes[1] = {-1, 0, -n1.x * tx, 0}; // nx1 tX v - x >= 0
    planes[2] = {0, -1, n0.y * ty, 0};  // -ny0 tY v - y >= 0
    planes[3] = {0, 1, -n1.y * ty, 0};  // y + ny1 tY v >= 0
    for (Plane& p : planes) p /= glm::length(glm::dvec3(p));
    return planes;
}

FrustumChunk makeFrustumChunk(const Projection& proj, const TileGrid::Rect& rect, double depthMin,
                              double depthMax) {
    FrustumChunk c;
    const auto side = tileSidePlanes(proj, rect);
    for (int i = 0; i < 4; ++i) c.planes[i] = side[i];
    c.planes[4] = {0, 0, -1, -depthMin}; // view depth -z >= depthMin
    c.planes[5] = {0, 0, 1, depthMax};   // view depth -z <= depthMax
    const glm::dvec2 px[4] = {{double(rect.x0), double(rect.y0)},
                              {double(rect.x1), double(rect.y0)},
                              {double(rect.x1), double(rect.y1)},
                              {double(rect.x0), double(rect.y1)}};
    for (int i = 0; i < 4; ++i) {
        c.corners[i] = proj.viewPositionAt(px[i], depthMin);
        c.corners[4 + i] = proj.viewPositionAt(px[i], depthMax);
    }
    c.depthMin = depthMin;
    c.depthMax = depthMax;
    return c;
}

const char* toString(SphereTest t) {
    switch (t) {
    case SphereTest::Planes: return "planes";
    case SphereTest::PlanesAabb: return "planes+aabb";
    case SphereTest::Exact: return "exact";
    }
    return "?";
}

const char* toString(Slicing s) {
    switch (s) {
    case Slicing::Log: return "log";
    case Slicing::Linear: return "linear";
    }
    return "?";
}

double sphereTestSlack(const glm::dvec3& c, double r) {
    return 1e-9 * (r + std::abs(c.x) + std::abs(c.y) + std::abs(c.z)) + 1e-12;
}

namespace {

bool planesPass(const FrustumChunk& chunk, const glm::dvec3& c, double r) {
    for (const Plane& p : chunk.planes)
        if (signedDistance(p, c) < -r) return false;
    return true;
}

bool aabbPass(const FrustumChunk& chunk, const glm::dvec3& c, double r) {
    glm::dvec3 lo = chunk.corners[0], hi = chunk.corners[0];
    for (const auto& k : chunk.corners) {
        lo = glm::min(lo, k);
        hi = glm::max(hi, k);
    }
    const glm::dvec3 q = glm::clamp(c, lo, hi);
    const glm::dvec3 d = c - q;
    return glm::dot(d, d) <= r * r;
}

double segmentDistance(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b) {
    const glm::dvec3 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    double t = len2 > 0 ? glm::dot(p - a, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    return glm::length(p - (a + t * ab));
}

} // namespace

// The closest point of a convex polyhedron to an outside point lies in the
// interior of a face (then p projects orthogonally into that face) or on an
// edge (vertices are edge end points). Every chunk plane has a unit normal.
double distanceToChunk(const FrustumChunk& chunk, const glm::dvec3& p) {
    double scale = std::abs(p.x) + std::abs(p.y) + std::abs(p.z) + chunk.depthMax + 1.0;
    const double tol = 1e-12 * scale;
    bool inside = true;
    for (const Plane& pl : chunk.planes)
        if (signedDistance(pl, p) < 0) inside = false;
    if (inside) return 0.0;

    double best = std::numeric_limits<double>::infinity();
    for (int f = 0; f < 6; ++f) {
        const double sd = signedDistance(chunk.planes[f], p);
        if (sd >= 0) continue; // p is on the inner side: that face is not the closest
        const glm::dvec3 q = p - sd * glm::dvec3(chunk.planes[f]);
        bool within = true;
        for (int g = 0; g < 6 && within; ++g)
            if (g != f && signedDistance(chunk.planes[g], q) < -tol) within = false;
        if (within) best = std::min(best, -sd);
    }
    static constexpr int kEdges[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6},
                                          {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
    for (const auto& e : kEdges)
        best = std::min(best, segmentDistance(p, chunk.corners[e[0]], chunk.corners[e[1]]));
    return best;
}

// The three tests nest: Exact implies PlanesAabb implies Planes, because each
// one runs the cheaper tests first (they are conservative, so this loses
// nothing) and then refines.
bool sphereIntersectsChunk(SphereTest test, const FrustumChunk& chunk, const glm::dvec3& c, double r) {
    const double rr = r + sphereTestSlack(c, r);
    if (!planesPass(chunk, c, rr)) return false;
    if (test == SphereTest::Planes) return true;
    if (!aabbPass(chunk, c, rr)) return false;
    if (test == SphereTest::PlanesAabb) return true;
    return distanceToChunk(chunk, c) <= rr;
}

// ---- slicing ---------------------------------------------------------------
// Log slicing needs lo > 0 (view depths bounded by the near plane); a
// non-positive lo falls back to linear so no log/pow of <= 0 is ever taken.

namespace {
bool useLog(Slicing s, double lo) { return s == Slicing::Log && lo > 0.0; }
} // namespace

double sliceBoundary(Slicing s, double lo, double hi, std::uint32_t cells, std::uint32_t i) {
    if (cells == 0 || i == 0) return lo;
    if (i >= cells) return hi;
    const double t = double(i) / double(cells);
    if (!(hi > lo)) return lo;
    if (useLog(s, lo)) return lo * std::pow(hi / lo, t);
    return lo + (hi - lo) * t;
}

// Slice k holds depths in [boundary(k), boundary(k+1)) (the last one is closed).
// The closed-form guess is corrected against the boundaries themselves so that
// the two functions agree exactly, whatever the rounding of log/pow.
std::uint32_t sliceOfDepth(Slicing s, double lo, double hi, std::uint32_t cells, double d) {
    if (cells <= 1 || !(hi > lo) || !(d > lo)) return 0; // also catches NaN d
    if (d >= hi) return cells - 1;
    double t = useLog(s, lo) ? std::log(d / lo) / std::log(hi / lo) : (d - lo) / (hi - lo);
    double k = std::floor(t * double(cells));
    if (!(k >= 0.0)) k = 0.0;
    if (k > double(cells - 1)) k = double(cells - 1);
    std::uint32_t i = std::uint32_t(k);
    while (i > 0 && d < sliceBoundary(s, lo, hi, cells, i)) --i;
    while (i + 1 < cells && d >= sliceBoundary(s, lo, hi, cells, i + 1)) ++i;
    return i;
}

SliceLocator::SliceLocator(Slicing s, double lo, double hi, std::uint32_t cells)
    : s_(s), lo_(lo), hi_(hi), cells_(cells) {
    if (cells <= 1 || !(hi > lo)) return;
    inner_.reserve(cells - 1);
    for (std::uint32_t i = 1; i < cells; ++i) inner_.push_back(sliceBoundary(s, lo, hi, cells, i));
}

std::uint32_t SliceLocator::operator()(double d) const {
    if (cells_ <= 1 || !(hi_ > lo_) || !(d > lo_)) return 0;
    if (d >= hi_) return cells_ - 1;
    // Slice k starts at boundary k: the count of inner boundaries <= d.
    return std::uint32_t(std::upper_bound(inner_.begin(), inner_.end(), d) - inner_.begin());
}

namespace {
// [a, b] clipped to [lo, hi] -> the slices from a's to b's (slice(d): the slice of d).
template <class Slice>
std::uint32_t rangeMaskOf(double lo, double hi, std::uint32_t cells, double a, double b, const Slice& slice) {
    if (cells == 0) return 0;
    if (!(b >= lo) || !(a <= hi)) return 0; // misses [lo, hi] (or NaN)
    // Clip to [lo, hi] first: an interval reaching behind the near plane starts at lo.
    const std::uint32_t ka = slice(std::max(a, lo));
    const std::uint32_t kb = slice(std::min(b, hi));
    const std::uint64_t upTo = (std::uint64_t(1) << (kb + 1)) - 1;
    const std::uint64_t below = (std::uint64_t(1) << ka) - 1;
    return std::uint32_t(upTo & ~below);
}
} // namespace

std::uint32_t sliceRangeMask(Slicing s, double lo, double hi, std::uint32_t cells, double a,
                             double b) {
    cells = std::min<std::uint32_t>(cells, 32);
    return rangeMaskOf(lo, hi, cells, a, b, [&](double d) { return sliceOfDepth(s, lo, hi, cells, d); });
}

std::uint32_t SliceLocator::rangeMask(double a, double b) const {
    if (cells_ > 32) return sliceRangeMask(s_, lo_, hi_, cells_, a, b); // over 32 slices: another range
    return rangeMaskOf(lo_, hi_, cells_, a, b, *this);
}

} // namespace lc
