#include "vk/cull_plan.hpp"

#include "culling/core/errors.hpp"

#include <algorithm>
#include <limits>

namespace lc::vk {

namespace {

// Stash slots per list at most (cull_common.glsl binding 10): the count pass
// keeps each list's first entries, so a cull whose lists all fit needs no
// write pass (P1: 1.6 entries per list on average, 21 at most). A CPU device
// (lavapipe) keeps up to kMaxStashSlotsCpu when the previous cull's longest
// list needed more than 32: there the stash is host memory read in place,
// and every list it holds whole is copied instead of culled a second time
// (measured, atrium 1280x720 with 1,024 lights, 73 entries per list: cull
// 27 ms with 32 slots, 18 ms with 128, 18 ms with 256), but a larger stash
// is fresh memory the count pass faults in (P1 measured slower with 128
// slots it does not need). A GPU keeps 32: its stash is read back through
// a staging copy, and it culls again cheaply.
constexpr std::uint32_t kMaxStashSlots = 32;
constexpr std::uint32_t kMaxStashSlotsCpu = 128;
// Local size of the one-invocation-per-item passes (light_bins, cull_lists):
// a multiple of every subgroup size in practice (8 on lavapipe, 32 on NVIDIA,
// 64 on AMD), so no partial subgroups.
constexpr std::uint32_t kLocal = 64;

// Workgroup counts (x, y) for `invocations` invocations of kLocal each,
// folded into y when x would exceed the device's limit.
Groups groupsFor(std::uint64_t invocations, const DeviceProfile& d) {
    const std::uint64_t groups = std::max<std::uint64_t>(1, (invocations + kLocal - 1) / kLocal);
    Groups g;
    g.x = std::uint32_t(std::min<std::uint64_t>(groups, d.maxGroupCountX));
    const std::uint64_t y = (groups + g.x - 1) / g.x;
    if (y > d.maxGroupCountY) throw SettingsError("tile", "too much work for one dispatch");
    g.y = std::uint32_t(y);
    return g;
}

} // namespace

std::uint32_t DeviceProfile::stashCap() const {
    return cpu ? kMaxStashSlotsCpu : kMaxStashSlots;
}

std::string CullSpec::key() const {
    const auto* v = reinterpret_cast<const std::uint32_t*>(this);
    std::string k;
    for (std::uint32_t i = 0; i < kCount; ++i)
        k += "." + std::to_string(v[i]);
    return k;
}

CullSpec CullSpec::only(std::uint32_t ids) const {
    CullSpec out = *this;
    auto* v = reinterpret_cast<std::uint32_t*>(&out);
    for (std::uint32_t i = 0; i < kCount; ++i)
        if (!(ids >> i & 1u)) v[i] = 0;
    return out;
}

std::uint32_t specConstantIds(const std::uint32_t* words, std::size_t wordCount) {
    constexpr std::uint32_t kMagic = 0x07230203, kOpDecorate = 71, kSpecId = 1;
    if (wordCount < 5 || words[0] != kMagic) throw Error("specConstantIds: not a SPIR-V module");
    std::uint32_t ids = 0;
    for (std::size_t i = 5; i < wordCount;) {
        const std::uint32_t op = words[i] & 0xffffu, n = words[i] >> 16;
        if (n == 0 || n > wordCount - i) throw Error("specConstantIds: a truncated instruction at word " + std::to_string(i));
        // OpDecorate %target SpecId N
        if (op == kOpDecorate && n >= 4 && words[i + 2] == kSpecId) {
            if (words[i + 3] >= CullSpec::kCount)
                throw Error("specConstantIds: constant_id " + std::to_string(words[i + 3]) + " is not a CullSpec field");
            ids |= 1u << words[i + 3];
        }
        i += n;
    }
    return ids;
}

const char* strategyName(CullStrategy s) {
    switch (s) {
    case CullStrategy::CountScan:
        return "count-scan";
    case CullStrategy::CountPools:
        return "count-pools";
    case CullStrategy::CountScanWrite:
        return "count-scan-write";
    case CullStrategy::Fused:
        return "fused";
    case CullStrategy::WalkAtomicWrite:
        return "walk-atomic-write";
    }
    return "?";
}

const char* listsFromName(ListsFrom f) {
    switch (f) {
    case ListsFrom::Nothing:
        return "nothing";
    case ListsFrom::Pools:
        return "pools";
    case ListsFrom::Stash:
        return "stash";
    case ListsFrom::Ranges:
        return "ranges";
    case ListsFrom::Written:
        return "written";
    case ListsFrom::SecondSubmission:
        return "second-submission";
    }
    return "?";
}

Groups CullPlan::pruneGroups(std::uint32_t entries) const {
    return groupsFor(std::uint64_t(entries) * pruneLanes(entries), profile);
}

ListsFrom CullPlan::listsFrom(std::uint32_t total, std::uint32_t longest, bool poolsFitted) const {
    if (total == 0) return ListsFrom::Nothing;
    if (walk && !writeFirst && poolsFitted) return ListsFrom::Pools;
    if (readStash && !walk && !writeFirst && longest <= stashSlots && !fptl) return ListsFrom::Stash;
    if (atomicRanges() && total <= firstCapacity) return ListsFrom::Ranges;
    if (writeFirst && total <= firstCapacity) return ListsFrom::Written;
    return ListsFrom::SecondSubmission;
}

namespace {

// The stash (slots per list, whether the host reads it) and the first index
// array's size, from the previous cull.
void planStash(CullPlan& plan, const DeviceProfile& dev, const CullHistory& history,
               const CullPlanInputs& in) {
    // Stash slots per list: kMaxStashSlots, doubled up to the device's cap
    // while the previous cull's longest list needed more; fewer where that
    // would outgrow the depth image (clustered has many lists); none for `all`.
    std::uint32_t maxStashSlots = kMaxStashSlots;
    while (maxStashSlots < dev.stashCap() && maxStashSlots < history.longestList)
        maxStashSlots *= 2;
    plan.stashSlots =
        plan.all ? 0 : std::uint32_t(std::min<std::uint64_t>(maxStashSlots, in.depthPixels / in.listTotal));
    // On a CPU device the stash is host memory: when the previous cull's
    // lists fitted it, the host takes the lists from there (a write pass
    // copying them cost lavapipe more, 4.2-4.3 against 3.8-4.5 ms at P1).
    plan.readStash = dev.hostReadsStash() && plan.stashBytes() > 0;
    // The write pass runs in the same submission (no read-back between the
    // passes) into an index array sized from the previous cull's entries with
    // as many lists, with a margin (else the stash's size); only when the
    // lists outgrow it does a second submission write them again, sized
    // exactly. fptl prunes the written lists by entry: always a second
    // submission, sized exactly.
    plan.firstCapacity = history.listTotal == plan.listTotal && history.entries > 0
                             ? std::size_t(history.entries) + std::size_t(history.entries) / 16 + 256
                             : std::max<std::size_t>(std::size_t(plan.listTotal) * plan.stashSlots, 1);
}

// Light bins: one bit per light per tile column and per tile row, then per
// depth bin twice (near ends, far ends; light_bins.comp). `naive` spans
// every light's depth and `all` tests nothing: no depth bins.
void planBins(CullPlan& plan, const DeviceProfile& dev, const CullPlanInputs& in) {
    const std::uint32_t n = plan.lights;
    plan.depthBins = !plan.all && plan.algorithm != Algorithm::Naive && !plan.zbin && n > 0;
    // Words per column, row or depth bin: a bit per light, padded to whole
    // uvec4s (cull_lists.comp reads four words a load on a CPU device).
    plan.binWords = (n + 127) / 128 * 4;
    plan.planeBinWords = std::uint64_t(plan.binWords) * (in.grid.tilesX + in.grid.tilesY);
    plan.depthBinWords = plan.depthBins ? std::uint64_t(plan.binWords) * LC_DEPTH_BINS : 0;
    // zbin: its bins' (lo, hi) after the plane bins.
    plan.binTotalWords =
        plan.planeBinWords + 2 * plan.depthBinWords + (plan.zbin ? 2 * std::uint64_t(in.settings.bins) : 0);
    if (plan.binTotalWords * 4 > dev.maxStorageBufferRange)
        throw SettingsError("lights", "too many lights for the light bins of this device");
}

// The constants every culling pass shares.
CullSpec baseSpec(const CullPlan& plan, const DeviceProfile& dev, const CullPlanInputs& in) {
    const CullSettings& settings = in.settings;
    // The spot refinement as a specialisation constant, not a parameter:
    // lavapipe runs an if's body whatever its condition (masked), so a
    // runtime choice cost every test the spot cone's loads and tests, spot
    // lights or none (P1 / clustered 4.5-4.6 -> 4.2 ms).
    const bool coneTests =
        settings.spotTest == SpotTest::ConeSphere || settings.spotTest == SpotTest::ConePlanes;
    CullSpec base;
    base.local = kLocal;
    base.tileSize = in.grid.tileSize;
    base.cells = settings.cells;
    base.slicing = std::uint32_t(settings.slicing);
    base.algorithm = std::uint32_t(plan.algorithm);
    base.sphereTest = std::uint32_t(settings.test);
    base.depthBins = plan.depthBins ? 1u : 0u;
    base.spotTest = !(in.spotCones && coneTests)                ? LC_SPOT_NONE
                    : settings.spotTest == SpotTest::ConeSphere ? LC_SPOT_CONE_SPHERE
                                                                : LC_SPOT_CONE_PLANES;
    // Cell ranges that start beyond 0 wherever the bounds pass maps pixels
    // (tile_bounds.comp, CELL_LOG): log slicing with a perspective camera
    // (geometry lies beyond the near plane) and, for clustered, its near.
    base.cellLog = settings.slicing == Slicing::Log && !in.orthographic &&
                   (plan.algorithm != Algorithm::Clustered || float(in.clusterNear) > 0.0f);
    base.ortho = in.orthographic ? 1u : 0u;
    // Mask words per lane a GPU list walk keeps in registers (cull_lists.comp,
    // KEPT_WORDS): as many as the bins have per lane, at most 4. Fewer
    // registers where the lights are few (P1 on the H100: 0.0205-0.0206 ->
    // 0.0203 ms against 4).
    base.keptWords =
        std::clamp<std::uint32_t>((plan.binWords + dev.subgroupSize - 1) / dev.subgroupSize, 1, 4);
    // Whether a test counter could wrap around 2^32: a counter takes the
    // tests of every LC_TEST_COUNTERS-th list (or tile walk, fewer than the
    // lists), each at most every light, counted at most twice.
    const std::uint64_t perCounter =
        (std::uint64_t(plan.listTotal) + LC_TEST_COUNTERS - 1) / LC_TEST_COUNTERS;
    base.testsWrap = 2 * perCounter * plan.lights > std::numeric_limits<std::uint32_t>::max() ? 1u : 0u;
    return base;
}

// Work layout per device kind (the LANES constant): on a CPU device
// (lavapipe) an invocation per tile and per list, so SIMD lanes are tiles /
// lists and workgroups hold many of them, and a one-subgroup scan without
// barriers; on a GPU a subgroup per tile and per list (coalesced pixel
// reads, words of the bins spread over the lanes) and a wide scan.
//
// lavapipe stops all loops of one invocation after 65,535 iterations in
// all (silently; the shaders flag it). A list costs at most 65 loop
// iterations per mask word (the word, up to 32 tests, up to 32 writes)
// and as many as it has stash slots (stashing; copying a stashed list), so
// a CPU device takes an invocation per list only while that fits, else
// spreads the words over a subgroup; beyond that it refuses.
// (stashCap: the largest stash any cull of this device takes.)
void planLayout(CullPlan& plan, const DeviceProfile& dev, const CullPlanInputs& in) {
    const std::uint32_t n = plan.lights, sg = dev.subgroupSize, stashCap = dev.stashCap();
    const std::uint64_t loopLimit = dev.loopLimit();
    const std::uint64_t itersPerList = std::uint64_t(plan.binWords) * 65 + 64 + stashCap;
    std::uint32_t lanes = sg;
    if (kLocal % sg != 0)
        lanes = 1;
    else if (dev.lanesAreItems())
        lanes = itersPerList <= loopLimit ? 1 : sg;
    // fptl's passes: a tile's pixels plus a 32-step search per entry, a
    // list's entries (at most the lights) per list.
    const std::uint32_t tileSize = in.grid.tileSize;
    if (plan.fptl && loopLimit && (std::uint64_t(tileSize) * tileSize + 32 > loopLimit || n > loopLimit))
        throw SettingsError("tile",
                            "fptl on '" + dev.name + "' takes tiles of at most 255 pixels and at most " +
                                std::to_string(loopLimit) +
                                " lights (the driver caps a shader invocation at 65,535 loop iterations)");
    if (loopLimit && itersPerList / lanes > loopLimit)
        throw SettingsError(
            "lights", std::to_string(n) + " lights is more than the culling passes can take on '" + dev.name +
                          "' (at most " + std::to_string((loopLimit - 64 - stashCap) / 65 * lanes * 32) +
                          ": the driver caps a shader invocation at 65,535 loop iterations)");
    plan.lanes = lanes;
    // clustered on a CPU device: an invocation per tile and `walk` slices
    // (cull_lists.comp, clusteredTileWalk), as many as its loops fit the cap:
    // the words, per candidate at most walk + 3 iterations (its slice range,
    // found without a loop, walked), the slices' counts and checks, and the
    // stashed lists copied. Fewer invocations walk the words fewer times.
    const std::uint32_t cells = in.settings.cells;
    plan.walk = 0;
    if (plan.algorithm == Algorithm::Clustered && dev.lanesAreItems() && lanes == 1)
        for (std::uint32_t s : {32u, 16u, 8u, 4u}) {
            const std::uint64_t iters =
                std::uint64_t(plan.binWords) + (s + 3ull) * n + 6ull * s + std::uint64_t(s) * stashCap;
            if (iters <= loopLimit) {
                plan.walk = std::min(s, cells);
                break;
            }
        }
    plan.walkGroups = plan.walk ? (cells + plan.walk - 1) / plan.walk : 0;
    // Wide depth loads (tile_bounds.comp): an invocation per tile
    // (LC_WIDE_DEPTH_LOADS), 8 or 2 pixels a load; a subgroup per tile, 4 a
    // load; where the width and the tile size are multiples of it, so every
    // tile row starts on a whole load.
    auto loadsOf = [&](std::uint32_t px) { return in.grid.width % px == 0 && tileSize % px == 0; };
    plan.depthLoad = lanes != 1 ? (loadsOf(4) ? 4 : 1) : !dev.int64 ? 1 : loadsOf(8) ? 8 : loadsOf(2) ? 2 : 1;
    plan.wideBounds = lanes == 1 && plan.depthLoad > 1;
    // The bins pass on a GPU: two invocations per mask word, 16 lights each,
    // their masks ORed by a subgroup shuffle: half the loop on the path to
    // the list pass (P1 on the H100: 0.023 -> 0.021 ms, the Live scene 0.025
    // -> 0.022; four or eight a word: P2 0.326 -> 0.341-0.344).
    // (Whole subgroups in a workgroup, as the list passes ask.)
    plan.binLanes = !dev.cpu && dev.subgroupShuffle && kLocal % sg == 0 ? 2 : 1;
    // Scan: one subgroup on a CPU device while each lane's run (read and
    // write: 2 loop iterations per list) fits the loop cap, else wide.
    plan.wideScan = !dev.cpu || 2 * (std::uint64_t(plan.listTotal) / sg + 1) > DeviceProfile::kLoopLimit / 2;
    plan.scanLocal =
        plan.wideScan ? std::min({1024u, dev.maxWorkGroupInvocations, dev.maxWorkGroupSizeX, 128 * sg}) : sg;
}

// The first submission's strategy, from the layout and the previous cull.
void planStrategy(CullPlan& plan, const DeviceProfile& dev, const CullHistory& history) {
    // A write pass in the first submission unless the previous cull's lists
    // all fitted the stash (a tile walk's: its pools, cull_lists.comp).
    const bool stashHeldLast = plan.walk ? history.poolsFitted : history.longestList <= plan.stashSlots;
    plan.writeFirst = !plan.fptl && !(plan.readStash && stashHeldLast) &&
                      plan.firstCapacity * 4 <= dev.maxStorageBufferRange;
    // A tile walk taking its lists from the pools needs no scan on the
    // device: the host adds up the counts (the scan of P1 / clustered's
    // 261,120 counts took lavapipe about 1 ms).
    plan.hostScan = plan.walk != 0 && !plan.writeFirst;
    // On a GPU the count pass writes the lists too (fused, LC_PASS_FUSED):
    // each list takes its range of the index array with an atomic add on the
    // total, so neither the scan nor a write pass waits on the count pass
    // (P1 on the H200: the scan cost 10 of 40 us, the write pass 5; clustered's
    // scan of 261,120 counts 400 of 582 us). The ranges come in no fixed
    // order; the host reads each list at its range.
    plan.fused = plan.writeFirst && dev.fusesCountAndWrite() && plan.lanes > 1 && !plan.all;
    // clustered's tile walk (CPU devices) keeps its write pass but drops the
    // scan before it the same way: a walk's lists take their ranges by one
    // atomic add (P1 on lavapipe: the scan of 261,120 counts cost 1.1 ms).
    plan.atomicWrite = plan.writeFirst && plan.walk != 0;
    // The fused pass writes 16-bit light indices while the lights fit them
    // (zbin's sorted positions too: below the light count): half the bytes
    // to write and to read back (P3 on the H100: 33 MB of lists).
    plan.index16 = plan.fused && plan.lights <= 65536 && dev.index16;
    plan.strategy = plan.fused         ? CullStrategy::Fused
                    : plan.atomicWrite ? CullStrategy::WalkAtomicWrite
                    : plan.writeFirst  ? CullStrategy::CountScanWrite
                    : plan.hostScan    ? CullStrategy::CountPools
                                       : CullStrategy::CountScan;
}

// Each pass's constants and workgroups.
void planPasses(CullPlan& plan, const DeviceProfile& dev, const CullSpec& base, const CullPlanInputs& in) {
    plan.bounds = base;
    plan.bounds.lanes = plan.lanes;
    plan.bounds.depthLoad = plan.depthLoad;
    const std::uint32_t itemsPerGroup = kLocal / plan.lanes;
    plan.boundsGroups = Groups{(in.grid.tilesX + itemsPerGroup - 1) / itemsPerGroup, in.grid.tilesY};
    plan.bins = base;
    plan.bins.binLanes = plan.binLanes;
    plan.count = base;
    plan.count.lanes = plan.lanes;
    plan.count.tileWalk = plan.walk;
    plan.write = plan.count;
    plan.write.writePass = LC_PASS_WRITE;
    plan.atomicWriteSpec = plan.count;
    plan.atomicWriteSpec.writePass = LC_PASS_WRITE_AT_RANGES;
    plan.fusedSpec = plan.count;
    plan.fusedSpec.writePass = LC_PASS_FUSED;
    plan.scan = base;
    plan.scan.local = plan.scanLocal;
    plan.scan.lanes = plan.wideScan ? dev.subgroupSize : 1;
    plan.prune = base;
    plan.prune.writePass = LC_PRUNE_MARK;
    plan.pruneWide = plan.prune;
    plan.pruneWide.lanes = plan.lanes;
    plan.pack = base;
    plan.pack.writePass = LC_PRUNE_PACK;
    plan.zbinInit = base;
    plan.zbinInit.writePass = LC_ZBIN_INIT;
    plan.zbinBins = base;
    plan.zbinBins.writePass = LC_ZBIN_BIN;
    // One bins invocation per plane word and per pair of depth-bin words.
    const std::uint64_t listItems =
        plan.walk ? std::uint64_t(plan.tiles) * plan.walkGroups : std::uint64_t(plan.listTotal) * plan.lanes;
    plan.binGroups = groupsFor((plan.planeBinWords + plan.depthBinWords) * plan.binLanes, dev);
    plan.countGroups = groupsFor(plan.all ? 1 : listItems, dev);
    plan.writeGroups = groupsFor(plan.all ? plan.lights : listItems, dev);
    plan.packGroups = groupsFor(plan.listTotal, dev);
    plan.zbinInitGroups = groupsFor(in.settings.bins, dev);
    plan.zbinGroups = groupsFor(plan.lights, dev);
}

} // namespace

CullPlan planCull(const DeviceProfile& dev, const CullHistory& history, const CullPlanInputs& in) {
    const TileGrid& grid = in.grid;
    if (grid.tilesX > dev.maxGroupCountX || grid.tilesY > dev.maxGroupCountY)
        throw SettingsError("tile", "too many tiles for one dispatch on this device");
    if (in.listTotal >= std::numeric_limits<std::uint32_t>::max())
        throw SettingsError("tile", "more than 2^32 light lists");
    CullPlan plan;
    plan.profile = dev;
    plan.algorithm = in.settings.algorithm;
    plan.fptl = plan.algorithm == Algorithm::Fptl;
    plan.zbin = plan.algorithm == Algorithm::ZBin;
    plan.all = plan.algorithm == Algorithm::All;
    plan.tiles = grid.tileCount();
    plan.listTotal = std::uint32_t(in.listTotal);
    plan.lights = in.lights;
    planStash(plan, dev, history, in);
    planBins(plan, dev, in);
    const CullSpec base = baseSpec(plan, dev, in);
    planLayout(plan, dev, in);
    planStrategy(plan, dev, history);
    planPasses(plan, dev, base, in);
    return plan;
}

} // namespace lc::vk
