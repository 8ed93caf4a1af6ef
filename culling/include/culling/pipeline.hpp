#pragma once
// One run of the whole pipeline: depth pre-pass, culling pass, ground truth.
// The CLI, the studio's worker and the tests all go through here.

#include "culling/backend.hpp"
#include "culling/ground_truth.hpp"
#include "culling/scene.hpp"

namespace lc {

struct RunOutput {
    DepthImage depth;
    CullResult result;
    GroundTruth truth;
    ViewLights lights;
};

struct RunOptions {
    bool groundTruth = true;
    GroundTruthOptions truthOptions;
};

// Validates the scene and settings (typed errors), runs every phase on
// `backend`, and fills result.timings (depth, cull, ground truth).
RunOutput runPipeline(const Scene& scene, const CullSettings& settings, CullBackend& backend,
                      const RunOptions& options = {}, const CancelToken* cancel = nullptr);

} // namespace lc
