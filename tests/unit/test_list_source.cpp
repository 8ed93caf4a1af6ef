// The one pipeline with a list source of a test's own (core/pipeline.hpp):
// a fourth source, written here as a newcomer would write one, gets the
// depth, ground truth, the located misses and the exports from runPipeline
// without touching anything else.
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/custom/custom_cull.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/ground_truth.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

using namespace lc;

namespace {

// An engine whose "culling" lists every light in every tile, but forgets
// light `forget` (-1: none).
class EveryLightSource final : public ListSource {
public:
    explicit EveryLightSource(int forget = -1) : forget_(forget) {}
    CullResult makeLists(const Scene&, const DepthImage&, const Projection&, const TileGrid& grid,
                         const ViewLights& lights) override {
        CullResult r;
        r.algorithm = Algorithm::MinMax; // one list per tile
        r.grid = grid;
        r.tileDepthMin.assign(grid.tileCount(), 0.0);
        r.tileDepthMax.assign(grid.tileCount(), 1e30);
        for (std::uint32_t t = 0; t < grid.tileCount(); ++t) {
            r.listOffset.push_back(std::uint32_t(r.lightIndices.size()));
            for (std::uint32_t i = 0; i < lights.size(); ++i)
                if (int(i) != forget_) r.lightIndices.push_back(i);
            r.listCount.push_back(std::uint32_t(r.lightIndices.size()) - r.listOffset.back());
        }
        r.backend = "every-light";
        r.device = "a test's engine";
        r.timingMethod = "not timed";
        ++calls;
        return r;
    }
    int calls = 0;

private:
    int forget_;
};

Scene smallAtrium() {
    Scene s = makeBuiltinScene("atrium");
    s.camera.width = 160;
    s.camera.height = 96;
    s.lights.resize(24);
    return s;
}

} // namespace

TEST(ListSource, ANewSourceGetsDepthTruthAndExportsFromThePipeline) {
    const Scene scene = smallAtrium();
    auto cpu = makeCpuBackend();
    EveryLightSource source;
    RunOptions o;
    o.truthOptions.imageError = false;
    const RunOutput run = runPipeline(scene, source, cpu.get(), o);
    EXPECT_EQ(source.calls, 1);
    ASSERT_TRUE(run.truthComputed);
    EXPECT_GT(run.truth.metrics.geometryPixels, 0u);
    EXPECT_EQ(run.truth.metrics.falseNegatives, 0u); // every light everywhere misses none
    EXPECT_LT(run.truth.metrics.efficiency, 1.0);
    // The pipeline's own figures around the source's lists.
    EXPECT_GE(run.result.timings.depthMs, 0.0);
    EXPECT_GE(run.result.timings.cullMs, 0.0); // not timed by the source: the wall clock around it
    EXPECT_EQ(run.result.depthTriangles, scene.triangleCount());
    EXPECT_EQ(run.result.backend, "every-light");
    EXPECT_EQ(run.depthFrom, "pre-pass on cpu (" + cpu->deviceName() + ")"); // not the lists' maker
    const nlohmann::json j = nlohmann::json::parse(summaryJson(scene, CullSettings{}, run));
    EXPECT_EQ(j["metrics"]["false_negatives"], 0);
    EXPECT_EQ(j["depth_source"], run.depthFrom);
}

TEST(ListSource, ASourcesMissesAreLocatedAndItsBadListsRefused) {
    const Scene scene = smallAtrium();
    auto cpu = makeCpuBackend();
    RunOptions o;
    o.truthOptions.imageError = false;
    // A light some pixel needs, forgotten: located in the tiles whose pixels need it.
    std::uint32_t needing = 0;
    {
        EveryLightSource all;
        const RunOutput full = runPipeline(scene, all, cpu.get(), o);
        int needed = -1;
        for (std::uint32_t t = 0; t < full.result.grid.tileCount() && needed < 0; ++t) {
            const auto rows = pixelsNeedingLights(full.depth, Projection(scene.camera), full.lights, full.result.grid, t);
            if (!rows.empty()) needed = int(rows.front().first);
        }
        ASSERT_GE(needed, 0) << "no pixel of the atrium needs any of its first 24 lights";
        EveryLightSource forgetful(needed);
        const RunOutput run = runPipeline(scene, forgetful, cpu.get(), o);
        const auto missed = locateFalseNegatives(run, Projection(scene.camera));
        for (const MissedLight& m : missed) {
            EXPECT_EQ(m.light, std::uint32_t(needed));
            EXPECT_EQ(m.cause, MissCause::CullingTest);
            needing += m.pixels;
        }
        EXPECT_EQ(needing, run.truth.metrics.falseNegatives);
        EXPECT_GT(needing, 0u);
        EXPECT_EQ(full.truth.metrics.exactWork - run.truth.metrics.exactWork, 0u); // needs do not depend on lists
    }
    // A source whose lists name a light that does not exist: refused by the
    // pipeline's check, never judged.
    class Broken final : public ListSource {
        CullResult makeLists(const Scene& sc, const DepthImage& d, const Projection& p, const TileGrid& g,
                             const ViewLights& l) override {
            CullResult r = EveryLightSource().makeLists(sc, d, p, g, l);
            r.lightIndices.back() = std::uint32_t(l.size() + 5);
            return r;
        }
    } broken;
    EXPECT_THROW(runPipeline(scene, broken, cpu.get(), o), Error);
    // No backend and no depth: nothing to cull over.
    EveryLightSource all;
    EXPECT_THROW(runPipeline(scene, all, nullptr, o), Error);
    // No backend, a depth given: shaded on the CPU reference.
    const DepthImage depth = cpu->renderDepth(scene, Projection(scene.camera));
    o.reuseDepth = &depth;
    o.truthOptions.imageError = true;
    const RunOutput given = runPipeline(scene, all, nullptr, o);
    EXPECT_TRUE(given.depthReused);
    EXPECT_TRUE(given.truth.metrics.imageErrorComputed);
    EXPECT_EQ(given.truth.metrics.imageMaxError, 0.0); // every light in every list: the all-lights image
}
