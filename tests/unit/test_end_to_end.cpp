// End to end through the CLI: every built-in scene with every algorithm on the
// CPU backend reports no false negatives, and `all` reports W = (pixels with
// geometry) x lights and efficiency = E / W. 320x180 keeps the whole file
// to well under a minute.
#include "cli_support.hpp"

#include "culling/core/params.hpp"
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
            EXPECT_GE(m["image_rmse"].get<double>(), 0.0) << tag;
            EXPECT_GE(m["image_max_error"].get<double>(), m["image_rmse"].get<double>()) << tag;
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
