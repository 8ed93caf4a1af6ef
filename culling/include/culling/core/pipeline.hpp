#pragma once
// One run of the whole pipeline: depth pre-pass, culling pass, ground truth.
// The CLI, the studio's worker and the tests all go through here.

#include "culling/core/backend.hpp"
#include "culling/truth/ground_truth.hpp"
#include "culling/scene/scene.hpp"
#include "culling/scene/scene_io.hpp"

#include <cstdint>
#include <memory>
#include <optional>

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
    // Where the depth image came from when that is not this run's own
    // pre-pass on its own backend (`check` judges a dump on another backend's
    // pre-pass; a depth file): said in summary.json's depth_source. Empty
    // otherwise.
    std::string depthFrom;
    // Per channel of shadedAll, after shadeAndCompare updated an earlier
    // run's image: the magnitudes the value has carried through updates since
    // its pixel was last shaded from every light, which bound how far it may
    // stand from a freshly shaded value. Empty when every pixel was shaded
    // from every light (or the image is not kept).
    std::vector<float> shadedAllCarried;
    // True when shadeAndCompare took an earlier run's all-lights image
    // instead of shading it again.
    bool allLightsReused = false;
    // Set when shadeAndCompare made the all-lights image from an earlier
    // run's by the lights that changed: their old terms taken out, their new
    // ones added, and the pixels where that cancelled too much shaded again
    // from every light.
    struct AllLightsUpdate {
        std::size_t removed = 0, added = 0; // light terms taken out, put in
        std::uint64_t pixelsShadedAgain = 0;
    };
    std::optional<AllLightsUpdate> allLightsUpdate;
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

// Where a run's light lists come from: a built-in algorithm on a backend
// (BackendLists), a user's culling shader or an engine's list dump
// (culling/custom/custom_cull.hpp); a capture will be one more. The pipeline
// owns the rest of the chain for every source alike: the scene's check, the
// view lights, the depth (a pre-pass or an image it is given), the lists'
// check, ground truth, shading and every timing but the lists' own.
class ListSource {
public:
    virtual ~ListSource() = default;
    // The frame's lists over `depth`: valid for `lights`; timings.cullMs,
    // backend, device and timingMethod set where the source knows them (the
    // pipeline fills the rest: its wall clock, the depth backend's names).
    virtual CullResult makeLists(const Scene& scene, const DepthImage& depth, const Projection& proj,
                                 const TileGrid& grid, const ViewLights& lights) = 0;
    // What the source did beside its lists (a shader's or a dump's report,
    // RunOutput::custom); null for a built-in algorithm.
    virtual std::shared_ptr<const CustomCullReport> report() const { return nullptr; }
};

// A built-in algorithm: `settings` culled on `backend` (CullBackend::cull).
class BackendLists final : public ListSource {
public:
    BackendLists(CullBackend& backend, const CullSettings& settings) : backend_(backend), settings_(settings) {}
    CullResult makeLists(const Scene&, const DepthImage& depth, const Projection& proj, const TileGrid& grid,
                         const ViewLights& lights) override {
        return backend_.cull(depth, proj, grid, lights, settings_);
    }

private:
    CullBackend& backend_;
    CullSettings settings_;
};

// The one pipeline: validates the scene (typed errors), takes the depth from
// options.reuseDepth or a pre-pass on `backend`, the lists from `source`,
// then ground truth and shading as `options` say (shading on `backend`, or
// the CPU reference when it is null; then options.reuseDepth is required).
// Fills result.timings (depth, cull, ground truth, shade), the depth's
// triangles and, when another rasteriser than the lists' drew the depth,
// RunOutput::depthFrom.
RunOutput runPipeline(const Scene& scene, ListSource& source, CullBackend* backend, const RunOptions& options = {},
                      const CancelToken* cancel = nullptr);

// A built-in algorithm through the one pipeline: BackendLists(backend,
// settings) with depth and shading on `backend`. Settings are checked first.
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
// same backend with the same camera (samePixels) and its images kept. Where
// its lights equal this run's in order (sameAllLightsImage), its all-lights
// image is taken as it is (out.allLightsReused). Where the lights that
// changed (moved, recoloured, added or removed: their old and new terms) are
// at most half as many as the lights and the others keep their order, its
// image is updated: the old terms shaded alone and subtracted, the new ones
// added, and every pixel whose carried magnitudes (starting from sqrt(n)
// times a value shaded from n lights: that sum's own rounding) exceed
// kCarryLimit times its value shaded again from every light
// (out.allLightsUpdate, out.shadedAllCarried). Otherwise, or where more than
// half the pixels would be shaded again, the image is shaded from every
// light. `earlier` with other depth pixels is not used.
void shadeAndCompare(CullBackend& backend, RunOutput& out, const Projection& proj, bool keepImages,
                     const CancelToken* cancel = nullptr, double sliceMs = 0,
                     const Progress& progress = {}, const RunOutput* earlier = nullptr);

// True when run `b` (camera cb) shades the same all-lights image as run `a`
// (camera ca) has: the same camera (its tile size aside), depth pixels and
// lights' positions, power and cones. Lists, settings, tiles and light radii
// do not enter that image, so a change of algorithm, tile size or a light's
// range keeps it.
bool sameAllLightsImage(const RunOutput& a, const Camera& ca, const RunOutput& b, const Camera& cb);

// True when runs `a` and `b` shade the same pixels: the same camera (its tile
// size aside) and depth pixels. Their lights may differ.
bool samePixels(const RunOutput& a, const Camera& ca, const RunOutput& b, const Camera& cb);

// An updated all-lights value is shaded again from every light once the
// magnitudes it carried exceed this many times its own (shadeAndCompare).
inline constexpr float kCarryLimit = 256.0f;

} // namespace lc
