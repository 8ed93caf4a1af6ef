// `lightcull report` end to end on a tiny scene: csv rows and columns,
// report.md, a pareto.png that decodes; bad flags fail with one line and
// leave no output folder.
#include "cli_support.hpp"

#include <gtest/gtest.h>
#include <png.h>

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
    const std::string csv = slurp(out / "report.csv");
    // header + 3 tests x (cells 1 + cells 4 x 2 slicings)
    ASSERT_EQ(lineCount(csv), 10u) << csv;
    const std::string header = csv.substr(0, csv.find('\n'));
    for (const char* col : {"backend", "algorithm", "tile", "cells", "slicing", "test", "cull_ms", "shade_ms",
                            "total_ms", "efficiency", "false_negatives", "mean_list", "max_list", "result_bytes",
                            "image_rmse", "image_max_error"})
        EXPECT_NE(header.find(col), std::string::npos) << col;
    const auto commas = [](const std::string& s) { return std::count(s.begin(), s.end(), ','); };
    std::istringstream lines(csv);
    std::string line;
    std::getline(lines, line);
    while (std::getline(lines, line)) {
        EXPECT_EQ(commas(line), commas(header)) << line;
        EXPECT_EQ(line.rfind("cpu,", 0), 0u) << line;
        EXPECT_NE(line.find(",2.5d,"), std::string::npos) << line;
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
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"report", "--builtin", "sky", "--algorithm", "fastest", "--out", out.string()},
          {"report", "--builtin", "sky", "--cells", "1,64", "--out", out.string()},
          {"report", "--builtin", "sky", "--backend", "nope", "--out", out.string()},
          {"report", "--out", out.string()},
          {"report", "--builtin", "sky", "--out", (tmp.path / "no" / "rep").string()}}) {
        const CliResult r = runCli(args, tmp.path);
        EXPECT_NE(r.code, 0) << args[2];
        EXPECT_EQ(lineCount(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("lightcull: error:"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
    }
}
