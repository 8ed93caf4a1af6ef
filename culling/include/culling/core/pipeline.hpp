#pragma once
// One run of the whole pipeline: depth pre-pass, culling pass, ground truth.
// The CLI, the studio's worker and the tests all go through here.

#include "culling/core/backend.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/scene/scene.hpp"
#include "culling/scene/scene_io.hpp"

#include <memory>

namespace lc {

struct CustomCullReport; // culling/custom/custom_cull.hpp

struct RunOutput {
    DepthImage depth;
    CullResult result;
    GroundTruth truth;
    ViewLights lights;
    // The shaded images (RGB, 3 floats per pixel) when RunOptions::keepShadedImages.
    std::vector<float> shadedCulled, shadedAll;
    // True when the depth pre-pass was skipped for RunOptions::reuseDepth
    // (timings.depthMs is then 0).
    bool depthReused = false;
    // True when shadeAndCompare took an earlier run's all-lights image
    // instead of shading it again.
    bool allLightsReused = false;
    // False when RunOptions::groundTruth was off: `truth` is then empty.
    bool truthComputed = false;
    // Set when the lists came from a custom shader or an engine's dump
    // (culling/custom/custom_cull.hpp): what it did beside its lists.
    std::shared_ptr<const CustomCullReport> custom;
};

struct RunOptions {
    bool groundTruth = true;
    // truthOptions.imageError: the backend's shading pass shades the culled
    // and the all-lights image (timings.shadeMs = the culled one) and the
    // image error compares them; off, nothing is shaded.
    GroundTruthOptions truthOptions;
    bool keepShadedImages = false; // keep both images in RunOutput (for export)
    // A depth image of an earlier run with the same meshes and camera (an edit
    // that moved only lights, as Live drags do): the pre-pass is skipped and
    // this image used. Its size must match the camera (checked).
    const DepthImage* reuseDepth = nullptr;
};

// Validates the scene and settings (typed errors), runs every phase on
// `backend`, and fills result.timings (depth, cull, ground truth, shade).
RunOutput runPipeline(const Scene& scene, const CullSettings& settings, CullBackend& backend,
                      const RunOptions& options = {}, const CancelToken* cancel = nullptr);

// The phases of runPipeline after its cull, for lists made elsewhere (custom
// culling): ground truth when options.groundTruth (timed into
// out.result.timings), then, when options.truthOptions.imageError, the
// shading pass on `shadeBackend` and the image error (shadeAndCompare).
// out.result must be valid for out.lights.
void judgeRun(RunOutput& out, const Projection& proj, CullBackend& shadeBackend, const RunOptions& options,
              const CancelToken* cancel = nullptr);

// The shading phase of runPipeline on its own: shades `out.result`'s lists and
// every light on `backend` over out.depth, sets timings.shadeMs (the culled
// image) and the image error in out.truth.metrics; keeps the images in `out`
// when asked. sliceMs > 0 shades each image in row slices of about that wall
// time and checks `cancel` between them (the studio: a newer edit waits one
// slice, not a whole image), with the same pixels as whole images; shadeMs is
// then the sum of the slices'. `progress` gets the fraction of rows shaded
// over both images after each slice. `earlier`: a run shaded before on the
// same backend whose all-lights image this run's equals
// (sameAllLightsImage); its image is taken instead of shading every light
// again, and out.allLightsReused set.
void shadeAndCompare(CullBackend& backend, RunOutput& out, const Projection& proj, bool keepImages,
                     const CancelToken* cancel = nullptr, double sliceMs = 0,
                     const Progress& progress = {}, const RunOutput* earlier = nullptr);

// True when run `b` (camera cb) shades the same all-lights image as run `a`
// (camera ca) has: the same camera (its tile size aside), depth pixels and
// lights' positions, power and cones. Lists, settings, tiles and light radii
// do not enter that image, so a change of algorithm, tile size or a light's
// range keeps it.
bool sameAllLightsImage(const RunOutput& a, const Camera& ca, const RunOutput& b, const Camera& cb);

} // namespace lc
