// The three sphere-vs-chunk tests against brute-force sampling. Containment in
// a chunk is decided here without the chunk's planes: a point is inside when
// its view depth lies in [depthMin, depthMax] and it projects into the tile's
// pixel rectangle.
#include "culling/math/tile_math.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace lc;

namespace {

struct World {
    Projection proj;
    TileGrid grid;
};

World makeWorld(ProjectionKind kind) {
    Camera cam;
    cam.projection = kind;
    cam.width = 96;
    cam.height = 64;
    cam.nearPlane = 0.5;
    cam.farPlane = 60.0;
    cam.fovYDeg = 55.0;
    cam.orthoHeight = 16.0;
    return {Projection(cam), TileGrid::make(96, 64, 16)};
}

bool insideChunk(const Projection& proj, const TileGrid::Rect& r, double a, double b, const glm::dvec3& p) {
    const double v = -p.z;
    if (v < a || v > b || v <= 0) return false;
    const glm::dvec2 px = proj.pixelFromView(p);
    return px.x >= r.x0 && px.x <= r.x1 && px.y >= r.y0 && px.y <= r.y1;
}

// A random point of the chunk: a pixel position inside the rect at a depth in [a, b].
glm::dvec3 pointInChunk(const Projection& proj, const TileGrid::Rect& r, double a, double b, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    return proj.viewPositionAt({r.x0 + u(rng) * (r.x1 - r.x0), r.y0 + u(rng) * (r.y1 - r.y0)},
                               a + u(rng) * (b - a));
}

const ProjectionKind kKinds[] = {ProjectionKind::Perspective, ProjectionKind::ReversedZ,
                                 ProjectionKind::Orthographic};

struct RandomChunk {
    TileGrid::Rect rect;
    double a, b;
    FrustumChunk chunk;
};

RandomChunk randomChunk(const World& w, std::mt19937& rng, bool degenerate) {
    std::uniform_int_distribution<std::uint32_t> tx(0, w.grid.tilesX - 1), ty(0, w.grid.tilesY - 1);
    std::uniform_real_distribution<double> d(0.5, 20.0);
    RandomChunk c;
    c.rect = w.grid.tileRect(tx(rng), ty(rng));
    c.a = d(rng);
    c.b = degenerate ? c.a : c.a + d(rng) * 0.5;
    c.chunk = makeFrustumChunk(w.proj, c.rect, c.a, c.b);
    return c;
}

} // namespace

// No test may say false when a point of the sphere lies in the chunk, and the
// tests nest: Exact => PlanesAabb => Planes.
TEST(SphereTests, NoFalseNegativesAndNesting) {
    std::mt19937 rng(1234);
    std::uniform_real_distribution<double> u(-1, 1), ur(0.05, 4.0);
    for (ProjectionKind kind : kKinds) {
        const World w = makeWorld(kind);
        int positives = 0, exactRejects = 0;
        for (int iter = 0; iter < 1500; ++iter) {
            const RandomChunk rc = randomChunk(w, rng, iter % 5 == 0);
            // Centre near the chunk: a chunk point plus an offset of the radius' scale.
            const double r = ur(rng);
            const glm::dvec3 c = pointInChunk(w.proj, rc.rect, rc.a, rc.b, rng) +
                                 glm::dvec3(u(rng), u(rng), u(rng)) * (r * 1.8);
            const bool planes = sphereIntersectsChunk(SphereTest::Planes, rc.chunk, c, r);
            const bool aabb = sphereIntersectsChunk(SphereTest::PlanesAabb, rc.chunk, c, r);
            const bool exact = sphereIntersectsChunk(SphereTest::Exact, rc.chunk, c, r);
            if (exact) EXPECT_TRUE(aabb);
            if (aabb) EXPECT_TRUE(planes);
            exactRejects += planes && !exact;
            // Sample the sphere (volume and surface) looking for a shared point.
            bool shared = false;
            for (int s = 0; s < 400 && !shared; ++s) {
                glm::dvec3 dir(u(rng), u(rng), u(rng));
                if (glm::length(dir) < 1e-6) continue;
                dir = glm::normalize(dir);
                const double t = s % 2 ? r : r * std::cbrt((u(rng) + 1) / 2);
                shared = insideChunk(w.proj, rc.rect, rc.a, rc.b, c + dir * t);
            }
            // And the chunk: points of the chunk inside the sphere.
            for (int s = 0; s < 400 && !shared; ++s)
                shared = glm::length(pointInChunk(w.proj, rc.rect, rc.a, rc.b, rng) - c) <= r;
            if (shared) {
                ++positives;
                EXPECT_TRUE(exact) << "exact: false negative, kind " << int(kind) << " iter " << iter;
                EXPECT_TRUE(aabb) << "planes+aabb: false negative";
                EXPECT_TRUE(planes) << "planes: false negative";
            }
        }
        EXPECT_GT(positives, 200); // the sampling does exercise the positive case
        EXPECT_GT(exactRejects, 0) << "exact should reject some spheres the planes test accepts";
    }
}

// distanceToChunk against the minimum distance to a dense sampling of the
// chunk's surface: the sampled minimum is an upper bound, and it exceeds the
// true distance by at most the sampling spacing.
TEST(SphereTests, ExactDistanceAgreesWithSampling) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<double> u(-1, 1);
    for (ProjectionKind kind : kKinds) {
        const World w = makeWorld(kind);
        for (int iter = 0; iter < 60; ++iter) {
            const RandomChunk rc = randomChunk(w, rng, iter % 4 == 0);
            const glm::dvec3 p = pointInChunk(w.proj, rc.rect, rc.a, rc.b, rng) +
                                 glm::dvec3(u(rng), u(rng), u(rng)) * 3.0;
            const int N = 40;
            double sampled = 1e300, spacing = 0;
            auto at = [&](double sx, double sy, double sz) {
                return w.proj.viewPositionAt({rc.rect.x0 + sx * (rc.rect.x1 - rc.rect.x0),
                                              rc.rect.y0 + sy * (rc.rect.y1 - rc.rect.y0)},
                                             rc.a + sz * (rc.b - rc.a));
            };
            // Six faces, each an N x N grid in (pixel, depth) parameters.
            for (int f = 0; f < 6; ++f)
                for (int i = 0; i <= N; ++i)
                    for (int j = 0; j <= N; ++j) {
                        const double s = double(i) / N, t = double(j) / N, e = (f & 1) ? 1.0 : 0.0;
                        const glm::dvec3 q = f < 2 ? at(e, s, t) : f < 4 ? at(s, e, t) : at(s, t, e);
                        sampled = std::min(sampled, glm::length(q - p));
                        if (i > 0) {
                            const double ds = 1.0 / N;
                            const glm::dvec3 q2 = f < 2 ? at(e, s - ds, t) : f < 4 ? at(s - ds, e, t) : at(s - ds, t, e);
                            spacing = std::max(spacing, glm::length(q - q2));
                        }
                        if (j > 0) {
                            const double dt = 1.0 / N;
                            const glm::dvec3 q2 = f < 2 ? at(e, s, t - dt) : f < 4 ? at(s, e, t - dt) : at(s, t - dt, e);
                            spacing = std::max(spacing, glm::length(q - q2));
                        }
                    }
            const double d = distanceToChunk(rc.chunk, p);
            if (insideChunk(w.proj, rc.rect, rc.a, rc.b, p)) {
                EXPECT_EQ(d, 0.0);
                continue;
            }
            EXPECT_LE(d, sampled + 1e-9);
            EXPECT_GE(d, sampled - spacing) << "kind " << int(kind) << " iter " << iter;
            // Exact is tight: a sphere a little smaller than the distance misses.
            if (d > 1e-6) {
                EXPECT_FALSE(sphereIntersectsChunk(SphereTest::Exact, rc.chunk, p, d * (1 - 1e-6)));
                EXPECT_TRUE(sphereIntersectsChunk(SphereTest::Exact, rc.chunk, p, d * (1 + 1e-9)));
            }
        }
    }
}

TEST(SphereTests, PointsInsideTheChunkHaveDistanceZero) {
    std::mt19937 rng(5);
    for (ProjectionKind kind : kKinds) {
        const World w = makeWorld(kind);
        for (int iter = 0; iter < 200; ++iter) {
            const RandomChunk rc = randomChunk(w, rng, false);
            const glm::dvec3 p = pointInChunk(w.proj, rc.rect, rc.a, rc.b, rng);
            EXPECT_NEAR(distanceToChunk(rc.chunk, p), 0.0, 1e-9);
            // A tiny sphere around a point of the chunk passes every test.
            for (SphereTest t : {SphereTest::Planes, SphereTest::PlanesAabb, SphereTest::Exact})
                EXPECT_TRUE(sphereIntersectsChunk(t, rc.chunk, p, 1e-6));
        }
    }
}

TEST(SphereTests, DegenerateChunkAlongTheViewAxis) {
    const World w = makeWorld(ProjectionKind::Perspective);
    const auto rect = w.grid.tileRect(2, 1);
    const FrustumChunk ch = makeFrustumChunk(w.proj, rect, 5.0, 5.0);
    const glm::dvec3 onChunk = w.proj.viewPositionAt({(rect.x0 + rect.x1) / 2.0, (rect.y0 + rect.y1) / 2.0}, 5.0);
    EXPECT_NEAR(distanceToChunk(ch, onChunk), 0.0, 1e-9);
    // Straight behind the flat chunk along the view axis: distance is the depth gap.
    const glm::dvec3 behind = onChunk + glm::dvec3(0, 0, -2.0);
    EXPECT_NEAR(distanceToChunk(ch, behind), 2.0, 1e-9);
    EXPECT_TRUE(sphereIntersectsChunk(SphereTest::Exact, ch, behind, 2.01));
    EXPECT_FALSE(sphereIntersectsChunk(SphereTest::Exact, ch, behind, 1.99));
    EXPECT_FALSE(sphereIntersectsChunk(SphereTest::Planes, ch, behind, 1.99));
}

// The classic false positive of the plane test: a sphere near a chunk's corner,
// outside two planes by less than r each but farther than r from the corner.
TEST(SphereTests, PlaneTestCornerFalsePositiveIsRejectedByExact) {
    const World w = makeWorld(ProjectionKind::Orthographic);
    const auto rect = w.grid.tileRect(1, 1);
    const FrustumChunk ch = makeFrustumChunk(w.proj, rect, 2.0, 4.0);
    // Near-top-left corner, pushed out diagonally in x, y and towards the eye.
    const glm::dvec3 corner = ch.corners[0];
    const glm::dvec3 c = corner + glm::dvec3(-0.8, 0.8, 0.8);
    const double r = 1.0; // each plane is 0.8 away, the corner sqrt(3)*0.8 = 1.39
    EXPECT_TRUE(sphereIntersectsChunk(SphereTest::Planes, ch, c, r));
    EXPECT_FALSE(sphereIntersectsChunk(SphereTest::Exact, ch, c, r));
    EXPECT_NEAR(distanceToChunk(ch, c), std::sqrt(3.0) * 0.8, 1e-9);
}
