// End to end through the CLI: every built-in scene with every algorithm on the
// CPU backend reports no false negatives, and `all` reports W = (pixels with
// geometry) x lights and efficiency = E / W. 320x180 keeps the whole file
// to well under a minute.
#include "cli_support.hpp"

#include "culling/core/params.hpp"
#include "culling/diagnostics/export.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

using lc_test::runCli;
using lc_test::ScratchDir;
namespace fs = std::filesystem;

namespace {

const char* kAlgorithms[] = {"all", "naive", "minmax", "halfz", "2.5d", "clustered", "fptl", "zbin"};

nlohmann::json runAndRead(const ScratchDir& s, const std::vector<std::string>& extra, const std::string& tag) {
    const fs::path out = s.path / tag;
    std::vector<std::string> args = {"run", "--width", "320", "--height", "180", "--backend", "cpu",
                                      "--out", out.string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto r = runCli(args, s.path);
    EXPECT_EQ(r.code, 0) << tag << ": " << r.err;
    if (r.code != 0) return {};
    // tiles.csv: a header and one row per list.
    EXPECT_EQ(lc_test::lineCount(lc_test::slurp(out / "tiles.csv")),
              1 + nlohmann::json::parse(lc_test::slurp(out / "summary.json"))["metrics"]["lists"].get<std::size_t>())
        << tag;
    return nlohmann::json::parse(lc_test::slurp(out / "summary.json"));
}

// The run the CLI made, made again in process: the same built-in scene,
// parameters and backend. Its metrics are what summary.json must report
// (a summary that wrote a wrong image error still passed "is a number").
lc::RunOutput runInProcess(const std::string& scene, const std::string& alg) {
    lc::Scene s = lc::makeBuiltinScene(scene);
    lc::CullSettings cs;
    lc::setParam(cs, s.camera, "width", "320");
    lc::setParam(cs, s.camera, "height", "180");
    lc::setParam(cs, s.camera, "algorithm", alg);
    auto backend = lc::makeBackend("cpu");
    return lc::runPipeline(s, cs, *backend, lc::RunOptions{});
}

// summary.json's metrics against the run's own figures. The exporter writes
// doubles that read back exactly, and the CPU backend is deterministic: equal.
void expectMetricsOfTheRun(const nlohmann::json& m, const lc::Metrics& run, const std::string& tag) {
    ASSERT_TRUE(run.imageErrorComputed) << tag;
    EXPECT_EQ(m["false_negatives"].get<std::uint64_t>(), run.falseNegatives) << tag;
    EXPECT_EQ(m["shading_work"].get<std::uint64_t>(), run.shadingWork) << tag;
    EXPECT_EQ(m["exact_work"].get<std::uint64_t>(), run.exactWork) << tag;
    EXPECT_EQ(m["optimal_work"].get<std::uint64_t>(), run.optimalWork) << tag;
    EXPECT_EQ(m["geometry_pixels"].get<std::uint64_t>(), run.geometryPixels) << tag;
    EXPECT_EQ(m["efficiency"].get<double>(), run.efficiency) << tag;
    EXPECT_EQ(m["efficiency_vs_optimal"].get<double>(), run.efficiencyVsOptimal) << tag;
    EXPECT_EQ(m["mean_list"].get<double>(), run.meanList) << tag;
    EXPECT_EQ(m["max_list"].get<std::uint64_t>(), run.maxList) << tag;
    EXPECT_EQ(m["result_bytes"].get<std::uint64_t>(), run.resultBytes) << tag;
    EXPECT_EQ(m["image_rmse"].get<double>(), run.imageRmse) << tag;
    EXPECT_EQ(m["image_max_error"].get<double>(), run.imageMaxError) << tag;
}

} // namespace

TEST(EndToEnd, EveryBuiltinWithEveryAlgorithmHasNoFalseNegatives) {
    ScratchDir s;
    for (const auto& scene : lc::builtinScenes()) {
        std::uint64_t exactWork = 0;
        for (const char* alg : kAlgorithms) {
            const std::string tag = scene.name + "-" + alg;
            const auto j = runAndRead(s, {"--builtin", scene.name, "--algorithm", alg}, tag);
            if (j.is_null()) continue;
            const auto& m = j["metrics"];
            EXPECT_EQ(j["algorithm"], alg) << tag;
            EXPECT_EQ(m["false_negatives"], 0) << tag;
            const auto W = m["shading_work"].get<std::uint64_t>(), E = m["exact_work"].get<std::uint64_t>();
            EXPECT_LE(E, W) << tag;
            EXPECT_EQ(m["efficiency"].get<double>(), W ? double(E) / double(W) : 1.0) << tag;
            // The needed lights do not depend on the algorithm.
            if (exactWork == 0) exactWork = E;
            EXPECT_EQ(E, exactWork) << tag;
            if (std::string(alg) == "all") {
                EXPECT_EQ(W, m["geometry_pixels"].get<std::uint64_t>() * j["lights"].get<std::uint64_t>()) << tag;
                EXPECT_EQ(m["lists"], 1) << tag;
                EXPECT_EQ(m["image_rmse"].get<double>(), 0.0) << tag;
            } else {
                EXPECT_EQ(m["lists"].get<std::uint64_t>() % (j["tiles_x"].get<std::uint64_t>() * j["tiles_y"].get<std::uint64_t>()), 0u) << tag;
            }
            // With FN = 0 the image error is only the unlisted lights' tails.
            EXPECT_GE(m["image_max_error"].get<double>(), m["image_rmse"].get<double>()) << tag;
            // And every figure is the run's own, not one recomputed from this JSON.
            expectMetricsOfTheRun(m, runInProcess(scene.name, alg).truth.metrics, tag);
        }
    }
}

TEST(EndToEnd, EverySphereTestAndSlicingHasNoFalseNegatives) {
    ScratchDir s;
    for (const char* test : {"planes", "planes+aabb", "exact"})
        for (const char* alg : {"2.5d", "clustered"})
            for (const char* slicing : {"log", "linear"}) {
                const std::string tag = std::string("mountain-") + alg + "-" + test + "-" + slicing;
                const auto j = runAndRead(s, {"--builtin", "mountain", "--algorithm", alg, "--test", test,
                                              "--slicing", slicing, "--cells", "7", "--no-image-error",
                                              "--lights", "300", "--seed", "4"},
                                          tag);
                if (j.is_null()) continue;
                EXPECT_EQ(j["metrics"]["false_negatives"], 0) << tag;
                EXPECT_EQ(j["lights"], 300) << tag;
            }
}
