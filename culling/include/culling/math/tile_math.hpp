#pragma once
// Pure tile, plane, slicing and sphere-test math, shared by the CPU reference,
// the overlays and the tests. All in view space, double precision.

#include "culling/math/projection.hpp"

#include <array>
#include <cstdint>
#include <vector>

namespace lc {

// The screen split into tiles. Edge tiles are partial when the resolution is
// not a multiple of the tile size. tileIndex = ty * tilesX + tx, (0,0) top-left.
struct TileGrid {
    std::uint32_t width = 0, height = 0, tileSize = 16;
    std::uint32_t tilesX = 0, tilesY = 0;

    static TileGrid make(std::uint32_t width, std::uint32_t height, std::uint32_t tileSize);
    std::uint32_t tileCount() const { return tilesX * tilesY; }
    std::uint32_t tileIndex(std::uint32_t tx, std::uint32_t ty) const { return ty * tilesX + tx; }
    std::uint32_t tileOfPixel(std::uint32_t px, std::uint32_t py) const {
        return tileIndex(px / tileSize, py / tileSize);
    }
    // Pixel rectangle [x0,x1) x [y0,y1) of a tile, clipped to the image.
    struct Rect { std::uint32_t x0, y0, x1, y1; };
    Rect tileRect(std::uint32_t tx, std::uint32_t ty) const;
};

// A plane n.p + w >= 0 is the inside; n need not be unit length for the
// containment test, but tileSidePlanes returns unit normals.
using Plane = glm::dvec4;
inline double signedDistance(const Plane& pl, const glm::dvec3& p) {
    return pl.x * p.x + pl.y * p.y + pl.z * p.z + pl.w;
}

// The four side planes of a tile's frustum, inward-facing, unit normals, in the
// order left, right, top, bottom. They pass through the tile's outer pixel
// edges (a partial tile's planes pass through the image edge).
std::array<Plane, 4> tileSidePlanes(const Projection& proj, const TileGrid::Rect& rect);

// A frustum chunk: the tile's side planes cut at view depths [depthMin, depthMax].
struct FrustumChunk {
    std::array<Plane, 6> planes;       // left, right, top, bottom, near(depthMin), far(depthMax)
    std::array<glm::dvec3, 8> corners; // near: tl, tr, br, bl; far: tl, tr, br, bl
    double depthMin, depthMax;
};
// Precondition: 0 < depthMin <= depthMax < inf (orthographic allows depthMin >= 0).
FrustumChunk makeFrustumChunk(const Projection& proj, const TileGrid::Rect& rect, double depthMin,
                              double depthMax);

enum class SphereTest { Planes, PlanesAabb, Exact };
const char* toString(SphereTest t);

// Conservative tests: true whenever the sphere (centre c, radius r, view
// space) and the chunk share a point; Planes and PlanesAabb may also say true
// when they don't (false positives), Exact only within rounding.
bool sphereIntersectsChunk(SphereTest test, const FrustumChunk& chunk, const glm::dvec3& c, double r);
// The distance the conservative tests add to a sphere's radius (c, r in view
// space) so that rounding never rejects what touches: 1e-9 of the magnitudes
// involved (far above double rounding, far below any distance a scene cares
// about) plus 1e-12. Shared by the chunk tests, the spot tests and explain.
double sphereTestSlack(const glm::dvec3& c, double r);
// Exact Euclidean distance from p to the chunk (0 inside).
double distanceToChunk(const FrustumChunk& chunk, const glm::dvec3& p);

enum class Slicing { Log, Linear };
const char* toString(Slicing s);

// Boundary i (0..cells) of `cells` slices over [lo, hi]: linear, or
// logarithmic lo*(hi/lo)^(i/cells). Boundary 0 is lo, boundary `cells` is hi.
double sliceBoundary(Slicing s, double lo, double hi, std::uint32_t cells, std::uint32_t i);
// Slice holding view depth d, clamped to [0, cells-1]; lo == hi maps to 0.
// Defined for every finite d (no NaN, no out-of-range cast).
std::uint32_t sliceOfDepth(Slicing s, double lo, double hi, std::uint32_t cells, double d);

// sliceOfDepth(s, lo, hi, cells, d) for many depths of one range: the inner
// boundaries worked out once, then a search (the same slice, bit for bit:
// sliceOfDepth's answer is defined by those boundaries). For the per-pixel
// lookups of the ground truth, the shading inputs and the CPU backend.
class SliceLocator {
public:
    SliceLocator() = default;
    SliceLocator(Slicing s, double lo, double hi, std::uint32_t cells);
    std::uint32_t operator()(double d) const;
    // sliceRangeMask(s, lo, hi, cells, a, b), bit for bit.
    std::uint32_t rangeMask(double a, double b) const;
    double lo() const { return lo_; }
    double hi() const { return hi_; }

private:
    Slicing s_ = Slicing::Linear;
    double lo_ = 0, hi_ = 0;
    std::uint32_t cells_ = 0;
    std::vector<double> inner_; // boundaries 1 .. cells-1
};
// Bitmask of slices that the depth interval [a, b] overlaps (a <= b), 0 when
// it misses [lo, hi] entirely. cells <= 32.
std::uint32_t sliceRangeMask(Slicing s, double lo, double hi, std::uint32_t cells, double a, double b);

} // namespace lc
