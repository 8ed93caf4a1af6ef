// The Vulkan depth pre-pass against the CPU rasteriser, on the built-in scenes
// and every projection kind (reversed-Z with an infinite far plane included):
// the max depth difference over pixels both cover is reported and bounded, and
// coverage is identical except on triangle edges.
#include "gpu_test_env.hpp"

#include "culling/core/depth.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

// Every triangle of the scene in window space (x right, y down, pixels),
// clipped against the near and far planes (0 <= z <= w in clip space, as both
// rasterisers clip) so that clipped edges count as edges too.
std::vector<std::vector<glm::dvec2>> screenPolygons(const Scene& scene, const Projection& proj) {
    std::vector<std::vector<glm::dvec2>> out;
    const glm::dmat4 clipFromWorld = proj.clipFromView() * scene.camera.viewFromWorld();
    const double W = proj.width(), H = proj.height();
    for (const Mesh& m : scene.meshes) {
        const glm::dmat4 M = clipFromWorld * m.transform;
        for (std::size_t t = 0; t < m.triangleCount(); ++t) {
            std::vector<glm::dvec4> poly;
            for (int k = 0; k < 3; ++k) poly.push_back(M * glm::dvec4(glm::dvec3(m.vertex(m.indices[3 * t + k])), 1.0));
            // Sutherland-Hodgman against z >= 0 and w - z >= 0.
            for (int plane = 0; plane < 2 && !poly.empty(); ++plane) {
                auto dist = [&](const glm::dvec4& v) { return plane == 0 ? v.z : v.w - v.z; };
                std::vector<glm::dvec4> next;
                for (std::size_t i = 0; i < poly.size(); ++i) {
                    const glm::dvec4 a = poly[i], b = poly[(i + 1) % poly.size()];
                    const double da = dist(a), db = dist(b);
                    if (da >= 0) next.push_back(a);
                    if ((da >= 0) != (db >= 0)) next.push_back(a + (b - a) * (da / (da - db)));
                }
                poly = std::move(next);
            }
            if (poly.size() < 3) continue;
            std::vector<glm::dvec2> s;
            for (const auto& v : poly)
                s.push_back({(v.x / v.w * 0.5 + 0.5) * W, (v.y / v.w * 0.5 + 0.5) * H});
            out.push_back(std::move(s));
        }
    }
    return out;
}

double segmentDistance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
    const glm::dvec2 ab = b - a;
    const double len2 = glm::dot(ab, ab);
    const double t = len2 > 0 ? std::clamp(glm::dot(p - a, ab) / len2, 0.0, 1.0) : 0.0;
    return glm::length(p - (a + t * ab));
}

struct DepthCase {
    const char* scene;
    ProjectionKind kind;
    double far;
};

class VulkanDepth : public GpuTest, public ::testing::WithParamInterface<DepthCase> {};

// The Vulkan pre-pass of `scene` against the CPU rasteriser's: the same
// surface wins every pixel but on triangle edges.
// `out`: the Vulkan pass (its figures), when given.
void expectAgreesWithCpuRasteriser(const Scene& scene, const Projection& proj, const std::string& label,
                                   DepthPass* out = nullptr) {
    const DepthImage cpu = rasterizeDepthCpu(scene, proj);
    DepthPass pass = gputest::vulkan().depthPass(scene, proj);
    const DepthImage& gpu = pass.image;
    ASSERT_EQ(gpu.width, cpu.width);
    ASSERT_EQ(gpu.height, cpu.height);
    EXPECT_EQ(gpu.clearDepth, cpu.clearDepth);
    EXPECT_GE(pass.ms, 0.0);

    // Pixels whose centre lies within this distance of a triangle edge may be
    // covered by one rasteriser and not the other: lavapipe snaps vertices to
    // 1/256 pixel (8 sub-pixel bits), the CPU rasteriser works in double.
    constexpr double kEdgeTolerancePx = 1.0 / 256.0;
    // Both interpolate the same plane; float interpolation of depth costs a few
    // ulps of the window depth. A larger difference means a different triangle
    // won the pixel, which is only allowed where one rasteriser's coverage of
    // a nearer triangle differs from the other's: on an edge.
    constexpr double kDepthTolerance = 2e-5;
    std::vector<std::vector<glm::dvec2>> polys;
    auto nearEdge = [&](std::uint32_t x, std::uint32_t y, double& dist) {
        if (polys.empty()) polys = screenPolygons(scene, proj);
        const glm::dvec2 p(x + 0.5, y + 0.5);
        dist = std::numeric_limits<double>::infinity();
        for (const auto& poly : polys)
            for (std::size_t i = 0; i < poly.size(); ++i)
                dist = std::min(dist, segmentDistance(p, poly[i], poly[(i + 1) % poly.size()]));
        return dist <= kEdgeTolerancePx;
    };
    double maxDiff = 0, maxSameDiff = 0, maxDiffAwayFromEdges = 0, maxViewRel = 0, maxEdgeDist = 0;
    std::size_t both = 0, coverageDiffers = 0, depthWinnerDiffers = 0, notOnEdge = 0;
    for (std::uint32_t y = 0; y < cpu.height; ++y) {
        for (std::uint32_t x = 0; x < cpu.width; ++x) {
            const bool c = cpu.hasGeometry(x, y), g = gpu.hasGeometry(x, y);
            double diff = 0;
            if (c && g) {
                ++both;
                diff = std::abs(double(cpu.at(x, y)) - double(gpu.at(x, y)));
                maxDiff = std::max(maxDiff, diff);
                if (diff <= kDepthTolerance) {
                    maxSameDiff = std::max(maxSameDiff, diff);
                    const double vc = proj.viewDepthFromWindowDepth(cpu.at(x, y));
                    const double vg = proj.viewDepthFromWindowDepth(gpu.at(x, y));
                    maxViewRel = std::max(maxViewRel, std::abs(vc - vg) / vc);
                    continue;
                }
                ++depthWinnerDiffers;
            } else if (c != g) {
                ++coverageDiffers;
            } else {
                continue;
            }
            double dist;
            if (!nearEdge(x, y, dist)) {
                ++notOnEdge;
                maxDiffAwayFromEdges = std::max(maxDiffAwayFromEdges, diff);
                ADD_FAILURE() << "pixel (" << x << "," << y << ") differs " << (c != g ? "in coverage" : "in depth")
                              << " (cpu " << cpu.at(x, y) << ", gpu " << gpu.at(x, y)
                              << ") yet lies " << dist << " px from the nearest triangle edge";
            }
            maxEdgeDist = std::max(maxEdgeDist, dist);
        }
    }
    std::printf("[ depth    ] %s %s: %zu pixels both cover, max |depth diff| %.3g (%.3g where the same "
                "surface won: view depth rel %.3g); %zu coverage and %zu winner differences, all within "
                "%.3g px of an edge: %s\n",
                label.c_str(), toString(proj.kind()), both, maxDiff, maxSameDiff, maxViewRel,
                coverageDiffers, depthWinnerDiffers, maxEdgeDist, notOnEdge ? "NO" : "yes");
    EXPECT_GT(both, 0u);
    EXPECT_EQ(notOnEdge, 0u);
    EXPECT_LE(coverageDiffers + depthWinnerDiffers, both / 100) << "edge differences should be rare";
    if (out) *out = std::move(pass);
}


TEST_P(VulkanDepth, AgreesWithCpuRasteriser) {
    const DepthCase dc = GetParam();
    Scene scene = makeBuiltinScene(dc.scene);
    scene.camera.projection = dc.kind;
    scene.camera.width = 320;
    scene.camera.height = 180;
    scene.camera.farPlane = dc.far;
    if (isOrthographic(dc.kind)) scene.camera.orthoHeight = 40.0;
    expectAgreesWithCpuRasteriser(scene, Projection(scene.camera), dc.scene);
}

const double kInfFar = std::numeric_limits<double>::infinity();
INSTANTIATE_TEST_SUITE_P(Scenes, VulkanDepth,
                         ::testing::Values(DepthCase{"atrium", ProjectionKind::Perspective, 1000},
                                           DepthCase{"forest", ProjectionKind::PerspectiveGL, 1000},
                                           DepthCase{"mountain", ProjectionKind::ReversedZ, kInfFar},
                                           DepthCase{"mountain", ProjectionKind::Perspective, 1000},
                                           DepthCase{"wall", ProjectionKind::ReversedZ, 500},
                                           DepthCase{"atrium", ProjectionKind::Orthographic, 1000},
                                           DepthCase{"forest", ProjectionKind::OrthographicGL, 1000},
                                           DepthCase{"sky", ProjectionKind::ReversedZ, kInfFar}),
                         [](const auto& info) {
                             return std::string(info.param.scene) + "_" + std::to_string(info.index);
                         });

// The framebuffer's top row is image row 0: a triangle covering only the top
// half of the view lands only in the top rows (one place handles the y flip).
TEST_F(GpuTest, DepthImageIsTopRowFirst) {
    Scene scene;
    scene.camera.position = {0, 0, 5};
    scene.camera.target = {0, 0, 0};
    scene.camera.width = 64;
    scene.camera.height = 32;
    Mesh m;
    m.positions = {-100, 0.5f, 0, 100, 0.5f, 0, 0, 100, 0}; // only above y = 0.5 (world up)
    m.indices = {0, 1, 2};
    scene.meshes.push_back(m);
    const Projection proj(scene.camera);
    const DepthImage gpu = gputest::vulkan().renderDepth(scene, proj);
    std::size_t top = 0, bottom = 0;
    for (std::uint32_t y = 0; y < gpu.height; ++y)
        for (std::uint32_t x = 0; x < gpu.width; ++x)
            (y < gpu.height / 2 ? top : bottom) += gpu.hasGeometry(x, y);
    EXPECT_GT(top, 0u);
    EXPECT_EQ(bottom, 0u);
}

// A box wound counter-clockwise seen from outside (reversed: from inside).
Mesh boxMesh(glm::dvec3 lo, glm::dvec3 hi, bool reversed = false) {
    Mesh m;
    const glm::dvec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                             {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    for (const glm::dvec3& v : p) m.positions.insert(m.positions.end(), {float(v.x), float(v.y), float(v.z)});
    const std::uint32_t faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 4, 7, 3}, {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}};
    for (const auto& f : faces) {
        if (reversed)
            m.indices.insert(m.indices.end(), {f[0], f[2], f[1], f[0], f[3], f[2]});
        else
            m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
    }
    return m;
}

// The solids are found once per mesh content: a mesh edited in place, its
// sizes kept, is looked at again (a box opened by one index draws all its
// faces; closed again, it loses its back faces again).
TEST_F(GpuTest, ClosedSolidsFollowTheMeshContent) {
    Scene scene;
    scene.camera.position = {3, 4, 6};
    scene.camera.target = {0, 0, 0};
    scene.camera.width = 64;
    scene.camera.height = 36;
    scene.meshes.push_back(boxMesh({-1, -1, -1}, {1, 1, 1}));
    const Projection proj(scene.camera);
    std::unique_ptr<CullBackend> vk = makeVulkanBackend("");
    const Mesh closed = scene.meshes[0];
    EXPECT_EQ(vk->depthPass(scene, proj).trianglesDrawn, 6u) << "three faces of a box seen from a corner's direction";
    scene.meshes[0].indices[0] = scene.meshes[0].indices[1]; // a triangle that repeats a corner: not closed
    EXPECT_EQ(vk->depthPass(scene, proj).trianglesDrawn, 12u);
    scene.meshes[0] = closed;
    scene.meshes[0].positions[0] += 0.5f; // moved corner: still closed, other planes
    EXPECT_LT(vk->depthPass(scene, proj).trianglesDrawn, 12u);
    expectAgreesWithCpuRasteriser(scene, proj, "closed solids, edited box");
}

// A run on the Vulkan backend reports the triangles its pre-pass drew
// (summary.json's depth_triangles, the studio's message log): forest's
// trunks and crowns lose their back faces, its ground and blades do not.
TEST_F(GpuTest, ARunReportsTheTrianglesItsPrePassDrew) {
    Scene scene = makeBuiltinScene("forest");
    scene.camera.width = 320;
    scene.camera.height = 180;
    const std::size_t triangles = scene.triangleCount();
    RunOptions options;
    options.truthOptions.imageError = false;
    const RunOutput out = runPipeline(scene, CullSettings{}, gputest::vulkan(), options);
    EXPECT_EQ(out.result.depthTriangles, triangles);
    EXPECT_LT(out.result.depthTrianglesDrawn, triangles * 2 / 3);
    EXPECT_GT(out.result.depthTrianglesDrawn, triangles / 3);
    EXPECT_EQ(out.truth.metrics.falseNegatives, 0u);
}

// The pre-pass leaves out the faces of closed solids turned away from the
// camera, and only where no view ray can meet them first: a room around the
// camera keeps every face (inside it the faces turned away are the ones
// seen), boxes wound either way, mirrored or not, lose theirs; a box that the
// near plane cuts open shows its far face from inside. The depth is the CPU
// rasteriser's, which draws every triangle, in each projection.
TEST_F(GpuTest, ClosedSolidsLoseOnlyFacesNoRayMeetsFirst) {
    Scene room;
    room.camera.position = {0, 1.7, 8};
    room.camera.target = {0, 1.2, 0};
    room.camera.width = 320;
    room.camera.height = 180;
    room.camera.nearPlane = 0.1;
    room.camera.farPlane = 100;
    room.camera.orthoHeight = 6;
    Scene cut = room;
    room.meshes.push_back(boxMesh({-20, 0, -30}, {20, 12, 20}));     // around the camera
    room.meshes.push_back(boxMesh({-3, 0, -2}, {-1, 2.5, 0}));       // a plain box
    room.meshes.push_back(boxMesh({1, 0, -3}, {2.5, 1.5, -1}, true)); // wound inside out
    Mesh mirrored = boxMesh({0, 0, 0}, {1, 3, 1});
    mirrored.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 0, -6)) *
                         glm::scale(glm::dmat4(1.0), glm::dvec3(-1.5, 1, 1));
    room.meshes.push_back(mirrored);
    // From 0.05 to 0.6 in front of the eye and wider than the view: the near
    // plane (0.1) cuts it, and its far face fills the view from inside.
    // (The camera looks level, so that no corner of it lies behind the eye.)
    cut.camera.target = {0, 1.7, 0};
    cut.meshes.push_back(boxMesh({-8, -3, 7.4}, {8, 7, 7.95}));
    for (Scene* scene : {&room, &cut}) {
        const bool isRoom = scene == &room;
        const std::size_t total = scene->triangleCount();
        for (ProjectionKind kind :
             {ProjectionKind::Perspective, ProjectionKind::ReversedZ, ProjectionKind::Orthographic}) {
            scene->camera.projection = kind;
            const Projection proj(scene->camera);
            DepthPass pass;
            expectAgreesWithCpuRasteriser(*scene, proj, isRoom ? "closed solids, room" : "closed solids, cut", &pass);
            EXPECT_EQ(pass.triangles, total);
            if (isRoom) // the three boxes in the room show at most three faces each
                EXPECT_LE(pass.trianglesDrawn, total - 3 * 6) << toString(kind);
            else
                EXPECT_EQ(pass.trianglesDrawn, total) << toString(kind);
        }
    }
}

} // namespace

namespace {

// The backend keeps its depth image and buffer while the resolution and the
// depth direction stay. Renders that switch between them (a reversed-Z
// camera, another size, back) give exactly what a fresh backend renders.
TEST_F(GpuTest, DepthTargetsFollowTheResolutionAndDirection) {
    std::unique_ptr<CullBackend> kept = makeVulkanBackend("");
    Scene small = makeBuiltinScene("mountain");
    small.camera.width = 320;
    small.camera.height = 180;
    Scene reversed = small;
    reversed.camera.projection = ProjectionKind::ReversedZ;
    Scene large = small;
    large.camera.width = 400;
    large.camera.height = 300;
    for (const Scene* s : {&small, &reversed, &large, &small, &reversed}) {
        const Projection proj(s->camera);
        const DepthImage got = kept->renderDepth(*s, proj);
        const DepthImage want = makeVulkanBackend("")->renderDepth(*s, proj);
        ASSERT_EQ(got.width, want.width);
        ASSERT_EQ(got.height, want.height);
        EXPECT_EQ(got.clearDepth, want.clearDepth);
        EXPECT_TRUE(got.depth == want.depth) << s->camera.width << "x" << s->camera.height;
        EXPECT_GT(got.geometryPixelCount(), 0u);
    }
}

} // namespace
