#pragma once
// The `raster` algorithm's light proxies (docs/ALGORITHMS.md, "Rasterised
// light proxies"): the mesh each light is drawn as, how much it is enlarged
// (the overfit), and which tiles one of its triangles covers at one pixel per
// tile. The CPU reference culls with these functions; the Vulkan pass draws
// the same meshes (vk/raster_pass.cpp) with the same coverage rule, so both
// backends list the same tiles (the GPU's conservative coverage a superset).

#include "culling/core/params.hpp"
#include "culling/math/projection.hpp"
#include "culling/math/tile_math.hpp"

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

namespace lc {

// A closed triangle mesh in its own unit frame.
struct ProxyMesh {
    std::vector<glm::dvec3> vertices;
    std::vector<std::array<std::uint32_t, 3>> triangles;
};

// The icosphere of `level` subdivisions (0..4): the icosahedron's 20
// triangles, each split in four per level, every vertex on the unit sphere.
// Its faces lie inside the sphere: inscribed.
const ProxyMesh& unitIcosphere(std::uint32_t level);
// The cone of `segments` sides: apex at the origin, axis +z, base at z = 1
// with its corners at distance 1 from the axis, closed by a fan on the base.
const ProxyMesh& unitCone(std::uint32_t segments);

// The smallest overfit that makes the proxy enclose what it stands for:
// 1 / (the least distance from the centre to a face's plane) for the
// icosphere (every face of these meshes is acute, so that distance is the
// face's own); 1 / cos(pi / segments) for the cone's base polygon, whose
// sides' midpoints are nearest its axis.
double icosphereEnclosingOverfit(std::uint32_t level);
double coneEnclosingOverfit(std::uint32_t segments);

// One light's proxy in view space: the unit mesh placed by
// `origin + basis * v`. A point light (and a spot light wider than
// proxyConeAngle) is its range sphere's icosphere scaled by the overfit about
// the centre; a spot light is a cone from its apex along its axis, as long as
// its range, its base widened by the overfit (the cone r tan(angle) wide at
// the base holds the spot's whole volume; the polygon inscribed in that
// circle needs coneEnclosingOverfit more).
struct LightProxy {
    bool cone = false;
    double radius = 0;         // the light's range
    double overfit = 1;        // as applied (auto resolved)
    glm::dvec3 origin{0.0};    // sphere: centre; cone: apex
    glm::dmat3 basis{1.0};     // columns: the unit mesh's x, y, z in view space, scaled
    double depthMin = 0, depthMax = 0; // view-depth extent of the proxy's vertices
    const ProxyMesh* mesh = nullptr;
    glm::dvec3 vertex(std::uint32_t i) const { return origin + basis * mesh->vertices[i]; }
    // The tests' rounding slack at this proxy's size (sphereTestSlack).
    double slack() const;
    // The depth range, widened by the slack, reaches [depthMin, depthMax]
    // of a tile (the CPU reference's and Explain's test).
    bool depthReaches(double tileMin, double tileMax) const {
        return depthMin - slack() <= tileMax && depthMax + slack() >= tileMin;
    }
    // proxy-depth slices: the slices (`slices`: the settings' cells of
    // slicing over [clusterNear, clusterFar], their boundaries worked out
    // once for every light and tile) a tile lists the light in, from the
    // depths [lo, hi] its covering triangles span there
    // (proxyTriangleTileDepth), widened by the slack; from the first slice
    // when the proxy reaches the near plane (its part in front is clipped
    // away, and the camera may be inside), to the last when it reaches the
    // far one (Godot's "touches near / far"); with skip-empty only the
    // `occupied` slices.
    std::uint32_t sliceMask(const SliceLocator& slices, bool skipEmpty, double lo, double hi,
                            std::uint32_t occupied) const;
};
// `spotAngle` 0 for a point light; `axis` unit (ignored for a point light).
LightProxy makeLightProxy(const glm::dvec3& center, double radius, const glm::dvec3& axis, double spotAngle,
                          const CullSettings& settings);
// Light `l` of a frame's lights (a point light, or a spot by its axis and angle).
struct ViewLights;
LightProxy makeLightProxy(const ViewLights& lights, std::size_t l, const CullSettings& settings);

// The tiles one triangle (view space) covers, rasterised at one pixel per
// tile through the projection's clip matrix, the part nearer than the near
// plane clipped away (perspective: the rest covers every pixel a light
// reaches; docs/ALGORITHMS.md). Conservative: every tile its triangle overlaps (touching
// counts); else the tiles whose centre it covers (edges included). A
// triangle seen edge-on (no area on screen) covers nothing: its neighbours
// in a closed mesh cover its edges. Calls `covered(tx, ty)` once per tile,
// returns the tiles tested.
std::uint64_t proxyTriangleTiles(const Projection& proj, const TileGrid& grid, const std::array<glm::dvec3, 3>& tri,
                                 bool conservative, const std::function<void(std::uint32_t, std::uint32_t)>& covered);

// How far (tile units) triangle `tri` falls short of overlapping tile
// (tx, ty): the widest separation along the separating-axis test's axes (x,
// y, the edges' normals); <= 0 where it overlaps, +inf where nothing of it
// lies beyond the near plane. Explain's measure of a missed tile.
double proxyTriangleTileGap(const Projection& proj, const TileGrid& grid, const std::array<glm::dvec3, 3>& tri,
                            std::uint32_t tx, std::uint32_t ty);

// raster with proxy-depth slices: the view depths (-z) triangle `tri` spans
// over tile (tx, ty), the tile's whole square in tile units. Conservative:
// the range of its vertices, narrowed by the range its plane takes over the
// tile (1 / depth is affine in screen space under perspective, depth under
// orthographic, so the extremes lie at the tile's corners); not
// conservative: the plane's depth at the tile's centre (a rasteriser's
// interpolated sample), clamped to the vertices' range. A triangle reaching
// nearer than the near plane, or seen edge-on, gets its vertices' range. The
// Vulkan pass's fragment shader works the same out in float (widened).
std::pair<double, double> proxyTriangleTileDepth(const Projection& proj, const TileGrid& grid,
                                                 const std::array<glm::dvec3, 3>& tri, bool conservative,
                                                 std::uint32_t tx, std::uint32_t ty);

// A whole proxy with proxy-depth slices: calls `tile(t, lo, hi)` once per
// tile one of its triangles covers (proxyTriangleTiles), with the depths the
// covering triangles span there (proxyTriangleTileDepth); returns the tiles
// tested. The CPU reference's rule, and the Vulkan pass's for a proxy it
// draws as a box.
std::uint64_t proxySliceTiles(const Projection& proj, const TileGrid& grid, const LightProxy& proxy, bool conservative,
                              const std::function<void(std::uint32_t, double, double)>& tile);

} // namespace lc
