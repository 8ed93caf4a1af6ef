// The light generator reports progress and stops when cancelled, and neither
// changes what it generates.
#include "culling/core/errors.hpp"
#include "culling/scene/scene_io.hpp"

#include <glm/glm.hpp>
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

// Generated radii follow the scene's size: a 2 m model and a 20 km terrain get
// lights whose largest radius is 1%..20% of the placement box's diagonal,
// while scenes of the built-ins' sizes keep I_min = 0.05 (radius 14.1 units).
TEST(LightGen, RadiiAreRelativeToTheSceneSize) {
    auto boxScene = [](double size) {
        Scene s;
        Mesh m;
        m.name = "box";
        m.positions = {0, 0, 0, float(size), 0, 0, 0, float(size), 0, 0, 0, float(size)};
        m.indices = {0, 1, 2, 0, 2, 3, 0, 3, 1};
        s.meshes.push_back(m);
        return s;
    };
    for (const double size : {2.0, 20000.0}) {
        const Scene s = boxScene(size);
        const LightGenSettings g = defaultLightGen(s, 500, 3);
        const double diagonal = glm::length(g.boxMax - g.boxMin);
        double largest = 0;
        for (const PointLight& l : generateLights(g)) largest = std::max(largest, l.radius());
        EXPECT_LE(largest, kLightRadiusMaxFraction * diagonal * (1 + 1e-12)) << size;
        EXPECT_GE(largest, 0.5 * kLightRadiusMinFraction * diagonal) << size;
        if (size == 2.0) EXPECT_LT(largest, 1.0); // not the 14 units that covered the whole model
        else EXPECT_GT(largest, 100.0);
    }
    for (const auto& b : builtinScenes())
        EXPECT_EQ(defaultLightGen(makeBuiltinScene(b.name), 10, 1).minIntensity, 0.05) << b.name;
}
