// Spot lights: the scene model and its JSON, the generator, view-space spot
// data, each cone test function on hand-built cases and against brute-force
// sampling of the spherical sector, and the CPU backend's spot tests against
// the exact-cone ground truth on a fixed scene with many spots.
#include "culling/core/backend.hpp"
#include "culling/core/errors.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/core/params.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/shade.hpp"
#include "culling/math/spot_tests.hpp"
#include "truth/light_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <algorithm>
#include <cstdio>
#include <map>
#include <set>

using namespace lc;

namespace {

constexpr double kPi = 3.14159265358979323846;
double rad(double deg) { return deg * kPi / 180.0; }

// Basis perpendicular to the cone's axis.
std::pair<glm::dvec3, glm::dvec3> perpendicular(const glm::dvec3& axis) {
    const glm::dvec3 e1 =
        glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
    return {e1, glm::cross(axis, e1)};
}

// Uniform points of the spherical sector: cos(theta) uniform over the cone's
// solid angle, distance range * cbrt(u).
std::vector<glm::dvec3> sampleSector(const SpotCone& c, int count, std::mt19937& rng) {
    std::uniform_real_distribution<double> u(0, 1);
    const auto [e1, e2] = perpendicular(c.axis);
    std::vector<glm::dvec3> out;
    for (int i = 0; i < count; ++i) {
        const double ct = 1 - u(rng) * (1 - c.cosAngle), st = std::sqrt(std::max(0.0, 1 - ct * ct));
        const double ph = 2 * kPi * u(rng), d = c.range * std::cbrt(u(rng));
        out.push_back(c.apex + d * (ct * c.axis + st * (std::cos(ph) * e1 + std::sin(ph) * e2)));
    }
    return out;
}

// Points on the sector's boundary: its rim circle, its cap and the apex,
// where a bounding volume is tight.
std::vector<glm::dvec3> sectorBoundary(const SpotCone& c, int ring) {
    const auto [e1, e2] = perpendicular(c.axis);
    std::vector<glm::dvec3> out{c.apex, c.apex + c.range * c.axis};
    for (int k = 0; k <= 8; ++k) {
        const double th = std::acos(c.cosAngle) * k / 8.0; // cap: angle 0..outer
        for (int i = 0; i < ring; ++i) {
            const double ph = 2 * kPi * i / ring;
            out.push_back(c.apex + c.range * (std::cos(th) * c.axis +
                                              std::sin(th) * (std::cos(ph) * e1 + std::sin(ph) * e2)));
        }
    }
    return out;
}

Scene spotScene() {
    Scene s;
    s.name = "spots";
    s.camera.position = {0, 1, 6};
    s.camera.target = {0, 1, 0};
    PointLight p;
    p.name = "bulb";
    p.position = {1, 2, 3};
    p.intensity = 3;
    s.lights.push_back(p);
    PointLight sp;
    sp.name = "torch";
    sp.kind = LightKind::Spot;
    sp.position = {-1, 2.5, 0.5};
    sp.direction = {0.25, -1, -0.125};
    sp.outerAngleDeg = 22.5;
    sp.color = {1, 0.5, 0.25};
    sp.intensity = 8;
    sp.minIntensity = 0.02;
    s.lights.push_back(sp);
    return s;
}

std::string sceneText(const std::string& lightJson) {
    return R"({"format": "lightcull-scene", "version": 1, "lights": [)" + lightJson + "]}";
}

// Message of the InputError that parsing `text` throws, or "" if none.
std::string parseError(const std::string& text) {
    try {
        parseScene(text, "spot.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "";
}

} // namespace

// ------------------------------------------------------------ model and JSON

TEST(SpotModel, ValidationNamesTheField) {
    PointLight l;
    l.kind = LightKind::Spot;
    l.direction = {0, 0, 0};
    EXPECT_NE(l.validate().find("direction: must not be zero"), std::string::npos);
    l.direction = {0, -1, 0};
    EXPECT_EQ(l.validate(), "");
    for (double bad : {0.0, -5.0, 90.5, std::nan("")}) {
        l.outerAngleDeg = bad;
        EXPECT_EQ(l.validate().rfind("outer_angle_deg:", 0), 0u) << bad;
    }
    l.outerAngleDeg = 90;
    EXPECT_EQ(l.validate(), "");
    // A point light's spot fields are not its business.
    PointLight p;
    p.outerAngleDeg = -1;
    p.direction = {0, 0, 0};
    EXPECT_EQ(p.validate(), "");

    Scene s = spotScene();
    s.lights[1].outerAngleDeg = 120;
    try {
        s.validate();
        FAIL() << "no LightError";
    } catch (const LightError& e) {
        EXPECT_NE(std::string(e.what()).find("torch"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("outer_angle_deg"), std::string::npos) << e.what();
    }
}

TEST(SpotJson, RoundTripKeepsEverySpotField) {
    const Scene s = spotScene();
    const Scene back = parseScene(serializeScene(s, "."), "rt.json");
    ASSERT_EQ(back.lights.size(), 2u);
    EXPECT_EQ(back.lights[0].kind, LightKind::Point);
    const PointLight& a = s.lights[1];
    const PointLight& b = back.lights[1];
    EXPECT_EQ(b.kind, LightKind::Spot);
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.position, a.position);
    EXPECT_EQ(b.direction, a.direction); // written unnormalised, read back exactly
    EXPECT_EQ(b.outerAngleDeg, a.outerAngleDeg);
    EXPECT_EQ(b.color, a.color);
    EXPECT_EQ(b.intensity, a.intensity);
    EXPECT_EQ(b.minIntensity, a.minIntensity);
    // A point light is written as version 1 always wrote it: no spot keys.
    const std::string text = serializeScene(s, ".");
    const auto bulb = text.find("\"bulb\"");
    const auto torch = text.find("\"torch\"");
    ASSERT_LT(bulb, torch);
    EXPECT_EQ(text.substr(bulb, torch - bulb).find("direction"), std::string::npos);
}

TEST(SpotJson, OldFilesStillLoadAsPointLights) {
    const Scene s = parseScene(sceneText(R"({"position": [1, 2, 3], "intensity": 2})"), "old.json");
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].kind, LightKind::Point);
    const Scene t = parseScene(
        sceneText(R"({"type": "spot", "position": [0, 0, 0], "direction": [0, 0, -2], "outer_angle_deg": 10})"),
        "new.json");
    EXPECT_TRUE(t.lights[0].isSpot());
    EXPECT_EQ(t.lights[0].outerAngleDeg, 10);
}

TEST(SpotJson, ErrorsNameTheLightAndField) {
    struct Case {
        std::string light, field, what;
    } cases[] = {
        {R"({"name": "k", "type": "cone", "position": [0,0,0]})", "lights[0].type", "unknown light type 'cone'"},
        {R"({"name": "k", "position": [0,0,0], "direction": [0,0,-1]})", "lights[0].direction",
         "only spot lights"},
        {R"({"name": "k", "position": [0,0,0], "outer_angle_deg": 10})", "lights[0].outer_angle_deg",
         "only spot lights"},
        {R"({"name": "k", "type": "spot", "position": [0,0,0], "outer_angle_deg": 10})", "lights[0].direction",
         "missing required field"},
        {R"({"name": "k", "type": "spot", "position": [0,0,0], "direction": [0,0,-1]})",
         "lights[0].outer_angle_deg", "missing required field"},
        {R"({"name": "k", "type": "spot", "position": [0,0,0], "direction": [0,0,0], "outer_angle_deg": 10})",
         "lights[0].direction", "light 'k': must not be zero"},
        {R"({"name": "k", "type": "spot", "position": [0,0,0], "direction": [0,0,-1], "outer_angle_deg": 91})",
         "lights[0].outer_angle_deg", "light 'k': must be in (0, 90]"},
        {R"({"name": "k", "type": "spot", "position": [0,0,0], "direction": [0,"x",-1], "outer_angle_deg": 9})",
         "lights[0].direction[1]", "must be a number"},
    };
    for (const auto& c : cases) {
        const std::string msg = parseError(sceneText(c.light));
        EXPECT_NE(msg.find("spot.json:"), std::string::npos) << msg;
        EXPECT_NE(msg.find(c.field + ":"), std::string::npos) << c.light << " -> " << msg;
        EXPECT_NE(msg.find(c.what), std::string::npos) << c.light << " -> " << msg;
    }
}

TEST(SpotGenerator, FractionAnglesAndDeterminism) {
    LightGenSettings g;
    g.count = 2000;
    g.seed = 7;
    const auto points = generateLights(g);
    for (const auto& l : points) EXPECT_FALSE(l.isSpot());
    g.spotFraction = 0.25;
    g.spotAngleMinDeg = 5;
    g.spotAngleMaxDeg = 60;
    const auto mixed = generateLights(g);
    int spots = 0;
    for (const auto& l : mixed) {
        EXPECT_EQ(l.validate(), "");
        if (!l.isSpot()) continue;
        ++spots;
        EXPECT_GE(l.outerAngleDeg, 5);
        EXPECT_LE(l.outerAngleDeg, 60);
        EXPECT_NEAR(glm::length(l.direction), 1.0, 1e-12);
    }
    // Binomial(2000, 0.25): mean 500, sd ~19.4; +-100 is over 5 sd.
    EXPECT_NEAR(spots, 500, 100);
    const auto again = generateLights(g);
    for (std::size_t i = 0; i < mixed.size(); ++i) {
        EXPECT_EQ(again[i].direction, mixed[i].direction);
        EXPECT_EQ(again[i].kind, mixed[i].kind);
    }
    g.spotFraction = 1.5;
    EXPECT_THROW(generateLights(g), SettingsError);
    g.spotFraction = 0.5;
    g.spotAngleMaxDeg = 95;
    EXPECT_THROW(generateLights(g), SettingsError);
}

TEST(SpotViewLights, DirectionRotatesIntoViewSpace) {
    Scene s = spotScene();
    // Camera on +X looking at the origin, +Y up: world -X is view -Z, and
    // view +X (forward x up) is world -Z.
    s.camera.position = {5, 0, 0};
    s.camera.target = {0, 0, 0};
    s.lights[1].direction = {-3, 0, 0};
    s.lights[1].position = {1, 0, 0};
    const ViewLights v = makeViewLights(s);
    ASSERT_EQ(v.spotAngles.size(), 2u);
    EXPECT_FALSE(v.isSpot(0));
    EXPECT_TRUE(v.isSpot(1));
    EXPECT_NEAR(v.spotAxes[1].z, -1.0, 1e-12);
    EXPECT_NEAR(v.centers[1].z, -4.0, 1e-12);
    EXPECT_NEAR(v.spotAngles[1], rad(22.5), 1e-15);
    s.lights[1].direction = {0, 0, 1};
    EXPECT_NEAR(makeViewLights(s).spotAxes[1].x, -1.0, 1e-12);
    // No spot light: the spot arrays stay empty.
    s.lights.resize(1);
    EXPECT_TRUE(makeViewLights(s).spotAngles.empty());
}

TEST(SpotParams, SpotTestParameter) {
    CullSettings st;
    Camera cam;
    EXPECT_EQ(getParam(st, cam, "spot-test"), "apex-sphere");
    for (const char* v : {"tight-sphere", "cone-sphere", "cone-planes", "apex-sphere"}) {
        setParam(st, cam, "spot-test", v);
        EXPECT_EQ(getParam(st, cam, "spot-test"), v);
    }
    try {
        setParam(st, cam, "spot-test", "cone");
        FAIL();
    } catch (const SettingsError& e) {
        EXPECT_NE(std::string(e.what()).find("cone-planes"), std::string::npos) << e.what();
    }
}

// ------------------------------------------------------------ cone functions

TEST(ConeTests, ContainsIsTheSphericalSector) {
    const SpotCone c = makeSpotCone({1, 2, 3}, {0, 0, -2}, 10, rad(30));
    EXPECT_TRUE(coneContains(c, {1, 2, 3}));                 // apex
    EXPECT_TRUE(coneContains(c, {1, 2, 3 - 9.999}));         // on the axis, within range
    EXPECT_FALSE(coneContains(c, {1, 2, 3 - 10.001}));       // beyond range
    EXPECT_FALSE(coneContains(c, {1, 2, 3 + 1}));            // behind
    // At range 5, 29.9 and 30.1 degrees off the axis.
    for (double deg : {29.9, 30.1}) {
        const glm::dvec3 p(1 + 5 * std::sin(rad(deg)), 2, 3 - 5 * std::cos(rad(deg)));
        EXPECT_EQ(coneContains(c, p), deg < 30) << deg;
    }
    // Spherical cap, not a flat one: a rim-angle point at distance 9.99 is in.
    const glm::dvec3 rim(1 + 9.99 * std::sin(rad(29.9)), 2, 3 - 9.99 * std::cos(rad(29.9)));
    EXPECT_TRUE(coneContains(c, rim));
}

TEST(ConeTests, TightSphereHoldsTheSectorAndIsMinimal) {
    std::mt19937 rng(3);
    for (double deg : {1.0, 10.0, 30.0, 44.9, 45.0, 45.1, 60.0, 75.0, 89.0, 90.0}) {
        const SpotCone c = makeSpotCone({0.5, -1, 2}, {1, 2, -3}, 7, rad(deg));
        const BoundingSphere s = tightSphere(c);
        double farthest = 0;
        for (const auto& p : sampleSector(c, 2000, rng))
            EXPECT_LE(glm::length(p - s.center), s.radius * (1 + 1e-12)) << deg;
        for (const auto& p : sectorBoundary(c, 64)) {
            const double d = glm::length(p - s.center);
            EXPECT_LE(d, s.radius * (1 + 1e-12)) << deg;
            farthest = std::max(farthest, d);
        }
        // Minimal: some boundary point lies on the sphere (the rim, and for
        // <= 45 degrees also the apex).
        EXPECT_NEAR(farthest, s.radius, 1e-3 * s.radius) << deg;
        if (deg <= 45) EXPECT_NEAR(glm::length(c.apex - s.center), s.radius, 1e-9) << deg;
        // Never larger than the apex sphere, and smaller below 90 degrees.
        EXPECT_LE(s.radius, apexSphere(c).radius * (1 + 1e-12)) << deg;
        if (deg < 89) EXPECT_LT(s.radius, apexSphere(c).radius) << deg;
    }
    // Hand values: 60 degrees -> centre range/2 along the axis, radius range*sin 60.
    const SpotCone c = makeSpotCone({0, 0, 0}, {0, 0, -1}, 2, rad(60));
    EXPECT_NEAR(tightSphere(c).center.z, -1.0, 1e-12);
    EXPECT_NEAR(tightSphere(c).radius, std::sqrt(3.0), 1e-12);
    // 30 degrees -> centre and radius range / (2 cos 30) = 2/sqrt(3).
    const SpotCone d = makeSpotCone({0, 0, 0}, {0, 0, -1}, 2, rad(30));
    EXPECT_NEAR(tightSphere(d).radius, 2 / std::sqrt(3.0), 1e-12);
    EXPECT_NEAR(tightSphere(d).center.z, -2 / std::sqrt(3.0), 1e-12);
}

TEST(ConeTests, ConeVsSphereHandCases) {
    const SpotCone c = makeSpotCone({0, 0, 0}, {0, 0, -1}, 10, rad(20));
    EXPECT_TRUE(coneIntersectsSphere(c, {0, 0, -5}, 0.1));     // on the axis
    EXPECT_FALSE(coneIntersectsSphere(c, {0, 0, 2}, 1.0));     // behind the apex (back test)
    EXPECT_TRUE(coneIntersectsSphere(c, {0, 0, 0.9}, 1.0));    // reaches over the apex
    EXPECT_FALSE(coneIntersectsSphere(c, {0, 0, -12}, 1.0));   // in front, beyond range (front test)
    EXPECT_TRUE(coneIntersectsSphere(c, {0, 0, -10.9}, 1.0));
    // Beside the cone at depth 5: the lateral surface is at x = 5 tan 20;
    // the distance from (x, 0, -5) to it is (x - 5 tan 20) cos 20.
    const double edge = 5 * std::tan(rad(20));
    const double r = 0.5;
    const double touch = edge + r / std::cos(rad(20));
    EXPECT_TRUE(coneIntersectsSphere(c, {touch - 1e-6, 0, -5}, r));
    EXPECT_FALSE(coneIntersectsSphere(c, {touch + 1e-6, 0, -5}, r));   // angle test
    // Wide cone, sphere behind-and-beside: behind the apex plane -> out.
    const SpotCone w = makeSpotCone({0, 0, 0}, {0, 0, -1}, 10, rad(89));
    EXPECT_FALSE(coneIntersectsSphere(w, {3, 0, 1.5}, 1.0));
    EXPECT_TRUE(coneIntersectsSphere(w, {3, 0, 0.5}, 1.0));
}

TEST(ConeTests, ConeVsSphereNeverMissesASampledHit) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1, 1), ang(1, 90), rr(0.05, 4);
    int hits = 0, rejected = 0;
    for (int trial = 0; trial < 300; ++trial) {
        const SpotCone c = makeSpotCone({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng) + 1e-3}, 5,
                                        rad(ang(rng)));
        const auto pts = sampleSector(c, 400, rng);
        for (int k = 0; k < 20; ++k) {
            const glm::dvec3 s = c.apex + 8.0 * glm::dvec3(u(rng), u(rng), u(rng));
            const double r = rr(rng);
            bool touches = false;
            for (const auto& p : pts) touches = touches || glm::length(p - s) <= r;
            const bool says = coneIntersectsSphere(c, s, r);
            if (touches) {
                ++hits;
                EXPECT_TRUE(says) << "trial " << trial;
            }
            if (!says) ++rejected;
        }
    }
    // Both outcomes are exercised.
    EXPECT_GT(hits, 500);
    EXPECT_GT(rejected, 1000);
}

TEST(ConeTests, MaxSignedDistanceMatchesSampling) {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-1, 1), ang(1, 90);
    for (int trial = 0; trial < 200; ++trial) {
        const SpotCone c = makeSpotCone({u(rng), u(rng), u(rng)}, {u(rng), u(rng), u(rng) + 1e-3}, 3,
                                        rad(ang(rng)));
        const Plane pl(glm::normalize(glm::dvec3(u(rng), u(rng), u(rng) + 1e-3)), u(rng));
        double sampled = -1e300;
        auto pts = sectorBoundary(c, 180);
        // The cap point in the normal's direction, where the maximum lies when
        // the normal is inside the cone.
        const glm::dvec3 cap = c.apex + c.range * glm::dvec3(pl);
        if (coneContains(c, cap)) pts.push_back(cap);
        for (const auto& p : pts) sampled = std::max(sampled, signedDistance(pl, p));
        const double exact = coneMaxSignedDistance(c, pl);
        EXPECT_GE(exact, sampled - 1e-12) << trial;   // never below a real point
        EXPECT_LE(exact, sampled + 3e-3 * c.range) << trial; // and tight (sampling resolution)
    }
}

TEST(ConeTests, ConePlanesPassesACornerChunkTheConeMisses) {
    // The classic weakness: a chunk next to the cone's flank that no single
    // plane separates. Orthographic-like box chunk built by hand.
    FrustumChunk box;
    const glm::dvec3 lo(1, 1, -6), hi(2, 2, -5);
    box.planes = {Plane{1, 0, 0, -lo.x}, Plane{-1, 0, 0, hi.x}, Plane{0, -1, 0, hi.y},
                  Plane{0, 1, 0, -lo.y}, Plane{0, 0, -1, hi.z}, Plane{0, 0, 1, -lo.z}};
    for (int i = 0; i < 8; ++i)
        box.corners[i] = {(i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? lo.z : hi.z};
    box.depthMin = 5;
    box.depthMax = 6;
    // Cone along -Z at the origin, 12 degrees, range 6.5: it reaches
    // 6.5 sin 12 = 1.35 off the axis, so x = 1 and y = 1 alone, but never
    // the box, whose points are at least sqrt(2) off the axis.
    const SpotCone c = makeSpotCone({0, 0, 0}, {0, 0, -1}, 6.5, rad(12));
    std::mt19937 rng(1);
    bool anyInside = false;
    std::uniform_real_distribution<double> u(0, 1);
    for (int k = 0; k < 20000 && !anyInside; ++k)
        anyInside = coneContains(c, lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng)));
    EXPECT_FALSE(anyInside);
    EXPECT_TRUE(coneIntersectsChunkPlanes(c, box));   // false positive of the plane test
    // A narrower cone (6.5 sin 5 = 0.57 off the axis) lies wholly on the
    // outer side of x = 1: rejected.
    const SpotCone narrow = makeSpotCone({0, 0, 0}, {0, 0, -1}, 6.5, rad(5));
    EXPECT_FALSE(coneIntersectsChunkPlanes(narrow, box));
    // Cone-vs-sphere on the same box: the box's bounding sphere reaches in.
    const BoundingSphere bs = chunkBoundingSphere(box);
    EXPECT_NEAR(glm::length(bs.center - 0.5 * (lo + hi)), 0, 1e-12);
    EXPECT_NEAR(bs.radius, 0.5 * std::sqrt(3.0), 1e-12);
}

// ------------------------------------------------------------ on a scene

namespace {

struct SpotRun {
    DepthImage depth;
    ViewLights lights;
    TileGrid grid;
};

// A builtin scene at low resolution with many spot lights of every width,
// pointing everywhere (plus a few point lights, which the spot test ignores).
Scene fixedSpotScene() {
    Scene s = makeBuiltinScene("atrium");
    s.camera.width = 320;
    s.camera.height = 180;
    s.camera.tileSize = 16;
    LightGenSettings g = defaultLightGen(s, 400, 42);
    g.spotFraction = 0.9;
    g.spotAngleMinDeg = 1;
    g.spotAngleMaxDeg = 89;
    g.intensityMin = 0.5; // ranges 3..13 m in a 40 m atrium
    g.intensityMax = 8;
    s.lights = generateLights(g);
    return s;
}

std::vector<std::uint32_t> listOf(const CullResult& r, std::size_t i) {
    return {r.lightIndices.begin() + r.listOffset[i], r.lightIndices.begin() + r.listOffset[i] + r.listCount[i]};
}

bool isSubset(const std::vector<std::uint32_t>& a, const std::vector<std::uint32_t>& b) {
    return std::includes(b.begin(), b.end(), a.begin(), a.end());
}

} // namespace

TEST(SpotCull, GroundTruthNeedsTheExactCone) {
    // Orthographic wall at depth 10, one unit per pixel; a spot at the origin
    // pointing at it with a 20-degree cone and range 15: exactly the pixels
    // whose wall point is within 15 of the apex and 20 degrees of the axis.
    Camera cam;
    cam.position = {0, 0, 0};
    cam.target = {0, 0, -1};
    cam.projection = ProjectionKind::Orthographic;
    cam.orthoHeight = 32;
    cam.width = 32;
    cam.height = 32;
    cam.tileSize = 8;
    cam.nearPlane = 0.1;
    cam.farPlane = 100;
    const Projection proj(cam);
    DepthImage d;
    d.width = 32;
    d.height = 32;
    d.clearDepth = 1.0f;
    d.depth.assign(32 * 32, float(proj.windowDepthFromViewDepth(10.0)));
    ViewLights L;
    L.centers = {{0, 0, 0}};
    L.radii = {15};
    L.power = {glm::dvec3(1)};
    L.spotAxes = {{0, 0, -1}};
    L.spotAngles = {rad(20)};
    std::uint64_t inCone = 0, inSphere = 0;
    for (std::uint32_t y = 0; y < 32; ++y)
        for (std::uint32_t x = 0; x < 32; ++x) {
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, d.at(x, y));
            const double off = std::hypot(p.x, p.y);
            inSphere += glm::length(p) <= 15;
            inCone += glm::length(p) <= 15 && std::atan2(off, -p.z) <= rad(20);
        }
    ASSERT_GT(inCone, 0u);
    ASSERT_GT(inSphere, inCone);
    CullSettings st;
    st.algorithm = Algorithm::All;
    auto cpu = makeCpuBackend();
    const CullResult all = cpu->cull(d, proj, TileGrid::make(32, 32, 8), L, st);
    GroundTruthOptions o;
    o.imageError = false;
    const GroundTruth gt = computeGroundTruth(d, proj, L, all, o);
    EXPECT_EQ(gt.metrics.exactWork, inCone);
    EXPECT_EQ(gt.metrics.shadingWork, 32u * 32u);
}

TEST(SpotShading, ZeroOutsideTheConeAndAPointLightInside) {
    // A wall at depth 10 through a perspective camera; one light 4 in front of
    // it. As a spot (20 degrees, pointing at the wall) it must give exactly
    // the point light's value inside its cone and 0 outside.
    Scene s;
    s.camera.position = {0, 0, 0};
    s.camera.target = {0, 0, -1};
    s.camera.width = 96;
    s.camera.height = 64;
    s.camera.tileSize = 16;
    Mesh wall;
    wall.positions = {-20, -20, -10, 20, -20, -10, 20, 20, -10, -20, 20, -10};
    wall.indices = {0, 1, 2, 0, 2, 3};
    s.meshes.push_back(wall);
    PointLight l;
    l.position = {0.5, 0.25, -6};
    l.intensity = 20;
    s.lights.push_back(l);
    const Projection proj(s.camera);
    auto cpu = makeCpuBackend();
    const DepthImage depth = cpu->renderDepth(s, proj);
    const std::vector<float> asPoint = shadeLambertCpu(depth, proj, makeViewLights(s), nullptr);
    s.lights[0].kind = LightKind::Spot;
    s.lights[0].direction = {0, 0, -1};
    s.lights[0].outerAngleDeg = 20;
    const ViewLights spotLights = makeViewLights(s);
    const std::vector<float> asSpot = shadeLambertCpu(depth, proj, spotLights, nullptr);
    int inside = 0, outside = 0;
    for (std::uint32_t y = 0; y < depth.height; ++y)
        for (std::uint32_t x = 0; x < depth.width; ++x) {
            if (!depth.hasGeometry(x, y)) continue;
            const glm::dvec3 p = proj.viewPositionFromDepth(x, y, depth.at(x, y));
            const glm::dvec3 d = p - spotLights.centers[0];
            const double angle = std::acos(glm::dot(glm::normalize(d), spotLights.spotAxes[0]));
            const std::size_t i = 3 * (std::size_t(y) * depth.width + x);
            if (angle < rad(19.9)) {
                ++inside;
                EXPECT_EQ(asSpot[i], asPoint[i]) << x << "," << y;
                EXPECT_GT(asSpot[i], 0.0f);
            } else if (angle > rad(20.1)) {
                ++outside;
                EXPECT_EQ(asSpot[i], 0.0f) << x << "," << y;
            }
        }
    EXPECT_GT(inside, 20);
    EXPECT_GT(outside, 1000);
}

TEST(SpotCull, EveryTestHasNoFalseNegativesAndTheExpectedOrder) {
    const Scene scene = fixedSpotScene();
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    GroundTruthOptions o;
    o.imageError = false;
    for (Algorithm algo : {Algorithm::MinMax, Algorithm::TwoPointFiveD, Algorithm::Clustered,
                           Algorithm::HalfZ, Algorithm::Naive}) {
        std::map<SpotTest, CullResult> res;
        std::map<SpotTest, std::uint64_t> work;
        std::uint64_t exact = 0;
        for (SpotTest t : {SpotTest::ApexSphere, SpotTest::TightSphere, SpotTest::ConeSphere,
                           SpotTest::ConePlanes}) {
            CullSettings st;
            st.algorithm = algo;
            st.cells = 8;
            st.spotTest = t;
            res[t] = cpu->cull(depth, proj, grid, lights, st);
            const GroundTruth gt = computeGroundTruth(depth, proj, lights, res[t], o);
            EXPECT_EQ(gt.metrics.falseNegatives, 0u) << toString(algo) << " " << toString(t);
            work[t] = gt.metrics.shadingWork;
            exact = gt.metrics.exactWork;
        }
        const std::string at = std::string(toString(algo)) + ": ";
        ASSERT_GT(exact, 0u);
        // Per list: the cone tests refine the tight sphere, so their lists are
        // subsets of its lists (by construction, checked here).
        const auto& tight = res[SpotTest::TightSphere];
        for (std::size_t i = 0; i < tight.listCount.size(); ++i) {
            EXPECT_TRUE(isSubset(listOf(res[SpotTest::ConeSphere], i), listOf(tight, i))) << at << i;
            EXPECT_TRUE(isSubset(listOf(res[SpotTest::ConePlanes], i), listOf(tight, i))) << at << i;
        }
        // Tight vs apex sphere is ordered in total but not per list: the
        // tight sphere pokes out of the apex sphere (docs/SPOT_LIGHTS.md).
        std::size_t notNested = 0;
        for (std::size_t i = 0; i < tight.listCount.size(); ++i)
            notNested += !isSubset(listOf(tight, i), listOf(res[SpotTest::ApexSphere], i));
        std::printf("%-9s lists where tight-sphere lists a light apex-sphere does not: %zu of %zu\n",
                    toString(algo), notNested, tight.listCount.size());
        // Totals: each refinement removes work on this scene of narrow and
        // wide cones pointing everywhere (a test that did nothing would tie).
        EXPECT_LE(exact, work[SpotTest::ConeSphere]) << at;
        EXPECT_LE(exact, work[SpotTest::ConePlanes]) << at;
        // Except cone-sphere under naive: a tile's chunk runs from the camera's
        // near to its far plane, and a sphere around that holds every cone.
        if (algo == Algorithm::Naive)
            EXPECT_LE(work[SpotTest::ConeSphere], work[SpotTest::TightSphere]) << at;
        else
            EXPECT_LT(work[SpotTest::ConeSphere], work[SpotTest::TightSphere]) << at;
        EXPECT_LT(work[SpotTest::ConePlanes], work[SpotTest::TightSphere]) << at;
        EXPECT_LT(work[SpotTest::TightSphere], work[SpotTest::ApexSphere]) << at;
        std::printf("%-9s W: apex %llu tight %llu cone-sphere %llu cone-planes %llu exact %llu\n",
                    toString(algo), (unsigned long long)work[SpotTest::ApexSphere],
                    (unsigned long long)work[SpotTest::TightSphere],
                    (unsigned long long)work[SpotTest::ConeSphere],
                    (unsigned long long)work[SpotTest::ConePlanes], (unsigned long long)exact);
    }
}

TEST(SpotCull, PointLightsIgnoreTheSpotTest) {
    Scene scene = fixedSpotScene();
    for (auto& l : scene.lights) l.kind = LightKind::Point;
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    const ViewLights lights = makeViewLights(scene);
    CullSettings st;
    const CullResult base = cpu->cull(depth, proj, grid, lights, st);
    for (SpotTest t : {SpotTest::TightSphere, SpotTest::ConeSphere, SpotTest::ConePlanes}) {
        st.spotTest = t;
        const CullResult r = cpu->cull(depth, proj, grid, lights, st);
        EXPECT_EQ(r.lightIndices, base.lightIndices) << toString(t);
        EXPECT_EQ(r.listCount, base.listCount) << toString(t);
    }
}
