// Engine limits on light lists (limits.hpp).
#include "culling/core/limits.hpp"

#include "culling/core/backend.hpp"
#include "culling/core/errors.hpp"

#include <algorithm>
#include <glm/geometric.hpp>
#include <numeric>

namespace lc {

namespace {

// Entries the all-lights fallback may store in all (256 MiB of indices).
constexpr std::uint64_t kMaxFallbackEntries = std::uint64_t(1) << 26;

// Light order by distance of its position from the camera (view space), ties
// by index: the order an engine that sorts its lights keeps them in.
std::vector<std::uint32_t> nearestFirst(const ViewLights& lights, const std::vector<std::uint32_t>& among) {
    std::vector<std::pair<double, std::uint32_t>> d;
    d.reserve(among.size());
    for (std::uint32_t i : among) d.emplace_back(glm::length(lights.centers[i]), i);
    std::sort(d.begin(), d.end());
    std::vector<std::uint32_t> out;
    out.reserve(d.size());
    for (const auto& x : d) out.push_back(x.second);
    return out;
}

} // namespace

std::vector<std::uint8_t> lightsOverLimit(const ViewLights& lights, std::uint32_t maxLights, LimitKeep keep) {
    const std::size_t n = lights.size();
    if (maxLights == 0 || n <= maxLights) return {};
    std::vector<std::uint8_t> over(n, 1);
    if (keep == LimitKeep::Index) {
        std::fill(over.begin(), over.begin() + maxLights, 0);
    } else {
        std::vector<std::uint32_t> all(n);
        std::iota(all.begin(), all.end(), 0u);
        const std::vector<std::uint32_t> order = nearestFirst(lights, all);
        for (std::uint32_t k = 0; k < maxLights; ++k) over[order[k]] = 0;
    }
    return over;
}

void applyListLimits(CullResult& r, const ViewLights& lights, const CullSettings& s) {
    applyListLimits(r, lights, s, s.hasLimits() ? lightsOverLimit(lights, s.maxLights, s.limitKeep)
                                                : std::vector<std::uint8_t>());
}

void applyListLimits(CullResult& r, const ViewLights& lights, const CullSettings& s,
                     std::vector<std::uint8_t> overLimit) {
    r.limits = ListLimits{};
    if (!s.hasLimits()) return;
    ListLimits& lim = r.limits;
    lim.entriesUncapped = r.entries();
    for (std::uint32_t c : r.listCount) lim.longestUncapped = std::max(lim.longestUncapped, c);
    lim.overLightLimit = std::move(overLimit);
    // The lights the view keeps, for the all-lights fallback.
    std::vector<std::uint32_t> kept;
    for (std::uint32_t i = 0; i < lights.size(); ++i)
        if (!lim.isOverLimit(i)) kept.push_back(i);
    lim.lightsOverLimit = lights.size() - kept.size();

    const std::uint64_t noLimit = ~std::uint64_t(0);
    std::uint64_t recordsLeft = s.maxEntries ? s.maxEntries : noLimit;
    std::vector<std::uint32_t> offsets, counts, indices;
    offsets.reserve(r.listCount.size());
    counts.reserve(r.listCount.size());
    indices.reserve(r.lightIndices.size());
    std::vector<std::uint32_t> candidates;
    for (std::size_t l = 0; l < r.listCount.size(); ++l) {
        candidates.clear();
        const std::uint32_t* first = r.lightIndices.data() + r.listOffset[l];
        for (std::uint32_t k = 0; k < r.listCount[l]; ++k)
            if (!lim.isOverLimit(first[k])) candidates.push_back(first[k]);
        const std::uint64_t room = std::min<std::uint64_t>(s.cap ? s.cap : noLimit, recordsLeft);
        offsets.push_back(std::uint32_t(indices.size()));
        if (candidates.size() <= room) {
            indices.insert(indices.end(), candidates.begin(), candidates.end());
            counts.push_back(std::uint32_t(candidates.size()));
            if (recordsLeft != noLimit) recordsLeft -= candidates.size();
            continue;
        }
        lim.overflowLists.push_back(std::uint32_t(l));
        lim.droppedOffset.push_back(std::uint32_t(lim.droppedLights.size()));
        if (s.overflow == OverflowPolicy::AllLights) {
            // Out of records, every later list that holds a light falls back
            // too (Filament's Froxelizer); a list over the cap alone does not
            // use up the buffer.
            if (candidates.size() > recordsLeft) recordsLeft = 0;
            // The engine flags the list "shade with every light": no records
            // used. Stored here as every light: bounded, so a fallback on
            // every list of a huge scene is an error, not gigabytes.
            if (indices.size() + kept.size() > kMaxFallbackEntries)
                throw Error("overflow-policy all-lights: on " + std::to_string(lim.overflowLists.size()) +
                                                    "+ over-full lists of " + std::to_string(kept.size()) +
                                                    " lights would list more than " +
                                                    std::to_string(kMaxFallbackEntries) +
                                                    " entries; raise the cap or use overflow-policy index or nearest");
            indices.insert(indices.end(), kept.begin(), kept.end());
            counts.push_back(std::uint32_t(kept.size()));
            continue;
        }
        std::vector<std::uint32_t> order =
            s.overflow == OverflowPolicy::Nearest ? nearestFirst(lights, candidates) : candidates;
        std::vector<std::uint32_t> keep(order.begin(), order.begin() + std::ptrdiff_t(room));
        std::vector<std::uint32_t> drop(order.begin() + std::ptrdiff_t(room), order.end());
        std::sort(keep.begin(), keep.end());
        std::sort(drop.begin(), drop.end());
        indices.insert(indices.end(), keep.begin(), keep.end());
        counts.push_back(std::uint32_t(keep.size()));
        lim.droppedLights.insert(lim.droppedLights.end(), drop.begin(), drop.end());
        if (recordsLeft != noLimit) recordsLeft -= keep.size();
    }
    if (!lim.overflowLists.empty()) lim.droppedOffset.push_back(std::uint32_t(lim.droppedLights.size()));
    r.listOffset = std::move(offsets);
    r.listCount = std::move(counts);
    r.lightIndices = std::move(indices);
}

} // namespace lc
