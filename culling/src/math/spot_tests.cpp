// Spot-light culling tests; see spot_tests.hpp and docs/SPOT_LIGHTS.md.
#include "culling/math/spot_tests.hpp"

#include <algorithm>
#include <cmath>

namespace lc {

const char* toString(SpotTest t) {
    switch (t) {
    case SpotTest::ApexSphere: return "apex-sphere";
    case SpotTest::TightSphere: return "tight-sphere";
    case SpotTest::ConeSphere: return "cone-sphere";
    case SpotTest::ConePlanes: return "cone-planes";
    }
    return "?";
}

SpotCone makeSpotCone(const glm::dvec3& apex, const glm::dvec3& axis, double range, double angleRad) {
    SpotCone c;
    c.apex = apex;
    c.axis = glm::normalize(axis);
    c.range = range;
    c.cosAngle = std::cos(angleRad);
    c.sinAngle = std::sin(angleRad);
    return c;
}

bool coneContains(const SpotCone& cone, const glm::dvec3& p) {
    const glm::dvec3 d = p - cone.apex;
    const double len2 = glm::dot(d, d);
    if (len2 > cone.range * cone.range) return false;
    // angle(d, axis) <= a  <=>  d.axis >= |d| cos a (the apex itself is inside).
    return glm::dot(d, cone.axis) >= std::sqrt(len2) * cone.cosAngle;
}

BoundingSphere apexSphere(const SpotCone& cone) { return {cone.apex, cone.range}; }

BoundingSphere tightSphere(const SpotCone& cone) {
    // cos a >= sin a  <=>  a <= 45 degrees.
    if (cone.cosAngle >= cone.sinAngle) {
        const double r = cone.range / (2.0 * cone.cosAngle);
        return {cone.apex + cone.axis * r, r};
    }
    return {cone.apex + cone.axis * (cone.range * cone.cosAngle), cone.range * cone.sinAngle};
}

BoundingSphere chunkBoundingSphere(const FrustumChunk& chunk) {
    glm::dvec3 c(0.0);
    for (const auto& k : chunk.corners) c += k;
    c /= 8.0;
    double r2 = 0.0;
    for (const auto& k : chunk.corners) r2 = std::max(r2, glm::dot(k - c, k - c));
    return {c, std::sqrt(r2)};
}

bool coneIntersectsSphere(const SpotCone& cone, const glm::dvec3& c, double r) {
    const glm::dvec3 v = c - cone.apex;
    const double rr = r + sphereTestSlack(c, r + cone.range) + sphereTestSlack(cone.apex, 0.0);
    const double vLen2 = glm::dot(v, v);
    if (vLen2 > (cone.range + rr) * (cone.range + rr)) return false; // outside the range sphere
    const double vAxial = glm::dot(v, cone.axis);
    if (vAxial < -rr) return false;                                 // behind the apex plane
    // |v| sin(phi - a) with phi = angle(v, axis): the distance to the lateral
    // surface while phi <= a + 90 degrees, and less than the true distance
    // (the apex) beyond, so never an unsafe rejection.
    const double vRadial = std::sqrt(std::max(0.0, vLen2 - vAxial * vAxial));
    const double lateral = cone.cosAngle * vRadial - cone.sinAngle * vAxial;
    return lateral <= rr;
}

// Points of S are apex + t u, t in [0, range], u within angle a of the axis,
// so max n.p = n.apex + range * max(0, max_u n.u). For n at angle psi to the
// axis, max_u n.u = |n| when psi <= a, else |n| cos(psi - a)
// = (n.axis) cos a + |n - (n.axis) axis| sin a.
double coneMaxSignedDistance(const SpotCone& cone, const Plane& plane) {
    const glm::dvec3 n(plane);
    const double nLen = glm::length(n);
    const double nAxial = glm::dot(n, cone.axis);
    const double nRadial = std::sqrt(std::max(0.0, nLen * nLen - nAxial * nAxial));
    const double reach = nAxial >= nLen * cone.cosAngle ? nLen
                                                        : nAxial * cone.cosAngle + nRadial * cone.sinAngle;
    return signedDistance(plane, cone.apex) + cone.range * std::max(0.0, reach);
}

bool coneIntersectsChunkPlanes(const SpotCone& cone, const FrustumChunk& chunk) {
    const double tol = sphereTestSlack(cone.apex, cone.range);
    for (const Plane& p : chunk.planes)
        if (coneMaxSignedDistance(cone, p) < -tol) return false;
    return true;
}

BoundingSphere spotCullSphere(SpotTest test, const SpotCone& cone) {
    return test == SpotTest::ApexSphere ? apexSphere(cone) : tightSphere(cone);
}

bool spotIntersectsChunk(SpotTest test, SphereTest sphereTest, const SpotCone& cone,
                         const FrustumChunk& chunk) {
    const BoundingSphere s = spotCullSphere(test, cone);
    if (!sphereIntersectsChunk(sphereTest, chunk, s.center, s.radius)) return false;
    if (test == SpotTest::ConeSphere) {
        const BoundingSphere cell = chunkBoundingSphere(chunk);
        return coneIntersectsSphere(cone, cell.center, cell.radius);
    }
    if (test == SpotTest::ConePlanes) return coneIntersectsChunkPlanes(cone, chunk);
    return true;
}

} // namespace lc
