// Tile grid, tile side planes, frustum chunks and depth slicing.
#include "culling/math/tile_math.hpp"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>

using namespace lc;

namespace {

Camera camera(ProjectionKind kind, std::uint32_t w, std::uint32_t h) {
    Camera cam;
    cam.projection = kind;
    cam.width = w;
    cam.height = h;
    cam.nearPlane = 0.25;
    cam.farPlane = 80.0;
    cam.fovYDeg = 70.0;
    cam.orthoHeight = 12.0;
    return cam;
}

const ProjectionKind kKinds[] = {ProjectionKind::Perspective, ProjectionKind::PerspectiveGL,
                                 ProjectionKind::ReversedZ, ProjectionKind::Orthographic,
                                 ProjectionKind::OrthographicGL};

} // namespace

TEST(TileGrid, PartialEdgeTiles) {
    const TileGrid g = TileGrid::make(17, 9, 4);
    EXPECT_EQ(g.tilesX, 5u);
    EXPECT_EQ(g.tilesY, 3u);
    EXPECT_EQ(g.tileCount(), 15u);
    const auto r = g.tileRect(4, 2);
    EXPECT_EQ(r.x0, 16u);
    EXPECT_EQ(r.x1, 17u);
    EXPECT_EQ(r.y0, 8u);
    EXPECT_EQ(r.y1, 9u);
    EXPECT_EQ(g.tileOfPixel(16, 8), 14u);
    EXPECT_EQ(g.tileOfPixel(3, 4), g.tileIndex(0, 1));

    const TileGrid hd = TileGrid::make(1366, 768, 16);
    EXPECT_EQ(hd.tilesX, 86u); // 1366 / 16 = 85.375
    EXPECT_EQ(hd.tilesY, 48u);
    EXPECT_EQ(hd.tileRect(85, 47).x1, 1366u);

    const TileGrid one = TileGrid::make(1, 1, 16);
    EXPECT_EQ(one.tileCount(), 1u);
    EXPECT_EQ(one.tileRect(0, 0).x1, 1u);

    // Every pixel belongs to exactly the tile whose rect holds it.
    for (std::uint32_t y = 0; y < 9; ++y)
        for (std::uint32_t x = 0; x < 17; ++x) {
            const std::uint32_t t = g.tileOfPixel(x, y);
            const auto rr = g.tileRect(t % g.tilesX, t / g.tilesX);
            EXPECT_TRUE(x >= rr.x0 && x < rr.x1 && y >= rr.y0 && y < rr.y1);
        }
}

TEST(TilePlanes, PassThroughPixelEdgesWithInwardUnitNormals) {
    for (ProjectionKind kind : kKinds) {
        const Projection proj(camera(kind, 37, 23));
        const TileGrid g = TileGrid::make(37, 23, 8);
        for (std::uint32_t ty = 0; ty < g.tilesY; ++ty)
            for (std::uint32_t tx = 0; tx < g.tilesX; ++tx) {
                const auto r = g.tileRect(tx, ty);
                const auto planes = tileSidePlanes(proj, r);
                for (const Plane& p : planes) EXPECT_NEAR(glm::length(glm::dvec3(p)), 1.0, 1e-12);
                if (proj.orthographic()) {
                    // Axis-aligned.
                    EXPECT_EQ(planes[0].y, 0.0);
                    EXPECT_EQ(planes[0].z, 0.0);
                    EXPECT_EQ(planes[2].x, 0.0);
                    EXPECT_EQ(planes[2].z, 0.0);
                } else {
                    for (const Plane& p : planes) EXPECT_EQ(p.w, 0.0) << "through the eye";
                }
                for (double v : {0.25, 1.0, 33.0}) {
                    // Points on the tile's outer pixel edges lie on the planes
                    // (the partial tile's right/bottom plane is the image edge).
                    for (double s : {0.0, 0.3, 1.0}) {
                        const double y = r.y0 + s * (r.y1 - r.y0), x = r.x0 + s * (r.x1 - r.x0);
                        EXPECT_NEAR(signedDistance(planes[0], proj.viewPositionAt({double(r.x0), y}, v)), 0, 1e-9);
                        EXPECT_NEAR(signedDistance(planes[1], proj.viewPositionAt({double(r.x1), y}, v)), 0, 1e-9);
                        EXPECT_NEAR(signedDistance(planes[2], proj.viewPositionAt({x, double(r.y0)}, v)), 0, 1e-9);
                        EXPECT_NEAR(signedDistance(planes[3], proj.viewPositionAt({x, double(r.y1)}, v)), 0, 1e-9);
                    }
                    // Inward: the tile's centre is inside, a point a quarter pixel
                    // outside each edge is outside that plane only.
                    const glm::dvec2 c{(r.x0 + r.x1) / 2.0, (r.y0 + r.y1) / 2.0};
                    for (const Plane& p : planes) EXPECT_GT(signedDistance(p, proj.viewPositionAt(c, v)), 0);
                    EXPECT_LT(signedDistance(planes[0], proj.viewPositionAt({r.x0 - 0.25, c.y}, v)), 0);
                    EXPECT_LT(signedDistance(planes[1], proj.viewPositionAt({r.x1 + 0.25, c.y}, v)), 0);
                    EXPECT_LT(signedDistance(planes[2], proj.viewPositionAt({c.x, r.y0 - 0.25}, v)), 0);
                    EXPECT_LT(signedDistance(planes[3], proj.viewPositionAt({c.x, r.y1 + 0.25}, v)), 0);
                }
            }
        // The last column's right plane passes through the image's right edge x = 37.
        const auto last = tileSidePlanes(proj, g.tileRect(g.tilesX - 1, 0));
        EXPECT_NEAR(signedDistance(last[1], proj.viewPositionAt({37.0, 3.0}, 2.0)), 0, 1e-9);
        EXPECT_LT(signedDistance(last[1], proj.viewPositionAt({37.5, 3.0}, 2.0)), 0);
    }
}

TEST(FrustumChunk, CornersPlanesAndDepths) {
    for (ProjectionKind kind : kKinds) {
        const Projection proj(camera(kind, 40, 30));
        const TileGrid g = TileGrid::make(40, 30, 16);
        const auto r = g.tileRect(2, 1); // partial 8x14 tile
        for (auto [a, b] : {std::pair{1.0, 9.0}, std::pair{4.0, 4.0}}) {
            const FrustumChunk ch = makeFrustumChunk(proj, r, a, b);
            EXPECT_EQ(ch.depthMin, a);
            EXPECT_EQ(ch.depthMax, b);
            for (int i = 0; i < 8; ++i) {
                EXPECT_NEAR(-ch.corners[i].z, i < 4 ? a : b, 1e-12);
                for (const Plane& p : ch.planes) EXPECT_GE(signedDistance(p, ch.corners[i]), -1e-9);
            }
            // Corner order: near tl, tr, br, bl.
            EXPECT_NEAR(proj.pixelFromView(ch.corners[0]).x, 32.0, 1e-9);
            EXPECT_NEAR(proj.pixelFromView(ch.corners[0]).y, 16.0, 1e-9);
            EXPECT_NEAR(proj.pixelFromView(ch.corners[2]).x, 40.0, 1e-9);
            EXPECT_NEAR(proj.pixelFromView(ch.corners[2]).y, 30.0, 1e-9);
            // Near plane at depth a, far at depth b.
            EXPECT_NEAR(signedDistance(ch.planes[4], {0, 0, -a}), 0, 1e-12);
            EXPECT_LT(signedDistance(ch.planes[4], {0, 0, -(a - 0.1)}), 0);
            EXPECT_NEAR(signedDistance(ch.planes[5], {0, 0, -b}), 0, 1e-12);
            EXPECT_LT(signedDistance(ch.planes[5], {0, 0, -(b + 0.1)}), 0);
        }
    }
}

TEST(Slicing, BoundariesAreMonotoneWithExactEnds) {
    for (Slicing s : {Slicing::Log, Slicing::Linear})
        for (std::uint32_t cells : {1u, 2u, 7u, 32u}) {
            EXPECT_EQ(sliceBoundary(s, 0.1, 1000.0, cells, 0), 0.1);
            EXPECT_EQ(sliceBoundary(s, 0.1, 1000.0, cells, cells), 1000.0);
            for (std::uint32_t i = 0; i < cells; ++i)
                EXPECT_LT(sliceBoundary(s, 0.1, 1000.0, cells, i), sliceBoundary(s, 0.1, 1000.0, cells, i + 1));
        }
    // Log slicing: every slice spans the same depth ratio.
    const double r0 = sliceBoundary(Slicing::Log, 1, 1024, 10, 1) / 1.0;
    EXPECT_NEAR(r0, 2.0, 1e-12);
    EXPECT_NEAR(sliceBoundary(Slicing::Log, 1, 1024, 10, 5), 32.0, 1e-9);
    EXPECT_NEAR(sliceBoundary(Slicing::Linear, 2, 12, 5, 3), 8.0, 1e-12);
}

TEST(Slicing, SliceOfDepthAgreesWithBoundaries) {
    std::mt19937 rng(3);
    for (Slicing s : {Slicing::Log, Slicing::Linear})
        for (auto [lo, hi] : {std::pair{0.1, 1000.0}, std::pair{1e-6, 1e12}, std::pair{5.0, 5.0 + 1e-9},
                              std::pair{3.0, 4.0}})
            for (std::uint32_t cells : {1u, 3u, 32u}) {
                std::uniform_real_distribution<double> t(0, 1);
                for (int i = 0; i < 300; ++i) {
                    const double d = s == Slicing::Log ? lo * std::pow(hi / lo, t(rng)) : lo + (hi - lo) * t(rng);
                    const std::uint32_t k = sliceOfDepth(s, lo, hi, cells, d);
                    ASSERT_LT(k, cells);
                    EXPECT_GE(d, sliceBoundary(s, lo, hi, cells, k));
                    if (k + 1 < cells) EXPECT_LT(d, sliceBoundary(s, lo, hi, cells, k + 1));
                }
                // Boundaries themselves start their slice.
                for (std::uint32_t k = 0; k < cells; ++k)
                    EXPECT_EQ(sliceOfDepth(s, lo, hi, cells, sliceBoundary(s, lo, hi, cells, k)), k);
            }
}

TEST(Slicing, ExtremeInputsClampWithoutNaN) {
    const double big = DBL_MAX, tiny = DBL_MIN;
    for (Slicing s : {Slicing::Log, Slicing::Linear}) {
        for (double d : {-big, -1.0, 0.0, tiny, 0.05, big}) {
            const std::uint32_t k = sliceOfDepth(s, 0.1, 100.0, 32, d);
            EXPECT_LT(k, 32u);
            EXPECT_EQ(k, d <= 0.1 ? 0u : (d >= 100 ? 31u : k));
        }
        // lo == hi: everything in slice 0.
        for (double d : {-5.0, 2.0, 2.5, 1e300}) EXPECT_EQ(sliceOfDepth(s, 2.0, 2.0, 32, d), 0u);
        EXPECT_EQ(sliceRangeMask(s, 2.0, 2.0, 32, 1.0, 3.0), 1u);
        EXPECT_EQ(sliceRangeMask(s, 2.0, 2.0, 32, 2.5, 3.0), 0u);
        // Huge ranges, degenerate cells count.
        EXPECT_LT(sliceOfDepth(s, 1e-300, 1e300, 32, 1.0), 32u);
        EXPECT_EQ(sliceRangeMask(s, 0.1, 100.0, 32, -big, big), 0xFFFFFFFFu);
        EXPECT_EQ(sliceRangeMask(s, 0.1, 100.0, 1, -1.0, 0.5), 1u);
        EXPECT_FALSE(std::isnan(sliceBoundary(s, 1e-300, 1e300, 32, 17)));
    }
}

TEST(Slicing, RangeMaskCoversExactlyTheOverlappedSlices) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-5.0, 60.0);
    for (Slicing s : {Slicing::Log, Slicing::Linear})
        for (std::uint32_t cells : {1u, 5u, 32u}) {
            const double lo = 0.5, hi = 50.0;
            for (int i = 0; i < 500; ++i) {
                double a = u(rng), b = u(rng);
                if (a > b) std::swap(a, b);
                const std::uint32_t m = sliceRangeMask(s, lo, hi, cells, a, b);
                for (std::uint32_t k = 0; k < cells; ++k) {
                    const double k0 = sliceBoundary(s, lo, hi, cells, k);
                    const double k1 = sliceBoundary(s, lo, hi, cells, k + 1);
                    // Slice k holds [k0, k1) (the last is closed): overlap with [a, b].
                    const bool overlaps = a <= hi && b >= lo && b >= k0 && (k + 1 == cells ? a <= k1 : a < k1);
                    EXPECT_EQ(bool(m & (1u << k)), overlaps)
                        << "a=" << a << " b=" << b << " k=" << k << " cells=" << cells;
                }
            }
            // Behind the near plane: the interval is clipped, so it starts at slice 0.
            EXPECT_EQ(sliceRangeMask(s, lo, hi, cells, -3.0, 0.6) & 1u, 1u);
            EXPECT_EQ(sliceRangeMask(s, lo, hi, cells, -3.0, 0.4), 0u);
            EXPECT_EQ(sliceRangeMask(s, lo, hi, cells, 51.0, 52.0), 0u);
        }
}

TEST(Names, TestAndSlicingStrings) {
    EXPECT_STREQ(toString(SphereTest::Planes), "planes");
    EXPECT_STREQ(toString(SphereTest::PlanesAabb), "planes+aabb");
    EXPECT_STREQ(toString(SphereTest::Exact), "exact");
    EXPECT_STREQ(toString(Slicing::Log), "log");
    EXPECT_STREQ(toString(Slicing::Linear), "linear");
}

// SliceLocator answers as sliceOfDepth does, bit for bit: at every boundary,
// one ulp either side, random depths, out of range, NaN and degenerate ranges
// (the ground truth and the shading inputs look up every pixel through it);
// its range masks are sliceRangeMask's.
TEST(Slicing, LocatorAnswersAsSliceOfDepth) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::uint64_t checked = 0;
    for (Slicing s : {Slicing::Log, Slicing::Linear})
        for (std::uint32_t cells : {1u, 2u, 3u, 8u, 17u, 32u})
            for (auto [lo, hi] : std::initializer_list<std::pair<double, double>>{
                     {0.1, 100.0}, {1.0, 1.0 + 1e-9}, {-2.0, 5.0}, {0.0, 3.0}, {2.0, 2.0}, {5.0, 1.0}, {1e-6, 1e6}}) {
                const SliceLocator locate(s, lo, hi, cells);
                std::vector<double> depths = {lo, hi, -1e300, 1e300, nan, std::nextafter(lo, -1e300),
                                              std::nextafter(hi, 1e300)};
                for (std::uint32_t i = 0; i <= cells; ++i) {
                    const double b = sliceBoundary(s, lo, hi, cells, i);
                    depths.insert(depths.end(), {b, std::nextafter(b, -1e300), std::nextafter(b, 1e300)});
                }
                for (int k = 0; k < 200; ++k) depths.push_back(lo + (hi - lo) * (1.2 * u(rng) - 0.1));
                for (double d : depths) {
                    ASSERT_EQ(locate(d), sliceOfDepth(s, lo, hi, cells, d))
                        << toString(s) << " cells " << cells << " [" << lo << ", " << hi << "] d " << d;
                    ++checked;
                }
                // Its range masks (the raster slices' decode) are sliceRangeMask's.
                for (std::size_t k = 0; k + 1 < depths.size(); ++k) {
                    const double a = std::min(depths[k], depths[k + 1]), b = std::max(depths[k], depths[k + 1]);
                    for (auto [x, y] : {std::pair{a, b}, std::pair{depths[k], depths[k + 1]}, std::pair{a, a}})
                        ASSERT_EQ(locate.rangeMask(x, y), sliceRangeMask(s, lo, hi, cells, x, y))
                            << toString(s) << " cells " << cells << " [" << lo << ", " << hi << "] [" << x << ", "
                            << y << "]";
                }
            }
    EXPECT_GT(checked, 10000u);
}
