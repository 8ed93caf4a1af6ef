// One run of the pipeline: validate, depth pre-pass, culling pass, ground truth.
// Times are milliseconds: depth and cull as the backend measured them (its
// timingMethod says how), ground truth as CPU wall time around the call.

#include "culling/pipeline.hpp"

#include "culling/errors.hpp"

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
    out.depth = backend.renderDepth(scene, proj);
    const double depthWallMs = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    if (out.depth.width != grid.width || out.depth.height != grid.height ||
        out.depth.depth.size() != std::size_t(grid.width) * grid.height)
        throw Error("backend '" + backend.name() + "' returned a " + std::to_string(out.depth.width) +
                    "x" + std::to_string(out.depth.height) + " depth image for a " +
                    std::to_string(grid.width) + "x" + std::to_string(grid.height) + " camera");
    throwIfCancelled(cancel);

    const auto t1 = Clock::now();
    out.result = backend.cull(out.depth, proj, grid, out.lights, settings);
    const double cullWallMs = std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
    if (const std::string bad = out.result.validate(out.lights.size()); !bad.empty())
        throw Error("backend '" + backend.name() + "' produced an inconsistent result: " + bad);
    // A backend that did not time a phase gets the wall time around the call.
    out.result.timings.depthMs = backend.lastDepthMs() >= 0 ? backend.lastDepthMs() : depthWallMs;
    if (out.result.timings.cullMs < 0) out.result.timings.cullMs = cullWallMs;
    if (out.result.backend.empty()) out.result.backend = backend.name();
    if (out.result.device.empty()) out.result.device = backend.deviceName();
    if (out.result.timingMethod.empty()) out.result.timingMethod = backend.timingMethod();
    throwIfCancelled(cancel);

    if (options.groundTruth) {
        const auto t2 = Clock::now();
        out.truth = computeGroundTruth(out.depth, proj, out.lights, out.result, options.truthOptions, cancel);
        out.result.timings.groundTruthMs =
            std::chrono::duration<double, std::milli>(Clock::now() - t2).count();
    }
    return out;
}

} // namespace lc
