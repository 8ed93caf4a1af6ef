// The Vulkan cull's plan: which passes run, how their work is laid out and
// where the host takes the lists from, decided from the device's profile, the
// previous cull and this cull's inputs, with no device at hand. The backend
// (vulkan_backend.cpp) records what the plan says and decodes the lists the
// way it names; tests/unit/test_cull_plan.cpp checks the choices.
#pragma once

#include "culling/core/backend.hpp"
#include "culling/vk/gpu_shared.h"

#include <algorithm>
#include <cstdint>
#include <string>

namespace lc::vk {

// What a device is, for the culling passes: the facts the plan reads, and
// the policies a CPU device (lavapipe) and a GPU differ in, each named by
// what it means rather than by the device's type.
struct DeviceProfile {
    std::string name;
    // A CPU device: SIMD lanes hold items (an invocation per tile and per
    // list), device memory is host memory (the host reads the stash in
    // place), every loop of an invocation stops after kLoopLimit iterations,
    // a scan is one subgroup, and the host never waits in a spin.
    bool cpu = false;
    std::uint32_t subgroupSize = 32;
    bool int64 = false;           // shaderInt64: the wide depth loads
    bool index16 = false;         // 16-bit storage: the fused pass's 16-bit indices
    bool subgroupShuffle = false; // the bins pass's shuffle variant
    bool timestamps = false;      // timestamps in compute and graphics
    std::uint32_t maxGroupCountX = 65535, maxGroupCountY = 65535;
    std::uint32_t maxWorkGroupInvocations = 1024, maxWorkGroupSizeX = 1024;
    std::uint64_t maxStorageBufferRange = 1u << 27;

    // lavapipe (gallivm) ends every loop of a shader invocation after this
    // many iterations in all, without an error; work per invocation is sized
    // below it.
    static constexpr std::uint64_t kLoopLimit = 65535;
    // The loop cap the passes are sized under (0: none).
    std::uint64_t loopLimit() const { return cpu ? kLoopLimit : 0; }
    // An invocation per tile and per list where the loops fit (SIMD lanes
    // are items), else a subgroup each (coalesced reads, words over lanes).
    bool lanesAreItems() const { return cpu; }
    // The host reads a mapped stash in place, cheaper than a write pass.
    bool hostReadsStash() const { return cpu; }
    // The count pass writes each list at a range it takes by an atomic add
    // (no scan, no second pass): cheap where a subgroup walks a list.
    bool fusesCountAndWrite() const { return !cpu; }
    // Stash slots a list may get at most (see kMaxStashSlots).
    std::uint32_t stashCap() const;
    // Device time from timestamps (else wall clock around the submission:
    // compute timestamps read wrong on lavapipe once it has rendered).
    bool gpuTimestamps() const { return !cpu && timestamps; }
};

// What the previous cull on the same backend left: it sizes this one.
struct CullHistory {
    std::uint32_t longestList = 0;            // sizes a CPU device's stash
    bool poolsFitted = false;                 // a tile walk's pools held every entry
    std::uint32_t listTotal = 0, entries = 0; // size the first index array
};

// The specialisation constants of the culling shaders, in constant_id order
// (cull_common.glsl); a pipeline is cached per value of the constants its
// module declares (specConstantIds: `only`).
struct CullSpec {
    std::uint32_t local = 64;     // 0: local size
    std::uint32_t tileSize = 16;  // 1
    std::uint32_t cells = 32;     // 2
    std::uint32_t slicing = 0;    // 3: LC_SLICING_*
    std::uint32_t algorithm = 0;  // 4: LC_ALG_*
    std::uint32_t sphereTest = 0; // 5: LC_TEST_*
    std::uint32_t writePass = 0;  // 6: LC_PASS_* (cull_lists), or a pass's own stage
    std::uint32_t lanes = 1;      // 7: lanes per tile or list
    std::uint32_t depthLoad = 2;  // 8: pixels per depth load
    std::uint32_t depthBins = 0;  // 9
    std::uint32_t tileWalk = 0;   // 10: clustered's slices per invocation (CPU)
    std::uint32_t spotTest = 0;   // 11: LC_SPOT_*
    std::uint32_t binLanes = 1;   // 12
    std::uint32_t cellLog = 0;    // 13
    std::uint32_t ortho = 0;      // 14
    std::uint32_t keptWords = 4;  // 15
    std::uint32_t testsWrap = 1;  // 16
    static constexpr std::uint32_t kCount = 17;
    std::string key() const;
    // This spec with every constant outside `ids` (bit i: constant_id i) zero.
    CullSpec only(std::uint32_t ids) const;
};

// The constant_ids a SPIR-V module declares (bit i: constant_id i). glslang
// declares only the constants a shader reads, so the code of a pipeline made
// from the module depends on those alone: tile_bounds is the same pipeline
// whatever the sphere test, prefix_sum whatever the algorithm. A report
// sweep on lavapipe compiled each pass once per configuration (15 to 25 ms a
// pipeline) before it was keyed so. Throws Error on words that are not SPIR-V.
std::uint32_t specConstantIds(const std::uint32_t* words, std::size_t wordCount);
static_assert(sizeof(CullSpec) == CullSpec::kCount * 4, "CullSpec: one uint per constant_id");

// Workgroup counts (x, y) of a dispatch.
struct Groups {
    std::uint32_t x = 1, y = 1;
};

// The first submission's shape, by name:
enum class CullStrategy {
    // count (stashing each list's first entries) and the scan; the lists come
    // from the stash, or a second submission writes them.
    CountScan,
    // clustered's tile walk on a CPU device: count into each walk's pool, no
    // scan (the host adds up the counts); the lists come from the pools, or
    // a second submission writes them.
    CountPools,
    // count, scan and write into an index array sized from the previous cull.
    CountScanWrite,
    // a GPU: count and write in one dispatch, each list at the range it takes.
    Fused,
    // clustered's tile walk: count, then write at ranges taken by atomic adds.
    WalkAtomicWrite,
};
const char* strategyName(CullStrategy s);

// Where the host takes the lists from once the counts are read.
enum class ListsFrom {
    Nothing,          // no entries
    Pools,            // the tile walks' pools (CountPools)
    Stash,            // the stash holds every list whole (CountScan)
    Ranges,           // the first index array, each list at its range (Fused, WalkAtomicWrite)
    Written,          // the first index array, in list order (CountScanWrite)
    SecondSubmission, // a write pass (and fptl's prune and pack) sized exactly
};
const char* listsFromName(ListsFrom f);

struct CullPlanInputs {
    CullSettings settings;
    TileGrid grid;
    std::uint64_t listTotal = 1;
    std::uint32_t lights = 0;
    std::size_t depthPixels = 0;
    bool orthographic = false;
    bool spotCones = false; // spot cones go up (a cone test, or fptl's prune, with spots in the view)
    double clusterNear = 0; // clustered: its slices' near (for the log cell formula)
};

struct CullPlan {
    CullStrategy strategy = CullStrategy::CountScan;
    Algorithm algorithm = Algorithm::Naive;
    bool fptl = false, zbin = false, all = false;
    std::uint32_t tiles = 0, listTotal = 0, lights = 0;

    // Light bins: words per column, row or depth bin (a bit per light, whole
    // uvec4s); plane bins, depth bins (twice: near ends, far ends), zbin's
    // (lo, hi) after them.
    bool depthBins = false;
    std::uint32_t binWords = 0;
    std::uint64_t planeBinWords = 0, depthBinWords = 0, binTotalWords = 0;

    // The stash: slots per list (0 for `all`), and whether the host reads it.
    std::uint32_t stashSlots = 0;
    bool readStash = false;
    std::size_t stashBytes() const { return std::size_t(listTotal) * stashSlots * 4; }

    // Work layout.
    std::uint32_t lanes = 1;      // per tile / list
    std::uint32_t walk = 0;       // clustered's tile walk: slices per invocation
    std::uint32_t walkGroups = 0; // walks per tile
    std::uint32_t depthLoad = 1;
    bool wideBounds = false; // tile_bounds.wide (an invocation per tile, wide loads)
    std::uint32_t binLanes = 1;
    bool wideScan = false;
    std::uint32_t scanLocal = 1;

    // The first submission.
    bool writeFirst = false; // a write pass (or fused writes) in it
    bool hostScan = false;   // no scan on the device: the host adds up the counts
    bool fused = false, atomicWrite = false;
    bool atomicRanges() const { return fused || atomicWrite; }
    // The host adds up the lists' offsets in order (atomic ranges, or no
    // scan on the device).
    bool hostOffsets() const { return atomicRanges() || hostScan; }
    bool index16 = false;          // the fused pass writes 16-bit indices
    std::size_t firstCapacity = 1; // entries of the first index array
    std::size_t entryBytes() const { return index16 ? 2 : 4; }

    // Specialisation constants per pass.
    // fptl's prune: an invocation per entry (prune), or on GPUs a subgroup
    // per entry while the entries are few (pruneWide; pruneLanes).
    CullSpec bounds, bins, count, write, atomicWriteSpec, fusedSpec, scan, prune, pruneWide, pack, zbinInit, zbinBins;

    Groups boundsGroups, binGroups, countGroups, writeGroups, packGroups, zbinInitGroups, zbinGroups;
    // Lanes per entry of fptl's prune over `entries` coarse entries: the
    // subgroup while they are at most kWidePruneEntries (too few invocations
    // to fill a GPU otherwise), else 1 (a subgroup each did 32 times the
    // search and loads for entries found on the first pixels).
    static constexpr std::uint32_t kWidePruneEntries = 65536;
    std::uint32_t pruneLanes(std::uint32_t entries) const {
        return pruneWide.lanes > 1 && entries <= kWidePruneEntries ? pruneWide.lanes : 1;
    }
    Groups pruneGroups(std::uint32_t entries) const;

    // Where the lists come from, given what the count pass found.
    ListsFrom listsFrom(std::uint32_t total, std::uint32_t longest, bool poolsFitted) const;
    // The lists walk q of tile t holds: [first, end).
    std::pair<std::uint32_t, std::uint32_t> walkLists(std::uint32_t t, std::uint32_t q) const {
        const std::uint32_t first = t * count.cells + q * walk;
        return {first, std::min(first + walk, (t + 1) * count.cells)};
    }

    DeviceProfile profile;
};

// Plans one cull. Throws SettingsError where the device cannot take the
// inputs (its dispatch or storage limits, lavapipe's loop cap), naming them.
CullPlan planCull(const DeviceProfile& device, const CullHistory& history, const CullPlanInputs& in);

} // namespace lc::vk
