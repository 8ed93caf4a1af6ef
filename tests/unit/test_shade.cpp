// The shading pass's CPU reference (culling/truth/shade.hpp) on real scenes: every
// pixel against a brute-force double-precision sum over the lights of the list
// CullResult::listOfPixel names; the pipeline's image error against the
// ground truth's own CPU path; zero error when every list holds every light.
#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/shade.hpp"
#include "updated_image.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>

using namespace lc;
using lc::testutil::expectCloseToFresh;

namespace {

Scene smallScene(const std::string& builtin, std::uint32_t w, std::uint32_t h, std::uint32_t tile,
                 std::uint32_t lights) {
    Scene s = makeBuiltinScene(builtin);
    s.camera.width = w;
    s.camera.height = h;
    s.camera.tileSize = tile;
    s.lights = generateLights(defaultLightGen(s, lights, 7));
    return s;
}

// A small atrium with 24 lights, light 3 a spot: a cone among the inputs.
Scene atriumWithSpot() {
    Scene s = smallScene("atrium", 96, 54, 16, 24);
    s.lights[3].kind = LightKind::Spot;
    s.lights[3].outerAngleDeg = 40.0;
    return s;
}

RunOutput cpuRun(const Scene& scene, Algorithm algo, std::uint32_t cells = 8) {
    CullSettings settings;
    settings.algorithm = algo;
    settings.cells = cells;
    auto cpu = makeCpuBackend();
    RunOptions opt;
    opt.truthOptions.imageError = false;
    return runPipeline(scene, settings, *cpu, opt);
}

} // namespace

// Every geometry pixel: the sum over exactly the lights of its list (the rule
// of listOfPixel at the pixel's view depth), evaluated in double from the
// pixel's reconstructed position; background pixels stay 0.
TEST(Shade, CpuShadingIsTheBruteForceSumOverEachPixelsList) {
    const Scene scene = smallScene("mountain", 96, 64, 16, 48);
    const Projection proj(scene.camera);
    for (Algorithm algo : {Algorithm::HalfZ, Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::Naive}) {
        const RunOutput run = cpuRun(scene, algo);
        const ShadeInputs in = makeShadeInputs(run.depth, proj, &run.result);
        const std::vector<float> rgb = shadeCpu(in, run.lights, &run.result);
        std::size_t geometry = 0, lit = 0;
        for (std::uint32_t y = 0; y < run.depth.height; ++y)
            for (std::uint32_t x = 0; x < run.depth.width; ++x) {
                const std::size_t i = std::size_t(y) * run.depth.width + x;
                if (!run.depth.hasGeometry(x, y)) {
                    EXPECT_EQ(in.list[i], ShadeInputs::kNoList);
                    for (int c = 0; c < 3; ++c) ASSERT_EQ(rgb[3 * i + c], 0.0f) << "background " << x << "," << y;
                    continue;
                }
                ++geometry;
                const double d = run.depth.at(x, y);
                const glm::dvec3 p = proj.viewPositionFromDepth(x, y, d);
                const glm::dvec3 n(in.normal[3 * i], in.normal[3 * i + 1], in.normal[3 * i + 2]);
                EXPECT_NEAR(glm::length(n), 1.0, 1e-5);
                const std::uint32_t list = run.result.listOfPixel(x, y, proj.viewDepthFromWindowDepth(d));
                ASSERT_EQ(in.list[i], list);
                glm::dvec3 sum(0.0), magnitude(0.0);
                for (std::uint32_t k = 0; k < run.result.listCount[list]; ++k) {
                    const std::uint32_t li = run.result.lightIndices[run.result.listOffset[list] + k];
                    const glm::dvec3 to = run.lights.centers[li] - p;
                    const double d2 = glm::dot(to, to);
                    const double ndl = glm::dot(n, to) / std::sqrt(std::max(d2, 1e-30));
                    const glm::dvec3 term = run.lights.power[li] * (std::max(ndl, 0.0) / std::max(d2, 1e-4));
                    sum += term;
                    magnitude += glm::abs(term);
                }
                lit += sum.x > 0;
                for (int c = 0; c < 3; ++c)
                    ASSERT_NEAR(rgb[3 * i + c], sum[c], 1e-3 * magnitude[c] + 1e-12)
                        << toString(algo) << " pixel " << x << "," << y << " channel " << c;
            }
        EXPECT_GT(geometry, 1000u);
        EXPECT_GT(lit, 0u) << toString(algo) << ": no lit pixel, the comparison would prove nothing";
    }
}

// runPipeline takes the image error from the backend's shading pass; on the
// CPU backend it must equal the ground truth's own CPU path bitwise.
TEST(Shade, PipelineImageErrorEqualsTheGroundTruthsCpuPath) {
    const Scene scene = smallScene("forest", 128, 72, 16, 64);
    auto cpu = makeCpuBackend();
    for (Algorithm algo : {Algorithm::MinMax, Algorithm::Clustered}) {
        CullSettings settings;
        settings.algorithm = algo;
        RunOptions opt;
        opt.keepShadedImages = true;
        const RunOutput run = runPipeline(scene, settings, *cpu, opt);
        ASSERT_TRUE(run.truth.metrics.imageErrorComputed);
        EXPECT_GE(run.result.timings.shadeMs, 0.0);
        const Projection proj(scene.camera);
        const Metrics m = computeGroundTruth(run.depth, proj, run.lights, run.result).metrics;
        EXPECT_EQ(run.truth.metrics.imageRmse, m.imageRmse) << toString(algo);
        EXPECT_EQ(run.truth.metrics.imageMaxError, m.imageMaxError) << toString(algo);
        EXPECT_GT(m.imageRmse, 0.0) << "lights cut off by their spheres leave some error";
        ASSERT_EQ(run.shadedCulled.size(), std::size_t(128) * 72 * 3);
        EXPECT_EQ(run.shadedAll, shadeLambertCpu(run.depth, proj, run.lights, nullptr));
        EXPECT_EQ(run.shadedCulled, shadeLambertCpu(run.depth, proj, run.lights, &run.result));
    }
}

// Lists that hold every light (through the per-list path, not `all`) shade
// bitwise like the all-lights image: the error is exactly 0. Emptying the
// lists makes the error the all-lights image itself.
TEST(Shade, ErrorIsZeroWhenEveryListHoldsEveryLightAndFullWhenListsAreEmpty) {
    const Scene scene = smallScene("atrium", 80, 48, 16, 24);
    RunOutput run = cpuRun(scene, Algorithm::TwoPointFiveD);
    const Projection proj(scene.camera);
    CullResult every = run.result;
    const std::uint32_t n = std::uint32_t(run.lights.size());
    every.lightIndices.clear();
    for (std::size_t l = 0; l < every.listCount.size(); ++l) {
        every.listOffset[l] = std::uint32_t(every.lightIndices.size());
        every.listCount[l] = n;
        for (std::uint32_t i = 0; i < n; ++i) every.lightIndices.push_back(i);
    }
    const std::vector<float> all = shadeLambertCpu(run.depth, proj, run.lights, nullptr);
    const ImageError zero = compareShadedImages(run.depth, shadeLambertCpu(run.depth, proj, run.lights, &every), all);
    EXPECT_EQ(zero.rmse, 0.0);
    EXPECT_EQ(zero.maxAbs, 0.0);
    EXPECT_EQ(zero.pixels, run.depth.geometryPixelCount());

    CullResult none = run.result;
    std::fill(none.listCount.begin(), none.listCount.end(), 0u);
    std::fill(none.listOffset.begin(), none.listOffset.end(), 0u);
    none.lightIndices.clear();
    const ImageError full = compareShadedImages(run.depth, shadeLambertCpu(run.depth, proj, run.lights, &none), all);
    double sum2 = 0, mx = 0;
    for (float v : all) sum2 += double(v) * v, mx = std::max(mx, double(v));
    EXPECT_GT(mx, 0.0);
    EXPECT_NEAR(full.rmse, std::sqrt(sum2 / (3.0 * double(full.pixels))), 1e-9 * mx);
    EXPECT_EQ(full.maxAbs, mx);
}

TEST(Shade, BadListsAndSizesAreTypedErrors) {
    const Scene scene = smallScene("wall", 32, 32, 16, 8);
    RunOutput run = cpuRun(scene, Algorithm::MinMax);
    const Projection proj(scene.camera);
    ShadeInputs in = makeShadeInputs(run.depth, proj, &run.result);
    CullResult bad = run.result;
    ASSERT_FALSE(bad.lightIndices.empty());
    bad.lightIndices[0] = 999;
    EXPECT_THROW(shadeCpu(in, run.lights, &bad), Error);
    bad = run.result;
    bad.listCount[0] = std::uint32_t(bad.lightIndices.size()) + 1;
    EXPECT_THROW(shadeCpu(in, run.lights, &bad), Error);
    ShadeInputs wrongList = in;
    wrongList.list[0] = std::uint32_t(run.result.listCount.size());
    EXPECT_THROW(shadeCpu(wrongList, run.lights, &run.result), Error);
    ShadeInputs truncated = in;
    truncated.normal.pop_back();
    EXPECT_THROW(shadeCpu(truncated, run.lights, &run.result), Error);
    CullResult otherGrid = run.result;
    otherGrid.grid = TileGrid::make(16, 16, 16);
    EXPECT_THROW(makeShadeInputs(run.depth, proj, &otherGrid), Error);
    EXPECT_THROW(compareShadedImages(run.depth, std::vector<float>(3), std::vector<float>(3)), Error);
}

TEST(Shade, PicturesMapExposureAndDifference) {
    // Two pixels: 0.5 and 1.0 (reference) against 0.5 and 0.25 (culled).
    const std::vector<float> ref{0.5f, 0.5f, 0.5f, 1.0f, 1.0f, 1.0f};
    const std::vector<float> cul{0.5f, 0.5f, 0.5f, 0.25f, 0.25f, 0.25f};
    const std::vector<std::uint8_t> a = shadedPicture(ref, 1.0);
    EXPECT_EQ(a[3], 255); // 1.0 -> white
    EXPECT_EQ(a[0], 188); // sRGB(0.5) = 0.7354 -> 188
    const std::vector<std::uint8_t> d = differencePicture(cul, ref, 0.75);
    EXPECT_EQ(d[0], 0);   // no difference: black
    EXPECT_EQ(d[3], 255); // the largest difference: white
    DepthImage depth;
    depth.width = 2, depth.height = 1, depth.clearDepth = 1.0f, depth.depth = {0.5f, 0.5f};
    EXPECT_NEAR(exposureFor(depth, ref), 0.9, 1e-12); // 99th percentile of {0.5, 1} is 1
}

// zbin: a pixel shades the lights of its tile's mask within its bin's range,
// through every entry point (the G-buffer carries the per-pixel lists), not
// the whole mask (naive's lists).
TEST(Shade, ZBinPixelsShadeTheirBinsLightsOnly) {
    const Scene scene = smallScene("forest", 128, 72, 16, 200);
    const RunOutput zbin = cpuRun(scene, Algorithm::ZBin);
    const RunOutput naive = cpuRun(scene, Algorithm::Naive);
    ASSERT_EQ(zbin.result.lightIndices, naive.result.lightIndices); // the same masks
    const Projection proj(scene.camera);
    const CullResult perPixel = zbinPixelLists(zbin.result, zbin.depth, proj);
    ASSERT_EQ(perPixel.validate(zbin.lights.size()), "");
    ASSERT_LT(perPixel.entries(), zbin.result.entries() * 16); // few lists per tile
    const ShadeInputs in = makeShadeInputs(zbin.depth, proj, &zbin.result);
    ASSERT_TRUE(in.perPixelLists);
    const std::vector<float> viaResult = shadeCpu(in, zbin.lights, &zbin.result);
    EXPECT_EQ(viaResult, shadeCpu(makeShadeInputs(zbin.depth, proj, &perPixel), zbin.lights, &perPixel));
    EXPECT_EQ(viaResult, shadeLambertCpu(zbin.depth, proj, zbin.lights, &zbin.result));
    EXPECT_NE(viaResult, shadeLambertCpu(naive.depth, proj, naive.lights, &naive.result));
}

// One G-buffer pointed at one result after another (the report's sweep):
// each time the same inputs and image as inputs made for that result alone,
// the zbin result's per-pixel lists brought along and dropped again after.
TEST(Shade, InputsPointedAtAnotherResultAreThoseMadeForIt) {
    const Scene scene = smallScene("forest", 128, 72, 16, 200);
    const Projection proj(scene.camera);
    const RunOutput first = cpuRun(scene, Algorithm::Naive);
    ShadeInputs in = makeShadeInputs(first.depth, proj, nullptr);
    for (const Algorithm a : {Algorithm::ZBin, Algorithm::Clustered, Algorithm::TwoPointFiveD, Algorithm::All}) {
        const RunOutput run = cpuRun(scene, a);
        setShadeLists(in, run.depth, proj, &run.result);
        const ShadeInputs fresh = makeShadeInputs(run.depth, proj, &run.result);
        EXPECT_EQ(in.list, fresh.list) << toString(a);
        EXPECT_EQ(in.position, fresh.position) << toString(a);
        EXPECT_EQ(bool(in.perPixelLists), a == Algorithm::ZBin) << toString(a);
        EXPECT_EQ(shadeCpu(in, run.lights, &run.result), shadeCpu(fresh, run.lights, &run.result)) << toString(a);
    }
    const Scene narrow = smallScene("forest", 64, 72, 16, 200);
    const RunOutput other = cpuRun(narrow, Algorithm::Naive);
    EXPECT_THROW(setShadeLists(in, other.depth, Projection(narrow.camera), &other.result), Error);
}

// The all-lights image of an earlier run serves a later one only where the
// pixels and the lights' shading values are the same: a change of algorithm,
// tile size or light range keeps it (and the images and error then equal a
// run shaded from scratch); a moved or recoloured light, a turned spot, an
// edited depth pixel or another camera does not.
TEST(Shade, AllLightsImageIsKeptOnlyForTheSamePixelsAndLights) {
    const Scene scene = atriumWithSpot();
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    RunOutput first = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, first, proj, true);
    ASSERT_FALSE(first.allLightsReused);

    // Another algorithm, tile size and culling radius (a light's I_min): the
    // same all-lights image.
    Scene tiles = scene;
    tiles.camera.tileSize = 8;
    tiles.lights[5].minIntensity = 4 * scene.lights[5].minIntensity;
    RunOutput second = cpuRun(tiles, Algorithm::Clustered);
    ASSERT_TRUE(sameAllLightsImage(first, scene.camera, second, tiles.camera));
    // A light's range is part of its shading (KHR's window): another image.
    Scene ranged = tiles;
    ranged.lights[5].explicitRadius = 0.5 * scene.lights[5].radius();
    EXPECT_FALSE(sameAllLightsImage(first, scene.camera, cpuRun(ranged, Algorithm::Clustered), ranged.camera));
    RunOutput fresh = second;
    shadeAndCompare(*cpu, fresh, proj, true);
    shadeAndCompare(*cpu, second, proj, true, nullptr, 0, {}, &first);
    EXPECT_TRUE(second.allLightsReused);
    EXPECT_EQ(second.shadedAll, fresh.shadedAll);
    EXPECT_EQ(second.shadedCulled, fresh.shadedCulled);
    EXPECT_NE(second.shadedCulled, first.shadedCulled) << "the lists changed: the culled image must follow";
    EXPECT_EQ(second.truth.metrics.imageRmse, fresh.truth.metrics.imageRmse);
    EXPECT_EQ(second.truth.metrics.imageMaxError, fresh.truth.metrics.imageMaxError);

    // What the all-lights image depends on.
    auto differs = [&](const char* what, const std::function<void(Scene&)>& edit) {
        Scene s = scene;
        edit(s);
        const RunOutput run = cpuRun(s, Algorithm::TwoPointFiveD);
        EXPECT_FALSE(sameAllLightsImage(first, scene.camera, run, s.camera)) << what;
    };
    differs("a moved light", [](Scene& s) { s.lights[2].position.x += 0.01; });
    differs("a recoloured light", [](Scene& s) { s.lights[2].color.g *= 0.5; });
    differs("a turned spot", [](Scene& s) { s.lights[3].direction = glm::dvec3(0.1, -1, 0); });
    differs("a wider spot", [](Scene& s) { s.lights[3].outerAngleDeg = 45.0; });
    differs("another camera", [](Scene& s) { s.camera.fovYDeg += 1; });
    RunOutput edited = first;
    edited.depth.depth[edited.depth.depth.size() / 2] *= 0.999f;
    EXPECT_FALSE(sameAllLightsImage(first, scene.camera, edited, scene.camera)) << "a depth pixel";
}


// A chain of light edits, each run's all-lights image updated from the one
// before (the changed lights' old terms out, new terms in) rather than shaded
// from every light: moves, a recolour, a turned spot, a light added and one
// removed (the list shifts: matched by value, only the removed light's term
// goes). Each image stays within 2^-14 of a freshly shaded one, untouched
// pixels bitwise, and the counts of terms say what changed.
TEST(Shade, EditedLightsUpdateTheAllLightsImageCloseToAFreshOne) {
    Scene scene = atriumWithSpot();
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    RunOutput prev = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, prev, proj, true);
    ASSERT_FALSE(prev.allLightsUpdate);
    EXPECT_TRUE(prev.shadedAllCarried.empty()) << "shaded from every light: nothing carried";

    struct Edit {
        const char* what;
        std::function<void(Scene&)> apply;
        std::size_t removed, added;
    };
    std::vector<Edit> edits;
    for (int step = 0; step < 24; ++step)
        edits.push_back({"a drag step", [step](Scene& s) { s.lights[5].position.x += step % 2 ? 0.07 : -0.05; }, 1,
                         1});
    edits.push_back({"a recoloured light", [](Scene& s) { s.lights[2].color.g *= 0.5; }, 1, 1});
    edits.push_back({"a turned spot", [](Scene& s) { s.lights[3].direction = glm::dvec3(0.1, -1, 0); }, 1, 1});
    edits.push_back({"an added light", [](Scene& s) {
                         s.lights.push_back(s.lights[7]);
                         s.lights.back().position.y += 0.3;
                     },
                     0, 1});
    edits.push_back({"a removed light", [](Scene& s) { s.lights.erase(s.lights.begin() + 1); }, 1, 0});
    edits.push_back({"two lights moved at once", [](Scene& s) {
                         s.lights[0].position.z += 0.2;
                         s.lights[9].position.x -= 0.2;
                     },
                     2, 2});
    // The chain starts from a kept image (another algorithm, same lights).
    RunOutput kept = cpuRun(scene, Algorithm::Clustered);
    shadeAndCompare(*cpu, kept, proj, true, nullptr, 0, {}, &prev);
    ASSERT_TRUE(kept.allLightsReused);
    prev = std::move(kept);
    double worst = 0;
    std::size_t stepNo = 0;
    for (const Edit& e : edits) {
        e.apply(scene);
        // Every few steps from the image of `all` (its culled image is the all-lights one).
        const Algorithm algo = ++stepNo % 7 == 0 ? Algorithm::All : Algorithm::TwoPointFiveD;
        RunOutput run = cpuRun(scene, algo);
        RunOutput fresh = run, sliced = run;
        shadeAndCompare(*cpu, fresh, proj, true);
        shadeAndCompare(*cpu, run, proj, true, nullptr, 0, {}, &prev);
        if (algo == Algorithm::All) {
            EXPECT_FALSE(run.allLightsUpdate) << e.what << ": nothing to update";
            EXPECT_EQ(run.shadedAll, fresh.shadedAll) << e.what;
            prev = std::move(run);
            continue;
        }
        ASSERT_TRUE(run.allLightsUpdate) << e.what;
        EXPECT_FALSE(run.allLightsReused) << e.what;
        EXPECT_EQ(run.allLightsUpdate->removed, e.removed) << e.what;
        EXPECT_EQ(run.allLightsUpdate->added, e.added) << e.what;
        worst = std::max(worst, expectCloseToFresh(run, fresh, e.what));
        // The studio's way, in row slices with progress: the same image.
        std::vector<double> progress;
        shadeAndCompare(*cpu, sliced, proj, true, nullptr, 1e-6, [&](double f) { progress.push_back(f); }, &prev);
        EXPECT_EQ(sliced.shadedAll, run.shadedAll) << e.what;
        EXPECT_EQ(sliced.shadedAllCarried, run.shadedAllCarried) << e.what;
        ASSERT_GT(progress.size(), 2u) << e.what;
        EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end())) << e.what;
        EXPECT_GE(progress.front(), 0.0) << e.what;
        EXPECT_NEAR(progress.back(), 1.0, 1e-9) << e.what;
        prev = std::move(run);
    }
    EXPECT_GT(worst, 0.0) << "some pixel carried rounding: the updates did run";

    // Two lights swapped in the list and one moved: the unchanged lights
    // would be summed in another order; shaded from every light.
    std::swap(scene.lights[0], scene.lights[1]);
    scene.lights[6].position.x += 0.1;
    RunOutput swapped = cpuRun(scene, Algorithm::TwoPointFiveD);
    RunOutput swappedFresh = swapped;
    shadeAndCompare(*cpu, swappedFresh, proj, true);
    shadeAndCompare(*cpu, swapped, proj, true, nullptr, 0, {}, &prev);
    EXPECT_FALSE(swapped.allLightsUpdate);
    EXPECT_EQ(swapped.shadedAll, swappedFresh.shadedAll);

    // More lights changed than half the terms: shaded from every light.
    for (Light& l : scene.lights) l.position.y += 0.01;
    RunOutput moved = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, moved, proj, true, nullptr, 0, {}, &swapped);
    EXPECT_FALSE(moved.allLightsUpdate);
    EXPECT_TRUE(moved.shadedAllCarried.empty());
}

// A spot that outshines the rest in its cone, dimmed: subtracting its term
// leaves the other lights' small sum beside the rounding of a large one.
// Those pixels carry far more than kCarryLimit times their value and are
// shaded again from every light, so they equal a fresh image bitwise;
// without that they would be off by about the bright term's rounding, far
// beyond 2^-14. A point light as bright, which reaches most pixels, leaves
// most to shade again: then every light is shaded, as costly and exact.
TEST(Shade, PixelsWhereAnUpdateCancelsTooMuchAreShadedAgain) {
    Scene scene = smallScene("atrium", 96, 54, 16, 24);
    lc::testutil::makeOutshiningSpot(scene.lights[4], scene.camera);
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    RunOutput bright = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, bright, proj, true);

    scene.lights[4].intensity *= 1e-6;
    RunOutput dimmed = cpuRun(scene, Algorithm::TwoPointFiveD);
    RunOutput fresh = dimmed;
    shadeAndCompare(*cpu, fresh, proj, true);
    shadeAndCompare(*cpu, dimmed, proj, true, nullptr, 0, {}, &bright);
    ASSERT_TRUE(dimmed.allLightsUpdate);
    EXPECT_GT(dimmed.allLightsUpdate->pixelsShadedAgain, 50u);
    std::size_t lit = 0;
    for (std::uint32_t l : makeShadeInputs(dimmed.depth, proj, nullptr).list) lit += l != ShadeInputs::kNoList;
    EXPECT_LT(2 * dimmed.allLightsUpdate->pixelsShadedAgain, lit) << "only where the dimmed spot reached";
    expectCloseToFresh(dimmed, fresh, "the dimmed spot");
    std::size_t again = 0;
    for (std::size_t i = 0; i < dimmed.shadedAll.size() / 3; ++i)
        again += dimmed.shadedAllCarried[3 * i] == 0 && dimmed.shadedAllCarried[3 * i + 1] == 0 &&
                 dimmed.shadedAllCarried[3 * i + 2] == 0 && dimmed.shadedAll[3 * i] != bright.shadedAll[3 * i];
    EXPECT_EQ(again, dimmed.allLightsUpdate->pixelsShadedAgain) << "shaded again: nothing carried";

    scene.lights[7].intensity *= 1e6;
    RunOutput point = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, point, proj, true, nullptr, 0, {}, &dimmed);
    scene.lights[7].intensity *= 1e-6;
    RunOutput back = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, back, proj, true, nullptr, 0, {}, &point);
    EXPECT_FALSE(back.allLightsUpdate) << "most pixels to shade again: every light shaded";
    EXPECT_TRUE(back.shadedAllCarried.empty());
    EXPECT_EQ(back.shadedAll, fresh.shadedAll);
}

// With many lights the fresh image's own rounding, about sqrt(n) ulps of the
// sum, stays when a light that outshone the rest at some pixels moves away.
// The carried magnitudes of a value shaded from every light start from
// sqrt(n) times it, so the pixels that lose most of their value are shaded
// again, and each image stays within 2^-14 of a fresh one.
TEST(Shade, AnUpdateWithManyLightsCountsTheFreshImagesRounding) {
    Scene scene = smallScene("atrium", 96, 54, 16, 1024);
    scene.lights[10].intensity *= 100;
    auto cpu = makeCpuBackend();
    const Projection proj(scene.camera);
    RunOutput prev = cpuRun(scene, Algorithm::TwoPointFiveD);
    shadeAndCompare(*cpu, prev, proj, true);
    for (int step = 0; step < 3; ++step) {
        scene.lights[10].position.x += step % 2 ? -1.5 : 2.0;
        RunOutput run = cpuRun(scene, Algorithm::TwoPointFiveD);
        RunOutput fresh = run;
        shadeAndCompare(*cpu, fresh, proj, true);
        shadeAndCompare(*cpu, run, proj, true, nullptr, 0, {}, &prev);
        ASSERT_TRUE(run.allLightsUpdate);
        if (step == 0) {
            // Every value updated from the fresh image carries its sum's rounding.
            std::size_t short_ = 0, touched = 0;
            for (std::size_t k = 0; k < run.shadedAllCarried.size(); ++k) {
                if (run.shadedAllCarried[k] == 0) continue;
                ++touched;
                short_ += !(run.shadedAllCarried[k] >= 32.0f * std::fabs(prev.shadedAll[k]));
            }
            EXPECT_GT(touched, 1000u);
            EXPECT_EQ(short_, 0u) << "carried without the fresh sum's sqrt(1024) ulps";
        }
        expectCloseToFresh(run, fresh, "the bright light moved, step " + std::to_string(step));
        prev = std::move(run);
    }
}

namespace {

// The atrium with every light given a range (as a glTF `range` or a scene
// JSON `radius` gives one): 0.6 of its inverse-square radius, so that the
// cut-off would leave a visible error if the shading ignored the range.
Scene atriumWithRanges(std::uint32_t lights) {
    Scene s = smallScene("atrium", 128, 72, 16, lights);
    for (PointLight& l : s.lights) l.explicitRadius = 0.6 * l.radius();
    s.lights[2].kind = LightKind::Spot;
    s.lights[2].outerAngleDeg = 50.0;
    return s;
}

} // namespace

// A light with a range shades with KHR_lights_punctual's window, which reaches
// 0 at the range: per pixel the brute-force double sum with the window, and
// exactly 0 from a light beyond its range.
TEST(Shade, LightsWithARangeShadeWithTheKhrWindow) {
    Scene scene = atriumWithRanges(32);
    for (std::size_t i = 1; i < scene.lights.size(); i += 2) scene.lights[i].explicitRadius = 0.0; // half without
    const Projection proj(scene.camera);
    const RunOutput run = cpuRun(scene, Algorithm::All);
    ASSERT_EQ(run.lights.shadingRanges.size(), scene.lights.size());
    const ShadeInputs in = makeShadeInputs(run.depth, proj, nullptr);
    std::size_t beyond = 0, windowed = 0;
    for (std::size_t li = 0; li < scene.lights.size(); ++li) {
        // One light at a time: its own image.
        CullResult one = run.result;
        one.lightIndices = {std::uint32_t(li)};
        one.listOffset = {0};
        one.listCount = {1};
        const std::vector<float> rgb = shadeCpu(in, run.lights, &one);
        const double range = scene.lights[li].explicitRadius;
        EXPECT_EQ(run.lights.shadingRange(li), range);
        for (std::size_t i = 0; i < in.list.size(); ++i) {
            if (in.list[i] == ShadeInputs::kNoList) continue;
            const glm::dvec3 p(in.position[3 * i], in.position[3 * i + 1], in.position[3 * i + 2]);
            const glm::dvec3 n(in.normal[3 * i], in.normal[3 * i + 1], in.normal[3 * i + 2]);
            const glm::dvec3 to = run.lights.centers[li] - p;
            const double d2 = glm::dot(to, to);
            double f = std::max(glm::dot(n, to) / std::sqrt(std::max(d2, 1e-30)), 0.0) / std::max(d2, 1e-4);
            if (run.lights.isSpot(li) && glm::dot(-to, run.lights.spotAxes[li]) < std::sqrt(d2) * std::cos(run.lights.spotAngles[li]))
                f = 0;
            if (range > 0) {
                const double t = d2 / (range * range);
                f *= std::pow(std::max(1.0 - t * t, 0.0), 2.0);
                if (d2 > range * range * (1 + 1e-5)) {
                    ++beyond;
                    for (int c = 0; c < 3; ++c) ASSERT_EQ(rgb[3 * i + c], 0.0f) << "light " << li << " beyond its range";
                } else if (f > 0) {
                    ++windowed;
                }
            }
            for (int c = 0; c < 3; ++c)
                ASSERT_NEAR(rgb[3 * i + c], run.lights.power[li][c] * f, 1e-4 * run.lights.power[li][c] * f + 1e-9)
                    << "light " << li << " pixel " << i;
        }
    }
    EXPECT_GT(beyond, 1000u);
    EXPECT_GT(windowed, 50u);
}

// The image error of a culling without false negatives is only what a radius
// cut-off really loses: none for lights whose radius is their own range (the
// default run on a glTF Sponza reported RMSE 25 and fptl scored worse than
// naive). Lights with inverse-square radii keep the cut-off's error.
TEST(Shade, ImageErrorIsZeroForLightsWithARangeWhenNothingIsMissed) {
    const Scene ranged = atriumWithRanges(48);
    Scene cutOff = ranged;
    for (PointLight& l : cutOff.lights) l.explicitRadius = 0.0;
    auto cpu = makeCpuBackend();
    for (Algorithm algo : {Algorithm::Naive, Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::Fptl,
                           Algorithm::ZBin}) {
        CullSettings settings;
        settings.algorithm = algo;
        RunOptions opt;
        opt.keepShadedImages = true;
        const RunOutput run = runPipeline(ranged, settings, *cpu, opt);
        ASSERT_EQ(run.truth.metrics.falseNegatives, 0u) << toString(algo);
        ASSERT_TRUE(run.truth.metrics.imageErrorComputed);
        float peak = 0;
        for (float v : run.shadedAll) peak = std::max(peak, v);
        ASSERT_GT(peak, 0.0f) << toString(algo) << ": nothing lit";
        // Float rounding only: a pixel a hair inside a range in float but
        // outside in double (the ground truth's) gets a window of ~1e-14.
        EXPECT_LE(run.truth.metrics.imageMaxError, 1e-5 * peak) << toString(algo);
        EXPECT_LE(run.truth.metrics.imageRmse, 1e-6 * peak) << toString(algo);

        const RunOutput cut = runPipeline(cutOff, settings, *cpu, opt);
        EXPECT_EQ(cut.truth.metrics.falseNegatives, 0u) << toString(algo);
        EXPECT_GT(cut.truth.metrics.imageRmse, 1e-3 * peak) << toString(algo) << ": the cut-off's error vanished";
    }
}

// shadeCpu groups a band's pixels by list before shading. Lists close
// together (a tile row's) are counted into place, lists spread wider than the
// band's pixels are sorted: either way every pixel gets the sum over its own
// list, the same as shading that pixel alone, and pixels without a list stay 0.
TEST(Shade, EachPixelIsShadedWithItsOwnListHoweverTheBandsListsAreSpread) {
    const Scene scene = atriumWithSpot();
    const RunOutput run = cpuRun(scene, Algorithm::Naive);
    const Projection proj(scene.camera);
    const ShadeInputs base = makeShadeInputs(run.depth, proj, nullptr);
    const std::size_t pixels = base.list.size(), lightCount = run.lights.size();
    for (const std::uint32_t spread : {40u, 50000u}) {
        CullResult lists;
        lists.grid = run.result.grid;
        for (std::uint32_t l = 0; l < spread; ++l) {
            std::vector<std::uint32_t> own{l % std::uint32_t(lightCount), (l * 7 + 3) % std::uint32_t(lightCount),
                                           (l * 13 + 5) % std::uint32_t(lightCount)};
            std::sort(own.begin(), own.end());
            own.erase(std::unique(own.begin(), own.end()), own.end());
            lists.listOffset.push_back(std::uint32_t(lists.lightIndices.size()));
            lists.listCount.push_back(std::uint32_t(own.size()));
            lists.lightIndices.insert(lists.lightIndices.end(), own.begin(), own.end());
        }
        ShadeInputs in = base;
        std::size_t shaded = 0;
        for (std::size_t i = 0; i < pixels; ++i)
            if (in.list[i] != ShadeInputs::kNoList && i % 11 != 0) {
                in.list[i] = std::uint32_t((i * 7919) % spread);
                ++shaded;
            } else {
                in.list[i] = ShadeInputs::kNoList;
            }
        ASSERT_GT(shaded, pixels / 4);
        const std::vector<float> rgb = shadeCpu(in, run.lights, &lists);
        std::size_t lit = 0;
        for (std::size_t i = 0; i < pixels; ++i) {
            ShadeInputs one;
            one.width = one.height = 1;
            one.position.assign(in.position.begin() + std::ptrdiff_t(3 * i), in.position.begin() + std::ptrdiff_t(3 * i + 3));
            one.normal.assign(in.normal.begin() + std::ptrdiff_t(3 * i), in.normal.begin() + std::ptrdiff_t(3 * i + 3));
            one.list = {in.list[i]};
            const std::vector<float> alone = shadeCpu(one, run.lights, &lists);
            for (int c = 0; c < 3; ++c) {
                ASSERT_NEAR(rgb[3 * i + c], alone[c], 1e-6 * (std::abs(alone[c]) + 1e-6))
                    << "pixel " << i << " list " << in.list[i] << " of " << spread;
                if (in.list[i] == ShadeInputs::kNoList) ASSERT_EQ(rgb[3 * i + c], 0.0f);
            }
            lit += alone[0] + alone[1] + alone[2] > 0.0f;
        }
        EXPECT_GT(lit, shaded / 4) << "too few lit pixels for the comparison to mean anything";
    }
}
