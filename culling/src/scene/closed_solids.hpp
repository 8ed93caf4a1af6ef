#pragma once
// The closed solids of a mesh, so that the depth pre-pass can leave out the
// faces of a solid that are turned away from the camera: seen from outside a
// closed, consistently wound surface, the nearest surface along every ray is
// a face turned towards the ray's origin, so the faces turned away never win
// a pixel. On llvmpipe the pre-pass costs in proportion to the fragments
// rasterised, and those faces are about half of a solid's.
//
// A solid here is a set of triangles joined across edges where every directed
// edge (a, b), vertices welded by exact position, is met by exactly one
// directed edge (b, a) of the set: closed, two-manifold at its edges and
// consistently wound. Its signed volume says which way it is wound (outward
// when positive). Every other triangle (open sheets such as a ground quad or
// a grass blade, non-manifold or inconsistently wound parts, triangles whose
// corners repeat a vertex) is open and always drawn.
//
// Written here rather than with OpenMesh (which the mesh readers use): its
// mesh kernel refuses the faces that would make an edge non-manifold instead
// of reporting them, and a mesh mixes solids and open sheets, so the question
// is asked of every edge-connected part, on the positions and indices as they
// are.

#include "culling/math/projection.hpp"
#include "culling/scene/scene.hpp"

#include <cstdint>
#include <glm/glm.hpp>
#include <vector>

namespace lc {

struct ClosedSolids {
    // Per triangle of the mesh: the solid it belongs to, or -1 (open).
    std::vector<std::int32_t> solidOf;
    // Per triangle: the outward normal n (unnormalised, model space) and n . a
    // for a corner a; zero for open triangles.
    std::vector<glm::dvec4> planes;
    // Per solid: its bounding box in model space.
    std::vector<glm::dvec3> lo, hi;

    std::size_t solidCount() const { return lo.size(); }
};

// The analysis above, of the mesh's model-space positions (O(T log T)).
ClosedSolids findClosedSolids(const Mesh& mesh);

// Appends to `out` the indices (three per triangle, the mesh's own vertex
// indices, in the mesh's triangle order) of the triangles a depth pre-pass
// through `proj` must draw, `viewFromModel` taking the mesh to view space:
// every open triangle; every triangle of a solid that is not wholly beyond
// the near plane (the camera could be inside it, or the near plane cut it
// open); of the other solids, the faces turned towards the camera (towards
// the eye in perspective, against the view direction in orthographic).
// Everything is drawn when viewFromModel is not an invertible affine map.
// Returns the number of triangles appended.
std::size_t appendDepthTriangles(const Mesh& mesh, const ClosedSolids& solids,
                                 const glm::dmat4& viewFromModel, const Projection& proj,
                                 std::vector<std::uint32_t>& out);

} // namespace lc
