// `lightcull report` end to end on a tiny scene: csv rows and columns,
// report.md, a pareto.png that decodes; bad flags fail with one line and
// leave no output folder.
#include "cli_support.hpp"

#include "culling/core/params.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <png.h>

#include <algorithm>
#include <cstdlib>

using namespace lc_test;
namespace fs = std::filesystem;

TEST(CliReport, WritesCsvMarkdownAndPareto) {
    ScratchDir tmp;
    const fs::path out = tmp.path / "rep";
    const CliResult r = runCli({"report", "--builtin", "sky", "--width", "64", "--height", "36", "--lights", "8",
                                "--backend", "cpu", "--algorithm", "2.5d", "--tile", "16", "--cells", "1,4",
                                "--repeat", "1", "--warmup", "0", "--out", out.string()},
                               tmp.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find("9 configurations"), std::string::npos) << r.out;
    // Progress for a log (stderr is no terminal here): the count and an
    // estimate after the second configuration, then a line at each tenth.
    EXPECT_EQ(r.err.rfind("report: 9 configurations, ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(" left\n"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\n[5/9], "), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\n[9/9]\n"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 8) << r.err; // the count, then configurations 3 to 9
    const std::string csv = slurp(out / "report.csv");
    // header + 3 tests x (cells 1 + cells 4 x 2 slicings)
    ASSERT_EQ(lineCount(csv), 10u) << csv;
    const std::string header = csv.substr(0, csv.find('\n'));
    for (const char* col : {"backend", "algorithm", "tile", "cells", "slicing", "test", "cull_ms", "shade_ms",
                            "total_ms", "efficiency", "false_negatives", "mean_list", "max_list", "result_bytes",
                            "image_rmse", "image_max_error"})
        EXPECT_NE(header.find(col), std::string::npos) << col;
    const auto commas = [](const std::string& s) { return std::count(s.begin(), s.end(), ','); };
    // Split at every comma: the cpu rows hold no quoted field (their comma
    // count is the header's, checked below).
    const auto fields = [](const std::string& s) {
        std::vector<std::string> out(1);
        for (char c : s) {
            if (c == ',') out.emplace_back();
            else out.back().push_back(c);
        }
        return out;
    };
    const std::vector<std::string> cols = fields(header);
    const auto col = [&](const std::string& name) {
        const auto it = std::find(cols.begin(), cols.end(), name);
        EXPECT_NE(it, cols.end()) << name;
        return std::size_t(it - cols.begin());
    };
    // The scene the command ran: sky, 64x36, 8 generated lights (seed 1).
    lc::Scene scene = lc::makeBuiltinScene("sky");
    scene.camera.width = 64;
    scene.camera.height = 36;
    scene.lights = lc::generateLights(lc::defaultLightGen(scene, 8, 1));
    auto cpu = lc::makeBackend("cpu");
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
        EXPECT_EQ(commas(line), commas(header)) << line;
        EXPECT_EQ(line.rfind("cpu,", 0), 0u) << line;
        EXPECT_NE(line.find(",2.5d,"), std::string::npos) << line;
        // The row's figures are its configuration's own run, made here again
        // from the parameter columns (the CPU backend is deterministic and
        // the CSV's doubles round-trip): not merely numbers in range.
        const std::vector<std::string> f = fields(line);
        ASSERT_EQ(f.size(), cols.size()) << line;
        lc::Scene s = scene;
        lc::CullSettings cs;
        for (const lc::ParamSpec& p : lc::cullParams()) {
            if (p.name == "width" || p.name == "height") continue;
            std::string c = p.name;
            std::replace(c.begin(), c.end(), '-', '_');
            if (const std::string& v = f[col(c)]; !v.empty()) lc::setParam(cs, s.camera, p.name, v);
        }
        const lc::Metrics m = lc::runPipeline(s, cs, *cpu).truth.metrics;
        ASSERT_TRUE(m.imageErrorComputed);
        const auto num = [&](const char* name) { return std::strtod(f[col(name)].c_str(), nullptr); };
        EXPECT_EQ(num("image_rmse"), m.imageRmse) << line;
        EXPECT_EQ(num("image_max_error"), m.imageMaxError) << line;
        EXPECT_EQ(num("efficiency"), m.efficiency) << line;
        EXPECT_EQ(num("mean_list"), m.meanList) << line;
        EXPECT_EQ(f[col("false_negatives")], std::to_string(m.falseNegatives)) << line;
        EXPECT_EQ(f[col("max_list")], std::to_string(m.maxList)) << line;
        EXPECT_EQ(f[col("result_bytes")], std::to_string(m.resultBytes)) << line;
        EXPECT_EQ(f[col("optimal_work")], std::to_string(m.optimalWork)) << line;
    }
    EXPECT_NE(slurp(out / "report.md").find("| backend | configuration |"), std::string::npos);
    png_image img{};
    img.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&img, (out / "pareto.png").c_str())) << img.message;
    img.format = PNG_FORMAT_RGB;
    std::vector<png_byte> px(PNG_IMAGE_SIZE(img));
    ASSERT_TRUE(png_image_finish_read(&img, nullptr, px.data(), 0, nullptr)) << img.message;
    EXPECT_GT(img.width, 500u);
    EXPECT_GT(img.height, 300u);
}

TEST(CliReport, BadInputFailsWithOneLineAndNoFolder) {
    ScratchDir tmp;
    const fs::path out = tmp.path / "rep";
    std::ofstream(tmp.path / "afile") << "x"; // a file where a parent folder would be
    // A custom shader that does not compile: refused before the sweep (no
    // progress line before the error), not after every built-in row.
    std::ofstream(tmp.path / "broken.comp") << "#version 450\nthis does not compile\n";
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"report", "--builtin", "sky", "--algorithm", "fastest", "--out", out.string()},
          {"report", "--builtin", "sky", "--width", "64", "--height", "36", "--backend", "cpu", "--algorithm",
           "naive", "--tile", "8,16", "--shader", (tmp.path / "broken.comp").string(), "--out", out.string()},
          {"report", "--builtin", "sky", "--cells", "1,64", "--out", out.string()},
          {"report", "--builtin", "sky", "--backend", "nope", "--out", out.string()},
          {"report", "--builtin", "sky", "--backend", "cpu", "--backend", "metal", "--out", out.string()},
          {"report", "--out", out.string()},
          {"report", "--builtin", "sky", "--out", (tmp.path / "afile" / "rep").string()}}) {
        const CliResult r = runCli(args, tmp.path);
        EXPECT_NE(r.code, 0) << args[2];
        EXPECT_EQ(lineCount(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("lightcull: error:"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
    }
}

// The last progress line is always there for a log to find, from one
// configuration on, and the count is said in the singular for one.
TEST(CliReport, ProgressEndsWithTheTotalForAnyCount) {
    ScratchDir tmp;
    for (const char* tiles : {"16", "8,16"}) {
        const fs::path out = tmp.path / (std::string("rep") + tiles);
        const CliResult r = runCli({"report", "--builtin", "sky", "--width", "32", "--height", "16", "--lights", "2",
                                    "--backend", "cpu", "--algorithm", "naive", "--test", "planes", "--tile", tiles,
                                    "--repeat", "1", "--warmup", "0", "--out", out.string()},
                                   tmp.path);
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string n = std::string(tiles) == "16" ? "1" : "2";
        EXPECT_EQ(r.err, "report: " + n + (n == "1" ? " configuration\n" : " configurations\n") + "[" + n + "/" +
                             n + "]\n");
        EXPECT_NE(r.out.find(n == "1" ? "1 configuration\n" : "2 configurations\n"), std::string::npos) << r.out;
    }
}
