// lc::explainLight: its tests give the reference's verdict for every light of
// every tile checked, for every algorithm, sphere test and spot test; its
// ground-truth counts agree with the tile inspector's; a forced miss is named
// MISSING; `lightcull explain` prints the same explanation.
#include "cli_support.hpp"

#include "culling/diagnostics/explain.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/diagnostics/overlays.hpp"
#include "culling/math/tile_math.hpp"
#include "culling/scene/scene_io.hpp"

#include <gtest/gtest.h>

using namespace lc;

namespace {

Scene smallAtrium() {
    Scene s = makeBuiltinScene("atrium");
    LightGenSettings g = defaultLightGen(s, 80, 12);
    g.spotFraction = 0.3;
    s.lights = generateLights(g);
    s.camera.width = 150;
    s.camera.height = 90;
    return s;
}

RunOutput cpuRun(const Scene& s, const CullSettings& cs) {
    auto backend = makeCpuBackend();
    RunOptions o;
    o.truthOptions.imageError = false;
    return runPipeline(s, cs, *backend, o);
}

CullSettings minmax() {
    CullSettings cs;
    cs.algorithm = Algorithm::MinMax;
    return cs;
}

} // namespace

TEST(Explain, TestsAgreeWithTheReferenceListsForEveryAlgorithm) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    // Every algorithm, and raster's clustered lists (proxy-depth slices) last.
    const Algorithm algorithms[] = {Algorithm::All,       Algorithm::Naive, Algorithm::MinMax,
                                    Algorithm::HalfZ,     Algorithm::TwoPointFiveD, Algorithm::Clustered,
                                    Algorithm::Fptl,      Algorithm::ZBin,  Algorithm::Raster,
                                    Algorithm::Raster};
    for (std::size_t v = 0; v < std::size(algorithms); ++v) {
        const Algorithm a = algorithms[v];
        for (const SphereTest t : {SphereTest::Planes, SphereTest::Exact}) {
            for (const SpotTest st : {SpotTest::ApexSphere, SpotTest::ConePlanes}) {
                CullSettings cs;
                cs.algorithm = a;
                cs.proxySlices = v + 1 == std::size(algorithms);
                cs.test = t;
                cs.spotTest = st;
                cs.cells = 8;
                const RunOutput run = cpuRun(s, cs);
                const CullResult& r = run.result;
                std::uint64_t listedSeen = 0, checked = 0;
                for (std::uint32_t l = 0; l < r.listCount.size(); l += 5) {
                    // The tile and cell a run's first-miss hint names lead
                    // explain back to the same list.
                    EXPECT_EQ(r.listOf(r.tileOfList(l), r.cellOfList(l)), l) << toString(a) << " list " << l;
                    for (std::uint32_t i = 0; i < run.lights.size(); ++i) {
                        const Explanation e = explainLight(run, proj, l, i);
                        ASSERT_EQ(e.testsPass, e.listed)
                            << toString(a) << " " << toString(t) << " " << toString(st) << " list " << l << " light "
                            << i << "\n" << e.text();
                        EXPECT_FALSE(!e.listed && e.pixelsNeeding > 0) << e.text(); // the reference misses nothing
                        listedSeen += e.listed;
                        ++checked;
                    }
                }
                EXPECT_GT(listedSeen, 0u) << toString(a);
                if (a != Algorithm::All) EXPECT_LT(listedSeen, checked) << toString(a); // some are rejected
            }
        }
    }
}

// A spot's false positive whose nearest pixel is within its range lies
// outside its cone: the verdict says so, not "0 beyond its range".
TEST(Explain, ASpotFalsePositiveWithinRangeIsOutsideItsCone) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    const RunOutput run = cpuRun(s, minmax());
    int seen = 0;
    for (std::uint32_t l = 0; l < run.result.listCount.size(); ++l)
        for (std::uint32_t i = 0; i < run.lights.size(); ++i) {
            const Explanation e = explainLight(run, proj, l, i);
            if (!e.listed || e.pixelsNeeding > 0 || e.nearestDistance < 0) continue;
            const bool inCone = e.nearestDistance == 0.0 && run.lights.isSpot(i);
            EXPECT_EQ(e.verdict.find("outside its cone") != std::string::npos, inCone) << e.verdict;
            EXPECT_EQ(e.verdict.find(" 0 beyond") != std::string::npos, false) << e.verdict;
            seen += inCone;
        }
    EXPECT_GT(seen, 0); // the scene has such spots
}

// The deciding plane: chunkFace's corners lie on the plane it names, and it
// is the plane of least margin (a failed one when a plane rejects).
TEST(Explain, TheDecidingPlaneIsTheOneOfLeastMargin) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    const RunOutput run = cpuRun(s, minmax());
    std::uint32_t rejectedByPlane = 0, kept = 0, rejectedVerdicts = 0;
    for (std::uint32_t t = 0; t < run.result.grid.tileCount(); t += 7) {
        const auto chunk = tileFrustum(run.result, proj, run.lights, t);
        if (!chunk) continue;
        for (int k = 0; k < 6; ++k)
            for (const glm::dvec3& c : chunkFace(chunk->corners, k))
                EXPECT_NEAR(signedDistance(chunk->planes[std::size_t(k)], c), 0.0, 1e-9 * (1 + glm::length(c)))
                    << chunkPlaneName(k);
        for (std::uint32_t i = 0; i < run.lights.size(); ++i) {
            const Explanation e = explainLight(run, proj, t, i);
            ASSERT_TRUE(e.hasChunk);
            ASSERT_GE(e.decisivePlane, 0);
            double least = 1e300;
            bool planeFailed = false;
            for (const ExplainStep& st : e.steps)
                for (int k = 0; k < 6; ++k)
                    if (st.test == chunkPlaneName(k)) planeFailed = planeFailed || !st.passed;
            const double rr = e.sphereRadius + sphereTestSlack(e.sphereCenter, e.sphereRadius);
            for (int k = 0; k < 6; ++k)
                least = std::min(least, signedDistance(chunk->planes[std::size_t(k)], e.sphereCenter) + rr);
            EXPECT_DOUBLE_EQ(e.decisiveMargin, least);
            EXPECT_EQ(e.decisiveMargin < 0, planeFailed) << e.text();
            // One answer to "which test rejected it": the verdict names the
            // first failing step; the plane line says it ranks the planes.
            const auto firstFail = std::find_if(e.steps.begin(), e.steps.end(), [](const ExplainStep& st) { return !st.passed; });
            if (!e.listed) {
                // A rejected light has a failing step, and the verdict names the first.
                ASSERT_NE(firstFail, e.steps.end()) << e.text();
                EXPECT_NE(e.verdict.find("the first test to reject it: '" + firstFail->test + "'"), std::string::npos) << e.text();
                ++rejectedVerdicts;
            }
            EXPECT_EQ(e.text().find("rejected by"), std::string::npos) << e.text();
            rejectedByPlane += planeFailed;
            kept += !planeFailed;
        }
    }
    EXPECT_GT(rejectedByPlane, 0u);
    EXPECT_GT(kept, 0u);
    EXPECT_GT(rejectedVerdicts, 0u); // the verdict check above ran
}

TEST(Explain, GroundTruthCountsMatchTheTileInspector) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    const RunOutput run = cpuRun(s, minmax());
    std::size_t neededChecked = 0;
    for (std::uint32_t t = 0; t < run.result.grid.tileCount(); t += 3) {
        const auto needing = pixelsNeedingLights(run.depth, proj, run.lights, run.result.grid, t);
        neededChecked += needing.size();
        for (const auto& [light, count] : needing) {
            const Explanation e = explainLight(run, proj, run.result.listOf(t), light);
            EXPECT_EQ(e.pixelsNeeding, count) << "tile " << t << " light " << light;
            EXPECT_TRUE(e.listed);
            EXPECT_NE(e.verdict.find("needed"), std::string::npos) << e.verdict;
        }
    }
    ASSERT_GT(neededChecked, 0u); // some tile needs some light: the loop above checked something
    // A false positive names the nearest pixel and its distance.
    bool sawFalsePositive = false;
    for (std::uint32_t l = 0; l < run.result.listCount.size() && !sawFalsePositive; ++l)
        for (std::uint32_t k = 0; k < run.result.listCount[l]; ++k) {
            const Explanation e = explainLight(run, proj, l, run.result.lightIndices[run.result.listOffset[l] + k]);
            if (e.pixelsNeeding == 0 && e.listPixels > 0) {
                EXPECT_GT(e.nearestDistance, 0.0) << e.text();
                EXPECT_NE(e.verdict.find("false positive"), std::string::npos) << e.verdict;
                const glm::dvec3 p = proj.viewPositionFromDepth(e.nearestX, e.nearestY, run.depth.at(e.nearestX, e.nearestY));
                EXPECT_LT(glm::length(p - e.nearestPosition), 1e-9);
                sawFalsePositive = true;
                break;
            }
        }
    EXPECT_TRUE(sawFalsePositive);
}

TEST(Explain, AForcedMissIsNamedMissing) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    CullSettings cs;
    cs.algorithm = Algorithm::MinMax;
    RunOutput run = cpuRun(s, cs);
    // Drop the first needed light of the busiest tile from its list, as a
    // broken pass would.
    std::uint32_t tile = 0, best = 0;
    for (std::uint32_t t = 0; t < run.result.grid.tileCount(); ++t)
        if (run.result.listCount[t] > best) best = run.result.listCount[t], tile = t;
    const auto needing = pixelsNeedingLights(run.depth, proj, run.lights, run.result.grid, tile);
    ASSERT_FALSE(needing.empty());
    const std::uint32_t victim = needing[0].first;
    CullResult& r = run.result;
    std::vector<std::uint32_t> idx;
    for (std::uint32_t l = 0; l < r.listCount.size(); ++l) {
        const std::uint32_t off = std::uint32_t(idx.size());
        for (std::uint32_t k = 0; k < r.listCount[l]; ++k) {
            const std::uint32_t v = r.lightIndices[r.listOffset[l] + k];
            if (!(l == tile && v == victim)) idx.push_back(v);
        }
        r.listCount[l] = std::uint32_t(idx.size()) - off;
        r.listOffset[l] = off;
    }
    r.lightIndices = idx;
    run.truth = computeGroundTruth(run.depth, proj, run.lights, r, {false});
    const Explanation e = explainLight(run, proj, tile, victim);
    EXPECT_FALSE(e.listed);
    EXPECT_TRUE(e.testsPass);
    EXPECT_EQ(e.pixelsNeeding, needing[0].second);
    EXPECT_EQ(e.verdict.rfind("MISSING", 0), 0u) << e.verdict;
    EXPECT_NE(e.verdict.find("this pass dropped it"), std::string::npos) << e.verdict;
}

// raster with an inscribed icosahedron and centre sampling misses lights:
// each miss is named MISSING, its failed step the proxy's coverage of the
// tile (the depth range reaches it), with the triangle that came nearest.
TEST(Explain, ARasterMissNamesTheProxyCoverage) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    CullSettings cs;
    cs.algorithm = Algorithm::Raster;
    cs.proxyLevel = 0;
    cs.proxyOverfit = 1.0;
    cs.conservative = false;
    const RunOutput run = cpuRun(s, cs);
    ASSERT_GT(run.truth.metrics.falseNegatives, 0u) << "the case no longer misses";
    std::uint32_t named = 0, grazed = 0;
    for (std::uint32_t t = 0; t < run.result.grid.tileCount() && named < 40; ++t) {
        if (run.truth.listFalseNegatives[t] == 0) continue;
        for (const auto& [light, pixels] : pixelsNeedingLights(run.depth, proj, run.lights, run.result.grid, t)) {
            const Explanation e = explainLight(run, proj, t, light);
            if (e.listed) continue;
            EXPECT_EQ(e.verdict.rfind("MISSING", 0), 0u) << e.text();
            ASSERT_GE(e.steps.size(), 2u) << e.text();
            const ExplainStep& cover = e.steps[e.steps.size() - 2];
            EXPECT_EQ(cover.test.rfind(run.lights.isSpot(light) ? "proxy coverage: cone of 8 sides" : "proxy coverage: icosphere level 0 (20 triangles), overfit 1", 0), 0u) << e.text();
            EXPECT_FALSE(cover.passed) << e.text();
            EXPECT_NE(cover.numbers.find("no triangle covers the centre of tile"), std::string::npos) << e.text();
            // Either the proxy grazes the tile (centre sampling) or the
            // inscribed proxy falls short of it (the nearest triangle named).
            const bool grazes = cover.numbers.find("overlaps it (centre sampling") != std::string::npos;
            const bool short_ = cover.numbers.find("the nearest, triangle") != std::string::npos;
            EXPECT_TRUE(grazes || short_) << e.text();
            grazed += grazes;
            EXPECT_TRUE(e.steps.back().passed) << "the depth range reaches it: " << e.text();
            ++named;
        }
    }
    EXPECT_GT(named, 0u);
    EXPECT_GT(grazed, 0u) << "no miss of centre sampling among " << named;
}

// raster with proxy-depth slices: a light the inscribed proxy misses in
// depth (its triangles' depths over the tile end before the pixel's slice)
// is named at the slice step, with the depths and the slices.
TEST(Explain, ARasterSliceMissNamesTheSlices) {
    const Scene s = smallAtrium();
    const Projection proj(s.camera);
    CullSettings cs;
    cs.algorithm = Algorithm::Raster;
    cs.proxySlices = true;
    cs.proxyLevel = 0;
    cs.proxyOverfit = 1.0;
    cs.cells = 32;
    const RunOutput run = cpuRun(s, cs);
    ASSERT_GT(run.truth.metrics.falseNegatives, 0u) << "the case no longer misses";
    std::uint32_t bySlice = 0, byCoverage = 0;
    for (std::uint32_t l = 0; l < run.result.listCount.size(); ++l) {
        if (run.truth.listFalseNegatives[l] == 0) continue;
        for (std::uint32_t i = 0; i < run.lights.size(); ++i) {
            const Explanation e = explainLight(run, proj, l, i);
            if (e.listed || e.pixelsNeeding == 0) continue;
            EXPECT_EQ(e.verdict.rfind("MISSING", 0), 0u) << e.text();
            EXPECT_FALSE(e.testsPass) << e.text();
            for (const ExplainStep& st : e.steps) {
                if (st.passed) continue;
                if (st.test.rfind("proxy depth slices (32 log of ", 0) == 0) {
                    EXPECT_NE(st.numbers.find("the covering triangles span depths "), std::string::npos) << e.text();
                    EXPECT_NE(st.numbers.find(", not slice " + std::to_string(l % 32)), std::string::npos) << e.text();
                    ++bySlice;
                }
                byCoverage += st.test.rfind("proxy coverage", 0) == 0;
                break;
            }
        }
    }
    EXPECT_GT(bySlice, 0u) << "no miss in depth";
    EXPECT_GT(byCoverage, 0u) << "no miss in coverage";
}

TEST(Explain, CliPrintsTheSameExplanation) {
    lc_test::ScratchDir d;
    const Scene s = smallAtrium();
    lc::saveSceneFile(s, (d.path / "s.json").string());
    CullSettings cs; // 2.5d, the default
    const RunOutput run = cpuRun(lc::loadSceneFile((d.path / "s.json").string()), cs);
    const Projection proj(s.camera);
    const std::uint32_t tx = 4, ty = 2, light = 7;
    const Explanation e = explainLight(run, proj, run.result.grid.tileIndex(tx, ty), light);
    const auto r = lc_test::runCli({"explain", "--scene", (d.path / "s.json").string(), "--backend", "cpu", "--tile", "4,2",
                                    "--light", s.lights[light].name},
                                   d.path);
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.out.find(e.text(s.lights[light].name)), std::string::npos) << r.out << "\nexpected:\n" << e.text();
    // Bad input: one line naming the problem.
    const auto bad = lc_test::runCli({"explain", "--builtin", "atrium", "--backend", "cpu", "--width", "64", "--height",
                                      "64", "--tile", "9,9", "--light", "0"},
                                     d.path);
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.err.find("--tile: 9,9 is outside the 4x4 tiles"), std::string::npos) << bad.err;
    // Two lights of one name: the name does not choose.
    Scene twice = s;
    twice.lights[9].name = twice.lights[light].name;
    lc::saveSceneFile(twice, (d.path / "twice.json").string());
    const auto ambiguous = lc_test::runCli({"explain", "--scene", (d.path / "twice.json").string(), "--backend", "cpu",
                                            "--tile", "4,2", "--light", s.lights[light].name},
                                           d.path);
    EXPECT_EQ(ambiguous.code, 2);
    EXPECT_NE(ambiguous.err.find("lights 7 and 9 are both named"), std::string::npos) << ambiguous.err;

    // Digits are an index even where a light is named with them (tiles.csv
    // names lights by index); a negative or too large one is said plainly.
    Scene numeric = s;
    numeric.lights[0].name = "7";
    lc::saveSceneFile(numeric, (d.path / "numeric.json").string());
    const auto byIndex = lc_test::runCli({"explain", "--scene", (d.path / "numeric.json").string(), "--backend", "cpu",
                                          "--tile", "4,2", "--light", "7"},
                                         d.path);
    EXPECT_EQ(byIndex.code, 0) << byIndex.err;
    EXPECT_NE(byIndex.out.find("light 7 '" + s.lights[light].name + "'"), std::string::npos) << byIndex.out;
    EXPECT_NE(byIndex.err.find("light 0 is named '7'"), std::string::npos) << byIndex.err;
    for (const char* wrong : {"-1", "4294967295"}) {
        const auto r2 = lc_test::runCli({"explain", "--scene", (d.path / "s.json").string(), "--backend", "cpu",
                                         "--tile", "4,2", "--light", wrong},
                                        d.path);
        EXPECT_EQ(r2.code, 2) << wrong;
        EXPECT_EQ(r2.err.find("4294967295 is outside"), std::string::npos) << r2.err;
    }
}
