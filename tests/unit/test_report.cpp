// The report's sweep (culling/diagnostics/report.hpp): which configurations it builds from
// the parameter table and which it skips, a real run on a tiny scene (rows,
// timings, metrics, progress, cancel), the Pareto flags against their
// definition, and the written folder (csv shape, atomic refusal).
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/diagnostics/report.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

#include <png.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

using namespace lc;
namespace fs = std::filesystem;

namespace {

std::size_t countIf(const std::vector<ReportConfig>& cfgs, Algorithm a) {
    return std::size_t(std::count_if(cfgs.begin(), cfgs.end(),
                                     [&](const ReportConfig& c) { return c.settings.algorithm == a; }));
}

Scene tinyScene() {
    Scene s = makeBuiltinScene("atrium");
    s.camera.width = 64;
    s.camera.height = 40;
    s.lights = generateLights(defaultLightGen(s, 24, 5));
    return s;
}

std::vector<std::string> splitCsvLine(const std::string& line) {
    std::vector<std::string> out;
    std::string cur;
    bool quoted = false;
    for (char c : line) {
        if (c == '"') quoted = !quoted;
        else if (c == ',' && !quoted) out.push_back(cur), cur.clear();
        else cur += c;
    }
    out.push_back(cur);
    return out;
}

// A report row against a run of its own configuration, made apart from the
// report (runPipeline on the CPU backend, image error on). The CPU backend is
// deterministic and the report judges a row as runPipeline does (the same
// ground truth, the backend's shading pass, compareShadedImages): equal.
void expectRowIsTheRunsOwn(const Scene& scene, const ReportRow& row) {
    ASSERT_EQ(row.config.backend, "cpu");
    Scene s = scene;
    s.camera.tileSize = row.config.tileSize;
    auto backend = makeBackend("cpu");
    const RunOutput run = runPipeline(s, row.config.settings, *backend, RunOptions{});
    const Metrics& m = run.truth.metrics;
    ASSERT_TRUE(m.imageErrorComputed);
    const std::string what = row.config.label();
    EXPECT_EQ(row.falseNegatives, m.falseNegatives) << what;
    EXPECT_EQ(row.efficiency, m.efficiency) << what;
    EXPECT_EQ(row.optimalWork, m.optimalWork) << what;
    EXPECT_EQ(row.efficiencyVsOptimal, m.efficiencyVsOptimal) << what;
    EXPECT_EQ(row.meanList, m.meanList) << what;
    EXPECT_EQ(row.maxList, m.maxList) << what;
    EXPECT_EQ(row.resultBytes, m.resultBytes) << what;
    EXPECT_EQ(row.imageRmse, m.imageRmse) << what;
    EXPECT_EQ(row.imageMaxError, m.imageMaxError) << what;
}

struct TempDir {
    fs::path path;
    TempDir() {
        std::string t = (fs::temp_directory_path() / "lc_report_XXXXXX").string();
        path = ::mkdtemp(t.data());
    }
    ~TempDir() { fs::remove_all(path); }
};

} // namespace

// Default sweep: all x1; naive/minmax/halfz x tile 3 x test 3; 2.5d x tile 3 x
// test 3 x (cells 1 + cells {2..32} x slicing 2); clustered as 2.5d x
// skip-empty 2. Parameters that do not apply have empty values.
TEST(Report, DefaultSweepFollowsTheParameterTableAndSkipsWhatDoesNotApply) {
    const std::vector<ReportConfig> cfgs = reportConfigs(ReportOptions{}, "cpu");
    EXPECT_EQ(countIf(cfgs, Algorithm::All), 1u);
    EXPECT_EQ(countIf(cfgs, Algorithm::Naive), 9u);
    EXPECT_EQ(countIf(cfgs, Algorithm::MinMax), 9u);
    EXPECT_EQ(countIf(cfgs, Algorithm::HalfZ), 9u);
    EXPECT_EQ(countIf(cfgs, Algorithm::TwoPointFiveD), 3u * 3u * (1u + 5u * 2u));
    EXPECT_EQ(countIf(cfgs, Algorithm::Clustered), 3u * 3u * (1u + 5u * 2u) * 2u);
    std::set<std::string> labels;
    for (const ReportConfig& c : cfgs) {
        EXPECT_TRUE(labels.insert(c.label()).second) << "duplicate " << c.label();
        EXPECT_TRUE(c.settings.validate().empty()) << c.label();
        // Every table parameter but the camera's size is a column.
        for (const ParamSpec& p : cullParams()) {
            const bool camera = p.name == "width" || p.name == "height";
            EXPECT_EQ(c.params.count(p.name), camera ? 0u : 1u) << p.name;
            if (!camera && c.params.count(p.name))
                EXPECT_EQ(c.params.at(p.name).empty(), !paramAppliesTo(p.name, c.settings, false))
                    << c.label() << " " << p.name;
        }
        if (c.settings.algorithm == Algorithm::All) EXPECT_EQ(c.label(), "all");
        if (c.settings.algorithm == Algorithm::TwoPointFiveD && c.settings.cells == 1)
            EXPECT_EQ(c.params.at("slicing"), "");
        if (!c.params.at("tile").empty()) EXPECT_EQ(std::to_string(c.tileSize), c.params.at("tile"));
    }
}

// A parameter added to the table later is swept where it applies: spot-test
// multiplies every culling algorithm's rows by its choices, but only for a
// scene with spot lights.
TEST(Report, SpotTestIsSweptOnlyForScenesWithSpotLights) {
    const ParamSpec& spot = cullParam("spot-test");
    ReportOptions o;
    o.fixed["algorithm"] = "minmax";
    EXPECT_EQ(reportConfigs(o, "cpu", false).size(), 9u);
    const std::vector<ReportConfig> withSpots = reportConfigs(o, "cpu", true);
    EXPECT_EQ(withSpots.size(), 9u * spot.choices.size());
    for (const ReportConfig& c : withSpots) EXPECT_FALSE(c.params.at("spot-test").empty());
    o.fixed = {{"algorithm", "all"}};
    EXPECT_EQ(reportConfigs(o, "cpu", true).size(), 1u);
}

TEST(Report, FixedParametersAndListsNarrowTheSweep) {
    ReportOptions o;
    o.fixed["algorithm"] = "halfz";
    o.fixed["test"] = "exact";
    o.tileSizes = {8, 32};
    const std::vector<ReportConfig> cfgs = reportConfigs(o, "cpu");
    ASSERT_EQ(cfgs.size(), 2u);
    EXPECT_EQ(cfgs[0].label(), "halfz test=exact tile=8");
    EXPECT_EQ(cfgs[1].label(), "halfz test=exact tile=32");

    ReportOptions bad;
    bad.fixed["no-such-parameter"] = "1";
    EXPECT_THROW(reportConfigs(bad, "cpu"), SettingsError);
    bad.fixed = {{"algorithm", "fastest"}};
    EXPECT_THROW(reportConfigs(bad, "cpu"), SettingsError);
    bad.fixed = {{"width", "64"}};
    EXPECT_THROW(reportConfigs(bad, "cpu"), SettingsError);
}

TEST(Report, RunsOnATinySceneWithProgressAndParetoFlags) {
    ReportOptions o;
    o.backends = {"cpu"};
    o.fixed["algorithm"] = "2.5d";
    o.tileSizes = {16};
    o.cellCounts = {1, 8};
    o.repeat = 1;
    o.warmup = 0;
    std::vector<std::size_t> seen;
    const Scene scene = tinyScene();
    const Report rep = runReport(scene, o, [&](std::size_t done, std::size_t total, const std::string&) {
        EXPECT_EQ(total, 9u);
        seen.push_back(done);
    });
    ASSERT_EQ(rep.rows.size(), 9u); // 3 tests x (cells 1 + cells 8 x 2 slicings)
    EXPECT_EQ(seen, (std::vector<std::size_t>{1, 2, 3, 4, 5, 6, 7, 8, 9}));
    ASSERT_EQ(rep.backendDevices.size(), 1u);
    std::size_t onFront = 0;
    for (const ReportRow& r : rep.rows) {
        EXPECT_EQ(r.falseNegatives, 0u) << r.config.label();
        EXPECT_GE(r.cullMs, 0.0);
        EXPECT_GE(r.shadeMs, 0.0);
        EXPECT_DOUBLE_EQ(r.totalMs, r.cullMs + r.shadeMs);
        EXPECT_GT(r.efficiency, 0.0);
        EXPECT_LE(r.efficiency, 1.0);
        EXPECT_GT(r.resultBytes, 0u);
        // The row's figures are its configuration's own, not merely numbers.
        expectRowIsTheRunsOwn(scene, r);
        onFront += r.paretoEfficiency;
        // The flag is exactly "no row dominates it".
        bool dominated = false;
        for (const ReportRow& o2 : rep.rows)
            dominated |= o2.totalMs <= r.totalMs && o2.efficiency >= r.efficiency &&
                         (o2.totalMs < r.totalMs || o2.efficiency > r.efficiency);
        EXPECT_EQ(r.paretoEfficiency, !dominated) << r.config.label();
    }
    EXPECT_GE(onFront, 1u);
    // One cell and eight: more cells never lose efficiency on the same tile/test.
    for (const ReportRow& a : rep.rows)
        for (const ReportRow& b : rep.rows)
            if (a.config.settings.cells == 1 && b.config.settings.cells == 8 &&
                a.config.settings.test == b.config.settings.test)
                EXPECT_GE(b.efficiency, a.efficiency - 1e-12) << b.config.label();

    // `all` shades every light: its image error is exactly 0.
    ReportOptions all = o;
    all.fixed = {{"algorithm", "all"}};
    const Report allRep = runReport(scene, all);
    ASSERT_EQ(allRep.rows.size(), 1u);
    EXPECT_EQ(allRep.rows[0].imageRmse, 0.0);
    expectRowIsTheRunsOwn(scene, allRep.rows[0]);
    EXPECT_EQ(allRep.rows[0].efficiency, allRep.rows[0].efficiency); // not NaN
}

// Rows whose lists and pixels' lists equal an earlier row's (minmax's are
// 2.5d's with one cell) take that row's ground truth, shading time and image
// error instead of working them out again; every row's figures are still its
// own configuration's, zbin's and the clusters' included.
TEST(Report, RowsWithTheSameListsShareOneJudgement) {
    ReportOptions o;
    o.backends = {"cpu"};
    o.fixed["algorithm"] = "minmax,2.5d,clustered,zbin";
    o.fixed["test"] = "planes";
    o.fixed["skip-empty"] = "false";
    o.tileSizes = {8, 16};
    o.cellCounts = {1, 2, 8};
    o.repeat = 1;
    o.warmup = 0;
    const Scene scene = tinyScene();
    const Report rep = runReport(scene, o);
    std::set<double> shadeTimes;
    for (const ReportRow& r : rep.rows) {
        expectRowIsTheRunsOwn(scene, r);
        shadeTimes.insert(r.shadeMs);
    }
    for (const std::uint32_t tile : {8u, 16u}) {
        const auto find = [&](Algorithm a, std::uint32_t cells) {
            return std::find_if(rep.rows.begin(), rep.rows.end(), [&](const ReportRow& r) {
                return r.config.settings.algorithm == a && r.config.tileSize == tile &&
                       (a == Algorithm::MinMax || r.config.settings.cells == cells);
            });
        };
        const auto minmax = find(Algorithm::MinMax, 1), oneCell = find(Algorithm::TwoPointFiveD, 1),
                   clusters = find(Algorithm::Clustered, 8);
        ASSERT_NE(minmax, rep.rows.end());
        ASSERT_NE(oneCell, rep.rows.end());
        ASSERT_NE(clusters, rep.rows.end());
        // A shading time measured again would differ in its last bits.
        EXPECT_EQ(oneCell->shadeMs, minmax->shadeMs) << "tile " << tile << ": one judgement for the same lists";
        EXPECT_NE(clusters->shadeMs, minmax->shadeMs) << "tile " << tile << ": other lists, another judgement";
    }
    EXPECT_LT(shadeTimes.size(), rep.rows.size());
}

TEST(Report, CancelStopsTheSweep) {
    ReportOptions o;
    o.backends = {"cpu"};
    o.fixed["algorithm"] = "minmax";
    o.repeat = 1;
    CancelToken cancel;
    std::size_t calls = 0;
    EXPECT_THROW(runReport(tinyScene(), o,
                           [&](std::size_t, std::size_t, const std::string&) {
                               ++calls;
                               cancel.cancelled = true;
                           },
                           &cancel),
                 Cancelled);
    EXPECT_EQ(calls, 1u);
}

TEST(Report, MarkParetoOnHandMadeRows) {
    auto row = [](const char* backend, double ms, double eff, double rmse, std::uint64_t fn = 0) {
        ReportRow r;
        r.config.backend = backend;
        r.totalMs = ms, r.efficiency = eff, r.imageRmse = rmse, r.falseNegatives = fn;
        return r;
    };
    std::vector<ReportRow> rows{row("cpu", 1, 0.2, 0.5), row("cpu", 2, 0.5, 0.1), row("cpu", 3, 0.4, 0.05),
                                row("cpu", 0.5, 0.9, 0.0, 3), row("vulkan", 9, 0.1, 0.9)};
    markPareto(rows);
    EXPECT_TRUE(rows[0].paretoEfficiency);
    EXPECT_TRUE(rows[1].paretoEfficiency);
    EXPECT_FALSE(rows[2].paretoEfficiency); // slower and less efficient than row 1
    EXPECT_TRUE(rows[2].paretoError);       // but the lowest error
    EXPECT_FALSE(rows[3].paretoEfficiency); // false negatives: never on a front
    EXPECT_FALSE(rows[3].paretoError);
    EXPECT_TRUE(rows[4].paretoEfficiency);  // fronts are per backend
}

TEST(Report, WritesCsvMarkdownAndPngAtomically) {
    ReportOptions o;
    o.backends = {"cpu"};
    o.fixed["algorithm"] = "halfz";
    o.tileSizes = {16, 32};
    o.repeat = 1;
    const Report rep = runReport(tinyScene(), o);
    TempDir tmp;
    const fs::path out = tmp.path / "rep";
    writeReport(rep, out.string());
    std::ifstream csv(out / "report.csv");
    std::string header, line;
    std::getline(csv, header);
    const std::vector<std::string> cols = splitCsvLine(header);
    EXPECT_EQ(cols.front(), "backend");
    EXPECT_NE(std::find(cols.begin(), cols.end(), "image_rmse"), cols.end());
    EXPECT_NE(std::find(cols.begin(), cols.end(), "skip_empty"), cols.end());
    const auto col = [&](const char* name) {
        const auto it = std::find(cols.begin(), cols.end(), name);
        EXPECT_NE(it, cols.end()) << name;
        return std::size_t(it - cols.begin());
    };
    std::size_t rows = 0;
    while (std::getline(csv, line)) {
        const std::vector<std::string> f = splitCsvLine(line);
        ASSERT_EQ(f.size(), cols.size()) << line;
        ASSERT_LT(rows, rep.rows.size());
        // Each row's figures as the report holds them (doubles round-trip).
        const ReportRow& r = rep.rows[rows];
        const auto num = [&](const char* name) { return std::strtod(f[col(name)].c_str(), nullptr); };
        EXPECT_EQ(num("image_rmse"), r.imageRmse) << line;
        EXPECT_EQ(num("image_max_error"), r.imageMaxError) << line;
        EXPECT_EQ(num("efficiency"), r.efficiency) << line;
        EXPECT_EQ(num("efficiency_vs_optimal"), r.efficiencyVsOptimal) << line;
        EXPECT_EQ(num("mean_list"), r.meanList) << line;
        EXPECT_EQ(f[col("false_negatives")], std::to_string(r.falseNegatives)) << line;
        EXPECT_EQ(f[col("max_list")], std::to_string(r.maxList)) << line;
        EXPECT_EQ(f[col("result_bytes")], std::to_string(r.resultBytes)) << line;
        EXPECT_EQ(f[col("optimal_work")], std::to_string(r.optimalWork)) << line;
        ++rows;
    }
    EXPECT_EQ(rows, rep.rows.size());
    EXPECT_EQ(rows, 6u);
    std::ifstream md(out / "report.md");
    std::stringstream mds;
    mds << md.rdbuf();
    EXPECT_NE(mds.str().find("fastest configuration"), std::string::npos);
    EXPECT_NE(mds.str().find("Pareto front"), std::string::npos);
    png_image img{};
    img.version = PNG_IMAGE_VERSION;
    ASSERT_TRUE(png_image_begin_read_from_file(&img, (out / "pareto.png").c_str())) << img.message;
    EXPECT_EQ(img.width, 1120u);
    png_image_free(&img);

    // Rewriting replaces the folder; a folder holding anything else is refused
    // and left untouched.
    writeReport(rep, out.string());
    std::ofstream(out / "notes.txt") << "mine";
    EXPECT_THROW(writeReport(rep, out.string()), Error);
    EXPECT_TRUE(fs::exists(out / "notes.txt"));
    // A file where a parent folder would be; a missing parent is made.
    std::ofstream(tmp.path / "afile") << "x";
    EXPECT_THROW(writeReport(rep, (tmp.path / "afile" / "rep").string()), Error);
    writeReport(rep, (tmp.path / "missing" / "rep").string());
    EXPECT_TRUE(fs::exists(tmp.path / "missing" / "rep" / "report.csv"));
    for (const auto& e : fs::directory_iterator(tmp.path))
        EXPECT_EQ(e.path().filename().string().rfind(".rep", 0), std::string::npos) << "staging left behind";
}

// pareto.png and the studio's chart tell algorithms apart by colour alone:
// no two share one (clustered, fptl and zbin did).
TEST(Report, EveryAlgorithmHasItsOwnColour) {
    const auto names = lc::cullParam("algorithm").choices;
    ASSERT_EQ(names.size(), 9u);
    for (std::size_t i = 0; i < names.size(); ++i)
        for (std::size_t j = i + 1; j < names.size(); ++j) {
            const glm::dvec3 a = lc::algorithmColour(lc::algorithmFromString(names[i]));
            const glm::dvec3 b = lc::algorithmColour(lc::algorithmFromString(names[j]));
            EXPECT_GT(glm::length(a - b), 0.15) << names[i] << " and " << names[j];
        }
}

// A configuration that misses lights is never "the fastest" or "the most
// efficient": the reading ranks only rows without false negatives and lists
// the others apart (a flawed shader was named the fastest on Sponza).
TEST(Report, ReadingRanksOnlyConfigurationsWithoutFalseNegatives) {
    Report rep;
    rep.sceneName = "hand";
    rep.backendDevices = {{"cpu", "reference"}};
    rep.backendTiming = {{"cpu", "wall clock"}};
    auto row = [](const char* custom, double ms, double eff, std::uint64_t fn) {
        ReportRow r;
        r.config.backend = "cpu";
        r.config.customLabel = custom;
        r.cullMs = ms / 2, r.shadeMs = ms / 2, r.totalMs = ms, r.efficiency = eff, r.falseNegatives = fn;
        return r;
    };
    rep.rows = {row("custom:flawed.comp", 0.5, 1.2, 7), row("custom:good.comp", 2.0, 0.8, 0),
                row("custom:slow.comp", 3.0, 0.6, 0)};
    markPareto(rep.rows);
    const std::string md = reportMarkdown(rep);
    const std::size_t fastest = md.find("the fastest configuration without false negatives is `custom:good.comp`");
    EXPECT_NE(fastest, std::string::npos) << md;
    EXPECT_NE(md.find("The most efficient is `custom:good.comp`"), std::string::npos) << md;
    EXPECT_NE(md.find("`custom:flawed.comp` (cpu, 7); they are left off the Pareto fronts and are not ranked below"),
              std::string::npos)
        << md;
    // The flawed row appears in the reading only in that list (and in the table).
    const std::string reading = md.substr(0, md.find("## Table"));
    EXPECT_EQ(reading.find("custom:flawed.comp"), reading.rfind("custom:flawed.comp")) << reading;

    for (ReportRow& r : rep.rows) r.falseNegatives = 3;
    const std::string none = reportMarkdown(rep);
    EXPECT_NE(none.find("no configuration is free of false negatives: none is ranked"), std::string::npos) << none;
    EXPECT_EQ(none.find("the fastest configuration"), std::string::npos) << none;
}

// pareto.png's axes: ticks at round values whose labels say exactly where they
// sit (ticks read 0, 441, 881, "1E+03", "2E+03", with "1E+03" at 1,322).
TEST(Report, AxisTicksAreRoundAndLabelledWithTheirValue) {
    const AxisTicks a = axisTicks(0, 1762, false);
    EXPECT_LE(a.lo, 0.0);
    EXPECT_GE(a.hi, 1762.0);
    ASSERT_GE(a.ticks.size(), 3u);
    EXPECT_EQ(a.ticks.front(), a.lo);
    EXPECT_EQ(a.ticks.back(), a.hi);
    const double step = a.ticks[1] - a.ticks[0];
    EXPECT_EQ(step, 500.0);
    for (std::size_t i = 0; i < a.ticks.size(); ++i) {
        EXPECT_DOUBLE_EQ(a.ticks[i], a.lo + step * double(i));
        // The label is the value: parsing it back gives the tick.
        EXPECT_DOUBLE_EQ(std::stod(tickText(a.ticks[i])), a.ticks[i]) << tickText(a.ticks[i]);
    }
    EXPECT_EQ(tickText(1500), "1500");
    EXPECT_EQ(tickText(0.25), "0.25");

    const AxisTicks f = axisTicks(0.13, 0.97, false);
    for (double v : f.ticks) EXPECT_EQ(tickText(v).size() <= 3u, true) << tickText(v); // 0, 0.2, ..., 1
    EXPECT_NE(std::find(f.ticks.begin(), f.ticks.end(), 0.6), f.ticks.end());

    // Log axis: 1, 2, 5 per decade over the decades that hold the data.
    const AxisTicks l = axisTicks(0.37, 42, true);
    EXPECT_EQ(l.lo, 0.1);
    EXPECT_EQ(l.hi, 100.0);
    const std::vector<double> want{0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100};
    ASSERT_EQ(l.ticks.size(), want.size());
    for (std::size_t i = 0; i < want.size(); ++i) EXPECT_DOUBLE_EQ(l.ticks[i], want[i]);
}
