// One run of the pipeline: validate, depth pre-pass, culling pass, ground truth.
// Times are milliseconds: depth and cull as the backend measured them (its
// timingMethod says how), ground truth as CPU wall time around the call.

#include "culling/pipeline.hpp"

#include "culling/errors.hpp"
#include "culling/shade.hpp"

#include <chrono>

namespace lc {

namespace {

void throwIfCancelled(const CancelToken* cancel) {
    if (cancel && cancel->cancelled.load()) throw Cancelled();
}

// CullSettings::validate names the field first ("cells: must be in 1..32");
// the field becomes the SettingsError's field.
[[noreturn]] void throwSettings(const std::string& message) {
    const auto colon = message.find(": ");
    if (colon != std::string::npos && colon > 0 && message.find(' ') > colon)
        throw SettingsError(message.substr(0, colon), message.substr(colon + 2));
    throw SettingsError("settings", message);
}

} // namespace

void shadeAndCompare(CullBackend& backend, RunOutput& out, const Projection& proj, bool keepImages,
                     const CancelToken* cancel) {
    const ShadeInputs culledIn = makeShadeInputs(out.depth, proj, &out.result);
    std::vector<float> culled = backend.shade(culledIn, out.lights, &out.result);
    out.result.timings.shadeMs = backend.lastShadeMs();
    throwIfCancelled(cancel);
    // `all` with one list of every light in order shades exactly the reference.
    const CullResult& r = out.result;
    bool identity = r.listCount.size() == 1 && r.listCount[0] == out.lights.size();
    for (std::size_t i = 0; identity && i < out.lights.size(); ++i)
        identity = r.lightIndices[r.listOffset[0] + i] == i;
    std::vector<float> all;
    if (identity) {
        all = culled;
    } else {
        ShadeInputs allIn = culledIn;
        for (std::uint32_t& l : allIn.list)
            if (l != ShadeInputs::kNoList) l = 0;
        all = backend.shade(allIn, out.lights, nullptr);
        throwIfCancelled(cancel);
    }
    const ImageError e = compareShadedImages(out.depth, culled, all);
    Metrics& m = out.truth.metrics;
    m.imageRmse = e.rmse;
    m.imageMaxError = e.maxAbs;
    m.imageErrorComputed = true;
    if (keepImages) {
        out.shadedCulled = std::move(culled);
        out.shadedAll = std::move(all);
    }
}

RunOutput runPipeline(const Scene& scene, const CullSettings& settings, CullBackend& backend,
                      const RunOptions& options, const CancelToken* cancel) {
    using Clock = std::chrono::steady_clock;
    scene.validate();
    if (const std::string bad = settings.validate(); !bad.empty()) throwSettings(bad);

    const Projection proj(scene.camera);
    const TileGrid grid = TileGrid::make(scene.camera.width, scene.camera.height, scene.camera.tileSize);

    RunOutput out;
    out.lights = makeViewLights(scene);
    throwIfCancelled(cancel);

    const auto t0 = Clock::now();
    if (options.reuseDepth) {
        out.depth = *options.reuseDepth;
        out.depthReused = true;
    } else {
        out.depth = backend.renderDepth(scene, proj);
    }
    const double depthWallMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (out.depth.width != grid.width || out.depth.height != grid.height ||
        out.depth.depth.size() != std::size_t(grid.width) * grid.height) {
        const std::string size = std::to_string(out.depth.width) + "x" + std::to_string(out.depth.height);
        const std::string cam = std::to_string(grid.width) + "x" + std::to_string(grid.height);
        if (out.depthReused)
            throw Error("the reused depth image is " + size + " but the camera is " + cam);
        throw Error("backend '" + backend.name() + "' returned a " + size + " depth image for a " + cam +
                    " camera");
    }
    throwIfCancelled(cancel);

    const auto t1 = Clock::now();
    out.result = backend.cull(out.depth, proj, grid, out.lights, settings);
    const double cullWallMs = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    if (const std::string bad = out.result.validate(out.lights.size()); !bad.empty())
        throw Error("backend '" + backend.name() + "' produced an inconsistent result: " + bad);
    // A backend that did not time a phase gets the wall time around the call.
    out.result.timings.depthMs = out.depthReused           ? 0.0
                                 : backend.lastDepthMs() >= 0 ? backend.lastDepthMs()
                                                              : depthWallMs;
    if (out.result.timings.cullMs < 0) out.result.timings.cullMs = cullWallMs;
    if (out.result.backend.empty()) out.result.backend = backend.name();
    if (out.result.device.empty()) out.result.device = backend.deviceName();
    if (out.result.timingMethod.empty()) out.result.timingMethod = backend.timingMethod();
    throwIfCancelled(cancel);

    if (options.groundTruth) {
        GroundTruthOptions truthOptions = options.truthOptions;
        truthOptions.imageError = false; // from the backend's shading pass below
        const auto t2 = Clock::now();
        out.truth = computeGroundTruth(out.depth, proj, out.lights, out.result, truthOptions, cancel);
        out.truthComputed = true;
        out.result.timings.groundTruthMs =
            std::chrono::duration<double, std::milli>(Clock::now() - t2).count();
    }
    if (options.truthOptions.imageError) {
        throwIfCancelled(cancel);
        shadeAndCompare(backend, out, proj, options.keepShadedImages, cancel);
    }
    return out;
}

} // namespace lc
