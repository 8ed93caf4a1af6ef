// The CPU reference rasteriser: analytic depth of full-screen planes for every
// projection kind, the top-left fill rule, the y orientation, clipping and the
// depth test.
#include "culling/core/depth.hpp"
#include "culling/core/errors.hpp"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <limits>
#include <random>

using namespace lc;

namespace {

// Camera at the origin looking down -Z: world space == view space.
Camera viewCamera(ProjectionKind kind, std::uint32_t w, std::uint32_t h, double farPlane = 100.0) {
    Camera cam;
    cam.position = {0, 0, 0};
    cam.target = {0, 0, -1};
    cam.up = {0, 1, 0};
    cam.projection = kind;
    cam.width = w;
    cam.height = h;
    cam.nearPlane = 0.5;
    cam.farPlane = farPlane;
    cam.fovYDeg = 60;
    cam.orthoHeight = 10;
    return cam;
}

void addTriangle(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c) {
    const auto base = std::uint32_t(m.vertexCount());
    for (const glm::dvec3& p : {a, b, c}) {
        m.positions.push_back(float(p.x));
        m.positions.push_back(float(p.y));
        m.positions.push_back(float(p.z));
    }
    m.indices.insert(m.indices.end(), {base, base + 1, base + 2});
}

// The float-rounded vertex as the rasteriser sees it.
glm::dvec3 f(glm::dvec3 p) { return glm::dvec3(glm::vec3(p)); }

struct KindCase {
    ProjectionKind kind;
    double farPlane;
};
const KindCase kKinds[] = {{ProjectionKind::Perspective, 100.0},
                           {ProjectionKind::PerspectiveGL, 100.0},
                           {ProjectionKind::ReversedZ, 100.0},
                           {ProjectionKind::ReversedZ, std::numeric_limits<double>::infinity()},
                           {ProjectionKind::Orthographic, 100.0},
                           {ProjectionKind::OrthographicGL, 100.0}};

} // namespace

// A quad far larger than the view (so it is clipped by the guard band), either
// facing the camera or tilted: every pixel holds the depth where the pixel
// centre's ray meets the plane, to float precision.
TEST(Raster, FullScreenPlaneHasAnalyticDepthForEveryKind) {
    for (const KindCase& kc : kKinds) {
        for (int tilted = 0; tilted < 2; ++tilted) {
            Scene scene;
            scene.camera = viewCamera(kc.kind, 61, 37, kc.farPlane);
            const Projection proj(scene.camera);
            // Plane through (0,0,-6) with normal n: n.p = n.(0,0,-6).
            const glm::dvec3 n = glm::normalize(tilted ? glm::dvec3(0.15, -0.1, 1.0) : glm::dvec3(0, 0, 1));
            const double k = glm::dot(n, glm::dvec3(0, 0, -6));
            // Quad corners on the plane: solve z from x, y.
            auto on = [&](double x, double y) { return glm::dvec3(x, y, (k - n.x * x - n.y * y) / n.z); };
            const double e = 200.0;
            Mesh m;
            addTriangle(m, on(-e, -e), on(e, -e), on(e, e));
            addTriangle(m, on(-e, -e), on(e, e), on(-e, e));
            scene.meshes.push_back(m);
            const DepthImage img = rasterizeDepthCpu(scene, proj);
            ASSERT_EQ(img.width, 61u);
            ASSERT_EQ(img.height, 37u);
            EXPECT_EQ(img.clearDepth, float(proj.clearDepth()));
            EXPECT_EQ(img.geometryPixelCount(), 61u * 37u);
            // The plane through the float-rounded vertices (what was drawn).
            const glm::dvec3 a = f(on(-e, -e)), b = f(on(e, -e)), c = f(on(e, e));
            const glm::dvec3 nn = glm::normalize(glm::cross(b - a, c - a));
            const double kk = glm::dot(nn, a);
            double worst = 0;
            for (std::uint32_t y = 0; y < 37; ++y)
                for (std::uint32_t x = 0; x < 61; ++x) {
                    // Ray through the pixel centre: p(v) = viewPositionAt(pixel, v) is affine in v.
                    const glm::dvec3 p0 = proj.viewPositionAt({x + 0.5, y + 0.5}, 0.0);
                    const glm::dvec3 p1 = proj.viewPositionAt({x + 0.5, y + 0.5}, 1.0);
                    const double v = (kk - glm::dot(nn, p0)) / glm::dot(nn, p1 - p0);
                    const double expected = proj.windowDepthFromViewDepth(v);
                    const double got = img.at(x, y);
                    worst = std::max(worst, std::abs(got - expected));
                    ASSERT_NEAR(got, expected, 4 * FLT_EPSILON * std::max(std::abs(expected), 1e-3))
                        << "kind " << int(kc.kind) << " tilted " << tilted << " pixel " << x << "," << y;
                }
        }
    }
}

// Triangles sharing edges (a fan around an interior point of a random convex
// polygon, vertices snapped onto pixel centres so that edges run exactly
// through pixel centres) cover every interior pixel exactly once. Each triangle
// is rasterised alone and the coverage counted.
TEST(Raster, TopLeftRuleCoversSharedEdgesExactlyOnce) {
    Scene base;
    base.camera = viewCamera(ProjectionKind::Orthographic, 48, 40);
    const Projection proj(base.camera);
    std::mt19937 rng(17);
    for (int round = 0; round < 6; ++round) {
        // Polygon vertices at pixel centres on a circle, plus a centre vertex.
        const int sides = 5 + round;
        std::vector<glm::dvec2> poly;
        for (int i = 0; i < sides; ++i) {
            const double ang = 2 * M_PI * i / sides + 0.1 * round;
            poly.push_back({std::floor(24 + 18 * std::cos(ang)) + 0.5, std::floor(20 + 16 * std::sin(ang)) + 0.5});
        }
        const glm::dvec2 centre{24.5 + (round % 3), 20.5 - (round % 2)};
        auto world = [&](glm::dvec2 px) { return proj.viewPositionAt(px, 5.0); };
        std::vector<int> coverage(48 * 40, 0);
        for (int i = 0; i < sides; ++i) {
            Scene s = base;
            Mesh m;
            // Alternate the winding: both faces are drawn.
            if (i % 2) addTriangle(m, world(centre), world(poly[i]), world(poly[(i + 1) % sides]));
            else addTriangle(m, world(centre), world(poly[(i + 1) % sides]), world(poly[i]));
            s.meshes.push_back(m);
            const DepthImage img = rasterizeDepthCpu(s, proj);
            for (std::uint32_t y = 0; y < 40; ++y)
                for (std::uint32_t x = 0; x < 48; ++x) coverage[y * 48 + x] += img.hasGeometry(x, y);
        }
        // Compare with the polygon (convex, counter-clockwise on screen with y down? use a
        // winding-independent inside test): strictly inside -> covered once, outside -> never.
        auto side = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 p) {
            return (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
        };
        int covered = 0;
        for (std::uint32_t y = 0; y < 40; ++y)
            for (std::uint32_t x = 0; x < 48; ++x) {
                const glm::dvec2 p{x + 0.5, y + 0.5};
                bool allPos = true, allNeg = true, onEdge = false;
                for (int i = 0; i < sides; ++i) {
                    const double sd = side(poly[i], poly[(i + 1) % sides], p);
                    allPos &= sd > 0;
                    allNeg &= sd < 0;
                    onEdge |= sd == 0;
                }
                const int c = coverage[y * 48 + x];
                EXPECT_LE(c, 1) << "pixel " << x << "," << y << " drawn twice";
                if ((allPos || allNeg) && !onEdge) {
                    EXPECT_EQ(c, 1) << "interior pixel " << x << "," << y << " missed";
                } else if (!onEdge) {
                    EXPECT_EQ(c, 0) << "exterior pixel " << x << "," << y;
                }
                covered += c;
            }
        EXPECT_GT(covered, 300);
    }
}

// The same with a regular grid of quads split along alternating diagonals, in
// a perspective view: every pixel of the grid's area is covered once.
TEST(Raster, QuadGridHasNoCracksOrOverlaps) {
    Scene base;
    base.camera = viewCamera(ProjectionKind::Perspective, 40, 30);
    const Projection proj(base.camera);
    // Grid points at pixel centres 4 px apart covering [2.5, 38.5] x [1.5, 28.5].
    std::vector<int> coverage(40 * 30, 0);
    for (int gy = 0; gy < 3; ++gy)
        for (int gx = 0; gx < 4; ++gx) {
            auto w = [&](double px, double py) { return proj.viewPositionAt({px, py}, 3.0 + 0.1 * gx); };
            const double x0 = 2.5 + 9 * gx, x1 = x0 + 9, y0 = 1.5 + 9 * gy, y1 = y0 + 9;
            Scene s = base;
            Mesh m;
            addTriangle(m, w(x0, y0), w(x1, y0), w(x1, y1));
            s.meshes.push_back(m);
            const DepthImage a = rasterizeDepthCpu(s, proj);
            Scene s2 = base;
            Mesh m2;
            addTriangle(m2, w(x0, y0), w(x1, y1), w(x0, y1));
            s2.meshes.push_back(m2);
            const DepthImage b = rasterizeDepthCpu(s2, proj);
            for (std::size_t i = 0; i < coverage.size(); ++i)
                coverage[i] += (a.depth[i] != a.clearDepth) + (b.depth[i] != b.clearDepth);
        }
    // The neighbouring quads sit at different depths but share their grid lines
    // in screen space only approximately (different depths: float rounding), so
    // check the inner region of each single quad's two triangles and the union.
    int once = 0;
    for (std::uint32_t y = 0; y < 30; ++y)
        for (std::uint32_t x = 0; x < 40; ++x) {
            const double px = x + 0.5, py = y + 0.5;
            const bool inside = px > 2.5 && px < 38.5 && py > 1.5 && py < 28.5;
            const int c = coverage[y * 40 + x];
            if (inside) EXPECT_GE(c, 1) << x << "," << y;
            else if (px < 2.5 || px > 38.5 || py < 1.5 || py > 28.5) EXPECT_EQ(c, 0) << x << "," << y;
            once += c == 1;
        }
    EXPECT_GT(once, 900);
}

TEST(Raster, GeometryAboveTheAxisLandsInTheTopRows) {
    for (const KindCase& kc : kKinds) {
        Scene scene;
        scene.camera = viewCamera(kc.kind, 32, 24, kc.farPlane);
        const Projection proj(scene.camera);
        Mesh m;
        // A triangle entirely above the view axis (view y > 0), in front of the camera.
        addTriangle(m, {-1, 0.5, -5}, {1, 0.5, -5}, {0, 2, -5});
        scene.meshes.push_back(m);
        const DepthImage img = rasterizeDepthCpu(scene, proj);
        ASSERT_GT(img.geometryPixelCount(), 0u);
        for (std::uint32_t y = 0; y < 24; ++y)
            for (std::uint32_t x = 0; x < 32; ++x)
                if (img.hasGeometry(x, y)) EXPECT_LT(y, 12u) << "kind " << int(kc.kind);
    }
}

TEST(Raster, ClipsAtTheNearPlaneAndDropsGeometryBehindTheCamera) {
    for (const KindCase& kc : kKinds) {
        Scene scene;
        scene.camera = viewCamera(kc.kind, 32, 24, kc.farPlane);
        const Projection proj(scene.camera);
        Mesh behind;
        addTriangle(behind, {-1, -1, 2}, {1, -1, 2}, {0, 1, 2});
        scene.meshes.push_back(behind);
        EXPECT_EQ(rasterizeDepthCpu(scene, proj).geometryPixelCount(), 0u);
        // A floor running from behind the camera into the distance, sloping down
        // (an orthographic camera would see a level floor edge-on).
        Mesh floor;
        addTriangle(floor, {-50, -1, 5}, {50, -1, 5}, {0, -4, -60});
        scene.meshes = {floor};
        const DepthImage img = rasterizeDepthCpu(scene, proj);
        EXPECT_GT(img.geometryPixelCount(), 0u) << "kind " << int(kc.kind);
        for (std::uint32_t y = 0; y < 24; ++y)
            for (std::uint32_t x = 0; x < 32; ++x) {
                if (!img.hasGeometry(x, y)) continue;
                const double d = img.at(x, y);
                EXPECT_GE(d, 0.0);
                EXPECT_LE(d, 1.0);
                const double v = proj.viewDepthFromWindowDepth(d);
                EXPECT_GE(v, 0.5 * (1 - 1e-5)); // nothing nearer than the near plane
                EXPECT_GE(y, 12u);              // the floor is below the view axis
            }
    }
}

TEST(Raster, NearerSurfaceWinsForStandardAndReversedDepth) {
    for (const KindCase& kc : kKinds) {
        Scene scene;
        scene.camera = viewCamera(kc.kind, 20, 20, kc.farPlane);
        const Projection proj(scene.camera);
        Mesh m;
        // Far quad first, then a near one over the left half, then the far one again.
        addTriangle(m, {-50, -50, -9}, {50, -50, -9}, {0, 50, -9});
        addTriangle(m, {-50, -50, -3}, {0, -50, -3}, {0, 50, -3});
        addTriangle(m, {-50, -50, -9}, {50, -50, -9}, {0, 50, -9});
        scene.meshes.push_back(m);
        const DepthImage img = rasterizeDepthCpu(scene, proj);
        const double dn = proj.windowDepthFromViewDepth(3), df = proj.windowDepthFromViewDepth(9);
        EXPECT_NEAR(img.at(2, 10), dn, 1e-6) << int(kc.kind);
        EXPECT_NEAR(img.at(17, 10), df, 1e-6) << int(kc.kind);
    }
}

TEST(Raster, TinyAndOddResolutions) {
    for (auto [w, h] : {std::pair{1u, 1u}, std::pair{17u, 9u}}) {
        Scene scene;
        scene.camera = viewCamera(ProjectionKind::Perspective, w, h);
        const Projection proj(scene.camera);
        Mesh m;
        addTriangle(m, {-100, -100, -4}, {100, -100, -4}, {0, 100, -4});
        scene.meshes.push_back(m);
        const DepthImage img = rasterizeDepthCpu(scene, proj);
        EXPECT_EQ(img.depth.size(), std::size_t(w) * h);
        EXPECT_EQ(img.geometryPixelCount(), std::size_t(w) * h);
    }
}

TEST(Raster, CancelTokenStopsTheRaster) {
    Scene scene;
    scene.camera = viewCamera(ProjectionKind::Perspective, 64, 64);
    const Projection proj(scene.camera);
    Mesh m;
    for (int i = 0; i < 10000; ++i) addTriangle(m, {-1, -1, -4}, {1, -1, -4}, {0, 1, -4});
    scene.meshes.push_back(m);
    CancelToken token;
    token.cancelled = true;
    EXPECT_THROW(rasterizeDepthCpu(scene, proj, &token), Cancelled);
}
