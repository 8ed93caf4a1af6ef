// The deterministic light generator. It uses its own PRNG (splitmix64) and its
// own uniform mapping, never <random>'s distributions: those are allowed to
// differ between standard libraries, and a seed must give the same lights on
// every machine.

#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <algorithm>
#include <cmath>

namespace lc {

namespace {

// splitmix64 (Steele, Lea, Flood 2014): a full-period 64-bit generator with
// good statistical quality for this purpose and a one-line state.
struct SplitMix64 {
    std::uint64_t state;
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    // Uniform in [0, 1): the top 53 bits as a double's mantissa (exact).
    double unit() { return double(next() >> 11) * 0x1.0p-53; }
    double range(double lo, double hi) { return lo + (hi - lo) * unit(); }
};

void checkRange(const char* field, double lo, double hi) {
    if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi)
        throw SettingsError(field, "range must be finite with min <= max");
}

} // namespace

void checkLightGen(const LightGenSettings& s) {
    for (int k = 0; k < 3; ++k) {
        checkRange("lights.box", s.boxMin[k], s.boxMax[k]);
        checkRange("lights.color", s.colorMin[k], s.colorMax[k]);
    }
    checkRange("lights.intensity", s.intensityMin, s.intensityMax);
    if (s.intensityMin < 0) throw SettingsError("lights.intensity", "must be >= 0");
    if (s.colorMin.r < 0 || s.colorMin.g < 0 || s.colorMin.b < 0)
        throw SettingsError("lights.color", "must be >= 0");
    if (!(s.minIntensity > 0) || !std::isfinite(s.minIntensity))
        throw SettingsError("lights.min_intensity", "must be finite and > 0");

    if (!(s.spotFraction >= 0.0 && s.spotFraction <= 1.0))
        throw SettingsError("lights.spot_fraction", "must be in [0, 1]");
    checkRange("lights.spot_angle", s.spotAngleMinDeg, s.spotAngleMaxDeg);
    if (s.spotFraction > 0 && !(s.spotAngleMinDeg > 0.0 && s.spotAngleMaxDeg <= 90.0))
        throw SettingsError("lights.spot_angle", "must lie in (0, 90] degrees");
}

std::vector<PointLight> generateLights(const LightGenSettings& s, const CancelToken* cancel,
                                       const Progress& progress) {
    checkLightGen(s);
    SplitMix64 rng{s.seed};
    std::vector<PointLight> out;
    out.reserve(s.count);
    for (std::uint32_t i = 0; i < s.count; ++i) {
        if (i % 4096 == 0) {
            if (cancel) cancel->throwIfCancelled();
            if (progress) progress(double(i) / double(s.count));
        }
        PointLight l;
        l.name = "light_" + std::to_string(i);
        // Fixed draw order (x, y, z, r, g, b, intensity) keeps lights stable
        // when only one range changes.
        for (int k = 0; k < 3; ++k) l.position[k] = rng.range(s.boxMin[k], s.boxMax[k]);
        for (int k = 0; k < 3; ++k) l.color[k] = rng.range(s.colorMin[k], s.colorMax[k]);
        l.intensity = rng.range(s.intensityMin, s.intensityMax);
        l.minIntensity = s.minIntensity;
        if (s.spotFraction > 0.0) {
            // Four more draws per light, spot or not (kind, z, azimuth,
            // angle), so one light's kind never shifts the next light's draws.
            const bool spot = rng.unit() < s.spotFraction;
            const double z = rng.range(-1.0, 1.0), phi = rng.range(0.0, 2.0 * 3.14159265358979323846);
            const double ring = std::sqrt(std::max(0.0, 1.0 - z * z));
            const double angle = rng.range(s.spotAngleMinDeg, s.spotAngleMaxDeg);
            if (spot) {
                l.kind = LightKind::Spot;
                l.direction = {ring * std::cos(phi), ring * std::sin(phi), z};
                l.outerAngleDeg = angle;
            }
        }
        out.push_back(std::move(l));
    }
    if (progress) progress(1.0);
    return out;
}

LightGenSettings defaultLightGen(const Scene& scene, std::uint32_t count, std::uint64_t seed) {
    LightGenSettings s;
    s.count = count;
    s.seed = seed;
    auto [lo, hi] = scene.bounds();
    const bool noGeometry = lo == hi && scene.triangleCount() == 0;
    if (noGeometry) {
        lo = glm::dvec3(-10, 0, -10);  // no geometry: the settings' default box
        hi = glm::dvec3(10, 5, 10);
    }
    // Grow by 5% of the diagonal (at least 0.1 units) so lights also sit just
    // outside the geometry's surfaces, not only inside its bounding box.
    const double grow = std::max(0.1, 0.05 * glm::length(hi - lo));
    s.boxMin = lo - glm::dvec3(grow);
    s.boxMax = hi + glm::dvec3(grow);
    // Radii relative to the scene's size: the brightest light's radius,
    // sqrt(intensityMax / minIntensity) (14.1 units with the defaults), is
    // kept within 1%..20% of the box diagonal by adjusting I_min. Scenes of
    // tens to a thousand units (every built-in scene) stay inside that band
    // and keep their lights; a 2 m model no longer gets lights that each
    // cover all of it, nor a 20 km terrain lights of a pixel.
    if (!noGeometry) {
        const double diagonal = glm::length(s.boxMax - s.boxMin);
        const double rMax = std::sqrt(s.intensityMax / s.minIntensity);
        const double wanted = std::clamp(rMax, kLightRadiusMinFraction * diagonal, kLightRadiusMaxFraction * diagonal);
        if (wanted != rMax && wanted > 0.0) s.minIntensity = s.intensityMax / (wanted * wanted);
    }
    return s;
}

} // namespace lc
