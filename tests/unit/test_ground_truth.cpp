// Ground truth and metrics on hand-built cases whose answers are known, the
// spatial index against brute force, and the Lambert shading against
// hand-computed values.
#include "culling/core/errors.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/scene/scene_io.hpp"
#include "truth/light_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <random>

using namespace lc;

namespace {

const double kInf = std::numeric_limits<double>::infinity();

// Orthographic camera at the origin looking down -Z whose pixels are exactly
// one world unit: pixel (px, py) has its centre at view
// (px + 0.5 - w/2, h/2 - py - 0.5).
Camera orthoCamera(std::uint32_t w, std::uint32_t h, std::uint32_t tile) {
    Camera c;
    c.position = {0, 0, 0};
    c.target = {0, 0, -1};
    c.up = {0, 1, 0};
    c.projection = ProjectionKind::Orthographic;
    c.orthoHeight = double(h);
    c.nearPlane = 0.1;
    c.farPlane = 100;
    c.width = w;
    c.height = h;
    c.tileSize = tile;
    return c;
}

DepthImage wall(const Projection& proj, double viewDepth) {
    DepthImage d;
    d.width = proj.width();
    d.height = proj.height();
    d.clearDepth = float(proj.clearDepth());
    d.depth.assign(std::size_t(d.width) * d.height, float(proj.windowDepthFromViewDepth(viewDepth)));
    return d;
}

void addLight(ViewLights& l, glm::dvec3 c, double r, glm::dvec3 power = glm::dvec3(1.0)) {
    l.centers.push_back(c);
    l.radii.push_back(r);
    l.power.push_back(power);
}

// A one-list-per-tile result (algorithm `alg`, no depth use) with the given
// lists; every tile gets the depth bounds of the image's geometry.
CullResult tileResult(const TileGrid& grid, const std::vector<std::vector<std::uint32_t>>& lists,
                      const DepthImage& depth, const Projection& proj, Algorithm alg = Algorithm::MinMax) {
    CullResult r;
    r.algorithm = alg;
    r.settings.algorithm = alg;
    r.grid = grid;
    r.listsPerTile = 1;
    r.tileDepthMin.assign(grid.tileCount(), kInf);
    r.tileDepthMax.assign(grid.tileCount(), -kInf);
    for (std::uint32_t y = 0; y < depth.height; ++y)
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            if (!depth.hasGeometry(x, y)) continue;
            const double v = proj.viewDepthFromWindowDepth(depth.at(x, y));
            const auto t = grid.tileOfPixel(x, y);
            r.tileDepthMin[t] = std::min(r.tileDepthMin[t], v);
            r.tileDepthMax[t] = std::max(r.tileDepthMax[t], v);
        }
    if (alg == Algorithm::TwoPointFiveD) r.cellMask.assign(grid.tileCount(), 1);
    for (const auto& l : lists) {
        r.listOffset.push_back(std::uint32_t(r.lightIndices.size()));
        r.listCount.push_back(std::uint32_t(l.size()));
        r.lightIndices.insert(r.lightIndices.end(), l.begin(), l.end());
    }
    return r;
}

CullResult allResult(const TileGrid& grid, std::size_t lightCount) {
    CullResult r;
    r.algorithm = r.settings.algorithm = Algorithm::All;
    r.grid = grid;
    r.tileDepthMin.assign(grid.tileCount(), kInf);
    r.tileDepthMax.assign(grid.tileCount(), -kInf);
    r.listOffset = {0};
    r.listCount = {std::uint32_t(lightCount)};
    for (std::uint32_t i = 0; i < lightCount; ++i) r.lightIndices.push_back(i);
    return r;
}

GroundTruthOptions noImage() {
    GroundTruthOptions o;
    o.imageError = false;
    return o;
}

// The 4x4 case: a wall at view depth 5, 2x2-pixel tiles, one light centred on
// pixel (1,0) = view (-0.5, 1.5, -5) with radius 1.05. It contains exactly the
// centres of pixels (1,0) (distance 0), (0,0), (2,0) and (1,1) (distance 1);
// (0,1), (2,1) are at sqrt(2) > 1.05. Pixel (2,0) lies in tile 1, the others
// in tile 0.
struct FourByFour {
    Camera cam = orthoCamera(4, 4, 2);
    Projection proj{cam};
    TileGrid grid = TileGrid::make(4, 4, 2);
    DepthImage depth = wall(proj, 5.0);
    ViewLights lights;
    FourByFour() { addLight(lights, {-0.5, 1.5, -5.0}, 1.05); }
};

} // namespace

TEST(GroundTruth, PixelCentresFollowTheOrthographicConvention) {
    FourByFour f;
    const glm::dvec3 p = f.proj.viewPositionFromDepth(1, 0, f.depth.at(1, 0));
    EXPECT_NEAR(p.x, -0.5, 1e-9);
    EXPECT_NEAR(p.y, 1.5, 1e-9);
    EXPECT_NEAR(p.z, -5.0, 1e-5);
}

TEST(GroundTruth, MissingLightInOneTileCountsExactlyItsPixels) {
    FourByFour f;
    // Tile 1 omits light 0, which pixel (2,0) needs: exactly one false negative.
    const CullResult r = tileResult(f.grid, {{0}, {}, {0}, {0}}, f.depth, f.proj);
    const GroundTruth gt = computeGroundTruth(f.depth, f.proj, f.lights, r, noImage());
    EXPECT_EQ(gt.metrics.exactWork, 4u);
    EXPECT_EQ(gt.metrics.shadingWork, 12u); // tiles 0, 2, 3 list one light for 4 pixels each
    EXPECT_EQ(gt.metrics.falseNegatives, 1u);
    EXPECT_DOUBLE_EQ(gt.metrics.efficiency, 4.0 / 12.0);
    EXPECT_EQ(gt.metrics.geometryPixels, 16u);
    EXPECT_EQ(gt.listExactWork, (std::vector<std::uint64_t>{3, 1, 0, 0}));
    EXPECT_EQ(gt.listFalseNegatives, (std::vector<std::uint64_t>{0, 1, 0, 0}));
    EXPECT_EQ(gt.listShadingWork, (std::vector<std::uint64_t>{4, 0, 4, 4}));
    EXPECT_EQ(gt.tileGeometryPixels, (std::vector<std::uint32_t>{4, 4, 4, 4}));
    EXPECT_EQ(gt.metrics.maxList, 1u);
    EXPECT_DOUBLE_EQ(gt.metrics.meanList, 3.0 / 4.0);
    EXPECT_EQ(gt.metrics.resultBytes, r.bytes());
    EXPECT_FALSE(gt.metrics.imageErrorComputed);

    // Dropping it from tile 0 too misses its three pixels there as well.
    const CullResult r2 = tileResult(f.grid, {{}, {}, {0}, {0}}, f.depth, f.proj);
    EXPECT_EQ(computeGroundTruth(f.depth, f.proj, f.lights, r2, noImage()).metrics.falseNegatives, 4u);
}

TEST(GroundTruth, ExtraListedLightsLowerEfficiencyExactly) {
    FourByFour f;
    // Light 1 sits behind the camera and touches no pixel; listing it everywhere
    // adds 16 to W and nothing to E.
    addLight(f.lights, {0.0, 0.0, 50.0}, 1.0);
    const CullResult tight = tileResult(f.grid, {{0}, {0}, {}, {}}, f.depth, f.proj);
    const CullResult loose = tileResult(f.grid, {{0, 1}, {0, 1}, {1}, {1}}, f.depth, f.proj);
    const Metrics a = computeGroundTruth(f.depth, f.proj, f.lights, tight, noImage()).metrics;
    const Metrics b = computeGroundTruth(f.depth, f.proj, f.lights, loose, noImage()).metrics;
    EXPECT_EQ(a.falseNegatives, 0u);
    EXPECT_EQ(b.falseNegatives, 0u);
    EXPECT_EQ(a.exactWork, 4u);
    EXPECT_EQ(b.exactWork, 4u);
    EXPECT_EQ(a.shadingWork, 8u);
    EXPECT_EQ(b.shadingWork, 24u);
    EXPECT_DOUBLE_EQ(a.efficiency, 0.5);
    EXPECT_DOUBLE_EQ(b.efficiency, 4.0 / 24.0);
    EXPECT_EQ(b.maxList, 2u);
}

TEST(GroundTruth, BackgroundPixelsTakeNoPart) {
    FourByFour f;
    // Clear the right column and pixel (1,0): the light now reaches (0,0),
    // (2,0) and (1,1) only.
    for (std::uint32_t y = 0; y < 4; ++y) f.depth.depth[y * 4 + 3] = f.depth.clearDepth;
    f.depth.depth[1] = f.depth.clearDepth;
    const CullResult r = tileResult(f.grid, {{0}, {0}, {0}, {0}}, f.depth, f.proj);
    const GroundTruth gt = computeGroundTruth(f.depth, f.proj, f.lights, r, noImage());
    EXPECT_EQ(gt.metrics.geometryPixels, 11u);
    EXPECT_EQ(gt.tileGeometryPixels, (std::vector<std::uint32_t>{3, 2, 4, 2}));
    EXPECT_EQ(gt.metrics.exactWork, 3u);
    EXPECT_EQ(gt.metrics.shadingWork, 11u);
    EXPECT_EQ(gt.metrics.falseNegatives, 0u);
}

TEST(GroundTruth, NoGeometryGivesEfficiencyOne) {
    FourByFour f;
    std::fill(f.depth.depth.begin(), f.depth.depth.end(), f.depth.clearDepth);
    const CullResult r = tileResult(f.grid, {{}, {}, {}, {}}, f.depth, f.proj);
    const GroundTruth gt = computeGroundTruth(f.depth, f.proj, f.lights, r);
    EXPECT_EQ(gt.metrics.shadingWork, 0u);
    EXPECT_EQ(gt.metrics.geometryPixels, 0u);
    EXPECT_EQ(gt.metrics.efficiency, 1.0);
    EXPECT_TRUE(gt.metrics.imageErrorComputed);
    EXPECT_EQ(gt.metrics.imageRmse, 0.0);
}

TEST(GroundTruth, AllAlgorithmWorkIsPixelsTimesLights) {
    const Camera cam = orthoCamera(12, 10, 4);
    const Projection proj(cam);
    const TileGrid grid = TileGrid::make(12, 10, 4);
    DepthImage depth = wall(proj, 7.0);
    for (std::uint32_t x = 0; x < 12; ++x) depth.depth[x] = depth.clearDepth; // top row empty
    ViewLights lights;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-6, 6), rad(0.5, 4);
    for (int i = 0; i < 40; ++i) addLight(lights, {u(rng), u(rng), -7 + u(rng) / 3}, rad(rng));
    const GroundTruth gt = computeGroundTruth(depth, proj, lights, allResult(grid, lights.size()));
    const std::uint64_t pixels = 12 * 9;
    EXPECT_EQ(gt.metrics.geometryPixels, pixels);
    EXPECT_EQ(gt.metrics.shadingWork, pixels * lights.size());
    EXPECT_EQ(gt.metrics.falseNegatives, 0u);
    EXPECT_GT(gt.metrics.exactWork, 0u);
    EXPECT_EQ(gt.metrics.efficiency, double(gt.metrics.exactWork) / double(gt.metrics.shadingWork));
    EXPECT_EQ(gt.metrics.maxList, 40u);
    EXPECT_EQ(gt.metrics.imageRmse, 0.0);
    EXPECT_EQ(gt.metrics.imageMaxError, 0.0);
}

TEST(GroundTruth, SpatialIndexMatchesBruteForceOnRandomScenes) {
    for (std::uint32_t seed = 1; seed <= 6; ++seed) {
        std::mt19937 rng(seed);
        Camera cam;
        cam.position = {0, 0, 0};
        cam.target = {0, 0, -1};
        cam.projection = seed % 2 ? ProjectionKind::Perspective : ProjectionKind::ReversedZ;
        cam.nearPlane = 0.5;
        cam.farPlane = 200;
        cam.width = 48;
        cam.height = 36;
        cam.tileSize = 8;
        const Projection proj(cam);
        const TileGrid grid = TileGrid::make(cam.width, cam.height, cam.tileSize);

        // Random depths in [1, 150] view units, a quarter of the pixels empty.
        DepthImage depth;
        depth.width = cam.width, depth.height = cam.height;
        depth.clearDepth = float(proj.clearDepth());
        std::uniform_real_distribution<double> vd(1, 150), u01(0, 1);
        for (std::uint32_t i = 0; i < cam.width * cam.height; ++i)
            depth.depth.push_back(u01(rng) < 0.25 ? depth.clearDepth
                                                  : float(proj.windowDepthFromViewDepth(vd(rng))));

        // Lights from tiny to enormous (some go to the always-tested list),
        // some behind the camera, some far outside the view.
        ViewLights lights;
        std::uniform_real_distribution<double> ux(-60, 60), uz(-160, 10), logr(std::log(0.05), std::log(40.0));
        for (int i = 0; i < 600; ++i) addLight(lights, {ux(rng), ux(rng), uz(rng)}, std::exp(logr(rng)));
        for (int i = 0; i < 5; ++i) addLight(lights, {ux(rng), ux(rng), uz(rng)}, 1000.0);
        addLight(lights, {5000, 0, 0}, 1.0);

        glm::dvec3 bmin(kInf), bmax(-kInf);
        std::vector<glm::dvec3> pos;
        for (std::uint32_t y = 0; y < cam.height; ++y)
            for (std::uint32_t x = 0; x < cam.width; ++x)
                if (depth.hasGeometry(x, y)) {
                    pos.push_back(proj.viewPositionFromDepth(x, y, depth.at(x, y)));
                    bmin = glm::min(bmin, pos.back()), bmax = glm::max(bmax, pos.back());
                }
        const detail::LightGrid index(lights, bmin, bmax);
        EXPECT_GE(index.alwaysTestedCount(), 1u) << "the huge lights should not be binned";
        std::vector<std::uint32_t> fromIndex, brute;
        std::uint64_t total = 0;
        for (const glm::dvec3& p : pos) {
            index.neededAt(p, fromIndex);
            brute.clear();
            for (std::uint32_t i = 0; i < lights.size(); ++i) {
                const glm::dvec3 d = p - lights.centers[i];
                if (glm::dot(d, d) <= lights.radii[i] * lights.radii[i]) brute.push_back(i);
            }
            ASSERT_EQ(fromIndex, brute) << "seed " << seed;
            total += brute.size();
        }
        EXPECT_GT(total, pos.size()) << "the scene should exercise overlapping lights";

        // The full metrics against a brute-force evaluation of the same
        // random per-tile lists.
        std::vector<std::vector<std::uint32_t>> lists(grid.tileCount());
        for (auto& l : lists)
            for (std::uint32_t i = 0; i < lights.size(); ++i)
                if (u01(rng) < 0.3) l.push_back(i);
        const CullResult r = tileResult(grid, lists, depth, proj);
        const Metrics m = computeGroundTruth(depth, proj, lights, r, noImage()).metrics;
        std::uint64_t e = 0, w = 0, fn = 0;
        for (std::uint32_t y = 0; y < cam.height; ++y)
            for (std::uint32_t x = 0; x < cam.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
                const auto& l = lists[grid.tileOfPixel(x, y)];
                w += l.size();
                for (std::uint32_t i = 0; i < lights.size(); ++i) {
                    const glm::dvec3 d = p - lights.centers[i];
                    if (glm::dot(d, d) > lights.radii[i] * lights.radii[i]) continue;
                    ++e;
                    if (std::find(l.begin(), l.end(), i) == l.end()) ++fn;
                }
            }
        EXPECT_EQ(m.exactWork, e);
        EXPECT_EQ(m.shadingWork, w);
        EXPECT_EQ(m.falseNegatives, fn);
        EXPECT_GT(fn, 0u);
    }
}

TEST(GroundTruth, PixelsNeedingLightsCountsPerTile) {
    FourByFour f;
    addLight(f.lights, {1.5, -1.5, -5.0}, 0.2); // only pixel (3,3), tile 3
    using V = std::vector<std::pair<std::uint32_t, std::uint32_t>>;
    EXPECT_EQ(pixelsNeedingLights(f.depth, f.proj, f.lights, f.grid, 0), (V{{0, 3}}));
    EXPECT_EQ(pixelsNeedingLights(f.depth, f.proj, f.lights, f.grid, 1), (V{{0, 1}}));
    EXPECT_EQ(pixelsNeedingLights(f.depth, f.proj, f.lights, f.grid, 2), V{});
    EXPECT_EQ(pixelsNeedingLights(f.depth, f.proj, f.lights, f.grid, 3), (V{{1, 1}}));
    EXPECT_THROW(pixelsNeedingLights(f.depth, f.proj, f.lights, f.grid, 4), Error);
}

TEST(GroundTruth, BadInputIsATypedError) {
    FourByFour f;
    CullResult r = tileResult(f.grid, {{0}, {0}, {0}, {0}}, f.depth, f.proj);
    r.lightIndices[2] = 9; // names a light that does not exist
    EXPECT_THROW(computeGroundTruth(f.depth, f.proj, f.lights, r), Error);
    DepthImage small = f.depth;
    small.depth.pop_back();
    EXPECT_THROW(computeGroundTruth(small, f.proj, f.lights, tileResult(f.grid, {{}, {}, {}, {}}, f.depth, f.proj)),
                 Error);
}

TEST(GroundTruth, CancelledTokenStopsTheRun) {
    FourByFour f;
    CancelToken cancel;
    cancel.cancelled = true;
    const CullResult r = tileResult(f.grid, {{0}, {0}, {0}, {0}}, f.depth, f.proj);
    EXPECT_THROW(computeGroundTruth(f.depth, f.proj, f.lights, r, {}, &cancel), Cancelled);
}

// ---- Lambert shading ----------------------------------------------------------

TEST(Lambert, FlatWallMatchesHandComputedValue) {
    FourByFour f;
    ViewLights lights;
    addLight(lights, {0.3, -0.2, -3.0}, 10.0, {2.0, 1.0, 0.5});
    const std::vector<float> rgb = shadeLambertCpu(f.depth, f.proj, lights, nullptr);
    // Pixel (1,2): P = (-0.5, -0.5, -5), n = (0,0,1) (the wall faces the camera),
    // c - P = (0.8, 0.3, 2), d^2 = 4.73, n.l = 2 / sqrt(4.73).
    const double d2 = 0.8 * 0.8 + 0.3 * 0.3 + 4.0;
    const double f12 = (2.0 / std::sqrt(d2)) / d2;
    const std::size_t i = (2 * 4 + 1) * 3;
    EXPECT_NEAR(rgb[i + 0], 2.0 * f12, 1e-5 * f12);
    EXPECT_NEAR(rgb[i + 1], 1.0 * f12, 1e-5 * f12);
    EXPECT_NEAR(rgb[i + 2], 0.5 * f12, 1e-5 * f12);
    // Corner pixel (0,0) has neighbours on one side only: same normal.
    // P = (-1.5, 1.5, -5), c - P = (1.8, -1.7, 2).
    const double e2 = 1.8 * 1.8 + 1.7 * 1.7 + 4.0;
    const double f00 = (2.0 / std::sqrt(e2)) / e2;
    EXPECT_NEAR(rgb[0], 2.0 * f00, 1e-5 * f00);
}

TEST(Lambert, LightBehindTheSurfaceAndTooCloseAreHandled) {
    FourByFour f;
    // Behind the wall (z = -5, facing the camera): n.l < 0 at every pixel, so
    // it adds exactly nothing, not a negative or a clamped-away NaN.
    ViewLights behind;
    addLight(behind, {0.0, 0.0, -9.0}, 10.0, {1, 1, 1});
    for (float v : shadeLambertCpu(f.depth, f.proj, behind, nullptr)) EXPECT_EQ(v, 0.0f);

    // 1 mm in front of pixel (1,0)'s centre (-0.5, 1.5, -5): d^2 = 1e-6 is
    // under the 1e-4 floor, so that pixel gets power x n.l / 1e-4 (n.l ~ 1),
    // not 1e6 or inf; every other pixel the plain inverse-square Lambert term.
    ViewLights close;
    const glm::dvec3 c(-0.5, 1.5, -4.999);
    addLight(close, c, 1.0, {1, 1, 1});
    const std::vector<float> rgb = shadeLambertCpu(f.depth, f.proj, close, nullptr);
    ASSERT_EQ(rgb.size(), 4u * 4u * 3u);
    for (std::uint32_t y = 0; y < 4; ++y)
        for (std::uint32_t x = 0; x < 4; ++x) {
            const glm::dvec3 p(double(x) - 1.5, 1.5 - double(y), -5.0); // ortho pixel centres, the wall
            const glm::dvec3 d = c - p;
            const double d2 = glm::dot(d, d);
            const double expect = (d.z / std::sqrt(d2)) / std::max(d2, 1e-4); // n = (0, 0, 1)
            // The stored depth is a float: P.z is off by up to ~1e-6, which
            // moves n.l by that much at pixels 1 m away (1e-3 of their 1e-3).
            const double tol = x == 1 && y == 0 ? 1e-4 * expect : 2e-3 * expect + 1e-9;
            for (int ch = 0; ch < 3; ++ch)
                EXPECT_NEAR(rgb[(y * 4 + x) * 3 + ch], expect, tol) << "pixel " << x << "," << y;
        }
    EXPECT_GT(rgb[(0 * 4 + 1) * 3], 0.99e4f); // the floor, reached

    // Both together: the light behind adds nothing, bitwise.
    ViewLights both = behind;
    addLight(both, c, 1.0, {1, 1, 1});
    EXPECT_EQ(shadeLambertCpu(f.depth, f.proj, both, nullptr), rgb);
}

TEST(Lambert, SilhouettePixelTakesTheNormalOfItsOwnSurface) {
    // Ortho 4x4: columns 0-1 at depth 5, columns 2-3 at depth 10. Pixel (1,1)'s
    // forward x neighbour is 5 units away, its backward neighbour 1 unit: the
    // normal must come from the backward one, i.e. face the camera exactly.
    const Camera cam = orthoCamera(4, 4, 2);
    const Projection proj(cam);
    DepthImage depth = wall(proj, 5.0);
    for (std::uint32_t y = 0; y < 4; ++y)
        for (std::uint32_t x = 2; x < 4; ++x) depth.depth[y * 4 + x] = float(proj.windowDepthFromViewDepth(10.0));
    ViewLights lights;
    addLight(lights, {-0.5, 0.5, -3.0}, 10.0, {1, 1, 1}); // straight in front of pixel (1,1), 2 units
    const std::vector<float> rgb = shadeLambertCpu(depth, proj, lights, nullptr);
    EXPECT_NEAR(rgb[(1 * 4 + 1) * 3], 1.0 / 4.0, 1e-5); // n.l = 1, d^2 = 4
}

TEST(Lambert, IsolatedPixelFacesTheCamera) {
    Camera cam;
    cam.position = {0, 0, 0};
    cam.target = {0, 0, -1};
    cam.width = 8, cam.height = 6, cam.tileSize = 4;
    const Projection proj(cam);
    DepthImage depth;
    depth.width = 8, depth.height = 6;
    depth.clearDepth = float(proj.clearDepth());
    depth.depth.assign(48, depth.clearDepth);
    depth.depth[2 * 8 + 6] = float(proj.windowDepthFromViewDepth(4.0)); // pixel (6,2) alone
    ViewLights lights;
    addLight(lights, {0, 0, 0}, 100.0, {3, 2, 1}); // at the camera: n.l = 1
    const std::vector<float> rgb = shadeLambertCpu(depth, proj, lights, nullptr);
    const glm::dvec3 p = proj.viewPositionFromDepth(6, 2, depth.at(6, 2));
    const double expect = 1.0 / glm::dot(p, p);
    const std::size_t i = (2 * 8 + 6) * 3;
    EXPECT_NEAR(rgb[i], 3 * expect, 1e-5 * expect);
    EXPECT_NEAR(rgb[i + 1], 2 * expect, 1e-5 * expect);
    EXPECT_NEAR(rgb[i + 2], 1 * expect, 1e-5 * expect);
    for (std::size_t k = 0; k < rgb.size(); ++k)
        if (k / 3 != 2 * 8 + 6) EXPECT_EQ(rgb[k], 0.0f) << "background pixel " << k / 3;
}

TEST(Lambert, ImageErrorIsTheContributionOfUnlistedLights) {
    const Camera cam = orthoCamera(16, 12, 4);
    const Projection proj(cam);
    const TileGrid grid = TileGrid::make(16, 12, 4);
    const DepthImage depth = wall(proj, 6.0);
    ViewLights lights;
    addLight(lights, {-2, 1, -4}, 3.0, {1, 0.5, 0.25});
    addLight(lights, {3, -2, -5}, 2.0, {0.7, 0.7, 2.0});
    // Listing every light in every tile (a real per-tile path, not `all`):
    // bitwise the all-lights image.
    const std::vector<std::vector<std::uint32_t>> both(grid.tileCount(), {0, 1});
    const Metrics full = computeGroundTruth(depth, proj, lights, tileResult(grid, both, depth, proj)).metrics;
    ASSERT_TRUE(full.imageErrorComputed);
    EXPECT_EQ(full.imageRmse, 0.0);
    EXPECT_EQ(full.imageMaxError, 0.0);

    // Leaving light 1 out everywhere: the error is exactly its own image.
    const std::vector<std::vector<std::uint32_t>> only0(grid.tileCount(), {0});
    const Metrics part = computeGroundTruth(depth, proj, lights, tileResult(grid, only0, depth, proj)).metrics;
    ViewLights just1;
    addLight(just1, lights.centers[1], lights.radii[1], lights.power[1]);
    const std::vector<float> img1 = shadeLambertCpu(depth, proj, just1, nullptr);
    double sum2 = 0, mx = 0;
    for (float v : img1) sum2 += double(v) * v, mx = std::max(mx, double(v));
    const double rmse = std::sqrt(sum2 / img1.size());
    EXPECT_NEAR(part.imageRmse, rmse, 1e-5 * rmse);
    EXPECT_NEAR(part.imageMaxError, mx, 1e-5 * mx);
    EXPECT_GT(part.falseNegatives, 0u);
}

namespace {

// The atrium at 100x60 in tiles of 8 with 60 lights, a third of them spots.
Scene atriumWithSpots() {
    Scene s = makeBuiltinScene("atrium");
    LightGenSettings g = defaultLightGen(s, 60, 9);
    g.spotFraction = 0.3;
    s.lights = generateLights(g);
    s.camera.width = 100;
    s.camera.height = 60;
    s.camera.tileSize = 8;
    return s;
}

} // namespace

// The optimum of a granularity (DESIGN.md): for each list, the pixels that use
// it times the lights they need together, against brute force over every
// light and pixel, for every list rule; and E <= optimal <= W without misses.
TEST(GroundTruthOptimum, MatchesBruteForceForEveryListRule) {
    const Scene s = atriumWithSpots(); // tiles of 8: bands of 8 rows, not the 16 the other metrics used
    const Projection proj(s.camera);
    const DepthImage depth = rasterizeDepthCpu(s, proj);
    const ViewLights lights = makeViewLights(s);
    const TileGrid grid = TileGrid::make(s.camera.width, s.camera.height, s.camera.tileSize);
    auto backend = makeCpuBackend();
    for (const Algorithm a : {Algorithm::All, Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD,
                              Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin}) {
        CullSettings cs;
        cs.algorithm = a;
        cs.cells = 8;
        const CullResult r = backend->cull(depth, proj, grid, lights, cs);
        const GroundTruth gt = computeGroundTruth(depth, proj, lights, r, {false});
        std::map<std::uint32_t, std::set<std::uint32_t>> unions;
        std::map<std::uint32_t, std::uint64_t> pixels;
        for (std::uint32_t y = 0; y < depth.height; ++y)
            for (std::uint32_t x = 0; x < depth.width; ++x) {
                if (!depth.hasGeometry(x, y)) continue;
                const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
                const std::uint32_t l = r.listOfPixel(x, y, -p.z);
                ++pixels[l];
                for (std::uint32_t i = 0; i < lights.size(); ++i)
                    if (detail::lightNeeds(lights, i, p)) unions[l].insert(i);
            }
        std::uint64_t optimal = 0;
        for (const auto& [l, n] : pixels) optimal += n * unions[l].size();
        const Metrics& m = gt.metrics;
        EXPECT_EQ(m.optimalWork, optimal) << toString(a);
        EXPECT_EQ(m.falseNegatives, 0u) << toString(a);
        EXPECT_LE(m.exactWork, m.optimalWork) << toString(a);
        EXPECT_LE(m.optimalWork, m.shadingWork) << toString(a);
        EXPECT_DOUBLE_EQ(m.efficiencyVsOptimal, double(m.optimalWork) / double(m.shadingWork)) << toString(a);
        EXPECT_GT(m.optimalWork, 0u) << toString(a);
    }
}

// The report judges hundreds of results of one frame with the pixels' needed
// lights worked out once (computePixelNeeds): every figure must be the one
// computeGroundTruth finds on its own, for every list rule and under limits
// (misses by cause), and another frame's needs must be refused.
TEST(GroundTruthNeeds, PrecomputedNeedsJudgeEveryResultAsWithout) {
    const Scene s = atriumWithSpots();
    const Projection proj(s.camera);
    const DepthImage depth = rasterizeDepthCpu(s, proj);
    const ViewLights lights = makeViewLights(s);
    const TileGrid grid = TileGrid::make(s.camera.width, s.camera.height, s.camera.tileSize);
    const auto needs = computePixelNeeds(depth, proj, lights, std::size_t(1) << 20);
    ASSERT_TRUE(needs);
    auto backend = makeCpuBackend();
    std::uint64_t exactWork = 0;
    for (const Algorithm a : {Algorithm::All, Algorithm::Naive, Algorithm::TwoPointFiveD, Algorithm::Clustered,
                              Algorithm::Fptl, Algorithm::ZBin})
        for (const std::uint32_t cap : {0u, 2u}) {
            CullSettings cs;
            cs.algorithm = a;
            cs.cells = 8;
            cs.cap = cap;
            cs.maxLights = cap ? 40 : 0;
            const CullResult r = backend->cull(depth, proj, grid, lights, cs);
            GroundTruthOptions alone;
            alone.imageError = false;
            GroundTruthOptions shared = alone;
            shared.needs = needs.get();
            const GroundTruth want = computeGroundTruth(depth, proj, lights, r, alone);
            const GroundTruth got = computeGroundTruth(depth, proj, lights, r, shared);
            const std::string what = std::string(toString(a)) + " cap " + std::to_string(cap);
            EXPECT_EQ(got.metrics.falseNegatives, want.metrics.falseNegatives) << what;
            EXPECT_EQ(got.metrics.falseNegativesListFull, want.metrics.falseNegativesListFull) << what;
            EXPECT_EQ(got.metrics.falseNegativesLightLimit, want.metrics.falseNegativesLightLimit) << what;
            EXPECT_EQ(got.metrics.shadingWork, want.metrics.shadingWork) << what;
            EXPECT_EQ(got.metrics.exactWork, want.metrics.exactWork) << what;
            EXPECT_EQ(got.metrics.optimalWork, want.metrics.optimalWork) << what;
            EXPECT_EQ(got.metrics.geometryPixels, want.metrics.geometryPixels) << what;
            EXPECT_EQ(got.listFalseNegatives, want.listFalseNegatives) << what;
            EXPECT_EQ(got.listExactWork, want.listExactWork) << what;
            EXPECT_EQ(got.tileGeometryPixels, want.tileGeometryPixels) << what;
            if (cap) EXPECT_GT(want.metrics.falseNegatives, 0u) << what << ": the limits must drop lights here";
            exactWork = want.metrics.exactWork;
        }
    // The needs are exactly the (pixel, light) pairs: E of any result.
    EXPECT_EQ(needs->lights.size(), exactWork);
    EXPECT_FALSE(computePixelNeeds(depth, proj, lights, needs->lights.size() - 1))
        << "more pairs than allowed must give no needs, not an unbounded allocation";

    CullSettings cs;
    const CullResult r = backend->cull(depth, proj, grid, lights, cs);
    GroundTruthOptions other;
    other.imageError = false;
    PixelNeeds fewer = *needs;
    fewer.lightCount = lights.size() - 1;
    other.needs = &fewer;
    EXPECT_THROW(computeGroundTruth(depth, proj, lights, r, other), Error);
}
