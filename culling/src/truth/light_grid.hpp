#pragma once
// Internal to ground_truth.cpp (and its unit test): a uniform 3D grid over view
// space that bins each light sphere's axis-aligned box, so that "which lights
// contain point P" costs a handful of sphere tests instead of one per light.
// A spot light is binned by its range sphere and needed only inside its cone.
//
// It is deliberately independent of the tile, frustum and slicing math that
// the ground truth checks: only axis-aligned boxes and Euclidean distance.

#include "culling/core/backend.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace lc::detail {

// The one containment rule of the ground truth: |P - c| <= r, compared
// squared (no sqrt), in double, in view space.
inline bool lightContains(const glm::dvec3& c, double r, const glm::dvec3& p) {
    const glm::dvec3 d = p - c;
    return d.x * d.x + d.y * d.y + d.z * d.z <= r * r;
}

// Light i's cone at p (true for point lights): the angle between p - apex and
// the axis is at most the outer angle, i.e. d.axis >= |d| cos(angle). Written
// here, not taken from spot_tests.hpp, so that the ground truth does not share
// arithmetic with the tests it checks.
inline bool insideSpotCone(const ViewLights& l, std::size_t i, const glm::dvec3& p) {
    if (!l.isSpot(i)) return true;
    const glm::dvec3 d = p - l.centers[i];
    const glm::dvec3& a = l.spotAxes[i];
    const double len = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
    return d.x * a.x + d.y * a.y + d.z * a.z >= len * std::cos(l.spotAngles[i]);
}

// Whether light i reaches p: inside its range sphere and, for a spot light,
// inside its cone (the exact spherical sector).
inline bool lightNeeds(const ViewLights& l, std::size_t i, const glm::dvec3& p) {
    return lightContains(l.centers[i], l.radii[i], p) && insideSpotCone(l, i, p);
}

class LightGrid {
public:
    // Lights covering more than this many cells are tested at every point
    // instead of being binned (a few huge lights must not blow up memory).
    static constexpr std::uint64_t kMaxCellsPerLight = 4096;
    static constexpr std::uint32_t kMaxCellsPerAxis = 128;

    // Builds the grid over the view-space box [bmin, bmax] that holds every
    // point that will be queried. Lights whose box misses it are dropped.
    LightGrid(const ViewLights& lights, glm::dvec3 bmin, glm::dvec3 bmax) : lights_(&lights) {
        origin_ = bmin;
        const glm::dvec3 ext = bmax - bmin;
        const double maxExt = std::max({ext.x, ext.y, ext.z, 0.0});
        // Cell edge: half the median radius (a typical light then covers ~5^3
        // cells and a cell's candidates are ~4x the lights that contain a point
        // in it), but never finer than maxExt / kMaxCellsPerAxis.
        std::vector<double> radii;
        radii.reserve(lights.size());
        for (std::size_t i = 0; i < lights.size(); ++i)
            if (overlapsBox(i, bmin, bmax)) radii.push_back(lights.radii[i]);
        double median = 0;
        if (!radii.empty()) {
            std::nth_element(radii.begin(), radii.begin() + radii.size() / 2, radii.end());
            median = radii[radii.size() / 2];
        }
        const double scale = std::max({std::abs(bmin.x), std::abs(bmin.y), std::abs(bmin.z),
                                       std::abs(bmax.x), std::abs(bmax.y), std::abs(bmax.z), 1.0});
        cell_ = std::max({0.5 * median, maxExt / kMaxCellsPerAxis, scale * 1e-9});
        for (int a = 0; a < 3; ++a)
            dims_[a] = std::uint32_t(std::clamp(std::ceil(ext[a] / cell_), 1.0, double(kMaxCellsPerAxis)));

        const std::size_t cellCount = std::size_t(dims_[0]) * dims_[1] * dims_[2];
        cellStart_.assign(cellCount + 1, 0);
        // Two passes (count, then fill) give a CSR layout; lights are visited in
        // ascending order, so every cell's list is ascending too.
        for (int pass = 0; pass < 2; ++pass) {
            std::vector<std::uint32_t> cursor;
            if (pass == 1) {
                for (std::size_t c = 0; c < cellCount; ++c) cellStart_[c + 1] += cellStart_[c];
                cellLights_.resize(cellStart_[cellCount]);
                cellSpheres_.resize(cellStart_[cellCount]);
                cursor.assign(cellStart_.begin(), cellStart_.end() - 1);
            }
            for (std::uint32_t i = 0; i < lights.size(); ++i) {
                if (!overlapsBox(i, bmin, bmax)) continue;
                std::uint32_t lo[3], hi[3];
                cellRange(i, lo, hi);
                const std::uint64_t n = std::uint64_t(hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) *
                                        (hi[2] - lo[2] + 1);
                if (n > kMaxCellsPerLight) {
                    if (pass == 0) always_.push_back(i);
                    continue;
                }
                for (std::uint32_t z = lo[2]; z <= hi[2]; ++z)
                    for (std::uint32_t y = lo[1]; y <= hi[1]; ++y)
                        for (std::uint32_t x = lo[0]; x <= hi[0]; ++x) {
                            const std::size_t c = cellIndex(x, y, z);
                            if (pass == 0) ++cellStart_[c + 1];
                            else {
                                const glm::dvec3& lc = lights.centers[i];
                                const double lr = lights.radii[i];
                                cellSpheres_[cursor[c]] = {lc.x, lc.y, lc.z, lr * lr};
                                cellLights_[cursor[c]++] = i;
                            }
                        }
            }
        }
    }

    // Calls f(lightIndex) for every light that reaches p (lightNeeds; p inside
    // the grid's box). Binned lights come first, then the always-tested ones;
    // each group is ascending.
    template <class F> void forEachContaining(const glm::dvec3& p, F&& f) const {
        const std::size_t c = cellIndex(axisCell(p.x, 0), axisCell(p.y, 1), axisCell(p.z, 2));
        // Same arithmetic as lightContains, on a copy of the sphere stored with
        // the cell entry (streams through memory instead of gathering).
        for (std::uint32_t k = cellStart_[c]; k < cellStart_[c + 1]; ++k) {
            const Sphere& s = cellSpheres_[k];
            const double dx = p.x - s.x, dy = p.y - s.y, dz = p.z - s.z;
            if (dx * dx + dy * dy + dz * dz <= s.r2 && insideSpotCone(*lights_, cellLights_[k], p))
                f(cellLights_[k]);
        }
        for (std::uint32_t i : always_)
            if (lightNeeds(*lights_, i, p)) f(i);
    }

    // Needed lights at p, ascending.
    void neededAt(const glm::dvec3& p, std::vector<std::uint32_t>& out) const {
        out.clear();
        forEachContaining(p, [&](std::uint32_t i) { out.push_back(i); });
        std::sort(out.begin(), out.end());
    }

    std::size_t alwaysTestedCount() const { return always_.size(); }
    std::size_t binnedEntries() const { return cellLights_.size(); }
    std::size_t cellCount() const { return cellStart_.size() - 1; }

private:
    // Conservative: grown by a relative epsilon so that rounding in the
    // squared-distance test can never accept a point outside the binned cells.
    double pad(std::size_t i) const {
        const glm::dvec3& c = lights_->centers[i];
        const double r = lights_->radii[i];
        return r * 1e-9 + 1e-12 * std::max({std::abs(c.x), std::abs(c.y), std::abs(c.z), 1.0});
    }
    bool overlapsBox(std::size_t i, glm::dvec3 bmin, glm::dvec3 bmax) const {
        const glm::dvec3& c = lights_->centers[i];
        const double r = lights_->radii[i] + pad(i);
        for (int a = 0; a < 3; ++a)
            if (c[a] + r < bmin[a] || c[a] - r > bmax[a]) return false;
        return true;
    }
    std::uint32_t axisCell(double v, int a) const {
        const double t = std::floor((v - origin_[a]) / cell_);
        if (!(t > 0)) return 0; // also NaN
        return t >= double(dims_[a] - 1) ? dims_[a] - 1 : std::uint32_t(t);
    }
    void cellRange(std::size_t i, std::uint32_t lo[3], std::uint32_t hi[3]) const {
        const glm::dvec3& c = lights_->centers[i];
        const double r = lights_->radii[i] + pad(i);
        for (int a = 0; a < 3; ++a) {
            lo[a] = axisCell(c[a] - r, a);
            hi[a] = axisCell(c[a] + r, a);
        }
    }
    std::size_t cellIndex(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
        return (std::size_t(z) * dims_[1] + y) * dims_[0] + x;
    }

    struct Sphere {
        double x, y, z, r2;
    };
    const ViewLights* lights_;
    std::vector<Sphere> cellSpheres_;
    glm::dvec3 origin_{0.0};
    double cell_ = 1;
    std::uint32_t dims_[3] = {1, 1, 1};
    std::vector<std::uint32_t> cellStart_, cellLights_, always_;
};

} // namespace lc::detail
