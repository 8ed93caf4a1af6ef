#pragma once
// Spot-light culling tests (docs/SPOT_LIGHTS.md): pure functions over a spot
// light's cone and a tile's or cell's frustum chunk, in view space, double
// precision. The CPU reference backend uses them; tests call them directly;
// the overlays can draw the primitive a test used (tightSphere,
// chunkBoundingSphere).
//
// A spot light's volume is the spherical sector
//   S = { p : |p - apex| <= range  and  angle(p - apex, axis) <= angle },
// the points its light reaches before the inverse-square cut-off (the same
// range rule as a point light) inside its outer cone. Ground truth uses S
// exactly (coneContains).

#include "culling/math/tile_math.hpp"

namespace lc {

// The selectable spot test. Point lights ignore it.
enum class SpotTest {
    ApexSphere,  // the range sphere centred at the apex (the point-light test)
    TightSphere, // the smallest sphere holding S
    ConeSphere,  // TightSphere, then the cone against the chunk's bounding sphere
    ConePlanes,  // TightSphere, then the cone against each of the chunk's planes
};
const char* toString(SpotTest t); // "apex-sphere", "tight-sphere", "cone-sphere", "cone-planes"

struct SpotCone {
    glm::dvec3 apex{0.0};
    glm::dvec3 axis{0.0, 0.0, -1.0}; // unit length
    double range = 1.0;              // > 0
    double cosAngle = 1.0, sinAngle = 0.0; // outer half-angle in (0, 90] degrees
};
// Builds a cone from an outer half-angle in radians; `axis` need not be unit.
SpotCone makeSpotCone(const glm::dvec3& apex, const glm::dvec3& axis, double range, double angleRad);

struct BoundingSphere {
    glm::dvec3 center{0.0};
    double radius = 0.0;
};

// The exact volume: |p - apex| <= range and the angle to the axis <= angle.
bool coneContains(const SpotCone& cone, const glm::dvec3& p);

// The sphere centred at the apex with radius `range`. It holds S exactly
// (every point of S is within `range` of the apex); the issue's
// range / cos(angle) is the apex sphere of a flat-capped cone of axial length
// `range`, which is not the volume lit here (docs/SPOT_LIGHTS.md).
BoundingSphere apexSphere(const SpotCone& cone);

// The smallest sphere holding S. Angle <= 45 degrees: the sphere through the
// apex and the rim circle, centre on the axis at range / (2 cos a), radius the
// same. Above 45 degrees that sphere would exceed the rim's own: the rim
// circle is then a great circle, centre at range * cos a along the axis,
// radius range * sin a (it holds the apex because cos a <= sin a).
BoundingSphere tightSphere(const SpotCone& cone);

// The sphere a cone test uses for a chunk: the centroid of its 8 corners and
// the largest corner distance (it holds the chunk, the convex hull of them).
BoundingSphere chunkBoundingSphere(const FrustumChunk& chunk);

// Cone against a sphere (Bart Wronski, "Cull that cone!", 2017), for the
// spherical sector: false only when the sphere lies entirely outside the
// range sphere, outside the cone's angle (distance to the infinite cone's
// lateral surface > r), or behind the apex plane. Conservative: it may say
// true for a sphere that misses S near the apex's back side, never false for
// one that touches it.
bool coneIntersectsSphere(const SpotCone& cone, const glm::dvec3& c, double r);

// Largest signed distance n.p + w over S (exact, for any plane): the apex, or
// the farthest point of the spherical cap in the plane's normal direction.
double coneMaxSignedDistance(const SpotCone& cone, const Plane& plane);
// False when S lies entirely outside one of the chunk's six planes. It still
// passes chunks that S misses but that no single plane separates (next to a
// corner or an edge of the chunk).
bool coneIntersectsChunkPlanes(const SpotCone& cone, const FrustumChunk& chunk);

// The sphere the sphere tests use for a spot under `test`: the apex sphere for
// ApexSphere, the tight sphere otherwise.
BoundingSphere spotCullSphere(SpotTest test, const SpotCone& cone);

// The whole spot test of one light against one chunk: `sphereTest` (planes,
// planes+aabb, exact) on spotCullSphere, then, for ConeSphere/ConePlanes, the
// cone refinement. Conservative: true whenever S and the chunk share a point.
bool spotIntersectsChunk(SpotTest test, SphereTest sphereTest, const SpotCone& cone,
                         const FrustumChunk& chunk);

} // namespace lc
