#pragma once
// Depth buffers and the CPU reference rasteriser.

#include "culling/core/cancel.hpp"
#include "culling/math/projection.hpp"
#include "culling/scene/scene.hpp"

#include <cstdint>
#include <vector>

namespace lc {

// A D32 depth image, row-major, row 0 at the top. Window depth in [0,1]; a
// pixel equal to clearDepth holds no geometry.
struct DepthImage {
    std::uint32_t width = 0, height = 0;
    float clearDepth = 1.0f;
    std::vector<float> depth;
    // Non-zero when the Vulkan backend that rendered this image still holds
    // it on the device under this id: its cull() then reads that copy and
    // uploads nothing. Code that changes `depth` after a render sets it to 0
    // (the backend also compares a sample of the pixels).
    std::uint64_t deviceCopy = 0;

    float at(std::uint32_t x, std::uint32_t y) const { return depth[std::size_t(y) * width + x]; }
    bool hasGeometry(std::uint32_t x, std::uint32_t y) const { return at(x, y) != clearDepth; }
    std::size_t geometryPixelCount() const;
};

// Rasterises every mesh triangle into a depth image: pixel-centre sampling,
// top-left fill rule, clipping against the near plane (and the far plane where
// finite), depth interpolated linearly in screen space (as hardware does) and
// stored as float, LESS (GREATER for reversed-Z) depth test, both faces drawn.
DepthImage rasterizeDepthCpu(const Scene& scene, const Projection& proj,
                             const CancelToken* cancel = nullptr);

} // namespace lc
