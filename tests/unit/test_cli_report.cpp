// `lightcull report` end to end on a tiny scene: csv rows and columns,
// report.md, a pareto.png that decodes; bad flags fail with one line and
// leave no output folder.
#include "cli_support.hpp"

#include "culling/core/params.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <pty.h>
#include <sys/wait.h>
#include <unistd.h>
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
    const std::string kShader = std::string(LC_SOURCE_DIR) + "/resources/culling-examples/tiled_fixed.comp";
    fs::create_symlink(kShader, tmp.path / "link.comp"); // the same file by another name
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
          {"report", "--builtin", "sky", "--presets", "--preset", "urp", "--out", out.string()},
          {"report", "--builtin", "sky", "--shader", kShader, "--shader", kShader, "--out", out.string()},
          {"report", "--builtin", "sky", "--shader", kShader, "--shader", (tmp.path / "link.comp").string(),
           "--out", out.string()},
          {"report", "--builtin", "sky", "--timeout-ms", "500", "--out", out.string()},
          {"report", "--builtin", "sky", "--spot-fraction", "0.5", "--out", out.string()},
          {"report", "--builtin", "sky", "--lights", "4", "--spot-fraction", "2", "--out", out.string()},
          {"report", "--out", out.string()},
          {"report", "--builtin", "sky", "--out", (tmp.path / "afile" / "rep").string()}}) {
        const CliResult r = runCli(args, tmp.path);
        EXPECT_NE(r.code, 0) << args[2];
        EXPECT_EQ(lineCount(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find("lightcull: error:"), std::string::npos) << r.err;
        EXPECT_FALSE(fs::exists(out));
    }
}

// --spot-fraction makes some of the --lights spots, as `run`'s does: the
// spot test is then swept. report.md counts one of a thing in the singular.
TEST(CliReport, SpotFractionGivesSpotsAndTheSpotTestSweep) {
    ScratchDir tmp;
    std::size_t rows[2] = {0, 0};
    for (int spots = 0; spots < 2; ++spots) {
        const fs::path out = tmp.path / ("rep" + std::to_string(spots));
        std::vector<std::string> args = {"report", "--builtin", "sky", "--width", "32", "--height", "16", "--lights",
                                         "6", "--backend", "cpu", "--algorithm", "naive", "--test", "planes",
                                         "--tile", "16", "--repeat", "1", "--warmup", "0", "--out", out.string()};
        if (spots) args.insert(args.begin() + 9, {"--spot-fraction", "0.5"});
        const CliResult r = runCli(args, tmp.path);
        ASSERT_EQ(r.code, 0) << r.err;
        const std::string csv = slurp(out / "report.csv");
        rows[spots] = std::size_t(std::count(csv.begin(), csv.end(), '\n')) - 1;
        const std::string md = slurp(out / "report.md");
        if (!spots) {
            EXPECT_NE(md.find("32x16, 6 lights, 1 configuration; times are of 1 run after 0 untimed."),
                      std::string::npos)
                << md.substr(0, 200);
        }
    }
    EXPECT_EQ(rows[0], 1u);
    EXPECT_GT(rows[1], 1u); // one row per spot test
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
    // 20 configurations: a line at each tenth (every second one), none between.
    const CliResult r = runCli({"report", "--builtin", "sky", "--width", "32", "--height", "16", "--lights", "2",
                                "--backend", "cpu", "--algorithm", "2.5d", "--test", "planes", "--slicing", "log",
                                "--tile", "16", "--cells", "1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20",
                                "--repeat", "1", "--warmup", "0", "--out", (tmp.path / "rep20").string()},
                               tmp.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_EQ(lineCount(r.err), 10u) << r.err; // the count, then 4, 6, ..., 20
    EXPECT_EQ(r.err.find("[3/20]"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("\n[20/20]\n"), std::string::npos) << r.err;
}

namespace {

// The CLI with stderr on a terminal `columns` wide (stdout to a file): what
// the terminal received. `term`: the TERM the command sees.
std::string stderrOnTerminal(const std::vector<std::string>& args, unsigned short columns, const char* term,
                             const fs::path& scratch) {
    winsize ws{};
    ws.ws_col = columns;
    ws.ws_row = 24;
    int master = -1, slave = -1;
    if (::openpty(&master, &slave, nullptr, nullptr, &ws) != 0) return "openpty failed";
    const fs::path outFile = scratch / ".tty_stdout";
    const pid_t pid = ::fork();
    if (pid == 0) {
        ::close(master);
        ::setenv("TERM", term, 1);
        if (!std::freopen(outFile.c_str(), "w", stdout) || ::dup2(slave, STDERR_FILENO) < 0) ::_exit(126);
        std::vector<std::string> copy = args;
        std::string exe = LC_CLI_PATH;
        std::vector<char*> argv{exe.data()};
        for (auto& a : copy) argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(exe.c_str(), argv.data());
        ::_exit(127);
    }
    ::close(slave);
    std::string seen;
    char buf[4096];
    for (ssize_t n; (n = ::read(master, buf, sizeof buf)) > 0;) seen.append(buf, std::size_t(n));
    ::close(master);
    int status = 0;
    ::waitpid(pid, &status, 0);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return "exit status " + std::to_string(status) + ": " + seen;
    return seen;
}

} // namespace

// On a terminal the progress line is rewritten in place and cut to the
// terminal's width: a line that wrapped would leave its first rows behind at
// every rewrite (raster's labels are over 100 characters). TERM=dumb gets
// no escape codes.
TEST(CliReport, TerminalProgressFitsTheTerminalsWidth) {
    ScratchDir tmp;
    const std::vector<std::string> args{"report", "--builtin", "sky", "--width", "64", "--height", "36", "--lights",
                                        "4", "--backend", "cpu", "--algorithm", "raster", "--tile", "16",
                                        "--repeat", "1", "--warmup", "0", "--out", (tmp.path / "rep").string()};
    const std::string seen = stderrOnTerminal(args, 40, "xterm", tmp.path);
    ASSERT_NE(seen.find("[3/3"), std::string::npos) << seen;
    std::size_t rewrites = 0;
    for (std::size_t at = 0; at < seen.size();) {
        std::size_t end = seen.find_first_of("\r\n", at);
        if (end == std::string::npos) end = seen.size();
        std::string line = seen.substr(at, end - at);
        for (std::size_t k; (k = line.find("\033[K")) != std::string::npos;) line.erase(k, 3);
        if (line.rfind("[", 0) == 0) { // a progress line, rewritten in place (the count line is printed once)
            EXPECT_LT(line.size(), 40u) << "'" << line << "' would wrap on a 40-column terminal";
            ++rewrites;
        }
        at = end + 1;
    }
    EXPECT_GE(rewrites, 3u) << seen;
    const std::string dumb = stderrOnTerminal(args, 40, "dumb", tmp.path);
    EXPECT_EQ(dumb.find('\033'), std::string::npos) << dumb;
    EXPECT_NE(dumb.find("[3/3]"), std::string::npos) << dumb;
}
