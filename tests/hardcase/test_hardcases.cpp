// Hard cases (issue 7): every named case of hardcase_scenes.hpp through every
// algorithm on both backends, each combination its own test
// (HardCases/HardCase.Run/<case>__<algorithm>__<backend>). Each asserts:
//   - false negatives = 0 against the double-precision ground truth;
//   - no NaN or Inf in any output: per-tile depth bounds (an empty tile holds
//     exactly the +inf/-inf sentinel and an empty list), halfz splits, the
//     clustered range, the metrics and image error, the timings;
//   - the result is internally consistent (CullResult::validate);
//   - on Vulkan (validation layer on, any message fails): the GPU lists are a
//     superset of the CPU reference's on the same depth image, with the same
//     empty tiles, bounds within float rounding and few extra entries -- the
//     definition of tests/gpu/test_vulkan_cull.cpp;
//   - invalid cases throw the exact error text and type;
//   - the case's self-check (it really is the hard case it claims to be).
#include "../gpu/gpu_test_env.hpp"
#include "hardcase_scenes.hpp"

#include "culling/core/depth.hpp"
#include "culling/core/presets.hpp"
#include "culling/truth/ground_truth.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>

using namespace lc;
using lc::hardcase::HardCase;
using lc::hardcase::hardCases;

namespace {

// Every algorithm, and raster's clustered variant (proxy-depth slices).
struct Variant {
    Algorithm algorithm;
    bool proxySlices = false;
};
const Variant kVariants[] = {{Algorithm::All},           {Algorithm::Naive},     {Algorithm::MinMax},
                             {Algorithm::HalfZ},         {Algorithm::TwoPointFiveD}, {Algorithm::Clustered},
                             {Algorithm::Fptl},          {Algorithm::ZBin},      {Algorithm::Raster},
                             {Algorithm::Raster, true}};

const HardCase& caseNamed(const std::string& name) {
    for (const HardCase& c : hardCases())
        if (c.name == name) return c;
    throw std::runtime_error("no hard case " + name);
}

std::string algorithmId(std::size_t variant) {
    const Variant& v = kVariants[variant];
    std::string s = std::string(toString(v.algorithm)) + (v.proxySlices ? "_slices" : "");
    std::replace(s.begin(), s.end(), '.', '_'); // "2.5d" -> "2_5d"
    return s;
}

bool finite(double v) { return std::isfinite(v); }

// Every number of the result and the metrics is finite, except the documented
// sentinel of an empty tile (+inf min, -inf max, +inf halfz split) -- and an
// empty tile's lists are empty unless the algorithm ignores depth.
void expectFiniteOutputs(const RunOutput& run) {
    const CullResult& r = run.result;
    const std::uint32_t tiles = r.grid.tileCount();
    ASSERT_EQ(r.tileDepthMin.size(), tiles);
    ASSERT_EQ(r.tileDepthMax.size(), tiles);
    for (std::uint32_t t = 0; t < tiles; ++t) {
        const double lo = r.tileDepthMin[t], hi = r.tileDepthMax[t];
        ASSERT_FALSE(std::isnan(lo) || std::isnan(hi)) << "tile " << t << " bounds NaN";
        const bool empty = !(lo <= hi);
        if (empty) {
            EXPECT_EQ(lo, hardcase::kInf) << "empty tile " << t << " min";
            EXPECT_EQ(hi, -hardcase::kInf) << "empty tile " << t << " max";
            const bool depthFree = r.algorithm == Algorithm::All || r.algorithm == Algorithm::Naive ||
                                   r.algorithm == Algorithm::ZBin ||
                                   (r.algorithm == Algorithm::Clustered && !r.settings.skipEmpty);
            if (!depthFree)
                for (std::uint32_t k = 0; k < r.listsPerTile; ++k)
                    EXPECT_EQ(r.listCount[std::size_t(t) * r.listsPerTile + k], 0u) << "empty tile " << t << " has lights";
        } else {
            EXPECT_TRUE(finite(lo) && finite(hi)) << "tile " << t << " bounds " << lo << " " << hi;
            EXPECT_GT(lo, 0.0) << "tile " << t << " bounds in front of the eye";
        }
        if (r.algorithm == Algorithm::HalfZ) {
            ASSERT_EQ(r.halfzSplit.size(), tiles);
            if (empty) EXPECT_FALSE(std::isnan(r.halfzSplit[t]));
            else {
                EXPECT_TRUE(finite(r.halfzSplit[t])) << "tile " << t << " split";
                EXPECT_GE(r.halfzSplit[t], lo * (1 - 1e-6)) << "tile " << t;
                EXPECT_LE(r.halfzSplit[t], hi * (1 + 1e-6)) << "tile " << t;
            }
        }
    }
    if (r.algorithm == Algorithm::Clustered) {
        EXPECT_TRUE(finite(r.clusterNear) && finite(r.clusterFar)) << r.clusterNear << " " << r.clusterFar;
        EXPECT_LT(r.clusterNear, r.clusterFar);
    }
    const Metrics& m = run.truth.metrics;
    for (double v : {m.efficiency, m.meanList, m.imageRmse, m.imageMaxError})
        EXPECT_TRUE(finite(v)) << "metric " << v;
    EXPECT_GE(m.efficiency, 0.0);
    EXPECT_LE(m.efficiency, 1.0 + 1e-12);
    EXPECT_TRUE(m.imageErrorComputed);
    for (double v : {r.timings.depthMs, r.timings.cullMs, r.timings.groundTruthMs})
        EXPECT_TRUE(finite(v) && v >= 0) << "timing " << v;
    // The depth image itself: every pixel is the clear value or a window depth in [0, 1].
    for (float d : run.depth.depth) {
        ASSERT_TRUE(std::isfinite(d) && d >= 0.0f && d <= 1.0f) << "depth pixel " << d;
    }
    for (std::size_t i = 0; i < run.lights.size(); ++i) {
        ASSERT_TRUE(finite(run.lights.centers[i].x) && finite(run.lights.centers[i].y) && finite(run.lights.centers[i].z));
        ASSERT_TRUE(finite(run.lights.radii[i]) && run.lights.radii[i] >= 0) << "light " << i;
    }
}

// GPU lists contain every CPU entry (both ascending): extras are allowed only
// where a sphere touches a plane or bound within float rounding.
void expectConservativeAgreement(const CullResult& cpu, const CullResult& gpu) {
    ASSERT_EQ(gpu.listsPerTile, cpu.listsPerTile);
    ASSERT_EQ(gpu.listCountTotal(), cpu.listCountTotal());
    const std::uint32_t tiles = cpu.grid.tileCount();
    for (std::uint32_t t = 0; t < tiles; ++t) {
        const bool ce = !(cpu.tileDepthMin[t] <= cpu.tileDepthMax[t]);
        const bool ge = !(gpu.tileDepthMin[t] <= gpu.tileDepthMax[t]);
        EXPECT_EQ(ce, ge) << "tile " << t << " empty on one backend only";
        if (ce || ge) continue;
        EXPECT_NEAR(gpu.tileDepthMin[t], cpu.tileDepthMin[t], 1e-5 * cpu.tileDepthMin[t] + 1e-6) << "tile " << t;
        EXPECT_NEAR(gpu.tileDepthMax[t], cpu.tileDepthMax[t], 1e-5 * cpu.tileDepthMax[t] + 1e-6) << "tile " << t;
        if (cpu.settings.clusterLists())
            EXPECT_EQ(gpu.cellMask[t] & cpu.cellMask[t], cpu.cellMask[t]) << "tile " << t;
    }
    std::uint64_t missing = 0, extra = 0;
    std::string firstMissing, firstExtra;
    for (std::size_t l = 0; l < cpu.listCount.size(); ++l) {
        const auto cb = cpu.lightIndices.begin() + cpu.listOffset[l], ce = cb + cpu.listCount[l];
        const auto gb = gpu.lightIndices.begin() + gpu.listOffset[l], ge = gb + gpu.listCount[l];
        std::vector<std::uint32_t> lost;
        std::set_difference(cb, ce, gb, ge, std::back_inserter(lost));
        if (!lost.empty() && firstMissing.empty())
            firstMissing = "list " + std::to_string(l) + " lacks light " + std::to_string(lost[0]);
        missing += lost.size();
        if (firstExtra.empty()) {
            std::vector<std::uint32_t> more;
            std::set_difference(gb, ge, cb, ce, std::back_inserter(more));
            if (!more.empty())
                firstExtra = "list " + std::to_string(l) + " has extra light " + std::to_string(more[0]);
        }
        extra += gpu.listCount[l] - (cpu.listCount[l] - lost.size());
    }
    EXPECT_EQ(missing, 0u) << "GPU lists lack " << missing << " CPU entries; first: " << firstMissing;
    // raster's pushed edges reach 1/256 tile past a triangle, and a proxy
    // past float's reach near the camera comes as its box of tiles: a few
    // per cent more, by design (docs/ALGORITHMS.md).
    const std::uint64_t allowed = cpu.algorithm == Algorithm::Raster ? 8 + cpu.entries() / 32 : 8 + cpu.entries() / 200;
    EXPECT_LE(extra, allowed) << "too many extra GPU entries (" << extra << " over "
                                             << cpu.entries() << "); first: " << firstExtra;
    std::printf("[ agree    ] entries cpu %llu gpu %llu extra %llu\n", (unsigned long long)cpu.entries(),
                (unsigned long long)gpu.entries(), (unsigned long long)extra);
}

using Param = std::tuple<std::string, std::size_t, std::string>; // case, kVariants index, backend

class HardCaseTest : public gputest::GpuTest, public ::testing::WithParamInterface<Param> {};

TEST_P(HardCaseTest, Run) {
    const auto& [caseName, variant, backendName] = GetParam();
    const Algorithm algorithm = kVariants[variant].algorithm;
    const HardCase& hc = caseNamed(caseName);
    const Scene scene = hc.make();
    CullSettings settings;
    settings.algorithm = algorithm;
    settings.proxySlices = kVariants[variant].proxySlices;
    settings.test = hc.test;
    settings.cells = hc.cells;
    settings.slicing = hc.slicing;

    std::unique_ptr<CullBackend> cpuOwned = makeCpuBackend();
    CullBackend& backend = backendName == "vulkan" ? gputest::vulkan() : *cpuOwned;
    ASSERT_EQ(backend.name(), backendName);

    if (!hc.expectedError.empty()) {
        try {
            runPipeline(scene, settings, backend);
            FAIL() << "expected: " << hc.expectedError;
        } catch (const LightError& e) {
            EXPECT_EQ(std::string(e.what()), hc.expectedError);
            EXPECT_EQ(e.index(), hc.expectedLightIndex);
        }
        return;
    }

    if (algorithm == Algorithm::Fptl && backendName == "vulkan" && gputest::vulkanIsCpuDevice() &&
        scene.lights.size() > 65535) {
        // lavapipe caps a shader invocation at 65,535 loop iterations, and
        // fptl's pack walks a list in one: refused up front, with the reason.
        try {
            runPipeline(scene, settings, backend);
            FAIL() << "fptl with " << scene.lights.size() << " lights ran on a CPU device";
        } catch (const SettingsError& e) {
            EXPECT_NE(std::string(e.what()).find("65,535 loop iterations"), std::string::npos) << e.what();
        }
        return;
    }
    const RunOutput run = runPipeline(scene, settings, backend);
    ASSERT_EQ(run.result.validate(run.lights.size()), "");
    EXPECT_EQ(run.result.backend, backendName);
    EXPECT_EQ(run.truth.metrics.falseNegatives, 0u);
    expectFiniteOutputs(run);
    if (hc.selfCheck) EXPECT_EQ(hc.selfCheck(run), "") << "the case no longer exercises what it claims";
    std::printf("[ metrics  ] %s: geometry px %llu, entries %llu, W %llu, E %llu, efficiency %.4f, rmse %.3g\n",
                caseName.c_str(), (unsigned long long)run.truth.metrics.geometryPixels,
                (unsigned long long)run.result.entries(), (unsigned long long)run.truth.metrics.shadingWork,
                (unsigned long long)run.truth.metrics.exactWork, run.truth.metrics.efficiency,
                run.truth.metrics.imageRmse);

    if (backendName == "vulkan") {
        // The CPU reference on the GPU's own depth image: the GPU lists must
        // contain it.
        const Projection proj(scene.camera);
        const CullResult cpu = cpuOwned->cull(run.depth, proj, run.result.grid, run.lights, settings);
        expectConservativeAgreement(cpu, run.result);
        // The GPU depth pre-pass against the CPU rasteriser: the same pixels
        // hold geometry, except along triangle edges where float rounding of
        // the edge functions may decide a centre the other way.
        const DepthImage ref = rasterizeDepthCpu(scene, proj);
        std::size_t differ = 0;
        for (std::size_t i = 0; i < ref.depth.size(); ++i)
            differ += (ref.depth[i] != ref.clearDepth) != (run.depth.depth[i] != run.depth.clearDepth);
        EXPECT_LE(differ, 2 + ref.depth.size() / 100) << "GPU and CPU depth coverage differ in " << differ << " pixels";
    }
}

std::vector<std::string> caseNames() {
    std::vector<std::string> n;
    for (const HardCase& c : hardCases()) n.push_back(c.name);
    return n;
}

INSTANTIATE_TEST_SUITE_P(HardCases, HardCaseTest,
                         ::testing::Combine(::testing::ValuesIn(caseNames()), ::testing::Range(std::size_t(0), std::size(kVariants)),
                                            ::testing::Values(std::string("cpu"), std::string("vulkan"))),
                         [](const ::testing::TestParamInfo<Param>& info) {
                             return std::get<0>(info.param) + "__" + algorithmId(std::get<1>(info.param)) + "__" +
                                    std::get<2>(info.param);
                         });

// The cases shaped after engines' limit bugs, through every engine preset
// (CPU reference): the misses each preset's limits cause, by cause, are the
// table docs/ENGINES.md shows ("On the hard cases"). A change of a preset, a
// case or the limits' rule shows here as the table to put in the docs.
TEST(HardCasePresets, LossesMatchTheDocumentedTable) {
    const char* engineCases[] = {"lights_past_scene_limit", "dense_cluster_4k",     "wide_spots_short_far",
                                 "lights_seen_from_far",    "orthographic_far_cut", "near_gap_first_slice"};
    auto cpu = makeCpuBackend();
    std::string table;
    for (const char* name : engineCases) {
        const HardCase& c = caseNamed(name);
        const Scene base = c.make();
        for (const EnginePreset& p : enginePresets()) {
            Scene scene = base;
            CullSettings s;
            applyPreset(p, s, scene.camera, scene.lights.size());
            RunOptions o;
            o.truthOptions.imageError = false;
            const RunOutput run = runPipeline(scene, s, *cpu, o);
            const Metrics& m = run.truth.metrics;
            EXPECT_EQ(m.falseNegativesCullingTest(), 0u) << name << " " << p.name;
            table += "| " + std::string(name) + " | " + p.name + " | " + std::to_string(m.falseNegativesListFull) +
                     " | " + std::to_string(m.falseNegativesLightLimit) + " | " +
                     std::to_string(run.result.limits.overflowLists.size()) + " | " +
                     std::to_string(run.result.limits.lightsOverLimit) + " |\n";
        }
    }
    std::ifstream in(std::string(LC_SOURCE_DIR) + "/docs/ENGINES.md");
    ASSERT_TRUE(in);
    std::string doc, line;
    bool inside = false;
    while (std::getline(in, line)) {
        if (line.find("<!-- hardcase-presets: end -->") != std::string::npos) inside = false;
        if (inside && line.rfind("| ", 0) == 0 && line.find(" | ---") == std::string::npos &&
            line.find("| case |") == std::string::npos)
            doc += line + "\n";
        if (line.find("<!-- hardcase-presets: begin -->") != std::string::npos) inside = true;
    }
    EXPECT_EQ(doc, table) << "docs/ENGINES.md's table should read:\n" << table;
}

// tests/hardcase/cases.txt names the cases for CTest (one process per case):
// it must list exactly the cases above, in order.
TEST(HardCaseList, MatchesCasesTxt) {
    std::ifstream in(std::string(LC_SOURCE_DIR) + "/tests/hardcase/cases.txt");
    ASSERT_TRUE(in) << "tests/hardcase/cases.txt missing";
    std::vector<std::string> listed;
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line[0] != '#') listed.push_back(line);
    EXPECT_EQ(listed, caseNames());
    EXPECT_GE(caseNames().size(), 24u);
}

} // namespace
