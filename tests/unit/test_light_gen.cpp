// The light generator reports progress and stops when cancelled, and neither
// changes what it generates.
#include "culling/errors.hpp"
#include "culling/scene_io.hpp"

#include <gtest/gtest.h>

using namespace lc;

TEST(LightGen, ProgressRisesToOneAndDoesNotChangeTheLights) {
    const Scene scene = makeBuiltinScene("atrium");
    const LightGenSettings g = defaultLightGen(scene, 20000, 7);
    std::vector<double> seen;
    CancelToken never;
    const auto withProgress = generateLights(g, &never, [&](double f) { seen.push_back(f); });
    const auto plain = generateLights(g);
    ASSERT_EQ(withProgress.size(), 20000u);
    ASSERT_EQ(plain.size(), withProgress.size());
    for (std::size_t i = 0; i < plain.size(); ++i) {
        EXPECT_EQ(plain[i].position, withProgress[i].position) << i;
        EXPECT_EQ(plain[i].intensity, withProgress[i].intensity) << i;
    }
    // Several steps for 20,000 lights, never going back, ending at exactly 1.
    ASSERT_GE(seen.size(), 4u);
    for (std::size_t i = 1; i < seen.size(); ++i) EXPECT_LE(seen[i - 1], seen[i]);
    EXPECT_EQ(seen.front(), 0.0);
    EXPECT_EQ(seen.back(), 1.0);
}

TEST(LightGen, CancelStopsGeneration) {
    const LightGenSettings g = defaultLightGen(makeBuiltinScene("sky"), 50000, 1);
    CancelToken cancel;
    int calls = 0;
    // Cancel from inside the progress callback, as the studio's Cancel button
    // does from another thread: the generator must notice at its next check.
    EXPECT_THROW(generateLights(g, &cancel,
                                [&](double) {
                                    if (++calls == 2) cancel.cancelled = true;
                                }),
                 Cancelled);
    EXPECT_EQ(calls, 2);
}
