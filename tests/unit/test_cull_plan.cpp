// The Vulkan cull's planner (vk/cull_plan.cpp) without a device: which
// strategy each device kind, algorithm and history gets, where the lists are
// then read from, and which inputs the device's limits refuse.
#include "culling/core/errors.hpp"
#include "vk/cull_plan.hpp"
#include "embedded_spirv.hpp"

#include <vector>

#include <gtest/gtest.h>

namespace lc {
namespace {

using vk::CullHistory;
using vk::CullPlan;
using vk::CullPlanInputs;
using vk::CullSpec;
using vk::CullStrategy;
using vk::DeviceProfile;
using vk::ListsFrom;

// lavapipe on a 2-core machine, as the tests see it.
DeviceProfile lavapipe() {
    DeviceProfile d;
    d.name = "llvmpipe";
    d.cpu = true;
    d.subgroupSize = 8;
    d.int64 = true;
    d.index16 = true;
    d.subgroupShuffle = true;
    d.maxStorageBufferRange = 1u << 27;
    return d;
}

// An H100-like GPU.
DeviceProfile gpu() {
    DeviceProfile d;
    d.name = "NVIDIA H100";
    d.subgroupSize = 32;
    d.int64 = true;
    d.index16 = true;
    d.subgroupShuffle = true;
    d.timestamps = true;
    d.maxGroupCountX = 2147483647;
    d.maxStorageBufferRange = 0xffffffffu;
    return d;
}

// 1280x720 in 16-pixel tiles, `lights` lights.
CullPlanInputs inputs(Algorithm algo, std::uint32_t lights = 256) {
    CullPlanInputs in;
    in.settings.algorithm = algo;
    in.grid = TileGrid::make(1280, 720, 16);
    in.listTotal = algo == Algorithm::All ? 1 : std::uint64_t(in.grid.tileCount()) * listsPerTileOf(algo, 32);
    in.lights = lights;
    in.depthPixels = 1280 * 720;
    in.clusterNear = 0.1;
    return in;
}

TEST(CullPlan, AGpuCountsAndWritesEveryListInOneDispatch) {
    for (Algorithm a : {Algorithm::Naive, Algorithm::MinMax, Algorithm::HalfZ, Algorithm::TwoPointFiveD,
                        Algorithm::Clustered, Algorithm::ZBin}) {
        const CullPlan p = vk::planCull(gpu(), CullHistory{}, inputs(a));
        EXPECT_EQ(p.strategy, CullStrategy::Fused) << toString(a);
        EXPECT_EQ(p.lanes, 32u);
        EXPECT_EQ(p.walk, 0u);
        EXPECT_TRUE(p.index16) << "256 lights fit 16-bit indices";
        EXPECT_FALSE(p.readStash) << "a GPU's stash is not read in place";
        EXPECT_EQ(p.fusedSpec.writePass, LC_PASS_FUSED);
        EXPECT_EQ(p.listsFrom(1000, 10, false), ListsFrom::Ranges);
        // Lists that outgrow the first index array are written again.
        EXPECT_EQ(p.listsFrom(std::uint32_t(p.firstCapacity) + 1, 10, false), ListsFrom::SecondSubmission);
    }
    EXPECT_FALSE(vk::planCull(gpu(), CullHistory{}, inputs(Algorithm::MinMax, 70000)).index16)
        << "more lights than 16 bits index";
    // `all` is one list: counted, scanned and written in order, not fused.
    const CullPlan all = vk::planCull(gpu(), CullHistory{}, inputs(Algorithm::All));
    EXPECT_EQ(all.strategy, CullStrategy::CountScanWrite);
    EXPECT_EQ(all.stashSlots, 0u);
    EXPECT_EQ(all.listsFrom(256, 256, false), ListsFrom::SecondSubmission)
        << "no stash and no previous cull: the first index array holds one entry";
    const CullPlan again = vk::planCull(gpu(), CullHistory{256, false, 1, 256}, inputs(Algorithm::All));
    EXPECT_EQ(again.firstCapacity, 256u + 16 + 256) << "sized from the previous cull's entries";
    EXPECT_EQ(again.listsFrom(256, 256, false), ListsFrom::Written);
}

TEST(CullPlan, FptlAlwaysPrunesInASecondSubmission) {
    for (const DeviceProfile& d : {lavapipe(), gpu()}) {
        const CullPlan p = vk::planCull(d, CullHistory{}, inputs(Algorithm::Fptl));
        EXPECT_FALSE(p.writeFirst) << d.name;
        EXPECT_EQ(p.strategy, CullStrategy::CountScan) << d.name;
        EXPECT_EQ(p.listsFrom(10, 1, false), ListsFrom::SecondSubmission) << d.name << ": never the stash";
        EXPECT_EQ(p.prune.writePass, LC_PRUNE_MARK);
        EXPECT_EQ(p.pack.writePass, LC_PRUNE_PACK);
    }
}

TEST(CullPlan, ACpuDeviceReadsTheStashOnceThePreviousListsFittedIt) {
    const CullPlanInputs in = inputs(Algorithm::MinMax);
    // First cull: nothing known, the write pass runs in the first submission.
    const CullPlan first = vk::planCull(lavapipe(), CullHistory{}, in);
    EXPECT_EQ(first.lanes, 1u) << "an invocation per list";
    EXPECT_TRUE(first.readStash);
    EXPECT_EQ(first.stashSlots, 32u);
    // CullHistory{} has longest 0: it fitted, so the first cull already trusts the stash.
    EXPECT_EQ(first.strategy, CullStrategy::CountScan);
    EXPECT_EQ(first.listsFrom(100, 20, false), ListsFrom::Stash);
    EXPECT_EQ(first.listsFrom(100, 33, false), ListsFrom::SecondSubmission) << "a list past the stash";
    // After a cull whose longest list outgrew 32 slots: the stash doubles up
    // to 128 and, while the lists did not fit, the write pass runs at once
    // into an index array sized from the previous entries.
    const CullHistory longer{100, false, first.listTotal, 5000};
    const CullPlan grown = vk::planCull(lavapipe(), longer, in);
    EXPECT_EQ(grown.stashSlots, 128u);
    EXPECT_EQ(grown.strategy, CullStrategy::CountScan) << "100 fits 128 slots";
    const CullHistory tooLong{300, false, first.listTotal, 5000};
    const CullPlan written = vk::planCull(lavapipe(), tooLong, in);
    EXPECT_EQ(written.stashSlots, 128u);
    EXPECT_EQ(written.strategy, CullStrategy::CountScanWrite);
    EXPECT_EQ(written.firstCapacity, 5000u + 5000u / 16 + 256);
    EXPECT_EQ(written.listsFrom(5000, 300, false), ListsFrom::Written);
    // A GPU never grows its stash past 32.
    EXPECT_EQ(vk::planCull(gpu(), tooLong, in).stashSlots, 32u);
}

TEST(CullPlan, ClusteredOnACpuDeviceWalksTilesAndTakesListsFromThePools) {
    const CullPlanInputs in = inputs(Algorithm::Clustered);
    const CullPlan first = vk::planCull(lavapipe(), CullHistory{}, in);
    EXPECT_EQ(first.walk, 32u) << "256 lights: a whole tile's 32 slices per invocation";
    EXPECT_EQ(first.walkGroups, 1u);
    EXPECT_EQ(first.strategy, CullStrategy::WalkAtomicWrite) << "no pools known to fit yet";
    EXPECT_EQ(first.atomicWriteSpec.writePass, LC_PASS_WRITE_AT_RANGES);
    const CullPlan next = vk::planCull(lavapipe(), CullHistory{10, true, first.listTotal, 20000}, in);
    EXPECT_EQ(next.strategy, CullStrategy::CountPools);
    EXPECT_TRUE(next.hostScan);
    EXPECT_EQ(next.listsFrom(20000, 10, true), ListsFrom::Pools);
    EXPECT_EQ(next.listsFrom(20000, 10, false), ListsFrom::SecondSubmission);
    // Walk q of tile t covers its slices, the last walk cut at the tile's end.
    const auto [b, e] = next.walkLists(3, 0);
    EXPECT_EQ(b, 3u * 32);
    EXPECT_EQ(e, 4u * 32);
    // More lights: fewer slices per walk, so the loops stay under the cap.
    const CullPlan many = vk::planCull(lavapipe(), CullHistory{}, inputs(Algorithm::Clustered, 4000));
    EXPECT_GT(many.walk, 0u);
    EXPECT_LT(many.walk, 32u);
}

TEST(CullPlan, TheLoopCapAndTheDeviceLimitsRefuseByName) {
    CullPlanInputs bigTiles = inputs(Algorithm::Fptl);
    bigTiles.grid = TileGrid::make(1280, 720, 256);
    bigTiles.listTotal = bigTiles.grid.tileCount();
    try {
        vk::planCull(lavapipe(), CullHistory{}, bigTiles);
        FAIL() << "fptl with 256-pixel tiles passes lavapipe's loop cap";
    } catch (const SettingsError& e) {
        EXPECT_NE(std::string(e.what()).find("at most 255 pixels"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("llvmpipe"), std::string::npos) << e.what();
    }
    EXPECT_NO_THROW(vk::planCull(gpu(), CullHistory{}, bigTiles)) << "a GPU has no loop cap";
    // A million lights: more words than a CPU device's invocations can walk.
    EXPECT_THROW(vk::planCull(lavapipe(), CullHistory{}, inputs(Algorithm::MinMax, 1000000)), SettingsError);
    DeviceProfile small = gpu();
    small.maxStorageBufferRange = 1024;
    EXPECT_THROW(vk::planCull(small, CullHistory{}, inputs(Algorithm::MinMax, 100000)), SettingsError)
        << "bins past one storage buffer";
    DeviceProfile fewGroups = gpu();
    fewGroups.maxGroupCountY = 10;
    EXPECT_THROW(vk::planCull(fewGroups, CullHistory{}, inputs(Algorithm::MinMax)), SettingsError)
        << "45 tile rows past 10 workgroups";
}

TEST(CullPlan, SpecialisationFollowsTheInputs) {
    CullPlanInputs in = inputs(Algorithm::Clustered);
    in.settings.spotTest = SpotTest::ConePlanes;
    in.spotCones = true;
    const CullPlan p = vk::planCull(gpu(), CullHistory{}, in);
    EXPECT_EQ(p.count.spotTest, LC_SPOT_CONE_PLANES);
    EXPECT_EQ(p.count.cellLog, 1u) << "log slicing, perspective, near > 0";
    EXPECT_EQ(p.count.algorithm, LC_ALG_CLUSTERED);
    EXPECT_EQ(p.binLanes, 2u) << "a GPU with shuffles ORs two lanes per word";
    EXPECT_EQ(p.bins.binLanes, 2u);
    in.spotCones = false;
    EXPECT_EQ(vk::planCull(gpu(), CullHistory{}, in).count.spotTest, LC_SPOT_NONE)
        << "no spots, no cone test";
    in.orthographic = true;
    const CullPlan ortho = vk::planCull(gpu(), CullHistory{}, in);
    EXPECT_EQ(ortho.count.cellLog, 0u);
    EXPECT_EQ(ortho.count.ortho, 1u);
    // Keys differ wherever a constant does: pipelines are cached by them.
    EXPECT_NE(p.count.key(), ortho.count.key());
    EXPECT_NE(p.count.key(), p.write.key());
    // Wide depth loads on a CPU device: 8 pixels a load where the width and tile allow.
    EXPECT_TRUE(vk::planCull(lavapipe(), CullHistory{}, inputs(Algorithm::MinMax)).wideBounds);
    EXPECT_EQ(vk::planCull(lavapipe(), CullHistory{}, inputs(Algorithm::MinMax)).depthLoad, 8u);
}

// A pipeline is keyed by the constants its module declares (glslang -Os
// declares only those a shader reads): tile_bounds the same whatever the
// sphere test, prefix_sum whatever the algorithm.
TEST(CullPlan, PipelinesAreKeyedByTheConstantsTheirShaderDeclares) {
    const auto ids = [](spirv::Code c) { return vk::specConstantIds(c.words, c.wordCount); };
    const auto has = [](std::uint32_t mask, std::uint32_t id) { return (mask >> id & 1u) != 0; };
    const std::uint32_t bounds = ids(spirv::tileBounds()), cull = ids(spirv::cullLists()), scan = ids(spirv::prefixSum());
    EXPECT_TRUE(has(bounds, 1) && has(bounds, 2) && has(bounds, 4)) << "tile size, cells, algorithm";
    EXPECT_FALSE(has(bounds, 5)) << "tile_bounds does not read the sphere test";
    EXPECT_TRUE(has(cull, 5) && has(cull, 6) && has(cull, 11)) << "sphere test, pass, spot test";
    EXPECT_EQ(scan, (1u << 0) | (1u << 7)) << "prefix_sum: local size and lanes";
    EXPECT_EQ(ids(spirv::tileBoundsWide()), bounds);

    const CullPlan planes = vk::planCull(lavapipe(), CullHistory{}, inputs(Algorithm::Clustered));
    CullPlanInputs in = inputs(Algorithm::Clustered);
    in.settings.test = SphereTest::Exact;
    const CullPlan exact = vk::planCull(lavapipe(), CullHistory{}, in);
    EXPECT_EQ(planes.bounds.only(bounds).key(), exact.bounds.only(bounds).key());
    EXPECT_NE(planes.count.only(cull).key(), exact.count.only(cull).key());
    EXPECT_EQ(planes.bounds.only(~0u).key(), planes.bounds.key());
    EXPECT_EQ(planes.bounds.only(0).key(), CullSpec{}.only(0).key());

    // Words that are not SPIR-V, or a truncated instruction, are refused.
    std::vector<std::uint32_t> words(spirv::prefixSum().words, spirv::prefixSum().words + spirv::prefixSum().wordCount);
    EXPECT_THROW(vk::specConstantIds(words.data(), 4), Error);
    words[0] = 0;
    EXPECT_THROW(vk::specConstantIds(words.data(), words.size()), Error);
    words[0] = 0x07230203;
    words[5] = 0xffff0000u | (words[5] & 0xffffu); // the first instruction claims 65,535 words
    EXPECT_THROW(vk::specConstantIds(words.data(), words.size()), Error);
}

} // namespace
} // namespace lc
