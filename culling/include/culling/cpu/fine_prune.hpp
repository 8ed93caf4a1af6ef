#pragma once
// Fine-pruned tiled lighting (`fptl`, the approach Unity HDRP ships): a
// coarse minmax test per tile, then every light that passes is tested
// against the positions of the tile's own geometry pixels, and kept only
// when at least one of them could need it. The lists come close to the best a
// per-tile list can be (the per-tile optimum of ground_truth.hpp), for a
// culling cost of (coarse candidates x tile pixels) point tests.
//
// The per-pixel test, shared by the CPU reference and explain: p (view space)
// lies inside light i's range sphere and, for a spot light, inside its cone,
// each widened by sphereTestSlack so that rounding never drops a light a
// pixel needs. The Vulkan pass (shaders/fine_prune.comp) widens the same
// tests by its float margin, so its lists hold the reference's.

#include "culling/core/backend.hpp"

namespace lc {

bool fptlPixelKeeps(const ViewLights& lights, std::size_t i, const glm::dvec3& p);

} // namespace lc
