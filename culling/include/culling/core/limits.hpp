#pragma once
// Engine limits on light lists (docs/ALGORITHMS.md, "Caps and limits"): the
// fixed buffers a shipped engine culls into, applied to the lists a culling
// test made. One rule for both backends: CullBackend::cull applies it to
// every built-in algorithm's result, so the CPU reference and Vulkan keep
// and drop the same lights from the same lists.
//
// Order, as an engine meets its limits: the per-view light limit first
// (maxLights: only the kept lights are culled at all), then, list by list in
// list order, the per-list cap and the record buffer (maxEntries: the
// entries of every list together, handed out in list order as a compaction
// pass writes them). An over-full list keeps what settings.overflow says.

#include "culling/core/cull_result.hpp"

#include <cstdint>
#include <vector>

namespace lc {

struct ViewLights;

// The lights a per-view limit of `maxLights` keeps, as a flag per light (1 =
// past the limit); empty when maxLights is 0 or not reached. `nearest` keeps
// the lights whose position is nearest the camera (ties by index).
std::vector<std::uint8_t> lightsOverLimit(const ViewLights& lights, std::uint32_t maxLights, LimitKeep keep);

// Applies settings.cap, maxLights and maxEntries to `result`'s lists (in
// place) and records what they dropped in result.limits. Does nothing when
// no limit is set. The lists stay ascending and compact. `overLimit` is
// lightsOverLimit(lights, settings.maxLights, settings.limitKeep), given
// where the caller has it (CullBackend::cull, which culls the kept lights
// alone); the overload without it works it out.
void applyListLimits(CullResult& result, const ViewLights& lights, const CullSettings& settings,
                     std::vector<std::uint8_t> overLimit);
void applyListLimits(CullResult& result, const ViewLights& lights, const CullSettings& settings);

} // namespace lc
