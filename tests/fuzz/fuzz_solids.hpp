#pragma once
// What the depth pre-pass does on the host with every mesh a reader gives it
// (scene/closed_solids.hpp), run on each fuzzed mesh: the solids' per-triangle
// arrays match the mesh, and the triangles a camera keeps are the mesh's own,
// at most all of them. Any breach aborts.
#include "culling/math/projection.hpp"
#include "scene/closed_solids.hpp"

#include <cstdlib>

inline void fuzzClosedSolids(const lc::Mesh& mesh) {
    const lc::ClosedSolids solids = lc::findClosedSolids(mesh);
    if (solids.solidOf.size() != mesh.triangleCount() || solids.planes.size() != mesh.triangleCount() ||
        solids.lo.size() != solids.hi.size())
        std::abort();
    for (std::int32_t s : solids.solidOf)
        if (s < -1 || s >= std::int32_t(solids.solidCount())) std::abort();
    for (lc::ProjectionKind kind : {lc::ProjectionKind::Perspective, lc::ProjectionKind::Orthographic}) {
        lc::Camera cam;
        cam.position = {3, 4, 5};
        cam.target = {0, 0, 0};
        cam.projection = kind;
        std::vector<std::uint32_t> ix;
        const std::size_t n =
            lc::appendDepthTriangles(mesh, solids, cam.viewFromWorld() * mesh.transform, lc::Projection(cam), ix);
        if (n > mesh.triangleCount() || ix.size() != 3 * n) std::abort();
        for (std::uint32_t i : ix)
            if (i >= mesh.vertexCount()) std::abort();
    }
}
