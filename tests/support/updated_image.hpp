#pragma once
// Shared by the unit and gpu tiers: an all-lights image that shadeAndCompare
// updated from an earlier run's, checked against the same run shaded from
// every light on the same backend.
#include "culling/core/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <gtest/gtest.h>
#include <string>

namespace lc::testutil {

// An updated all-lights image against one shaded from every light: bitwise
// where no update touched the pixel since it was last shaded from every
// light (nothing carried), else within 2^-14 of the value, the bound the
// carried magnitudes keep (kCarryLimit). Returns the worst relative gap.
inline double expectCloseToFresh(const RunOutput& updated, const RunOutput& fresh, const std::string& what) {
    const std::vector<float>&u = updated.shadedAll, &f = fresh.shadedAll, &carried = updated.shadedAllCarried;
    EXPECT_EQ(u.size(), f.size()) << what;
    EXPECT_EQ(carried.size(), u.size()) << what;
    if (u.size() != f.size() || carried.size() != u.size()) return 1;
    double worst = 0;
    std::size_t bad = 0;
    for (std::size_t i = 0; i < u.size() / 3; ++i) {
        const bool touched = carried[3 * i] != 0 || carried[3 * i + 1] != 0 || carried[3 * i + 2] != 0;
        for (std::size_t k = 3 * i; k < 3 * i + 3; ++k) {
            if (!touched) {
                bad += u[k] != f[k];
                continue;
            }
            bad += !(carried[k] <= kCarryLimit * std::fabs(u[k]));
            const double gap =
                std::fabs(double(u[k]) - double(f[k])) / std::max(std::fabs(f[k]), std::fabs(u[k]));
            worst = std::max(worst, gap);
            bad += !(gap <= std::ldexp(1.0, -14));
        }
    }
    EXPECT_EQ(bad, 0u) << what << ": worst relative gap " << worst;
    EXPECT_EQ(updated.shadedCulled, fresh.shadedCulled) << what << ": the culled image is shaded afresh";
    const Metrics &mu = updated.truth.metrics, &mf = fresh.truth.metrics;
    EXPECT_NEAR(mu.imageRmse, mf.imageRmse, 1e-4 * mf.imageRmse + 1e-12) << what;
    EXPECT_NEAR(mu.imageMaxError, mf.imageMaxError, 1e-4 * mf.imageMaxError + 1e-12) << what;
    return worst;
}

// Makes `light` a narrow spot at the camera, aimed at its target and a
// million times as bright: it outshines the other lights in the middle of
// the view and reaches no other pixel, so dimming it again cancels most of
// those pixels' sums and leaves the rest untouched.
inline void makeOutshiningSpot(Light& light, const Camera& camera) {
    light.kind = LightKind::Spot;
    light.position = camera.position;
    light.direction = camera.target - camera.position;
    light.outerAngleDeg = 12.0;
    light.intensity *= 1e6;
}

} // namespace lc::testutil
