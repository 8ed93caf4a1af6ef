// `lightcull bench`: the sweep forms a cross product, every configuration gets
// median/min/max per phase, the JSON agrees with the configurations asked for,
// and bad sweeps fail with one line naming the problem. No timing is asserted
// beyond ordering (min <= median <= max): speed belongs to benchmarks.
#include "cli_support.hpp"

#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <set>

using lc_test::CliResult;
using lc_test::lineCount;
using lc_test::runCli;
using lc_test::ScratchDir;

TEST(CliBench, SweepCrossProductWritesEveryConfiguration) {
    ScratchDir s;
    const auto json = (s.path / "bench.json").string();
    const CliResult r = runCli({"bench", "--builtin", "wall", "--backend", "cpu", "--width", "160", "--height", "90",
                                "--repeat", "3", "--warmup", "1", "--sweep", "algorithm=naive,minmax,clustered",
                                "--sweep", "lights=0,16", "--json", json},
                               s.path);
    ASSERT_EQ(r.code, 0) << r.err;
    const nlohmann::json doc = nlohmann::json::parse(lc_test::slurp(json));
    EXPECT_EQ(doc["backend"], "cpu");
    EXPECT_EQ(doc["repeat"], 3);
    ASSERT_EQ(doc["configs"].size(), 6u);
    std::set<std::pair<std::string, std::size_t>> seen;
    const std::size_t wallTriangles = lc::makeBuiltinScene("wall").triangleCount();
    ASSERT_GT(wallTriangles, 0u);
    for (const auto& c : doc["configs"]) {
        seen.insert({c["algorithm"].get<std::string>(), c["lights"].get<std::size_t>()});
        EXPECT_EQ(c["width"], 160);
        EXPECT_EQ(c["height"], 90);
        // The wall clocks too (on the CPU backend the same clock as the
        // times), and the whole calls around them.
        for (const char* phase :
             {"depth_ms", "depth_wall_ms", "depth_call_ms", "cull_ms", "cull_wall_ms", "cull_call_ms"}) {
            const auto& st = c[phase];
            EXPECT_LE(st["min"].get<double>(), st["median"].get<double>()) << phase;
            EXPECT_LE(st["median"].get<double>(), st["max"].get<double>()) << phase;
            EXPECT_GE(st["min"].get<double>(), 0.0) << phase;
        }
        // Bytes follow the compact layout: never below 4 per entry + 8 per list.
        EXPECT_GE(c["result_bytes"].get<std::uint64_t>(),
                  4 * c["list_entries"].get<std::uint64_t>() + 8 * c["lists"].get<std::uint64_t>());
        if (c["lights"] == 0) EXPECT_EQ(c["list_entries"], 0);
        EXPECT_EQ(c["depth_wall_ms"], c["depth_ms"]);
        EXPECT_EQ(c["cull_wall_ms"], c["cull_ms"]);
        // The CPU rasteriser draws every triangle.
        EXPECT_EQ(c["depth_triangles"], wallTriangles);
        EXPECT_EQ(c["depth_triangles_drawn"], wallTriangles);
        // A call's clock runs around its pass's, run by run.
        EXPECT_GE(c["depth_call_ms"]["median"].get<double>(), c["depth_wall_ms"]["median"].get<double>());
        EXPECT_GE(c["cull_call_ms"]["median"].get<double>(), c["cull_wall_ms"]["median"].get<double>());
    }
    EXPECT_EQ(seen.size(), 6u);
    // One stdout line per configuration plus the header and the "wrote" line.
    EXPECT_EQ(lineCount(r.out), 8u) << r.out;
}

TEST(CliBench, BadSweepsFailWithOneLine) {
    ScratchDir s;
    for (const std::vector<std::string>& bad :
         {std::vector<std::string>{"--sweep", "nonsense=1,2"}, {"--sweep", "cells"}, {"--sweep", "cells=4,,8"},
          {"--sweep", "cells=4,99"}, {"--sweep", "resolution=640"}, {"--sweep", "lights=a"},
          {"--sweep", "cells=4", "--sweep", "cells=8"}, {"--repeat", "0"},
          // Found before the first run: nothing measured, nothing on stdout.
          {"--sweep", "resolution=64x36,0x5"}, {"--sweep", "tile=8,300"}, {"--sweep", "lights=5,2000000"},
          {"--sweep", "tile=8,16", "--json", "/nonexistent-folder/x.json"}}) {
        std::vector<std::string> args = {"bench", "--builtin", "wall", "--backend", "cpu", "--width", "64",
                                         "--height", "36", "--repeat", "1", "--warmup", "0"};
        args.insert(args.end(), bad.begin(), bad.end());
        const CliResult r = runCli(args, s.path);
        EXPECT_EQ(r.code, 2) << bad[1] << ": " << r.err;
        EXPECT_EQ(lineCount(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("error"), std::string::npos) << r.err;
        EXPECT_TRUE(r.out.empty()) << bad[1] << ": " << r.out;
    }
}
