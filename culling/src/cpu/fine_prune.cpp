#include "culling/cpu/fine_prune.hpp"

#include "culling/math/tile_math.hpp"

#include <cmath>

namespace lc {

bool fptlPixelKeeps(const ViewLights& lights, std::size_t i, const glm::dvec3& p) {
    const glm::dvec3& c = lights.centers[i];
    const double r = lights.radii[i];
    const double slack = sphereTestSlack(c, r);
    const glm::dvec3 d = p - c;
    const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    if (len > r + slack) return false;
    if (!lights.isSpot(i)) return true;
    const glm::dvec3& a = lights.spotAxes[i];
    return d.x * a.x + d.y * a.y + d.z * a.z >= len * std::cos(lights.spotAngles[i]) - slack;
}

} // namespace lc
