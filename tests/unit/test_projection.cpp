// Projection math for every projection kind: closed forms against the matrix
// and against GLM's own matrices, round trips, the y flip.
#include "culling/core/errors.hpp"
#include "culling/math/projection.hpp"

#include <glm/ext/matrix_clip_space.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

using namespace lc;

namespace {

struct Case {
    ProjectionKind kind;
    double farPlane;
    const char* label;
};

const Case kCases[] = {
    {ProjectionKind::Perspective, 50.0, "perspective"},
    {ProjectionKind::PerspectiveGL, 50.0, "perspective-gl"},
    {ProjectionKind::ReversedZ, 50.0, "reversed-z"},
    {ProjectionKind::ReversedZ, std::numeric_limits<double>::infinity(), "reversed-z-infinite"},
    {ProjectionKind::Orthographic, 50.0, "orthographic"},
    {ProjectionKind::OrthographicGL, 50.0, "orthographic-gl"},
};

Camera makeCamera(const Case& c) {
    Camera cam;
    cam.projection = c.kind;
    cam.nearPlane = 0.5;
    cam.farPlane = c.farPlane;
    cam.fovYDeg = 60.0;
    cam.orthoHeight = 10.0;
    cam.width = 64;
    cam.height = 48;
    return cam;
}

// Window depth computed independently of projection.cpp, from GLM's matrices
// (and for reversed-Z from d_rev = 1 - d_perspective, which holds for the finite
// form, or n / v for the infinite one).
double referenceWindowDepth(const Case& c, const Camera& cam, double v) {
    const double n = cam.nearPlane, f = cam.farPlane, aspect = cam.aspect();
    const glm::dvec4 p(0.3, -0.2, -v, 1.0);
    const double fovy = glm::radians(cam.fovYDeg);
    const double hh = cam.orthoHeight / 2, hw = hh * aspect;
    auto zo = [](const glm::dmat4& m, const glm::dvec4& q) {
        const glm::dvec4 cl = m * q;
        return cl.z / cl.w;
    };
    switch (c.kind) {
    case ProjectionKind::Perspective: return zo(glm::perspectiveRH_ZO(fovy, aspect, n, f), p);
    case ProjectionKind::PerspectiveGL: return 0.5 * (zo(glm::perspectiveRH_NO(fovy, aspect, n, f), p) + 1);
    case ProjectionKind::ReversedZ:
        if (std::isinf(f)) return n / v;
        return 1.0 - zo(glm::perspectiveRH_ZO(fovy, aspect, n, f), p);
    case ProjectionKind::Orthographic: return zo(glm::orthoRH_ZO(-hw, hw, -hh, hh, n, f), p);
    case ProjectionKind::OrthographicGL:
        return 0.5 * (zo(glm::orthoRH_NO(-hw, hw, -hh, hh, n, f), p) + 1);
    }
    return 0;
}

} // namespace

class ProjectionKinds : public ::testing::TestWithParam<Case> {};

TEST_P(ProjectionKinds, NearAndFarMapToTheDepthRangeEnds) {
    const Case c = GetParam();
    const Projection proj(makeCamera(c));
    const bool rev = isReversed(c.kind);
    EXPECT_NEAR(proj.windowDepthFromViewDepth(0.5), rev ? 1.0 : 0.0, 1e-12);
    if (std::isfinite(c.farPlane)) EXPECT_NEAR(proj.windowDepthFromViewDepth(50.0), rev ? 0.0 : 1.0, 1e-12);
    else EXPECT_NEAR(proj.windowDepthFromViewDepth(1e12), 0.0, 1e-9);
    EXPECT_EQ(proj.clearDepth(), rev ? 0.0 : 1.0);
    EXPECT_TRUE(proj.nearer(proj.windowDepthFromViewDepth(1.0), proj.windowDepthFromViewDepth(2.0)));
}

TEST_P(ProjectionKinds, LinearisationRoundTripsAndMatchesGlm) {
    const Case c = GetParam();
    const Camera cam = makeCamera(c);
    const Projection proj(cam);
    for (double v : {0.5, 0.51, 1.0, 3.7, 12.25, 49.0, 50.0}) {
        const double d = proj.windowDepthFromViewDepth(v);
        EXPECT_NEAR(d, referenceWindowDepth(c, cam, v), 1e-12) << c.label << " v=" << v;
        EXPECT_NEAR(proj.viewDepthFromWindowDepth(d), v, 1e-9 * v) << c.label << " v=" << v;
        // The float form GLSL evaluates, with the same constants.
        const float vf = lcViewDepthFromWindowDepth(float(d), proj.depthParams().ab_ortho_clear);
        EXPECT_NEAR(vf, v, 2e-3 * v) << c.label << " v=" << v;
    }
    EXPECT_EQ(proj.depthParams().ab_ortho_clear.z, proj.orthographic() ? 1.0f : 0.0f);
    EXPECT_EQ(proj.depthParams().ab_ortho_clear.w, float(proj.clearDepth()));
}

TEST_P(ProjectionKinds, MatrixAgreesWithClosedFormsAndPixelMapping) {
    const Case c = GetParam();
    const Projection proj(makeCamera(c));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1, 1), depth(0.5, 50.0);
    for (int i = 0; i < 200; ++i) {
        const double v = depth(rng);
        const glm::dvec2 pix{(u(rng) + 1) * 32, (u(rng) + 1) * 24};
        const glm::dvec3 p = proj.viewPositionAt(pix, v);
        EXPECT_NEAR(p.z, -v, 1e-12);
        const glm::dvec4 clip = proj.clipFromView() * glm::dvec4(p, 1.0);
        ASSERT_GT(clip.w, 0);
        EXPECT_NEAR(clip.z / clip.w, proj.windowDepthFromViewDepth(v), 1e-12);
        // NDC from the matrix -> pixel (y down) equals the closed-form pixel.
        const glm::dvec2 fromMatrix{(clip.x / clip.w + 1) * 32, (clip.y / clip.w + 1) * 24};
        EXPECT_NEAR(fromMatrix.x, pix.x, 1e-9);
        EXPECT_NEAR(fromMatrix.y, pix.y, 1e-9);
        const glm::dvec2 back = proj.pixelFromView(p);
        EXPECT_NEAR(back.x, pix.x, 1e-9);
        EXPECT_NEAR(back.y, pix.y, 1e-9);
    }
    // Pixel centre + stored depth -> view position -> the same pixel and depth.
    const double d = proj.windowDepthFromViewDepth(7.0);
    const glm::dvec3 q = proj.viewPositionFromDepth(10, 40, d);
    EXPECT_NEAR(-q.z, 7.0, 1e-9);
    EXPECT_NEAR(proj.pixelFromView(q).x, 10.5, 1e-9);
    EXPECT_NEAR(proj.pixelFromView(q).y, 40.5, 1e-9);
}

TEST_P(ProjectionKinds, PointAboveTheViewAxisLandsInTheTopHalf) {
    const Case c = GetParam();
    const Projection proj(makeCamera(c));
    const glm::dvec3 above(0.0, 1.0, -5.0); // view y up
    const glm::dvec4 clip = proj.clipFromView() * glm::dvec4(above, 1.0);
    EXPECT_LT(clip.y / clip.w, 0.0) << "Vulkan NDC y points down";
    EXPECT_LT(proj.pixelFromView(above).y, 24.0);
    const glm::dvec3 right(1.0, 0.0, -5.0);
    EXPECT_GT(proj.pixelFromView(right).x, 32.0);
    // The top-left pixel sees the upper-left of the view volume.
    const glm::dvec3 tl = proj.viewPositionAt({0.5, 0.5}, 5.0);
    EXPECT_LT(tl.x, 0);
    EXPECT_GT(tl.y, 0);
}

INSTANTIATE_TEST_SUITE_P(AllKinds, ProjectionKinds, ::testing::ValuesIn(kCases),
                         [](const auto& info) {
                             std::string s = info.param.label;
                             for (char& ch : s)
                                 if (ch == '-') ch = '_';
                             return s;
                         });

TEST(Projection, PerspectiveFieldOfViewAndAspect) {
    Camera cam;
    cam.width = 200;
    cam.height = 100;
    cam.fovYDeg = 90.0;
    const Projection proj(cam);
    // 90 degrees vertical: the top edge at depth v sits at y = v; aspect 2: x = 2 v.
    const glm::dvec3 tr = proj.viewPositionAt({200.0, 0.0}, 3.0);
    EXPECT_NEAR(tr.y, 3.0, 1e-12);
    EXPECT_NEAR(tr.x, 6.0, 1e-12);
}

TEST(Projection, OrthographicExtentIsTheOrthoHeight) {
    Camera cam;
    cam.projection = ProjectionKind::Orthographic;
    cam.orthoHeight = 8.0;
    cam.width = 300;
    cam.height = 100;
    const Projection proj(cam);
    for (double v : {1.0, 10.0}) {
        const glm::dvec3 tr = proj.viewPositionAt({300.0, 0.0}, v);
        EXPECT_NEAR(tr.y, 4.0, 1e-12);
        EXPECT_NEAR(tr.x, 12.0, 1e-12);
    }
}

TEST(Projection, InvalidDepthRangesAreTypedErrors) {
    Camera cam;
    cam.farPlane = std::numeric_limits<double>::infinity();
    EXPECT_THROW(Projection{cam}, SettingsError); // infinite far needs reversed-Z
    cam.projection = ProjectionKind::ReversedZ;
    EXPECT_NO_THROW(Projection{cam});
    cam.nearPlane = 0.0;
    EXPECT_THROW(Projection{cam}, SettingsError);
    cam.nearPlane = 2.0;
    cam.farPlane = 1.0;
    EXPECT_THROW(Projection{cam}, SettingsError);
}
