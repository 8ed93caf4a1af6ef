#pragma once
// Exact ground truth and the error metrics of docs/ARCHITECTURE.md:
// per pixel with geometry, the lights whose sphere contains the pixel's
// view-space position (double precision, from the depth at the pixel centre),
// compared with the list the shading pass would loop over there.

#include "culling/core/backend.hpp"
#include "culling/truth/shade.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace lc {

struct Metrics {
    std::uint64_t falseNegatives = 0; // sum_p |needed(p) \ listed(p)|
    // The false negatives by cause (the rest are the culling test's own): a
    // light the engine limits dropped from p's list (a cap or a full record
    // buffer: "list full"), and a light past the per-view light limit.
    std::uint64_t falseNegativesListFull = 0, falseNegativesLightLimit = 0;
    std::uint64_t falseNegativesCullingTest() const {
        return falseNegatives - falseNegativesListFull - falseNegativesLightLimit;
    }
    std::uint64_t shadingWork = 0;    // W = sum_p |listed(p)|
    std::uint64_t exactWork = 0;      // E = sum_p |needed(p)|
    double efficiency = 1.0;          // E / W (1 when W == 0)
    double meanList = 0;              // mean entries per list
    std::uint32_t maxList = 0;
    std::uint64_t resultBytes = 0;
    std::uint64_t geometryPixels = 0;
    // The best any culling of this result's granularity could do: with U(p)
    // the union of needed(q) over the pixels q sharing p's list (its tile,
    // cell or froxel), optimal_work = sum_p |U(p)| (DESIGN.md).
    std::uint64_t optimalWork = 0;
    double efficiencyVsOptimal = 1.0; // optimalWork / W (1 when W == 0)
    double imageRmse = 0, imageMaxError = 0; // Lambert, culled vs all lights
    bool imageErrorComputed = false;
};

struct GroundTruth {
    Metrics metrics;
    // Per list (CullResult numbering): sums over the pixels that use it.
    std::vector<std::uint64_t> listShadingWork, listExactWork, listFalseNegatives;
    // Per list, the part of listFalseNegatives from the engine limits
    // (Metrics::falseNegativesListFull, falseNegativesLightLimit).
    std::vector<std::uint64_t> listFalseNegativesListFull, listFalseNegativesLightLimit;
    // Per tile: pixels with geometry.
    std::vector<std::uint32_t> tileGeometryPixels;
};

// What the ground truth of one frame (depth image, camera, lights) needs,
// whatever was culled: per pixel its view depth and the lights whose volume
// contains its position. Built once, it judges many results of that frame
// (the report's sweep) without finding each pixel's lights again.
struct PixelNeeds {
    std::uint32_t width = 0, height = 0;
    std::size_t lightCount = 0;
    std::vector<double> viewDepth; // per pixel; meaningful where the depth has geometry
    // Pixel i needs lights[offset[i] .. offset[i + 1]) (width x height + 1 offsets).
    std::vector<std::uint32_t> offset, lights;
};

// Null when the frame holds more than `maxEntries` (pixel, light) pairs: the
// caller then judges without (memory stays bounded on a crowded scene).
std::shared_ptr<const PixelNeeds> computePixelNeeds(const DepthImage& depth, const Projection& proj,
                                                    const ViewLights& lights, std::size_t maxEntries,
                                                    const CancelToken* cancel = nullptr);

struct GroundTruthOptions {
    // Lambert image error on the CPU (costs pixels x lights). runPipeline turns
    // this off and takes the error from the backend's shading pass instead.
    bool imageError = true;
    // computePixelNeeds of this depth image, camera and lights (or null:
    // worked out here). Another frame's is an Error.
    const PixelNeeds* needs = nullptr;
    // Lists (ascending) that overflowed a custom shader's layout capacity:
    // their misses are the list being full, not the culling test (as
    // locateFalseNegatives labels them). Null or empty: none.
    const std::vector<std::uint32_t>* fullLists = nullptr;
};

GroundTruth computeGroundTruth(const DepthImage& depth, const Projection& proj,
                               const ViewLights& lights, const CullResult& result,
                               const GroundTruthOptions& opt = {}, const CancelToken* cancel = nullptr);

// For the tile inspector: in tile `tile`, how many geometry pixels need each
// light (light index -> count, only lights needed by at least one pixel).
std::vector<std::pair<std::uint32_t, std::uint32_t>>
pixelsNeedingLights(const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                    const TileGrid& grid, std::uint32_t tile);

// The Lambert shading and image error live in culling/truth/shade.hpp.

} // namespace lc
