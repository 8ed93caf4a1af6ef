// Closed solids (scene/closed_solids.hpp): which triangles of a mesh form
// closed, consistently wound solids, their outward planes, and which
// triangles a depth pre-pass draws through a camera. The Vulkan pre-pass that
// draws them is checked against the CPU rasteriser in
// tests/gpu/test_vulkan_depth.cpp.
#include "culling/scene/scene_io.hpp"
#include "scene/closed_solids.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>
#include <set>

using namespace lc;

namespace {

// A quad of four fresh vertices (as the built-in scenes' builder and many
// exporters make them: the solid is found on welded positions).
void addQuad(Mesh& m, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, glm::dvec3 d, bool reversed = false) {
    const auto first = std::uint32_t(m.vertexCount());
    for (const glm::dvec3& p : {a, b, c, d})
        m.positions.insert(m.positions.end(), {float(p.x), float(p.y), float(p.z)});
    const std::uint32_t i[4] = {first, first + 1, first + 2, first + 3};
    if (reversed)
        m.indices.insert(m.indices.end(), {i[0], i[2], i[1], i[0], i[3], i[2]});
    else
        m.indices.insert(m.indices.end(), {i[0], i[1], i[2], i[0], i[2], i[3]});
}

// An axis-aligned box wound counter-clockwise seen from outside (or, reversed,
// from inside), 12 triangles; `skip` leaves one face out (0..5).
void addBox(Mesh& m, glm::dvec3 lo, glm::dvec3 hi, bool reversed = false, int skip = -1) {
    const glm::dvec3 p[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                             {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    const int faces[6][4] = {{0, 3, 2, 1}, {4, 5, 6, 7}, {0, 4, 7, 3},
                             {1, 2, 6, 5}, {0, 1, 5, 4}, {3, 7, 6, 2}};
    for (int f = 0; f < 6; ++f)
        if (f != skip) addQuad(m, p[faces[f][0]], p[faces[f][1]], p[faces[f][2]], p[faces[f][3]], reversed);
}

glm::dvec3 corner(const Mesh& m, std::size_t t, int k) {
    return glm::dvec3(m.vertex(m.indices[3 * t + k]));
}

Camera lookingAt(glm::dvec3 eye, glm::dvec3 target, ProjectionKind kind = ProjectionKind::Perspective) {
    Camera c;
    c.position = eye;
    c.target = target;
    c.up = {0, 1, 0};
    c.projection = kind;
    c.fovYDeg = 60;
    c.nearPlane = 0.1;
    c.farPlane = 100;
    c.orthoHeight = 10;
    c.width = 64;
    c.height = 64;
    return c;
}

// The triangles (by index into the mesh) that appendDepthTriangles keeps.
std::vector<std::size_t> keptTriangles(const Mesh& m, const ClosedSolids& s, const Camera& cam) {
    std::vector<std::uint32_t> ix;
    const std::size_t n = appendDepthTriangles(m, s, cam.viewFromWorld() * m.transform, Projection(cam), ix);
    EXPECT_EQ(ix.size(), 3 * n);
    std::vector<std::size_t> kept;
    std::size_t t = 0;
    for (std::size_t i = 0; i < ix.size(); i += 3) {
        while (t < m.triangleCount() &&
               !std::equal(ix.begin() + i, ix.begin() + i + 3, m.indices.begin() + 3 * t))
            ++t;
        EXPECT_LT(t, m.triangleCount()) << "an appended triangle is not the mesh's, or out of order";
        kept.push_back(t++);
    }
    return kept;
}

} // namespace

TEST(ClosedSolids, ABoxOfSeparateQuadsIsOneSolidWithOutwardPlanes) {
    for (bool reversed : {false, true}) {
        Mesh m;
        addBox(m, {-1, -2, -3}, {1, 2, 3}, reversed);
        const ClosedSolids s = findClosedSolids(m);
        ASSERT_EQ(s.solidCount(), 1u) << "reversed " << reversed;
        EXPECT_EQ(s.lo[0], glm::dvec3(-1, -2, -3));
        EXPECT_EQ(s.hi[0], glm::dvec3(1, 2, 3));
        for (std::size_t t = 0; t < m.triangleCount(); ++t) {
            EXPECT_EQ(s.solidOf[t], 0);
            // Outward whichever way the box is wound: away from its centre.
            const glm::dvec3 n(s.planes[t]),
                centroid = (corner(m, t, 0) + corner(m, t, 1) + corner(m, t, 2)) / 3.0;
            EXPECT_GT(glm::dot(n, centroid), 0.0) << "triangle " << t << " reversed " << reversed;
            EXPECT_NEAR(s.planes[t].w, glm::dot(n, corner(m, t, 2)), 1e-12);
        }
    }
}

TEST(ClosedSolids, OpenOrIllFormedPartsAreNotSolids) {
    struct Case {
        const char* what;
        Mesh mesh;
    };
    std::vector<Case> cases;
    {
        Case c{"a box without its top", {}};
        addBox(c.mesh, {0, 0, 0}, {1, 1, 1}, false, 5);
        cases.push_back(std::move(c));
    }
    {
        Case c{"a box with one face wound the other way", {}};
        addBox(c.mesh, {0, 0, 0}, {1, 1, 1}, false, 5);
        addQuad(c.mesh, {0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}, true);
        cases.push_back(std::move(c));
    }
    {
        Case c{"a box with a face twice (edges met by three triangles)", {}};
        addBox(c.mesh, {0, 0, 0}, {1, 1, 1});
        addQuad(c.mesh, {0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0});
        cases.push_back(std::move(c));
    }
    {
        Case c{"a sheet and its reverse on the same vertices (no volume)", {}};
        addQuad(c.mesh, {0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0});
        c.mesh.indices.insert(c.mesh.indices.end(), {0, 2, 1, 0, 3, 2});
        cases.push_back(std::move(c));
    }
    {
        Case c{"triangles repeating a vertex", {}};
        addBox(c.mesh, {0, 0, 0}, {1, 1, 1});
        for (std::size_t t = 0; t < c.mesh.triangleCount(); ++t)
            c.mesh.indices[3 * t + 2] = c.mesh.indices[3 * t];
        cases.push_back(std::move(c));
    }
    {
        Case c{"indices beyond the vertices (a mesh Mesh::validate() refuses)", {}};
        addBox(c.mesh, {0, 0, 0}, {1, 1, 1});
        c.mesh.indices[7] = 1000000;
        cases.push_back(std::move(c));
    }
    for (const Case& c : cases) {
        const ClosedSolids s = findClosedSolids(c.mesh);
        EXPECT_EQ(s.solidCount(), 0u) << c.what;
        for (std::int32_t id : s.solidOf)
            EXPECT_EQ(id, -1) << c.what;
        // Open triangles are drawn whatever the camera.
        const Camera cam = lookingAt({3, 4, 5}, {0.5, 0.5, 0.5});
        EXPECT_EQ(keptTriangles(c.mesh, s, cam).size(), c.mesh.triangleCount()) << c.what;
    }
}

TEST(ClosedSolids, SolidsAndSheetsInOneMeshAreToldApart) {
    Mesh m;
    addQuad(m, {-10, 0, -10}, {-10, 0, 10}, {10, 0, 10}, {10, 0, -10}); // ground: triangles 0, 1
    addBox(m, {0, 0, 0}, {1, 1, 1});                                    // 2..13
    addBox(m, {1.5, 0, 0}, {2.5, 1, 1}, true);                          // 14..25
    addQuad(m, {5, 0, 5}, {5.1, 0, 5}, {5.1, 1, 5}, {5, 1, 5});         // a blade: 26, 27
    const ClosedSolids s = findClosedSolids(m);
    ASSERT_EQ(s.solidCount(), 2u);
    std::set<std::int32_t> first, second;
    for (std::size_t t = 2; t < 14; ++t)
        first.insert(s.solidOf[t]);
    for (std::size_t t = 14; t < 26; ++t)
        second.insert(s.solidOf[t]);
    EXPECT_EQ(first, std::set<std::int32_t>{0});
    EXPECT_EQ(second, std::set<std::int32_t>{1});
    for (std::size_t t : {0u, 1u, 26u, 27u})
        EXPECT_EQ(s.solidOf[t], -1) << t;

    // Two boxes sharing a face meet at edges of four triangles: neither is
    // taken for a solid (drawn whole, as before).
    Mesh stacked;
    addBox(stacked, {0, 0, 0}, {1, 1, 1});
    addBox(stacked, {0, 1, 0}, {1, 2, 1});
    EXPECT_EQ(findClosedSolids(stacked).solidCount(), 0u);
}

TEST(ClosedSolids, TheCameraSeesTheFacesTurnedTowardsIt) {
    Mesh m;
    addBox(m, {-1, -1, -1}, {1, 1, 1});
    const ClosedSolids s = findClosedSolids(m);
    ASSERT_EQ(s.solidCount(), 1u);
    // From a corner's direction three faces face the eye; from straight in
    // front one (the four side faces are edge-on, in orthographic as well).
    const glm::dvec3 eye(4, 5, 6);
    const std::vector<std::size_t> kept = keptTriangles(m, s, lookingAt(eye, {0, 0, 0}));
    EXPECT_EQ(kept.size(), 6u);
    for (std::size_t t : kept)
        EXPECT_GT(glm::dot(glm::dvec3(s.planes[t]), eye - corner(m, t, 0)), 0.0) << t;
    EXPECT_EQ(keptTriangles(m, s, lookingAt({0, 0, 10}, {0, 0, 0}, ProjectionKind::Orthographic)).size(), 2u);
    EXPECT_EQ(keptTriangles(m, s, lookingAt({0, 0, 10}, {0, 0, 0}, ProjectionKind::ReversedZ)).size(), 2u);

    // Inside the box, or with the near plane cutting it open: every face.
    EXPECT_EQ(keptTriangles(m, s, lookingAt({0.2, 0.1, 0.3}, {0, 0, -5})).size(), 12u);
    EXPECT_EQ(keptTriangles(m, s, lookingAt({0, 0, 1.05}, {0, 0, 0})).size(), 12u);
    // Just beyond the near plane (0.1), it is seen from outside again.
    EXPECT_EQ(keptTriangles(m, s, lookingAt({0, 0, 1.2}, {0, 0, 0})).size(), 2u);
    // Orthographic: the near plane is where the rays start.
    EXPECT_EQ(keptTriangles(m, s, lookingAt({0, 0, 1.05}, {0, 0, 0}, ProjectionKind::Orthographic)).size(),
              12u);
}

TEST(ClosedSolids, TheMeshTransformIsFollowedMirrorsIncluded) {
    Mesh m;
    addBox(m, {0, 0, 0}, {1, 1, 1});
    const ClosedSolids s = findClosedSolids(m);
    const Camera cam = lookingAt({0, 0.5, 10}, {0, 0.5, 0});
    // Moved to x in [4, 5] by a mirror in x: the face turned towards the
    // camera (at x = 0) beside the +z face (triangles 2, 3) is world x = 4,
    // the mesh's +x face (6, 7).
    m.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(5, 0, 0)) *
                  glm::scale(glm::dmat4(1.0), glm::dvec3(-1, 1, 1));
    EXPECT_EQ(keptTriangles(m, s, cam), (std::vector<std::size_t>{2, 3, 6, 7}));
    // Moved there without the mirror: the mesh's -x face (4, 5).
    m.transform = glm::translate(glm::dmat4(1.0), glm::dvec3(4, 0, 0));
    EXPECT_EQ(keptTriangles(m, s, cam), (std::vector<std::size_t>{2, 3, 4, 5}));
    // A projective transform (not affine): every triangle, as drawn before.
    m.transform = glm::dmat4(1.0);
    m.transform[2][3] = 0.1;
    EXPECT_EQ(keptTriangles(m, s, cam).size(), 12u);
}

TEST(ClosedSolids, BuiltInScenesShapesAreClosed) {
    // The built-in scenes' cylinders, cones, boxes and spheres are closed
    // solids (their caps wound as their sides, the spheres' poles one point
    // each): forest is 400 trunks and 400 crowns beside a ground and 2,400
    // grass blades; each cone's side has ten triangles that meet the apex
    // with two corners (no area, so no part of a solid).
    const Scene forest = makeBuiltinScene("forest");
    ASSERT_EQ(forest.meshes.size(), 1u);
    const ClosedSolids s = findClosedSolids(forest.meshes[0]);
    EXPECT_EQ(s.solidCount(), 800u);
    std::size_t open = 0;
    for (std::int32_t id : s.solidOf)
        open += id < 0;
    EXPECT_EQ(open, 2u + 400u * 6u * 2u + 400u * 10u);
    const Scene mountain = makeBuiltinScene("mountain");
    std::size_t solids = 0;
    for (const Mesh& m : mountain.meshes)
        solids += findClosedSolids(m).solidCount();
    EXPECT_EQ(solids, 4u) << "the figure's body, head and arms";
}
