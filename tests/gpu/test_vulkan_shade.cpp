// The Vulkan shading pass (shaders/shade.comp) against the CPU reference
// (culling/shade.cpp) on the SAME G-buffer and lists: per pixel within float
// rounding of the device's sqrt and division; background pixels exactly 0;
// the image error of the pipeline within rounding of the CPU backend's; bad
// lists are typed errors before anything reaches the device. Validation is on.
#include "gpu_test_env.hpp"

#include "culling/core/errors.hpp"
#include "culling/core/pipeline.hpp"
#include "culling/scene/scene_io.hpp"
#include "culling/truth/shade.hpp"
#include "updated_image.hpp"

#include <algorithm>
#include <cmath>

using namespace lc;
using lc::gputest::GpuTest;

namespace {

Scene smallScene(const std::string& builtin, std::uint32_t w, std::uint32_t h, std::uint32_t lights) {
    Scene s = makeBuiltinScene(builtin);
    s.camera.width = w;
    s.camera.height = h;
    s.camera.tileSize = 16;
    s.lights = generateLights(defaultLightGen(s, lights, 3));
    return s;
}

// Largest per-channel difference relative to the pixel's value (floored so
// that near-zero pixels compare absolutely), and whether backgrounds are 0.
void expectSameImage(const std::vector<float>& gpu, const std::vector<float>& cpu, const ShadeInputs& in,
                     const std::string& what) {
    ASSERT_EQ(gpu.size(), cpu.size()) << what;
    float peak = 0;
    for (float v : cpu) peak = std::max(peak, v);
    ASSERT_GT(peak, 0.0f) << what << ": nothing lit, the comparison would prove nothing";
    std::size_t bad = 0;
    double worst = 0;
    for (std::size_t i = 0; i < in.list.size(); ++i)
        for (int c = 0; c < 3; ++c) {
            const float g = gpu[3 * i + c], r = cpu[3 * i + c];
            if (in.list[i] == ShadeInputs::kNoList) {
                bad += g != 0.0f;
                continue;
            }
            // Float sums of up to a few hundred terms with 1-3 ulp sqrt/div
            // differences per term: 1e-4 relative, 1e-6 of the image peak.
            const double err = std::abs(double(g) - double(r)) / (std::abs(double(r)) + 1e-2 * peak);
            worst = std::max(worst, err);
            bad += !(err <= 1e-4);
        }
    EXPECT_EQ(bad, 0u) << what << ": worst relative difference " << worst;
}

} // namespace

class VulkanShade : public GpuTest {};

TEST_F(VulkanShade, MatchesTheCpuReferenceForEveryAlgorithmAndAllLights) {
    CullBackend& gpu = gputest::vulkan();
    auto cpu = makeCpuBackend();
    // The atrium: its 40 lights reach geometry (on the mountain at this size
    // none does, and fptl's lists would be empty).
    Scene scene = smallScene("atrium", 120, 68, 40);
    // Every third light has a range (KHR's window in both passes).
    for (std::size_t i = 0; i < scene.lights.size(); i += 3)
        scene.lights[i].explicitRadius = 0.6 * scene.lights[i].radius();
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(120, 68, 16);
    const ViewLights lights = makeViewLights(scene);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    {
        const ShadeInputs in = makeShadeInputs(depth, proj, nullptr);
        expectSameImage(gpu.shade(in, lights, nullptr), shadeCpu(in, lights, nullptr), in, "all lights");
        EXPECT_GE(gpu.lastShadeMs(), 0.0);
    }
    for (Algorithm algo : {Algorithm::All, Algorithm::Naive, Algorithm::MinMax, Algorithm::HalfZ,
                           Algorithm::TwoPointFiveD, Algorithm::Clustered, Algorithm::Fptl, Algorithm::ZBin}) {
        CullSettings settings;
        settings.algorithm = algo;
        settings.cells = 8;
        // Lists from the GPU cull (what the pipeline shades), inputs shared.
        const CullResult result = gpu.cull(depth, proj, grid, lights, settings);
        const ShadeInputs in = makeShadeInputs(depth, proj, &result);
        expectSameImage(gpu.shade(in, lights, &result), shadeCpu(in, lights, &result), in, toString(algo));
    }
}

TEST_F(VulkanShade, LightsBeyondOneUniformBlockShadeInChunksAsOneLoop) {
    // A uniform block holds at most 65,536 / 48 = 1,365 lights, so 3,000
    // lights take at least three chunks of the all-lights image, each adding
    // to the sums the last one left; a list image with as many lights goes
    // in the same chunks when its lists ascend (each chunk's lights one run
    // of the list, found by bisection), else reads the storage
    // buffer. All must equal the CPU reference's single loop over the same
    // lights in the same order. An odd width: the
    // last pixel group of each row is short.
    CullBackend& gpu = gputest::vulkan();
    const Scene scene = smallScene("atrium", 65, 37, 3000);
    const Projection proj(scene.camera);
    const ViewLights lights = makeViewLights(scene);
    ASSERT_EQ(lights.size(), 3000u);
    const DepthImage depth = makeCpuBackend()->renderDepth(scene, proj);
    const ShadeInputs allIn = makeShadeInputs(depth, proj, nullptr);
    expectSameImage(gpu.shade(allIn, lights, nullptr), shadeCpu(allIn, lights, nullptr), allIn, "all lights");
    CullSettings settings;
    settings.algorithm = Algorithm::Naive;
    const CullResult result = gpu.cull(depth, proj, TileGrid::make(65, 37, 16), lights, settings);
    ASSERT_GT(result.lightIndices.size(), 2000u);
    const ShadeInputs in = makeShadeInputs(depth, proj, &result);
    expectSameImage(gpu.shade(in, lights, &result), shadeCpu(in, lights, &result), in, "naive lists");
    // 6-pixel tiles: groups of four pixels across two tiles walk each
    // pixel's list on its own, chunk by chunk too.
    const CullResult small = gpu.cull(depth, proj, TileGrid::make(65, 37, 6), lights, settings);
    const ShadeInputs sin = makeShadeInputs(depth, proj, &small);
    expectSameImage(gpu.shade(sin, lights, &small), shadeCpu(sin, lights, &small), sin, "naive lists, 6 px tiles");
    // Lists not in ascending order (a custom shader's may be any): one pass
    // over the storage buffer, in the lists' own order.
    CullResult reversed = result;
    for (std::size_t l = 0; l < reversed.listCount.size(); ++l) {
        const auto b = reversed.lightIndices.begin() + reversed.listOffset[l];
        std::reverse(b, b + reversed.listCount[l]);
    }
    const ShadeInputs rin = makeShadeInputs(depth, proj, &reversed);
    expectSameImage(gpu.shade(rin, lights, &reversed), shadeCpu(rin, lights, &reversed), rin, "descending lists");
}

TEST_F(VulkanShade, FourPixelGroupsShadeEachPixelWithItsOwnListAtEveryWidth) {
    // shade.comp shades four pixels of a row an invocation: one loop for the
    // four where they share a list, a loop each where they do not. Widths of
    // every remainder mod 4 (the last group of a row is short) and 6-pixel
    // tiles, so that groups straddle two tiles' lists; the all-lights image
    // too. Each pixel must get its own list's lights, in its order.
    CullBackend& gpu = gputest::vulkan();
    for (std::uint32_t w : {60u, 61u, 62u, 63u}) {
        Scene scene = smallScene("atrium", w, 30, 40);
        scene.camera.tileSize = 6;
        const Projection proj(scene.camera);
        const ViewLights lights = makeViewLights(scene);
        const DepthImage depth = makeCpuBackend()->renderDepth(scene, proj);
        const std::string at = "width " + std::to_string(w);
        const ShadeInputs allIn = makeShadeInputs(depth, proj, nullptr);
        expectSameImage(gpu.shade(allIn, lights, nullptr), shadeCpu(allIn, lights, nullptr), allIn,
                        at + ", all lights");
        for (Algorithm algo : {Algorithm::Naive, Algorithm::TwoPointFiveD, Algorithm::Clustered}) {
            CullSettings settings;
            settings.algorithm = algo;
            settings.cells = 8;
            const CullResult result = gpu.cull(depth, proj, TileGrid::make(w, 30, 6), lights, settings);
            const ShadeInputs in = makeShadeInputs(depth, proj, &result);
            expectSameImage(gpu.shade(in, lights, &result), shadeCpu(in, lights, &result), in,
                            at + ", " + toString(algo));
        }
    }
}

TEST_F(VulkanShade, PipelineImageErrorAgreesWithTheCpuBackendOnTheSameDepth) {
    CullBackend& gpu = gputest::vulkan();
    const Scene scene = smallScene("forest", 96, 54, 48);
    CullSettings settings;
    settings.algorithm = Algorithm::HalfZ;
    RunOptions opt;
    opt.keepShadedImages = true;
    const RunOutput run = runPipeline(scene, settings, gpu, opt);
    ASSERT_TRUE(run.truth.metrics.imageErrorComputed);
    EXPECT_GE(run.result.timings.shadeMs, 0.0);
    const Projection proj(scene.camera);
    // The CPU reference on the GPU run's own depth and lists.
    const std::vector<float> all = shadeLambertCpu(run.depth, proj, run.lights, nullptr);
    const std::vector<float> cul = shadeLambertCpu(run.depth, proj, run.lights, &run.result);
    const ImageError ref = compareShadedImages(run.depth, cul, all);
    EXPECT_GT(ref.rmse, 0.0);
    EXPECT_NEAR(run.truth.metrics.imageRmse, ref.rmse, 1e-3 * ref.rmse);
    EXPECT_NEAR(run.truth.metrics.imageMaxError, ref.maxAbs, 1e-3 * ref.maxAbs);
}

// The studio's update of the all-lights image on the device: a dragged
// light's and a turned spot's old and new terms shaded alone by the Vulkan
// pass, and the pixels where dimming a spot that outshone the rest
// cancelled too much shaded again by the same pass, each image within
// 2^-14 of the device's fresh one (bitwise where nothing was carried).
TEST_F(VulkanShade, EditedLightsUpdateTheAllLightsImageCloseToAFreshOne) {
    CullBackend& gpu = gputest::vulkan();
    Scene scene = smallScene("atrium", 96, 54, 24);
    lc::testutil::makeOutshiningSpot(scene.lights[4], scene.camera);
    scene.lights[9].kind = LightKind::Spot; // a cone among the moved lights
    scene.lights[9].outerAngleDeg = 50.0;
    const Projection proj(scene.camera);
    CullSettings settings;
    settings.algorithm = Algorithm::TwoPointFiveD;
    RunOptions opt;
    opt.truthOptions.imageError = false;
    RunOutput prev = runPipeline(scene, settings, gpu, opt);
    shadeAndCompare(gpu, prev, proj, true);
    auto step = [&](const char* what) {
        opt.reuseDepth = &prev.depth; // the lights moved, not the meshes
        RunOutput run = runPipeline(scene, settings, gpu, opt);
        RunOutput fresh = run;
        shadeAndCompare(gpu, fresh, proj, true);
        shadeAndCompare(gpu, run, proj, true, nullptr, 0, {}, &prev);
        EXPECT_TRUE(run.allLightsUpdate) << what;
        lc::testutil::expectCloseToFresh(run, fresh, what);
        prev = std::move(run);
    };
    scene.lights[6].position.x += 0.2;
    step("a moved light");
    EXPECT_EQ(prev.allLightsUpdate->pixelsShadedAgain, 0u);
    scene.lights[9].position.z -= 0.2;
    scene.lights[9].direction = glm::dvec3(0.2, -1, 0.1);
    step("a moved and turned spot");
    EXPECT_EQ(prev.allLightsUpdate->pixelsShadedAgain, 0u);
    scene.lights[4].intensity *= 1e-6;
    step("a dimmed light that outshone the rest");
    EXPECT_GT(prev.allLightsUpdate->pixelsShadedAgain, 100u);
}

TEST_F(VulkanShade, BadListsAreTypedErrorsAndZeroLightsShadeBlack) {
    CullBackend& gpu = gputest::vulkan();
    auto cpu = makeCpuBackend();
    const Scene scene = smallScene("wall", 32, 32, 8);
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(32, 32, 16);
    const ViewLights lights = makeViewLights(scene);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    CullSettings settings;
    settings.algorithm = Algorithm::MinMax;
    const CullResult result = cpu->cull(depth, proj, grid, lights, settings);
    const ShadeInputs in = makeShadeInputs(depth, proj, &result);
    CullResult bad = result;
    ASSERT_FALSE(bad.lightIndices.empty());
    bad.lightIndices.back() = 1000;
    EXPECT_THROW(gpu.shade(in, lights, &bad), Error);
    ShadeInputs badIn = in;
    badIn.list[5] = 77;
    EXPECT_THROW(gpu.shade(badIn, lights, &result), Error);

    const ViewLights none;
    const ShadeInputs allIn = makeShadeInputs(depth, proj, nullptr);
    for (float v : gpu.shade(allIn, none, nullptr)) ASSERT_EQ(v, 0.0f);
}

// An image whose G-buffer is past one storage buffer's range (lavapipe:
// 128 MiB, 2048x2048 pixels of 32 bytes) is shaded in bands of rows: the same
// image as the CPU reference, every band's pixels with their own lists. Found
// by the 3840x2160 hard case, which failed on "G-buffer exceeds this device's
// storage buffer range".
TEST_F(VulkanShade, AnImagePastOneStorageBufferIsShadedInBands) {
    CullBackend& gpu = gputest::vulkan();
    auto cpu = makeCpuBackend();
    Scene scene = smallScene("atrium", 4096, 1100, 24);
    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(4096, 1100, 16);
    const ViewLights lights = makeViewLights(scene);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    CullSettings settings;
    settings.algorithm = Algorithm::MinMax;
    const CullResult result = cpu->cull(depth, proj, grid, lights, settings);
    const ShadeInputs in = makeShadeInputs(depth, proj, &result);
    ASSERT_GT(std::size_t(4096) * 1100 * 32, std::size_t(1) << 27); // past lavapipe's range: bands
    expectSameImage(gpu.shade(in, lights, &result), shadeCpu(in, lights, &result), in, "banded");
    EXPECT_GT(gpu.lastShadeMs(), 0.0);
}

// The pass keeps the last G-buffer it uploaded and skips the upload when it
// is handed the same one again (a sweep shades one G-buffer with many lists).
// Whatever it keeps, each image must be the one of the G-buffer it was
// handed: the same G-buffer with other lists, another frame of the same size
// (a key of sizes alone would reuse the old pixels), a copy whose pixels were
// changed (a key of the maker's id alone would), and the first again.
TEST_F(VulkanShade, AGBufferShadedAgainIsTheOneHandedEachTime) {
    CullBackend& gpu = gputest::vulkan();
    auto cpu = makeCpuBackend();
    Scene scene = smallScene("atrium", 120, 68, 40);
    const ViewLights lights = makeViewLights(scene);
    const TileGrid grid = TileGrid::make(120, 68, 16);
    const Projection proj(scene.camera);
    const DepthImage depth = cpu->renderDepth(scene, proj);
    CullSettings naive, clustered;
    naive.algorithm = Algorithm::Naive;
    clustered.algorithm = Algorithm::Clustered;
    clustered.cells = 8;
    const CullResult a1 = cpu->cull(depth, proj, grid, lights, naive);
    const CullResult a2 = cpu->cull(depth, proj, grid, lights, clustered);
    ShadeInputs a = makeShadeInputs(depth, proj, &a1);
    expectSameImage(gpu.shade(a, lights, &a1), shadeCpu(a, lights, &a1), a, "first G-buffer");
    setShadeLists(a, depth, proj, &a2);
    expectSameImage(gpu.shade(a, lights, &a2), shadeCpu(a, lights, &a2), a, "the same G-buffer, other lists");

    Scene turned = scene;
    turned.camera.position = scene.camera.position + 0.35 * (scene.camera.target - scene.camera.position);
    const Projection proj2(turned.camera);
    const DepthImage depth2 = cpu->renderDepth(turned, proj2);
    const ViewLights lights2 = makeViewLights(turned);
    const CullResult b1 = cpu->cull(depth2, proj2, grid, lights2, naive);
    const ShadeInputs b = makeShadeInputs(depth2, proj2, &b1);
    ASSERT_NE(b.position, a.position);
    expectSameImage(gpu.shade(b, lights2, &b1), shadeCpu(b, lights2, &b1), b, "another frame of the same size");

    ShadeInputs moved = b; // the maker's id comes along with the copy
    for (std::size_t i = 0; i < moved.position.size(); i += 3) moved.position[i + 1] += 0.25f;
    expectSameImage(gpu.shade(moved, lights2, &b1), shadeCpu(moved, lights2, &b1), moved, "a changed copy");
    expectSameImage(gpu.shade(a, lights, &a2), shadeCpu(a, lights, &a2), a, "the first G-buffer again");
}
