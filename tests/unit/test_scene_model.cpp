// The scene model: light radius, every validation path, the view matrix.
#include "culling/core/errors.hpp"
#include "culling/scene/scene.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace lc;

namespace {
const double kNaN = std::numeric_limits<double>::quiet_NaN();
const double kInf = std::numeric_limits<double>::infinity();
bool startsWith(const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; }
} // namespace

TEST(PointLight, RadiusFromInverseSquareLaw) {
    PointLight l;
    // I = 4, colour (1, 0.5, 0.25): brightest channel 4*1 = 4; I_min = 0.01
    // -> r = sqrt(4 / 0.01) = sqrt(400) = 20.
    l.intensity = 4;
    l.color = {1, 0.5, 0.25};
    l.minIntensity = 0.01;
    EXPECT_DOUBLE_EQ(l.radius(), 20.0);
    // The max channel decides, wherever it is: colour (0.1, 0.2, 2.25),
    // I = 1, I_min = 0.25 -> sqrt(2.25 / 0.25) = 3.
    l.intensity = 1;
    l.color = {0.1, 0.2, 2.25};
    l.minIntensity = 0.25;
    EXPECT_DOUBLE_EQ(l.radius(), 3.0);
    // Zero intensity: radius 0 (the light reaches nothing).
    l.intensity = 0;
    EXPECT_DOUBLE_EQ(l.radius(), 0.0);
    // An explicit radius overrides.
    l.explicitRadius = 7.5;
    EXPECT_DOUBLE_EQ(l.radius(), 7.5);
}

TEST(PointLight, EveryValidationPathNamesTheField) {
    auto err = [](auto mutate) {
        PointLight l;
        mutate(l);
        return l.validate();
    };
    EXPECT_EQ(err([](PointLight&) {}), "");
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.position.y = kNaN; }), "position"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.position.x = kInf; }), "position"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.color.g = kNaN; }), "color"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.color.b = -0.1; }), "color"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.intensity = kInf; }), "intensity"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.intensity = -1; }), "intensity"));
    // Finite but past what the float passes hold: 1e39 cd became inf in the
    // shading and the image error NaN; an inverse-square radius of 1e17 m.
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.intensity = 1e39; l.minIntensity = 1e30; }), "intensity: intensity x colour"));
    EXPECT_EQ(err([](PointLight& l) { l.intensity = 1e24; l.minIntensity = 1e20; }), "");
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.intensity = 1e20; l.minIntensity = 1e-300; }), "radius: the inverse-square radius"));
    EXPECT_EQ(err([](PointLight& l) { l.minIntensity = 1e-300; }), ""); // 1e150: huge, culled (hard case)
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.minIntensity = 0; }), "min_intensity"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.minIntensity = -1; }), "min_intensity"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.minIntensity = kNaN; }), "min_intensity"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.minIntensity = kInf; }), "min_intensity"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.explicitRadius = -2; }), "radius"));
    EXPECT_TRUE(startsWith(err([](PointLight& l) { l.explicitRadius = kInf; }), "radius"));
    // Boundary values that are valid.
    EXPECT_EQ(err([](PointLight& l) { l.intensity = 0; l.color = glm::dvec3(0); }), "");
}

TEST(Camera, EveryValidationPathNamesTheField) {
    auto err = [](auto mutate) {
        Camera c;
        mutate(c);
        return c.validate();
    };
    EXPECT_EQ(err([](Camera&) {}), "");
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.nearPlane = 0; }), "camera.near"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.nearPlane = -1; }), "camera.near"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.farPlane = c.nearPlane; }), "camera.far"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.farPlane = kNaN; }), "camera.far"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.farPlane = kInf; }), "camera.far"));
    EXPECT_EQ(err([](Camera& c) { c.farPlane = kInf; c.projection = ProjectionKind::ReversedZ; }), "");
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.fovYDeg = 0; }), "camera.fov_y_deg"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.fovYDeg = 180; }), "camera.fov_y_deg"));
    EXPECT_EQ(err([](Camera& c) { c.fovYDeg = 179.9; }), "");
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.orthoHeight = 0; }), "camera.ortho_height"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.width = 0; }), "camera.width"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.width = 16385; }), "camera.width"));
    EXPECT_EQ(err([](Camera& c) { c.width = 16384; }), "");
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.height = 0; }), "camera.height"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.tileSize = 0; }), "camera.tile_size"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.tileSize = 257; }), "camera.tile_size"));
    EXPECT_EQ(err([](Camera& c) { c.tileSize = 256; }), "");
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.target = c.position; }), "camera.target"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.up = {0, 0, 1}; }), "camera.up"));  // view dir is -Z
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.up = {0, 0, 0}; }), "camera.up"));
    EXPECT_TRUE(startsWith(err([](Camera& c) { c.position.x = kNaN; }), "camera.position"));
}

TEST(Camera, ViewFromWorldLooksDownMinusZ) {
    Camera c;
    c.position = {1, 2, 3};
    c.target = {1, 2, -7};  // straight down -Z, so view = translation by -position
    const glm::dmat4 v = c.viewFromWorld();
    const glm::dvec4 p = v * glm::dvec4(1, 2, -2, 1);  // 5 units in front
    EXPECT_NEAR(p.x, 0, 1e-12);
    EXPECT_NEAR(p.y, 0, 1e-12);
    EXPECT_NEAR(p.z, -5, 1e-12);  // view depth -z_view = 5
    // Looking along +X from the origin: a point at +X is in front (z < 0),
    // a point at +Y is up (y > 0), +Z is to the right (x > 0) in a
    // right-handed frame with forward +X and up +Y.
    c.position = {0, 0, 0};
    c.target = {1, 0, 0};
    const glm::dmat4 w = c.viewFromWorld();
    EXPECT_NEAR((w * glm::dvec4(4, 0, 0, 1)).z, -4, 1e-12);
    EXPECT_NEAR((w * glm::dvec4(0, 3, 0, 1)).y, 3, 1e-12);
    EXPECT_NEAR((w * glm::dvec4(0, 0, 2, 1)).x, 2, 1e-12);
}

TEST(ProjectionKindNames, RoundTripAndUnknown) {
    for (auto k : {ProjectionKind::Perspective, ProjectionKind::PerspectiveGL, ProjectionKind::ReversedZ,
                   ProjectionKind::Orthographic, ProjectionKind::OrthographicGL})
        EXPECT_EQ(projectionKindFromString(toString(k)), k);
    try {
        projectionKindFromString("perspektive");
        FAIL();
    } catch (const SettingsError& e) {
        EXPECT_EQ(e.field(), "projection");
        EXPECT_NE(std::string(e.what()).find("perspektive"), std::string::npos);
    }
    EXPECT_TRUE(isOrthographic(ProjectionKind::OrthographicGL));
    EXPECT_FALSE(isOrthographic(ProjectionKind::ReversedZ));
    EXPECT_TRUE(isReversed(ProjectionKind::ReversedZ));
}

TEST(Mesh, ValidateCatchesBadData) {
    Mesh m;
    m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    m.indices = {0, 1, 2};
    EXPECT_EQ(m.validate(), "");
    m.indices = {0, 1, 3};
    EXPECT_NE(m.validate().find("indices"), std::string::npos);
    m.indices = {0, 1};
    EXPECT_NE(m.validate().find("multiple of 3"), std::string::npos);
    m.indices = {0, 1, 2};
    m.positions[4] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_NE(m.validate().find("non-finite"), std::string::npos);
}

TEST(Scene, ValidateThrowsTypedErrors) {
    Scene s;
    Mesh m;
    m.name = "tri";
    m.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    m.indices = {0, 1, 2};
    s.meshes.push_back(m);
    s.lights.resize(3);
    s.lights[2].name = "bad";
    s.lights[2].minIntensity = 0;
    try {
        s.validate();
        FAIL();
    } catch (const LightError& e) {
        EXPECT_EQ(e.index(), 2u);
        EXPECT_EQ(e.lightName(), "bad");
        EXPECT_NE(std::string(e.what()).find("min_intensity"), std::string::npos);
    }
    s.lights[2].minIntensity = 0.1;
    EXPECT_NO_THROW(s.validate());
    s.camera.nearPlane = -1;
    try {
        s.validate();
        FAIL();
    } catch (const SettingsError& e) {
        EXPECT_EQ(e.field(), "camera.near");
    }
    s.camera.nearPlane = 0.1;
    s.meshes[0].indices[2] = 9;
    EXPECT_THROW(s.validate(), InputError);
}

TEST(Scene, BoundsUseTransformsAndOnlyUsedVertices) {
    Scene s;
    EXPECT_EQ(s.bounds().first, glm::dvec3(0));
    Mesh m;
    m.positions = {0, 0, 0, 1, 0, 0, 0, 2, 0, 100, 100, 100};  // last vertex unused
    m.indices = {0, 1, 2};
    m.transform[3] = glm::dvec4(10, 20, 30, 1);  // translate
    s.meshes.push_back(m);
    const auto [lo, hi] = s.bounds();
    EXPECT_EQ(lo, glm::dvec3(10, 20, 30));
    EXPECT_EQ(hi, glm::dvec3(11, 22, 30));
    EXPECT_EQ(s.triangleCount(), 1u);
}

TEST(CancelToken, Throws) {
    CancelToken t;
    EXPECT_NO_THROW(t.throwIfCancelled());
    t.cancelled = true;
    EXPECT_THROW(t.throwIfCancelled(), Cancelled);
}
