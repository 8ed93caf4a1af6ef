// The Vulkan backend: the depth pre-pass as a depth-only graphics pipeline and
// the culling passes as compute, headless (no window, no swapchain).
//
// Culling, per call (shaders/*.comp; one workgroup = one subgroup everywhere):
//   1. tile_bounds  (tilesX x tilesY groups): per-tile view-depth min/max over
//      the geometry pixels, halfz split, 2.5d cell / clustered slice masks.
//   2. cull_lists count pass (one group per list): lights tested in strides of
//      the subgroup size, counted by ballot; each list's first entries (up to
//      kMaxStashSlots, kMaxStashSlotsCpu on a CPU device) kept in the stash.
//   3. prefix_sum: counts -> offsets, total in offsets[N].
//   4. cull_lists write pass: stashed lists copied, the longer ones tested
//      again, indices written ascending into an index array sized from the
//      previous cull (its entries and a margin; else the stash's size).
//   On a GPU, 2-4 are one dispatch (cull_lists fused): each list, once
//   counted, takes its range of that index array with an atomic add on the
//   total and is written there at once; the host reads each list at its
//   range and lays them out in order.
//   -- one submission, no read-back between the passes; the host reads the
//      total, and only when the lists outgrew the index array does a second
//      submission run the write pass again (after the scan, where the first
//      ran none) into one sized exactly. On a CPU
//      device, whose stash the host reads in place, the write pass waits
//      for the total unless the previous cull's lists outgrew the stash --
//   The depth buffer is the one the depth pre-pass left on the device when
//   the cull is given that image (DepthImage::deviceCopy), else uploaded.
//   fptl adds (in the second submission, always, sized exactly: its lists
//   are minmax's so far):
//   5. fine_prune, an invocation per entry: the light against its tile's
//      geometry pixels, pruned entries marked;
//   6. fine_prune pack, an invocation per list: kept entries to the front
//      of the list's range, the new count; the host packs the ranges.
//   zbin uploads the lights sorted by depth and culls naive's screen-space
//   volume (its tile masks, as sorted positions, mapped back by the host),
//   and zbin.comp bins the sorted lights in depth after light_bins.
// So memory is the entries the scene produces, with no per-list cap and no
// tiles x lights x cells allocation.
#include "vk/vulkan_backend.hpp"

#include "scene/closed_solids.hpp"

#include "culling/core/errors.hpp"
#include "culling/vk/gpu_shared.h"
#include "embedded_spirv.hpp"
#include "vk/vk_context.hpp"
#include "vk/shade_pass.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

// Vulkan create-info structs are value-initialised as {VK_STRUCTURE_TYPE_...}:
// the remaining members are zero on purpose.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace lc {

namespace {

using namespace vk;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Widening of every float comparison (see cull_common.glsl): relative 2e-5 is
// ~170 float ulps, far above the rounding of the float passes and far below any
// distance a scene cares about; the absolute term covers values near zero.
constexpr float kRelEps = 2e-5f;
constexpr float kAbsEps = 1e-6f;

constexpr std::uint32_t kBindings = 11; // cull_common.glsl bindings 0..10
constexpr std::uint32_t kSpecConstants = 17; // cull_common.glsl constant_id 0..16
using SpecConstants = std::array<std::uint32_t, kSpecConstants>;
enum Binding : std::uint32_t { bParams, bDepth, bTiles, bLights, bCounts, bOffsets, bIndices, bStatus, bBins };
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
// The largest region of one staged download copy (Staging::recordDownloads).
constexpr VkDeviceSize kDownloadRegion = 512 * 1024;
// lavapipe (gallivm) ends every loop of a shader invocation after this many
// iterations in all, without an error; work per invocation is sized below it.
constexpr std::uint64_t kLoopLimit = 65535;

// Workgroup counts (x, y) for `invocations` invocations of kLocal each,
// folded into y when x would exceed the device's limit.
struct Grid {
    std::uint32_t x = 1, y = 1;
};
Grid groupsFor(std::uint64_t invocations, const VkPhysicalDeviceLimits& lim) {
    const std::uint64_t groups = std::max<std::uint64_t>(1, (invocations + kLocal - 1) / kLocal);
    Grid g;
    g.x = std::uint32_t(std::min<std::uint64_t>(groups, lim.maxComputeWorkGroupCount[0]));
    const std::uint64_t y = (groups + g.x - 1) / g.x;
    if (y > lim.maxComputeWorkGroupCount[1]) throw SettingsError("tile", "too much work for one dispatch");
    g.y = std::uint32_t(y);
    return g;
}

void computeBarrier(VkCommandBuffer cmd, VkAccessFlags dstAccess, VkPipelineStageFlags dstStage);

// Host <-> device data of one submission. Buffers the host can map are
// written and read in place (lavapipe: no copies at all); others go through
// host-visible staging buffers (the cache's "staging.upload.<role>" and
// "staging.download.<role>") copied at the start / end of the commands.
class Staging {
public:
    explicit Staging(BufferCache& cache) : cache_(cache) {}
    // Writes `bytes` of `data` into `dst`: now when mapped, else at recordUploads().
    void upload(const Buffer& dst, const void* data, std::size_t bytes, const std::string& role) {
        if (bytes == 0) return;
        if (dst.mapped) {
            std::memcpy(dst.mapped, data, bytes);
            return;
        }
        const Buffer& st = cache_.get("staging.upload." + role, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                                      BufferCache::Kind::Host);
        std::memcpy(st.mapped, data, bytes);
        copies_.push_back({dst.buffer, st.buffer, bytes, true});
    }
    // Host pointer to `src`'s first `bytes`, valid once the submission that
    // ran recordDownloads() has completed (until the role is staged again).
    const void* download(const Buffer& src, std::size_t bytes, const std::string& role) {
        if (src.mapped) {
            mappedReads_ = true;
            return src.mapped;
        }
        const Buffer& st = cache_.get("staging.download." + role, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                                      BufferCache::Kind::HostRead);
        copies_.push_back({src.buffer, st.buffer, bytes, false});
        return st.mapped;
    }
    // Records the staged copies and a barrier making them visible to
    // `dstAccess` at `dstStage` (by default: the compute passes); the
    // barrier also without a copy when `transferBefore` (transfer writes
    // the caller recorded before).
    void recordUploads(VkCommandBuffer cmd, VkPipelineStageFlags dstStage = VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                       VkAccessFlags dstAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                       bool transferBefore = false) const {
        bool any = transferBefore;
        for (const Copy& c : copies_)
            if (c.up) {
                VkBufferCopy region{0, 0, c.bytes};
                vkCmdCopyBuffer(cmd, c.staging, c.device, 1, &region);
                any = true;
            }
        if (!any) return;
        // The passes read (status: also OR into) what the copies wrote.
        memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, dstStage, dstAccess);
    }
    void recordDownloads(VkCommandBuffer cmd) const {
        bool anyCopy = false;
        for (const Copy& c : copies_) anyCopy = anyCopy || !c.up;
        if (anyCopy) {
            // The copies read what the compute passes wrote.
            computeBarrier(cmd, VK_ACCESS_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT);
            // A copy command per kDownloadRegion bytes: NVIDIA's driver
            // copied P3's 17.6 MB of lists to the host at 24 GB/s in one
            // command, at 46 GB/s in 512 KiB ones (H100, PCIe 5 x16).
            for (const Copy& c : copies_)
                if (!c.up)
                    for (VkDeviceSize at = 0; at < c.bytes; at += kDownloadRegion) {
                        VkBufferCopy region{at, at, std::min(kDownloadRegion, c.bytes - at)};
                        vkCmdCopyBuffer(cmd, c.device, c.staging, 1, &region);
                    }
            // The host reads the staging buffers the copies wrote.
            memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                          VK_ACCESS_HOST_READ_BIT);
        }
        // The host reads the mapped buffers the compute passes wrote.
        if (mappedReads_) computeBarrier(cmd, VK_ACCESS_HOST_READ_BIT, VK_PIPELINE_STAGE_HOST_BIT);
    }

private:
    struct Copy {
        VkBuffer device, staging;
        VkDeviceSize bytes;
        bool up;
    };
    BufferCache& cache_;
    std::vector<Copy> copies_;
    bool mappedReads_ = false;
};

// Memory barrier between two compute dispatches of one command buffer.
void computeBarrier(VkCommandBuffer cmd, VkAccessFlags dstAccess, VkPipelineStageFlags dstStage) {
    memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, dstStage, dstAccess);
}

// GpuCullParams.depthBins: LC_DEPTH_BINS slices of the lights' depth extent
// [lightNear, lightFar] (view depth). Log slices when the camera is a
// perspective one and the extent spans more than a doubling from the near
// plane on (every bin then covers the same ratio of depths, as a tile's
// depth range does at any distance), else linear ones; a flat extent gets
// scale 0 (every depth in bin 0, every light in every bin: no filtering).
glm::vec4 depthBinSlicing(const Projection& proj, double camNear, double lightNear, double lightFar) {
    const double bins = LC_DEPTH_BINS;
    if (!proj.orthographic()) {
        const double lo = std::max(lightNear, camNear);
        if (lo > 0 && lightFar > 2 * lo)
            return glm::vec4(float(std::log2(lo)), float(bins / std::log2(lightFar / lo)), 1.0f, 0.0f);
    }
    if (!(lightFar > lightNear) || !std::isfinite(lightFar - lightNear)) return glm::vec4(0.0f);
    return glm::vec4(float(lightNear), float(bins / (lightFar - lightNear)), 0.0f, 0.0f);
}

// Window depth d = A + B / v (perspective) or A + B * v (orthographic), with A
// and B recovered in double from the projection itself (two exact samples).
void depthConstants(const Projection& proj, double& a, double& b) {
    const double v1 = proj.nearPlane(), v2 = proj.orthographic() ? proj.nearPlane() + 1.0 : 2.0 * proj.nearPlane();
    const double d1 = proj.windowDepthFromViewDepth(v1), d2 = proj.windowDepthFromViewDepth(v2);
    if (proj.orthographic()) {
        b = (d2 - d1) / (v2 - v1);
        a = d1 - b * v1;
    } else {
        b = (d1 - d2) / (1.0 / v1 - 1.0 / v2);
        a = d1 - b / v1;
    }
}

// A 64-bit digest of a mesh's positions and indices (not its transform):
// the key of its closed solids, which depend on nothing else. Four lanes of
// 8-byte words, so that the multiplies do not wait on each other (0.06 ms
// for forest's 0.5 MB, against 0.12 with one lane).
std::uint64_t meshContentKey(const Mesh& m) {
    std::uint64_t lane[4] = {0x243F6A8885A308D3ull ^ m.positions.size(), 0x13198A2E03707344ull ^ m.indices.size(),
                             0xA4093822299F31D0ull, 0x082EFA98EC4E6C89ull};
    auto word = [&lane](int k, std::uint64_t w) {
        lane[k] = (lane[k] ^ (w * 0xC2B2AE3D27D4EB4Full)) * 0x9E3779B97F4A7C15ull;
        lane[k] ^= lane[k] >> 31;
    };
    auto mix = [&word](const void* data, std::size_t bytes) {
        const auto* p = static_cast<const unsigned char*>(data);
        std::size_t i = 0;
        for (; i + 32 <= bytes; i += 32)
            for (int k = 0; k < 4; ++k) {
                std::uint64_t w;
                std::memcpy(&w, p + i + 8 * k, 8);
                word(k, w);
            }
        for (int k = 0; i < bytes; i += 8, ++k) {
            std::uint64_t w = 0;
            std::memcpy(&w, p + i, std::min<std::size_t>(8, bytes - i));
            word(k, w);
        }
    };
    mix(m.positions.data(), m.positions.size() * sizeof(float));
    mix(m.indices.data(), m.indices.size() * sizeof(std::uint32_t));
    std::uint64_t h = lane[0];
    for (int k = 1; k < 4; ++k) h = ((h ^ lane[k]) * 0x9E3779B97F4A7C15ull) ^ (h >> 29);
    return h;
}

class VulkanBackend final : public CullBackend {
public:
    explicit VulkanBackend(const std::string& device) : ctx_(ContextOptions{device, "lc"}) {
        createComputeObjects();
    }
    std::string name() const override { return "vulkan"; }
    std::string deviceName() const override { return ctx_.deviceName(); }
    // Per device. Compute timestamps read wrong on lavapipe once the device
    // has rendered (DESIGN.md), and this device renders the depth pre-pass:
    // there, CPU time around submit + fence wait. A GPU with timestamps in
    // compute and graphics: device time between timestamps written around
    // the passes (uploads and readbacks excluded).
    std::string timingMethod() const override {
        return useGpuTimestamps() ? "gpu-timestamps (vkCmdWriteTimestamp around the passes, sum of submissions)"
                                  : "cpu-wall-clock around vkQueueSubmit+vkWaitForFences";
    }
    std::size_t peakDeviceBytes() const override { return std::size_t(ctx_.memoryStats().peak); }
    void resetPeakDeviceBytes() override { ctx_.resetPeakMemory(); }
    std::uint64_t deviceAllocations() const override { return ctx_.memoryStats().allocations; }

    // The Lambert shading pass (vk/shade_pass.cpp), created on first use.
    std::vector<float> shade(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled) override {
        if (!shadePass_) shadePass_ = std::make_unique<ShadePass>(ctx_);
        return shadePass_->run(in, lights, culled, lastShadeMs_);
    }

protected:
    DepthPass renderDepthPass(const Scene& scene, const Projection& proj) override;
    CullResult cullFrame(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                         const ViewLights& lights, const CullSettings& settings) override;

private:
    bool useGpuTimestamps() const { return !ctx_.isCpuDevice() && ctx_.timestampsSupported(); }
    void createComputeObjects();
    // `oneSubgroup`: the local size is the subgroup size and the pass relies on
    // the workgroup being one subgroup (REQUIRE_FULL_SUBGROUPS where supported).
    VkPipeline computePipeline(const char* what, VkShaderModule module, const SpecConstants& spec,
                               bool oneSubgroup);
    VkPipeline depthPipeline(bool reversed);
    VkRenderPass depthRenderPass(bool reversed);

    Context ctx_;
    // The buffers of the depth pre-pass and the cull, kept between calls
    // (after ctx_: freed before the device).
    BufferCache cache_{ctx_};
    DescriptorSetLayoutHandle setLayout_;
    PipelineLayoutHandle computeLayout_;
    ShaderModuleHandle boundsShader_, boundsWideShader_, binsShader_, binsShuffleShader_, cullShader_, cullShader16_,
        scanShader_, pruneShader_, zbinShader_, vertShader_;
    std::uint32_t lastLongestList_ = 0; // of the previous cull: sizes a CPU device's stash
    bool lastPoolsFitted_ = false;       // of the previous cull: a tile walk's pools held every entry
    // Of the previous cull: its lists and entries size the next one's index array.
    std::uint32_t lastListTotal_ = 0, lastEntries_ = 0;
    std::map<std::string, PipelineHandle> computePipelines_;
    PipelineLayoutHandle depthLayout_;
    RenderPassHandle renderPass_[2];
    PipelineHandle depthPipeline_[2];
    std::unique_ptr<ShadePass> shadePass_;
    // The last rendered depth image, kept on the device for the cull that
    // follows (DepthImage::deviceCopy): its id, buffer and a sample of its
    // pixels that a cull compares before trusting the id.
    // Ids are unique across backends (one counter for the process), so an
    // image another backend rendered never names this one's copy.
    std::uint64_t residentId_ = 0;
    static std::uint64_t nextDepthId() {
        static std::atomic<std::uint64_t> next{0};
        return ++next;
    }
    struct DepthTarget {
        std::uint32_t width = 0, height = 0;
        bool reversed = false;
        Image image;
        FramebufferHandle framebuffer;
        Buffer depth; // the storage buffer the image is copied to
    } depthTarget_;
    std::vector<float> residentSample_;
    // The closed solids of the meshes the last depth pre-pass drew, by
    // meshContentKey.
    std::map<std::uint64_t, std::shared_ptr<const ClosedSolids>> solids_;
    static std::vector<float> depthSample(const DepthImage& d) {
        std::vector<float> s;
        const std::size_t n = d.depth.size(), step = std::max<std::size_t>(1, n / 256);
        for (std::size_t i = 0; i < n; i += step) s.push_back(d.depth[i]);
        if (n) s.push_back(d.depth[n - 1]);
        return s;
    }
    bool isResident(const DepthImage& d) const {
        return d.deviceCopy != 0 && d.deviceCopy == residentId_ && depthTarget_.depth.buffer &&
               residentSample_ == depthSample(d);
    }
};

void VulkanBackend::createComputeObjects() {
    auto layouts = ctx_.createPassLayouts(std::vector<VkDescriptorType>(kBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER), "cull");
    setLayout_ = std::move(layouts.set);
    computeLayout_ = std::move(layouts.pipeline);

    auto mk = [&](spirv::Code c, const char* n) { return ctx_.createShader(c.words, c.wordCount, n); };
    boundsShader_ = mk(spirv::tileBounds(), "shader.tile_bounds");
    if (ctx_.int64Supported()) boundsWideShader_ = mk(spirv::tileBoundsWide(), "shader.tile_bounds_wide");
    binsShader_ = mk(spirv::lightBins(), "shader.light_bins");
    if (ctx_.subgroupShuffleSupported()) binsShuffleShader_ = mk(spirv::lightBinsShuffle(), "shader.light_bins_shuffle");
    cullShader_ = mk(spirv::cullLists(), "shader.cull_lists");
    if (ctx_.index16Supported()) cullShader16_ = mk(spirv::cullListsIndex16(), "shader.cull_lists_index16");
    scanShader_ = mk(spirv::prefixSum(), "shader.prefix_sum");
    pruneShader_ = mk(spirv::finePrune(), "shader.fine_prune");
    zbinShader_ = mk(spirv::zbin(), "shader.zbin");
    vertShader_ = mk(spirv::depthVert(), "shader.depth_vert");
}

// Specialisation constants, ids as in cull_common.glsl (0 local size, 1 tile
// size, 2 cells, 3 slicing, 4 algorithm, 5 sphere test, 6 write pass, 7 lanes
// per tile or list, 8 pixels per depth load, 9 depth bins, ... 16 tests
// wrap). Pipelines are cached per combination.
VkPipeline VulkanBackend::computePipeline(const char* what, VkShaderModule module,
                                          const SpecConstants& spec, bool oneSubgroup) {
    std::string key = what;
    for (auto v : spec) key += "." + std::to_string(v);
    auto it = computePipelines_.find(key);
    if (it != computePipelines_.end()) return it->second;
    std::array<VkSpecializationMapEntry, kSpecConstants> entries{};
    for (std::uint32_t i = 0; i < kSpecConstants; ++i) entries[i] = {i, i * 4u, 4u};
    VkSpecializationInfo si{};
    si.mapEntryCount = kSpecConstants;
    si.pMapEntries = entries.data();
    si.dataSize = sizeof(spec);
    si.pData = spec.data();
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = module;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = &si;
    // Full subgroups: a workgroup of subgroupSize invocations is one subgroup.
    if (oneSubgroup && ctx_.fullSubgroupsSupported())
        ci.stage.flags = VK_PIPELINE_SHADER_STAGE_CREATE_REQUIRE_FULL_SUBGROUPS_BIT;
    ci.layout = computeLayout_;
    VkPipeline p;
    LC_VK(vkCreateComputePipelines(ctx_.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &p));
    ctx_.name(VK_OBJECT_TYPE_PIPELINE, p, "pipeline." + key);
    return computePipelines_.emplace(key, PipelineHandle(ctx_.device(), p)).first->second;
}

VkRenderPass VulkanBackend::depthRenderPass(bool reversed) {
    RenderPassHandle& rp = renderPass_[reversed ? 1 : 0];
    if (rp) return rp;
    VkAttachmentDescription att{};
    att.format = VK_FORMAT_D32_SFLOAT;
    att.samples = VK_SAMPLE_COUNT_1_BIT;
    att.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    att.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    att.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    att.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    att.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    att.finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    VkAttachmentReference ref{0, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    sub.pDepthStencilAttachment = &ref;
    std::array<VkSubpassDependency, 2> deps{};
    // Before: the clear (a depth write at early fragment tests) after the
    // UNDEFINED -> attachment layout transition of a fresh image.
    deps[0].srcSubpass = VK_SUBPASS_EXTERNAL;
    deps[0].dstSubpass = 0;
    deps[0].srcStageMask = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    deps[0].dstStageMask = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    deps[0].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[0].dstAccessMask =
        VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    // After: the copy to the readback buffer reads what the depth test wrote
    // (read-after-write on the attachment, and the layout transition to
    // TRANSFER_SRC ordered between them).
    deps[1].srcSubpass = 0;
    deps[1].dstSubpass = VK_SUBPASS_EXTERNAL;
    deps[1].srcStageMask = VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
    deps[1].dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
    deps[1].srcAccessMask = VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
    deps[1].dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    ci.attachmentCount = 1;
    ci.pAttachments = &att;
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    ci.dependencyCount = std::uint32_t(deps.size());
    ci.pDependencies = deps.data();
    VkRenderPass r;
    LC_VK(vkCreateRenderPass(ctx_.device(), &ci, nullptr, &r));
    ctx_.name(VK_OBJECT_TYPE_RENDER_PASS, r, reversed ? "depth.renderPass.reversed" : "depth.renderPass");
    rp = RenderPassHandle(ctx_.device(), r);
    return rp;
}

VkPipeline VulkanBackend::depthPipeline(bool reversed) {
    PipelineHandle& pipe = depthPipeline_[reversed ? 1 : 0];
    if (pipe) return pipe;
    VkDevice dev = ctx_.device();
    if (!depthLayout_) {
        VkPushConstantRange pc{VK_SHADER_STAGE_VERTEX_BIT, 0, 64};
        VkPipelineLayoutCreateInfo lci{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
        lci.pushConstantRangeCount = 1;
        lci.pPushConstantRanges = &pc;
        VkPipelineLayout l;
        LC_VK(vkCreatePipelineLayout(dev, &lci, nullptr, &l));
        depthLayout_ = PipelineLayoutHandle(dev, l);
        ctx_.name(VK_OBJECT_TYPE_PIPELINE_LAYOUT, l, "depth.pipelineLayout");
    }
    VkPipelineShaderStageCreateInfo stage{VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stage.stage = VK_SHADER_STAGE_VERTEX_BIT;
    stage.module = vertShader_;
    stage.pName = "main";
    VkVertexInputBindingDescription vb{0, 12, VK_VERTEX_INPUT_RATE_VERTEX};
    VkVertexInputAttributeDescription va{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vi.vertexBindingDescriptionCount = 1;
    vi.pVertexBindingDescriptions = &vb;
    vi.vertexAttributeDescriptionCount = 1;
    vi.pVertexAttributeDescriptions = &va;
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = 1;
    vp.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.depthClampEnable = VK_FALSE; // clip at near (and far) like the CPU rasteriser
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE; // both faces, as the CPU rasteriser
    rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    ds.depthTestEnable = VK_TRUE;
    ds.depthWriteEnable = VK_TRUE;
    ds.depthCompareOp = reversed ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS;
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    std::array<VkDynamicState, 2> dyn{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dsi{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dsi.dynamicStateCount = std::uint32_t(dyn.size());
    dsi.pDynamicStates = dyn.data();
    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.stageCount = 1; // depth only: no fragment shader
    ci.pStages = &stage;
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vp;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pDepthStencilState = &ds;
    ci.pColorBlendState = &cb;
    ci.pDynamicState = &dsi;
    ci.layout = depthLayout_;
    ci.renderPass = depthRenderPass(reversed);
    VkPipeline p;
    LC_VK(vkCreateGraphicsPipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &p));
    ctx_.name(VK_OBJECT_TYPE_PIPELINE, p, reversed ? "depth.pipeline.reversed" : "depth.pipeline");
    pipe = PipelineHandle(dev, p);
    return pipe;
}

DepthPass VulkanBackend::renderDepthPass(const Scene& scene, const Projection& proj) {
    DepthPass pass;
    const std::uint32_t W = proj.width(), H = proj.height();
    if (W == 0 || H == 0) throw SettingsError("camera.width", "resolution must be at least 1x1");
    const auto& lim = ctx_.properties().limits;
    if (W > lim.maxFramebufferWidth || H > lim.maxFramebufferHeight || W > lim.maxImageDimension2D ||
        H > lim.maxImageDimension2D)
        throw SettingsError("camera.width", "resolution " + std::to_string(W) + "x" + std::to_string(H) +
                                                " exceeds the device's framebuffer limit");
    const bool reversed = isReversed(proj.kind());
    const float clearDepth = float(proj.clearDepth());
    VkDevice dev = ctx_.device();

    // All meshes in one vertex and one index buffer; one draw per mesh. The
    // index buffer leaves out the faces of closed solids turned away from the
    // camera (scene/closed_solids.hpp): they never win a pixel, and lavapipe
    // pays per fragment rasterised.
    struct Draw {
        glm::mat4 clipFromModel;
        std::uint32_t firstIndex, indexCount;
        std::int32_t vertexOffset;
    };
    std::vector<Draw> draws;
    std::vector<glm::dvec3> centres; // per drawn mesh, model space
    std::vector<std::uint32_t> ix;
    std::size_t vertexFloats = 0;
    const glm::dmat4 viewFromWorld = scene.camera.viewFromWorld();
    const glm::dmat4 clipFromWorld = proj.clipFromView() * viewFromWorld;
    std::map<std::uint64_t, std::shared_ptr<const ClosedSolids>> solidsInUse;
    const std::size_t sceneIndices = 3 * scene.triangleCount();
    ix.reserve(sceneIndices);
    for (const Mesh& m : scene.meshes) {
        if (m.triangleCount() == 0) continue;
        // A mesh that sits farther from its model origin than its own size
        // goes up relative to the centre of its bounding box (subtracted in
        // double) and the matrix takes the centre back: float then only holds
        // small coordinates and a camera-relative matrix, so a scene far from
        // the origin (1e5) keeps its depth precision instead of cancelling two
        // large float terms in the shader. Other meshes go up unchanged (the
        // shift would only move their rounding).
        glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
        for (std::size_t i = 0; i < m.vertexCount(); ++i) {
            const glm::dvec3 p(m.positions[3 * i], m.positions[3 * i + 1], m.positions[3 * i + 2]);
            lo = glm::min(lo, p);
            hi = glm::max(hi, p);
        }
        glm::dvec3 c = m.vertexCount() ? 0.5 * (lo + hi) : glm::dvec3(0.0);
        if (!(glm::length(c) > glm::length(hi - lo))) c = glm::dvec3(0.0);
        centres.push_back(c);
        // The mesh's solids, found once per mesh content.
        const std::uint64_t key = meshContentKey(m);
        auto known = solids_.find(key);
        std::shared_ptr<const ClosedSolids> solids =
            known != solids_.end() ? known->second : std::make_shared<const ClosedSolids>(findClosedSolids(m));
        solidsInUse.emplace(key, solids);
        const std::size_t first = ix.size();
        appendDepthTriangles(m, *solids, viewFromWorld * m.transform, proj, ix);
        // Composed in double, rounded once to float.
        draws.push_back({glm::mat4(clipFromWorld * m.transform * glm::translate(glm::dmat4(1.0), c)),
                         std::uint32_t(first), std::uint32_t(ix.size() - first), std::int32_t(vertexFloats / 3)});
        vertexFloats += m.vertexCount() * 3;
    }
    solids_ = std::move(solidsInUse); // the analyses of meshes no longer drawn go
    pass.triangles = sceneIndices / 3;
    pass.trianglesDrawn = ix.size() / 3;
    // Device-local vertex and index buffers (staged on a discrete GPU), the
    // index buffer sized for every triangle so that turning the camera does
    // not resize it.
    const Buffer& vbuf = cache_.get("depth.vertices", vertexFloats * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                                    BufferCache::Kind::Device);
    const Buffer& ibuf = cache_.get("depth.indices", sceneIndices * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                    BufferCache::Kind::Device);
    Staging staging(cache_);
    {
        std::vector<float> v;
        v.reserve(vertexFloats);
        std::size_t drawn = 0;
        for (const Mesh& m : scene.meshes) {
            if (m.triangleCount() == 0) continue;
            const glm::dvec3 c = centres[drawn++];
            for (std::size_t i = 0; i < m.vertexCount() * 3; ++i)
                v.push_back(float(double(m.positions[i]) - c[int(i % 3)]));
        }
        staging.upload(vbuf, v.data(), v.size() * 4, "depth.vertices");
        staging.upload(ibuf, ix.data(), ix.size() * 4, "depth.indices");
    }
    VkRenderPass rp = depthRenderPass(reversed);
    VkPipeline pipe = depthPipeline(reversed);
    // The depth image, its framebuffer and the storage buffer the depth goes
    // to (the cull reads it in place, no readback and upload between the
    // passes; the host gets it from there) are kept while the resolution and
    // the depth direction stay: fresh ones cost lavapipe a page fault per
    // 4 KiB page touched, milliseconds at 1080p.
    if (depthTarget_.width != W || depthTarget_.height != H || depthTarget_.reversed != reversed ||
        !depthTarget_.framebuffer) {
        depthTarget_ = DepthTarget{};
        depthTarget_.image = ctx_.createDepthImage(W, H, VK_FORMAT_D32_SFLOAT, "depth.image");
        VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
        fci.renderPass = rp;
        fci.attachmentCount = 1;
        VkImageView view = depthTarget_.image.view;
        fci.pAttachments = &view;
        fci.width = W;
        fci.height = H;
        fci.layers = 1;
        VkFramebuffer fbRaw;
        LC_VK(vkCreateFramebuffer(dev, &fci, nullptr, &fbRaw));
        depthTarget_.framebuffer = FramebufferHandle(dev, fbRaw);
        ctx_.name(VK_OBJECT_TYPE_FRAMEBUFFER, fbRaw, "depth.framebuffer");
        depthTarget_.depth = ctx_.createDeviceBuffer(
            VkDeviceSize(W) * H * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
            "depth.resident");
        depthTarget_.width = W;
        depthTarget_.height = H;
        depthTarget_.reversed = reversed;
    }
    residentId_ = 0; // rewritten below: no earlier image names it any more
    const Buffer& resident = depthTarget_.depth;
    const Image& img = depthTarget_.image;
    VkFramebuffer fb = depthTarget_.framebuffer;
    Staging back(cache_);
    const void* pixels = back.download(resident, std::size_t(W) * H * 4, "depth.resident");

    const bool gpuClock = useGpuTimestamps();
    TimestampPool stamps = gpuClock ? TimestampPool(ctx_, 1, "depth.timestamps") : TimestampPool();
    const double wallMs = ctx_.submitAndWait(
        [&](VkCommandBuffer cmd) {
            if (gpuClock) stamps.reset(cmd);
            staging.recordUploads(cmd, VK_PIPELINE_STAGE_VERTEX_INPUT_BIT,
                                  VK_ACCESS_VERTEX_ATTRIBUTE_READ_BIT | VK_ACCESS_INDEX_READ_BIT);
            if (gpuClock) stamps.begin(cmd, 0);
            VkClearValue clear{};
            clear.depthStencil.depth = clearDepth;
            VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
            rbi.renderPass = rp;
            rbi.framebuffer = fb;
            rbi.renderArea = {{0, 0}, {W, H}};
            rbi.clearValueCount = 1;
            rbi.pClearValues = &clear;
            vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
            if (!draws.empty()) {
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
                VkViewport vpt{0.0f, 0.0f, float(W), float(H), 0.0f, 1.0f};
                VkRect2D sc{{0, 0}, {W, H}};
                vkCmdSetViewport(cmd, 0, 1, &vpt);
                vkCmdSetScissor(cmd, 0, 1, &sc);
                VkDeviceSize off = 0;
                VkBuffer vb = vbuf.buffer;
                vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &off);
                vkCmdBindIndexBuffer(cmd, ibuf.buffer, 0, VK_INDEX_TYPE_UINT32);
                for (const Draw& d : draws) {
                    if (d.indexCount == 0) continue;
                    vkCmdPushConstants(cmd, depthLayout_, VK_SHADER_STAGE_VERTEX_BIT, 0, 64,
                                       glm::value_ptr(d.clipFromModel));
                    vkCmdDrawIndexed(cmd, d.indexCount, 1, d.firstIndex, d.vertexOffset, 0);
                }
            }
            vkCmdEndRenderPass(cmd);
            if (gpuClock) stamps.end(cmd, 0);
            VkBufferImageCopy region{};
            region.imageSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
            region.imageExtent = {W, H, 1};
            vkCmdCopyImageToBuffer(cmd, img.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, resident.buffer, 1, &region);
            // The readback copy (or, mapped, the host) reads what the image copy wrote.
            memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
            back.recordDownloads(cmd);
        },
        "depth.commands");
    // GPU: the render pass alone; CPU device: the whole submission (the
    // readback copy included).
    pass.ms = gpuClock ? stamps.milliseconds(0) : wallMs;
    pass.wallMs = wallMs;

    DepthImage& out = pass.image;
    out.width = W;
    out.height = H;
    out.clearDepth = clearDepth;
    const float* px = static_cast<const float*>(pixels);
    out.depth.assign(px, px + std::size_t(W) * H);
    residentId_ = out.deviceCopy = nextDepthId();
    residentSample_ = depthSample(out);
    return pass;
}

CullResult VulkanBackend::cullFrame(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                                    const ViewLights& lights, const CullSettings& settings) {
    const TileGrid& grid = frame.grid;
    // Spot lights: the sphere tests need only the chosen sphere (below); the
    // cone tests also upload each spot's cone (binding 9).
    const bool coneTests = settings.spotTest == SpotTest::ConeSphere || settings.spotTest == SpotTest::ConePlanes;
    const bool fptl = settings.algorithm == Algorithm::Fptl;
    // fptl's fine prune tests every spot's cone at the pixels, whatever the spot test.
    const bool spotCones = !lights.spotAngles.empty() && (coneTests || fptl);

    const Algorithm algo = settings.algorithm;
    const std::uint32_t tiles = grid.tileCount(), cells = settings.cells;
    const std::uint32_t n = std::uint32_t(lights.size());
    const auto& lim = ctx_.properties().limits;
    if (grid.tilesX > lim.maxComputeWorkGroupCount[0] || grid.tilesY > lim.maxComputeWorkGroupCount[1])
        throw SettingsError("tile", "too many tiles for one dispatch on this device");

    CullResult res;
    res.algorithm = algo;
    res.settings = settings;
    res.grid = grid;
    res.listsPerTile = frame.listsPerTile;
    const std::uint64_t listTotal64 = frame.listTotal;
    if (listTotal64 >= std::numeric_limits<std::uint32_t>::max())
        throw SettingsError("tile", "more than 2^32 light lists");
    const std::uint32_t listTotal = std::uint32_t(listTotal64);
    // Stash slots per list: kMaxStashSlots, doubled up to stashCap while the
    // previous cull's longest list needed more; fewer where that would
    // outgrow the depth image (clustered has many lists); none for `all`.
    const std::uint32_t stashCap = ctx_.isCpuDevice() ? kMaxStashSlotsCpu : kMaxStashSlots;
    std::uint32_t maxStashSlots = kMaxStashSlots;
    while (maxStashSlots < stashCap && maxStashSlots < lastLongestList_) maxStashSlots *= 2;
    const std::uint32_t stashSlots =
        algo == Algorithm::All ? 0
                               : std::uint32_t(std::min<std::uint64_t>(maxStashSlots, depth.depth.size() / listTotal64));
    // Light bins: one bit per light per tile column and per tile row, then
    // per depth bin twice (near ends, far ends; light_bins.comp). `naive`
    // spans every light's depth and `all` tests nothing: no depth bins.
    const bool zbin = algo == Algorithm::ZBin;
    const bool depthBins = algo != Algorithm::All && algo != Algorithm::Naive && !zbin && n > 0;
    // Words per column, row or depth bin: a bit per light, padded to whole
    // uvec4s (cull_lists.comp reads four words a load on a CPU device).
    const std::uint32_t binWords = (n + 127) / 128 * 4;
    const std::uint64_t planeBinWords = std::uint64_t(binWords) * (grid.tilesX + grid.tilesY);
    const std::uint64_t depthBinWords = depthBins ? std::uint64_t(binWords) * LC_DEPTH_BINS : 0;
    // zbin: its bins' (lo, hi) after the plane bins.
    const std::uint64_t binTotal64 = planeBinWords + 2 * depthBinWords + (zbin ? 2 * std::uint64_t(settings.bins) : 0);
    if (binTotal64 * 4 > lim.maxStorageBufferRange)
        throw SettingsError("lights", "too many lights for the light bins of this device");

    // The depth ranges of naive and clustered: the frame's, as the CPU reference's.
    const std::vector<BoundingSphere>& cullSpheres = frame.cullSpheres; // range spheres, or each spot test's
    double lightFar = 0.0, lightNear = kInf; // the light bins' depth span
    for (std::size_t l = 0; l < n; ++l) {
        lightFar = std::max(lightFar, -cullSpheres[l].center.z + cullSpheres[l].radius);
        lightNear = std::min(lightNear, -cullSpheres[l].center.z - cullSpheres[l].radius);
    }
    const bool farInfinite = !std::isfinite(proj.farPlane());
    const double camNear = frame.cameraNear;
    const double naiveFar = frame.cameraFar;
    if (algo == Algorithm::Clustered) {
        res.clusterNear = frame.clusterNear;
        res.clusterFar = frame.clusterFar;
    }
    // zbin: the lights go up sorted by depth (as the CPU reference sorts them).
    std::vector<std::uint32_t> upOrder(n);
    for (std::uint32_t l = 0; l < n; ++l) upOrder[l] = l;
    if (zbin) {
        std::vector<double> centreDepth(n);
        for (std::uint32_t l = 0; l < n; ++l) centreDepth[l] = -cullSpheres[l].center.z;
        zbinSortLights(centreDepth, res.zbinOrder, res.zbinRank);
        upOrder = res.zbinOrder;
        res.zbinNear = camNear;
        res.zbinFar = naiveFar;
    }

    // Inputs, prepared on the host.
    GpuCullParams p{};
    {
        std::uint32_t flags = 0;
        if (proj.orthographic()) flags |= LC_FLAG_ORTHO;
        if (isReversed(proj.kind())) flags |= LC_FLAG_REVERSED;
        if (farInfinite) flags |= LC_FLAG_FAR_INFINITE;
        if (settings.skipEmpty) flags |= LC_FLAG_SKIP_EMPTY;
        p.size = glm::uvec4(grid.width, grid.height, grid.tilesX, grid.tilesY);
        p.counts = glm::uvec4(n, res.listsPerTile, listTotal, flags);
        double a, b;
        depthConstants(proj, a, b);
        const float aHi = float(a);
        p.depth = glm::vec4(aHi, float(b), float(a - double(aHi)), depth.clearDepth);
        const glm::dvec3 corner = proj.viewPositionAt({double(proj.width()), 0.0}, 1.0);
        p.lens = glm::vec4(float(corner.x), float(corner.y), float(camNear), float(naiveFar));
        p.cluster = glm::vec4(float(res.clusterNear), float(res.clusterFar), kRelEps, kAbsEps);
        p.bins = glm::uvec4(binWords, binWords * grid.tilesX, stashSlots, std::uint32_t(planeBinWords));
        p.depthBins = depthBinSlicing(proj, camNear, lightNear, lightFar);
        if (zbin)
            p.depthBins = glm::vec4(float(camNear), naiveFar > camNear ? float(settings.bins / (naiveFar - camNear)) : 0.0f,
                                    float(settings.bins), 0.0f);
    }
    std::vector<GpuLight> gpuLights(n);
    for (std::uint32_t k = 0; k < n; ++k) {
        const BoundingSphere& s = cullSpheres[upOrder[k]];
        gpuLights[k].centerRadius = glm::vec4(glm::vec3(s.center), float(s.radius));
    }
    // One cone per light under a cone test (range 0: a point light), else a
    // single unused element.
    std::vector<GpuSpotCone> gpuSpots(spotCones ? n : 1, GpuSpotCone{});
    if (spotCones)
        for (std::uint32_t k = 0; k < n; ++k) {
            const std::uint32_t l = upOrder[k];
            if (!lights.isSpot(l)) continue;
            const SpotCone c = lights.spotCone(l);
            gpuSpots[k].apexRange = glm::vec4(glm::vec3(c.apex), float(c.range));
            gpuSpots[k].axisCos = glm::vec4(glm::vec3(c.axis), float(c.cosAngle));
            gpuSpots[k].sinAngle = glm::vec4(float(c.sinAngle), 0.0f, 0.0f, 0.0f);
        }
    // The status word and the test counters (gpu_shared.h), zeroed.
    constexpr std::size_t kStatusWords = 1 + std::size_t(LC_TEST_COUNTERS) * LC_TEST_COUNTER_STRIDE;
    static const std::array<std::uint32_t, kStatusWords> statusZero{};

    // Device buffers (sizes from the inputs; the index array comes after the count).
    const VkBufferUsageFlags ssbo = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
    // Descriptor ranges: the bytes each buffer was asked for (a kept buffer
    // may be larger; the passes see only this call's part).
    std::map<VkBuffer, VkDeviceSize> asked;
    auto deviceBuffer = [&](const std::string& role, std::size_t bytes) -> const Buffer& {
        const Buffer& b = cache_.get(role, bytes, ssbo, BufferCache::Kind::Device);
        asked[b.buffer] = std::max<VkDeviceSize>(bytes, 4);
        return b;
    };
    const Buffer& params = deviceBuffer("cull.params", sizeof(GpuCullParams));
    // The depth this backend rendered is on the device already.
    const bool residentDepth = isResident(depth);
    const Buffer& depthBuf =
        residentDepth ? depthTarget_.depth : deviceBuffer("cull.depth", depth.depth.size() * 4);
    if (residentDepth) asked[depthBuf.buffer] = depthBuf.size;
    const Buffer& tileBuf = deviceBuffer("cull.tiles", std::size_t(tiles) * sizeof(GpuTileBounds));
    const Buffer& lightBuf = deviceBuffer("cull.lights", std::size_t(n) * sizeof(GpuLight));
    const Buffer& binBuf = deviceBuffer("cull.bins", binTotal64 * 4);
    const Buffer& countBuf = deviceBuffer("cull.counts", std::size_t(listTotal) * 4);
    const Buffer& offsetBuf = deviceBuffer("cull.offsets", (std::size_t(listTotal) + 1) * 4);
    const Buffer& statusBuf = deviceBuffer("cull.status", kStatusWords * 4); // status bits, test counters
    const Buffer& placeholder = deviceBuffer("cull.indices.placeholder", 4);
    const Buffer& spotBuf = deviceBuffer("cull.spots", gpuSpots.size() * sizeof(GpuSpotCone));
    const std::size_t stashBytes = std::size_t(listTotal) * stashSlots * 4;
    const Buffer& stashBuf = deviceBuffer("cull.stash", stashBytes);

    Staging staging(cache_);
    staging.upload(params, &p, sizeof p, "cull.params");
    if (!residentDepth) staging.upload(depthBuf, depth.depth.data(), depth.depth.size() * 4, "cull.depth");
    staging.upload(lightBuf, gpuLights.data(), gpuLights.size() * sizeof(GpuLight), "cull.lights");
    staging.upload(spotBuf, gpuSpots.data(), gpuSpots.size() * sizeof(GpuSpotCone), "cull.spots");
    staging.upload(statusBuf, statusZero.data(), kStatusWords * 4, "cull.status");
    const auto* counts = static_cast<const std::uint32_t*>(
        staging.download(countBuf, std::size_t(listTotal) * 4, "cull.counts"));
    const auto* offs = static_cast<const std::uint32_t*>(
        staging.download(offsetBuf, (std::size_t(listTotal) + 1) * 4, "cull.offsets"));
    const auto* tb = static_cast<const GpuTileBounds*>(
        staging.download(tileBuf, std::size_t(tiles) * sizeof(GpuTileBounds), "cull.tiles"));
    const auto* status =
        static_cast<const std::uint32_t*>(staging.download(statusBuf, kStatusWords * 4, "cull.status"));
    // The write pass runs in the same submission (no read-back between the
    // passes) into an index array sized from the previous cull's entries with
    // as many lists, with a margin (else the stash's size); only when the
    // lists outgrow it does a second submission write them again, sized
    // exactly. fptl prunes the written lists by entry: always a second
    // submission, sized exactly.
    const std::size_t firstCapacity =
        lastListTotal_ == listTotal && lastEntries_ > 0
            ? std::size_t(lastEntries_) + std::size_t(lastEntries_) / 16 + 256
            : std::max<std::size_t>(std::size_t(listTotal) * stashSlots, 1);
    // On a CPU device the stash is host memory: when the previous cull's
    // lists fitted it, the host takes the lists from there (a write pass
    // copying them cost lavapipe more, 4.2-4.3 against 3.8-4.5 ms at P1).
    const auto* stashed =
        ctx_.isCpuDevice() && stashBytes
            ? static_cast<const std::uint32_t*>(staging.download(stashBuf, stashBytes, "cull.stash"))
            : nullptr;
    const auto* binWordsOut =
        zbin ? static_cast<const std::uint32_t*>(staging.download(binBuf, binTotal64 * 4, "cull.bins"))
             : nullptr;

    // Descriptor sets: one for passes 1-3, one with the sized index array for pass 4.
    VkDevice dev = ctx_.device();
    VkDescriptorPoolSize ps{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2 * kBindings};
    VkDescriptorPoolCreateInfo dpci{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    dpci.maxSets = 2;
    dpci.poolSizeCount = 1;
    dpci.pPoolSizes = &ps;
    VkDescriptorPool poolRaw;
    LC_VK(vkCreateDescriptorPool(dev, &dpci, nullptr, &poolRaw));
    DescriptorPoolHandle pool(dev, poolRaw);
    ctx_.name(VK_OBJECT_TYPE_DESCRIPTOR_POOL, poolRaw, "cull.descriptorPool");
    auto makeSet = [&](const Buffer& indices, const char* nm) {
        VkDescriptorSetLayout sl = setLayout_;
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = pool;
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &sl;
        VkDescriptorSet set;
        LC_VK(vkAllocateDescriptorSets(dev, &ai, &set));
        ctx_.name(VK_OBJECT_TYPE_DESCRIPTOR_SET, set, nm);
        const Buffer* bufs[kBindings] = {&params,    &depthBuf, &tileBuf,   &lightBuf, &countBuf,
                                         &offsetBuf, &indices,  &statusBuf, &binBuf,  &spotBuf,
                                         &stashBuf};
        std::array<VkDescriptorBufferInfo, kBindings> infos{};
        std::array<VkWriteDescriptorSet, kBindings> writes{};
        for (std::uint32_t i = 0; i < kBindings; ++i) {
            infos[i] = {bufs[i]->buffer, 0, asked.at(bufs[i]->buffer)};
            writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            writes[i].dstSet = set;
            writes[i].dstBinding = i;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        vkUpdateDescriptorSets(dev, kBindings, writes.data(), 0, nullptr);
        return set;
    };

    const std::uint32_t sg = ctx_.subgroupSize();
    const std::uint32_t algoId = std::uint32_t(algo), testId = std::uint32_t(settings.test),
                        slicingId = std::uint32_t(settings.slicing);
    // The spot refinement as a specialisation constant, not a parameter:
    // lavapipe runs an if's body whatever its condition (masked), so a
    // runtime choice cost every test the spot cone's loads and tests, spot
    // lights or none (P1 / clustered 4.5-4.6 -> 4.2 ms).
    const std::uint32_t spotTestId = !(spotCones && coneTests)                 ? LC_SPOT_NONE
                                     : settings.spotTest == SpotTest::ConeSphere ? LC_SPOT_CONE_SPHERE
                                                                                 : LC_SPOT_CONE_PLANES;
    // Cell ranges that start beyond 0 wherever the bounds pass maps pixels
    // (tile_bounds.comp, CELL_LOG): log slicing with a perspective camera
    // (geometry lies beyond the near plane) and, for clustered, its near.
    const std::uint32_t cellLog = settings.slicing == Slicing::Log && !proj.orthographic() &&
                                  (algo != Algorithm::Clustered || float(res.clusterNear) > 0.0f);
    // Mask words per lane a GPU list walk keeps in registers (cull_lists.comp,
    // KEPT_WORDS): as many as the bins have per lane, at most 4. Fewer
    // registers where the lights are few (P1 on the H100: 0.0205-0.0206 ->
    // 0.0203 ms against 4).
    const std::uint32_t keptWords = std::clamp<std::uint32_t>((binWords + sg - 1) / sg, 1, 4);
    // Whether a test counter could wrap around 2^32: a counter takes the
    // tests of every LC_TEST_COUNTERS-th list (or tile walk, fewer than the
    // lists), each at most every light, counted at most twice.
    const std::uint64_t perCounter = (std::uint64_t(listTotal) + LC_TEST_COUNTERS - 1) / LC_TEST_COUNTERS;
    const std::uint32_t testsWrap = 2 * perCounter * n > std::numeric_limits<std::uint32_t>::max() ? 1u : 0u;
    auto spec = [&](std::uint32_t local, std::uint32_t write, std::uint32_t lanesPerTile = 1,
                    std::uint32_t depthLoad = 2, std::uint32_t tileWalk = 0, std::uint32_t binLanes = 1) {
        return SpecConstants{local,      grid.tileSize, cells,    slicingId,  algoId,   testId,  write,
                             lanesPerTile, depthLoad, depthBins ? 1u : 0u, tileWalk, spotTestId, binLanes, cellLog,
                             proj.orthographic() ? 1u : 0u, keptWords, testsWrap};
    };
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
    const std::uint64_t itersPerList = std::uint64_t(binWords) * 65 + 64 + stashCap;
    std::uint32_t lanes = sg;
    if (kLocal % sg != 0) lanes = 1;
    else if (ctx_.isCpuDevice()) lanes = itersPerList <= kLoopLimit ? 1 : sg;
    // fptl's passes: a tile's pixels plus a 32-step search per entry, a
    // list's entries (at most the lights) per list.
    if (fptl && ctx_.isCpuDevice() &&
        (std::uint64_t(grid.tileSize) * grid.tileSize + 32 > kLoopLimit || n > kLoopLimit))
        throw SettingsError("tile", "fptl on '" + ctx_.deviceName() + "' takes tiles of at most 255 pixels and at most " +
                                        std::to_string(kLoopLimit) +
                                        " lights (the driver caps a shader invocation at 65,535 loop iterations)");
    if (ctx_.isCpuDevice() && itersPerList / lanes > kLoopLimit)
        throw SettingsError("lights", std::to_string(n) + " lights is more than the culling passes can take on '" +
                                          ctx_.deviceName() + "' (at most " +
                                          std::to_string((kLoopLimit - 64 - stashCap) / 65 * lanes * 32) +
                                          ": the driver caps a shader invocation at 65,535 loop iterations)");
    const bool subgroupLanes = lanes > 1;
    const std::uint32_t itemsPerGroup = kLocal / lanes;
    // clustered on a CPU device: an invocation per tile and `walk` slices
    // (cull_lists.comp, clusteredTileWalk), as many as its loops fit the cap:
    // the words, per candidate at most walk + 3 iterations (its slice range,
    // found without a loop, walked), the slices' counts and checks, and the
    // stashed lists copied. Fewer invocations walk the words fewer times.
    std::uint32_t walk = 0;
    if (algo == Algorithm::Clustered && ctx_.isCpuDevice() && lanes == 1)
        for (std::uint32_t s : {32u, 16u, 8u, 4u}) {
            const std::uint64_t iters = std::uint64_t(binWords) + (s + 3ull) * n + 6ull * s + std::uint64_t(s) * stashCap;
            if (iters <= kLoopLimit) {
                walk = std::min(s, cells);
                break;
            }
        }
    const std::uint64_t listItems =
        walk ? std::uint64_t(tiles) * ((cells + walk - 1) / walk) : std::uint64_t(listTotal) * lanes;
    // A write pass in the first submission unless the previous cull's lists
    // all fitted the stash (a tile walk's: its pools, cull_lists.comp).
    const bool stashHeldLast = walk ? lastPoolsFitted_ : lastLongestList_ <= stashSlots;
    const bool writeFirst = !fptl && !(stashed && stashHeldLast) && firstCapacity * 4 <= lim.maxStorageBufferRange;
    // A tile walk taking its lists from the pools needs no scan on the
    // device: the host adds up the counts (the scan of P1 / clustered's
    // 261,120 counts took lavapipe about 1 ms).
    const bool hostScan = walk != 0 && !writeFirst;
    // Wide depth loads (tile_bounds.comp): an invocation per tile
    // (LC_WIDE_DEPTH_LOADS), 8 or 2 pixels a load; a subgroup per tile, 4 a
    // load; where the width and the tile size are multiples of it, so every
    // tile row starts on a whole load.
    auto loadsOf = [&](std::uint32_t px) { return grid.width % px == 0 && grid.tileSize % px == 0; };
    const std::uint32_t depthLoad = lanes != 1             ? (loadsOf(4) ? 4 : 1)
                                    : !ctx_.int64Supported() ? 1
                                    : loadsOf(8)             ? 8
                                    : loadsOf(2)             ? 2
                                                             : 1;
    VkPipeline boundsPipe =
        lanes == 1 && depthLoad > 1
            ? computePipeline("tile_bounds.wide", boundsWideShader_, spec(kLocal, 0, lanes, depthLoad), false)
            : computePipeline("tile_bounds", boundsShader_, spec(kLocal, 0, lanes, depthLoad), subgroupLanes);
    const Grid boundsGroups = Grid{(grid.tilesX + itemsPerGroup - 1) / itemsPerGroup, grid.tilesY};
    // The bins pass on a GPU: two invocations per mask word, 16 lights each,
    // their masks ORed by a subgroup shuffle: half the loop on the path to
    // the list pass (P1 on the H100: 0.023 -> 0.021 ms, the Live scene 0.025
    // -> 0.022; four or eight a word: P2 0.326 -> 0.341-0.344).
    // (Whole subgroups in a workgroup, as the list passes ask.)
    const std::uint32_t binLanes = !ctx_.isCpuDevice() && binsShuffleShader_ && kLocal % sg == 0 ? 2 : 1;
    VkPipeline binsPipe = binLanes > 1 ? computePipeline("light_bins.shuffle", binsShuffleShader_,
                                                         spec(kLocal, 0, 1, 2, 0, binLanes), true)
                                       : computePipeline("light_bins", binsShader_, spec(kLocal, 0), false);
    VkPipeline countPipe =
        computePipeline("cull_lists.count", cullShader_, spec(kLocal, 0, lanes, 2, walk), subgroupLanes);
    VkPipeline writePipe =
        computePipeline("cull_lists.write", cullShader_, spec(kLocal, 1, lanes, 2, walk), subgroupLanes);
    VkPipeline prunePipe = fptl ? computePipeline("fine_prune", pruneShader_, spec(kLocal, 0), false) : VK_NULL_HANDLE;
    VkPipeline packPipe = fptl ? computePipeline("fine_prune.pack", pruneShader_, spec(kLocal, 1), false) : VK_NULL_HANDLE;
    VkPipeline zbinInitPipe = zbin ? computePipeline("zbin.init", zbinShader_, spec(kLocal, 0), false) : VK_NULL_HANDLE;
    VkPipeline zbinPipe = zbin ? computePipeline("zbin", zbinShader_, spec(kLocal, 1), false) : VK_NULL_HANDLE;
    const Grid zbinInitGroups = groupsFor(settings.bins, lim), zbinGroups = groupsFor(n, lim);
    // Scan: one subgroup on a CPU device while each lane's run (read and
    // write: 2 loop iterations per list) fits the loop cap, else wide.
    const bool wideScan = !ctx_.isCpuDevice() || 2 * (std::uint64_t(listTotal) / sg + 1) > kLoopLimit / 2;
    const std::uint32_t scanLocal =
        wideScan ? std::min({1024u, lim.maxComputeWorkGroupInvocations, lim.maxComputeWorkGroupSize[0], 128 * sg}) : sg;
    VkPipeline scanPipe = computePipeline("prefix_sum", scanShader_, spec(scanLocal, 0, wideScan ? sg : 1), true);
    const bool all = algo == Algorithm::All;
    // On a GPU the count pass writes the lists too (fused, WRITE_PASS 2):
    // each list takes its range of the index array with an atomic add on the
    // total, so neither the scan nor a write pass waits on the count pass
    // (P1 on the H200: the scan cost 10 of 40 us, the write pass 5; clustered's
    // scan of 261,120 counts 400 of 582 us). The ranges come in no fixed
    // order; the host reads each list at its range.
    const bool fused = writeFirst && !ctx_.isCpuDevice() && subgroupLanes && !all;
    // clustered's tile walk (CPU devices) keeps its write pass but drops the
    // scan before it the same way: a walk's lists take their ranges by one
    // atomic add (P1 on lavapipe: the scan of 261,120 counts cost 1.1 ms).
    const bool atomicWrite = writeFirst && walk != 0;
    const bool atomicRanges = fused || atomicWrite;
    VkPipeline atomicWritePipe =
        atomicWrite ? computePipeline("cull_lists.write.atomic", cullShader_, spec(kLocal, 3, lanes, 2, walk), false)
                    : VK_NULL_HANDLE;
    // The fused pass writes 16-bit light indices while the lights fit them
    // (zbin's sorted positions too: below the light count): half the bytes
    // to write and to read back (P3 on the H100: 33 MB of lists).
    const bool index16 = fused && n <= 65536 && ctx_.index16Supported();
    VkPipeline fusedPipe =
        !fused    ? VK_NULL_HANDLE
        : index16 ? computePipeline("cull_lists.fused.index16", cullShader16_,
                                    spec(kLocal, 2, lanes, 2, walk), true)
                  : computePipeline("cull_lists.fused", cullShader_, spec(kLocal, 2, lanes, 2, walk), true);
    const std::size_t entryBytes = index16 ? 2 : 4;
    const Buffer& firstIndices =
        writeFirst ? deviceBuffer("cull.indices.first", (firstCapacity * entryBytes + 3) / 4 * 4)
                   : placeholder;
    const void* firstOut =
        writeFirst ? staging.download(firstIndices, firstCapacity * entryBytes, "cull.indices.first")
                   : nullptr;
    const auto* firstIdx = index16 ? nullptr : static_cast<const std::uint32_t*>(firstOut);
    VkDescriptorSet set1 = makeSet(firstIndices, "cull.set.count");
    // One bins invocation per plane word and per pair of depth-bin words.
    const Grid binGroups = groupsFor((planeBinWords + depthBinWords) * binLanes, lim);
    const Grid countGroups = groupsFor(all ? 1 : listItems, lim);
    const Grid writeGroups = groupsFor(all ? n : listItems, lim);
    const Grid packGroups = groupsFor(listTotal, lim);

    // A dispatch that reads (or ORs into) what the dispatches before it wrote.
    auto dispatchAfter = [](VkCommandBuffer cmd, VkPipeline pipe, Grid groups) {
        computeBarrier(cmd, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
        vkCmdDispatch(cmd, groups.x, groups.y, 1);
    };
    const bool gpuClock = useGpuTimestamps();
    TimestampPool stamps = gpuClock ? TimestampPool(ctx_, 2, "cull.timestamps") : TimestampPool();
    double wallMs = ctx_.submitAndWait(
        [&](VkCommandBuffer cmd) {
            if (gpuClock) stamps.reset(cmd);
            // The total the lists' atomic adds start from, zeroed with the
            // uploads and under their barrier: as a transfer command between
            // the passes, with a barrier of its own, it cost P1 on the H100
            // 4 us of 29.
            if (atomicRanges) vkCmdFillBuffer(cmd, offsetBuf.buffer, VkDeviceSize(listTotal) * 4, 4, 0);
            staging.recordUploads(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, atomicRanges);
            // The passes read the depth the depth submission's copy wrote.
            if (residentDepth)
                memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
            if (gpuClock) stamps.begin(cmd, 0);
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, computeLayout_, 0, 1, &set1, 0, nullptr);
            if (!all && n > 0) {
                // The bins pass first, with no barrier between it and the
                // bounds pass: it reads only params and lights and writes only
                // the bins, which the bounds pass never touches. Dispatched
                // first, its few workgroups (a loop over a word's lights) start
                // before the bounds pass's fill the GPU, instead of waiting
                // for them (P1 on the H100: 0.024-0.025 -> 0.022 ms).
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, binsPipe);
                vkCmdDispatch(cmd, binGroups.x, binGroups.y, 1);
            }
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, boundsPipe);
            vkCmdDispatch(cmd, boundsGroups.x, boundsGroups.y, 1);
            if (zbin) {
                // The bins' words follow the plane bins' in one buffer: ordered
                // after light_bins, then the empty ranges before the lights.
                dispatchAfter(cmd, zbinInitPipe, zbinInitGroups);
                if (n > 0) dispatchAfter(cmd, zbinPipe, zbinGroups);
            }
            // The count pass reads the tile bounds and bins the two passes above wrote
            // (and ORs status after the bounds pass did).
            if (fused) {
                dispatchAfter(cmd, fusedPipe, countGroups);
            } else if (atomicWrite) {
                dispatchAfter(cmd, countPipe, countGroups);
                // The write pass reads the counts the count pass wrote.
                dispatchAfter(cmd, atomicWritePipe, writeGroups);
            } else {
                dispatchAfter(cmd, countPipe, countGroups);
                if (!hostScan) {
                    // The scan reads the counts the count pass wrote.
                    dispatchAfter(cmd, scanPipe, Grid{1, 1});
                    // The write pass reads the offsets the scan wrote.
                    if (writeFirst) dispatchAfter(cmd, writePipe, writeGroups);
                }
            }
            if (gpuClock) stamps.end(cmd, 0);
            staging.recordDownloads(cmd);
        },
        "cull.commands.count");
    double gpuMs = gpuClock ? stamps.milliseconds(0) : 0.0;

    if (*status & 1u)
        throw DeviceError("Vulkan device '" + ctx_.deviceName() +
                          "' split a subgroup-sized workgroup into several subgroups; the culling passes need one");
    const std::string loopLimitError = "Vulkan device '" + ctx_.deviceName() +
                                       "' ended a culling shader loop early (a driver loop cap); result discarded";
    if (*status & 8u) throw DeviceError(loopLimitError);
    const std::string countMismatchError = "Vulkan write pass found a different entry count than the count pass";
    if (*status & 2u) throw DeviceError(countMismatchError);
    std::uint64_t tests = 0;
    for (std::uint32_t c = 0; c < LC_TEST_COUNTERS; ++c) tests += status[1 + c * LC_TEST_COUNTER_STRIDE];
    res.volumeTests = (status[0] & 4u) ? 0 : tests; // wrapped: not counted
    std::uint64_t total64 = 0;
    std::uint32_t longest = 0;
    // Ranges by atomic add, or no scan on the device: the offsets of the
    // lists in order come from here (a second submission that writes the
    // lists scans the same counts).
    const bool hostOffsets = atomicRanges || hostScan;
    std::vector<std::uint32_t> hostOffs(hostOffsets ? std::size_t(listTotal) + 1 : 0);
    for (std::uint32_t l = 0; l < listTotal; ++l) {
        if (hostOffsets) hostOffs[l] = std::uint32_t(total64);
        total64 += counts[l];
        longest = std::max(longest, counts[l]);
    }
    // The device's ranges, and the total its atomic adds reached.
    const std::uint32_t* rangeOffs = atomicRanges ? offs : nullptr;
    if (hostOffsets) {
        // (A total beyond 32 bits fails the size check below.)
        hostOffs[listTotal] = std::uint32_t(total64);
        if (atomicRanges && total64 <= std::numeric_limits<std::uint32_t>::max() && total64 != offs[listTotal])
            throw DeviceError("Vulkan culling's lists took " + std::to_string(offs[listTotal]) +
                              " entries of the index array for " + std::to_string(total64) + " counted");
        offs = hostOffs.data();
    }
    // A tile walk's pools (cull_lists.comp): whether each held its walk's
    // entries, so that the host can take the lists from there. Walk q of
    // tile t takes lists [first, end).
    const std::uint32_t walkGroups = walk ? (cells + walk - 1) / walk : 0;
    auto walkLists = [&](std::uint32_t t, std::uint32_t q) {
        const std::uint32_t first = t * cells + q * walk;
        return std::pair{first, std::min(first + walk, (t + 1) * cells)};
    };
    bool poolsFitted = walk != 0 && stashed;
    for (std::uint32_t t = 0; poolsFitted && t < tiles; ++t)
        for (std::uint32_t q = 0; q < walkGroups; ++q) {
            const auto [first, end] = walkLists(t, q);
            if (offs[end] - offs[first] > (end - first) * stashSlots) poolsFitted = false;
        }
    const std::uint32_t total = offs[listTotal];
    if (total64 != total || total64 * 4 > lim.maxStorageBufferRange)
        throw DeviceError("culling produced " + std::to_string(total64) +
                          " list entries, more than one storage buffer of this device holds (" +
                          std::to_string(lim.maxStorageBufferRange / 4) + ")");

    // The coarse counts and offsets, before fptl's pack rewrites the counts
    // (in place when the buffer is mapped).
    const std::vector<std::uint32_t> counts0 = fptl ? std::vector<std::uint32_t>(counts, counts + listTotal)
                                                    : std::vector<std::uint32_t>();
    const std::vector<std::uint32_t> offs0 = fptl ? std::vector<std::uint32_t>(offs, offs + listTotal)
                                                  : std::vector<std::uint32_t>();
    lastIndexBits_ = 32; // unless the lists come from the 16-bit index array below
    if (total > 0 && walk && !writeFirst && poolsFitted) {
        // Every walk's pool holds its entries, (slice << 24) | light in walk
        // order: each goes to the end of its slice's list.
        res.lightIndices.resize(total);
        std::vector<std::uint32_t> at(offs, offs + listTotal);
        for (std::uint32_t t = 0; t < tiles; ++t)
            for (std::uint32_t q = 0; q < walkGroups; ++q) {
                const auto [first, end] = walkLists(t, q);
                const std::uint32_t* pool = stashed + std::size_t(first) * stashSlots;
                for (std::uint32_t i = 0, m = offs[end] - offs[first]; i < m; ++i) {
                    const std::uint32_t slice = pool[i] >> 24, list = t * cells + slice;
                    if (list < first || list >= end || at[list] >= offs[list] + counts[list])
                        throw DeviceError("Vulkan clustered walk pooled an entry outside its lists");
                    res.lightIndices[at[list]++] = pool[i] & 0xffffffu;
                }
            }
    } else if (total > 0 && stashed && !walk && !writeFirst && longest <= stashSlots && !fptl) {
        // The stash holds every list whole: the entries are in, no write pass.
        res.lightIndices.resize(total);
        for (std::uint32_t l = 0; l < listTotal; ++l)
            std::copy_n(stashed + std::size_t(l) * stashSlots, counts[l], res.lightIndices.begin() + offs[l]);
    } else if (total > 0 && atomicRanges && total <= firstCapacity) {
        // Every list was written, each at the range it took; appended in list
        // order (offs: the counts added up), so no zero fill first.
        // (16-bit entries widened on the way.)
        auto appendLists = [&](const auto* written) {
            res.lightIndices.reserve(total);
            for (std::uint32_t l = 0; l < listTotal; ++l) {
                if (counts[l] == 0) continue;
                if (rangeOffs[l] > total - counts[l])
                    throw DeviceError("Vulkan culling placed list " + std::to_string(l) +
                                      " beyond the index array");
                res.lightIndices.insert(res.lightIndices.end(), written + rangeOffs[l],
                                        written + rangeOffs[l] + counts[l]);
            }
        };
        if (index16) {
            appendLists(static_cast<const std::uint16_t*>(firstOut));
            lastIndexBits_ = 16;
        } else {
            appendLists(firstIdx);
        }
    } else if (total > 0 && writeFirst && total <= firstCapacity) {
        // The first submission wrote every list.
        res.lightIndices.assign(firstIdx, firstIdx + total);
    } else if (total > 0) {
        const Buffer& indexBuf = deviceBuffer("cull.indices", std::size_t(total) * 4);
        const std::uint32_t* idx = nullptr;
        VkDescriptorSet set2 = makeSet(indexBuf, "cull.set.write");
        Staging back(cache_);
        idx = static_cast<const std::uint32_t*>(
            back.download(indexBuf, std::size_t(total) * 4, "cull.indices"));
        const auto* status2 =
            static_cast<const std::uint32_t*>(back.download(statusBuf, 4, "cull.status.write"));
        // fptl: the packed counts (mapped: the same memory as `counts`).
        const auto* packed = fptl ? static_cast<const std::uint32_t*>(back.download(
                                        countBuf, std::size_t(listTotal) * 4, "cull.counts.packed"))
                                  : nullptr;
        const Grid pruneGroups = groupsFor(total, lim);
        wallMs += ctx_.submitAndWait(
            [&](VkCommandBuffer cmd) {
                // The write pass reads counts/offsets/bounds written by the previous submission.
                computeBarrier(cmd, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
                if (gpuClock) stamps.begin(cmd, 1);
                vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, computeLayout_, 0, 1, &set2, 0,
                                        nullptr);
                if (!hostOffsets) {
                    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, writePipe);
                    vkCmdDispatch(cmd, writeGroups.x, writeGroups.y, 1);
                } else {
                    // The offsets in order, as the host added them up, then
                    // the write pass (the stash as the count pass left it).
                    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, scanPipe);
                    vkCmdDispatch(cmd, 1, 1, 1);
                    dispatchAfter(cmd, writePipe, writeGroups);
                }
                if (fptl) {
                    // The prune reads the entries the write pass wrote, and
                    // the pack the marks the prune wrote over them.
                    dispatchAfter(cmd, prunePipe, pruneGroups);
                    dispatchAfter(cmd, packPipe, packGroups);
                }
                if (gpuClock) stamps.end(cmd, 1);
                back.recordDownloads(cmd);
            },
            "cull.commands.write");
        if (gpuClock) gpuMs += stamps.milliseconds(1);
        if (*status2 & 8u) throw DeviceError(loopLimitError);
        if (*status2 & 2u) throw DeviceError(countMismatchError);
        if (fptl) {
            // Each list's kept entries lead its range: pack the ranges.
            std::uint32_t at = 0;
            res.listOffset.resize(listTotal);
            res.listCount.assign(packed, packed + listTotal);
            for (std::uint32_t l = 0; l < listTotal; ++l) {
                if (res.listCount[l] > counts0[l])
                    throw DeviceError("Vulkan fine prune kept more entries than the list had");
                res.listOffset[l] = at;
                res.lightIndices.insert(res.lightIndices.end(), idx + offs0[l], idx + offs0[l] + res.listCount[l]);
                at += res.listCount[l];
            }
        } else {
            res.lightIndices.assign(idx, idx + total);
        }
    }

    if (zbin) {
        // The masks hold sorted positions, ascending: back to light indices,
        // ascending. A list of more than one light in 512 is read out of a
        // bitmask of the lights (its bits set, then the words read in order:
        // one pass over n / 64 words, where sorting P3's 21 million zbin
        // entries, 650 a list, took the host 880 ms on the H100's machine);
        // shorter lists are sorted.
        const std::size_t maskWords = (std::size_t(n) + 63) / 64;
        std::vector<std::uint64_t> seen(maskWords, 0);
        for (std::uint32_t l = 0; l < listTotal; ++l) {
            auto b = res.lightIndices.begin() + offs[l], e = b + counts[l];
            std::uint64_t next = 0; // the least position the next entry may hold
            for (auto it = b; it != e; ++it) {
                if (*it >= n || *it < next)
                    throw DeviceError("Vulkan culling put position " + std::to_string(*it) + " in list " +
                                      std::to_string(l) + " of " + std::to_string(n) +
                                      " lights, not in ascending order below the light count");
                next = std::uint64_t(*it) + 1;
                *it = res.zbinOrder[*it];
            }
            if (std::size_t(counts[l]) * 512 <= n) {
                std::sort(b, e);
                continue;
            }
            for (auto it = b; it != e; ++it)
                seen[*it >> 6] |= std::uint64_t(1) << (*it & 63);
            auto out = b;
            for (std::size_t w = 0; w < maskWords; ++w) {
                for (std::uint64_t m = seen[w]; m != 0; m &= m - 1)
                    *out++ = std::uint32_t(w * 64 + std::size_t(std::countr_zero(m)));
                seen[w] = 0;
            }
        }
        res.zbinLo.assign(binWordsOut + planeBinWords, binWordsOut + planeBinWords + 2 * std::size_t(settings.bins));
        res.zbinHi.resize(settings.bins);
        for (std::uint32_t b = 0; b < settings.bins; ++b) {
            res.zbinHi[b] = res.zbinLo[2 * std::size_t(b) + 1];
            res.zbinLo[b] = res.zbinLo[2 * std::size_t(b)];
        }
        res.zbinLo.resize(settings.bins);
    }

    // Results out of the mapped (or staged) buffers.
    res.tileDepthMin.resize(tiles);
    res.tileDepthMax.resize(tiles);
    if (algo == Algorithm::HalfZ) res.halfzSplit.resize(tiles);
    if (algo == Algorithm::TwoPointFiveD || algo == Algorithm::Clustered) res.cellMask.resize(tiles);
    for (std::uint32_t t = 0; t < tiles; ++t) {
        const bool empty = !(tb[t].depthMin <= tb[t].depthMax);
        res.tileDepthMin[t] = empty ? kInf : double(tb[t].depthMin);
        res.tileDepthMax[t] = empty ? -kInf : double(tb[t].depthMax);
        if (algo == Algorithm::HalfZ) res.halfzSplit[t] = empty ? kInf : double(tb[t].split);
        if (!res.cellMask.empty()) res.cellMask[t] = tb[t].cellMask;
    }
    if (!fptl || total == 0) {
        res.listCount.assign(counts, counts + listTotal);
        res.listOffset.assign(offs, offs + listTotal);
    }

    res.backend = name();
    res.device = deviceName();
    res.timingMethod = timingMethod();
    res.timings.cullMs = gpuClock ? gpuMs : wallMs;
    lastCullWallMs_ = wallMs;
    lastLongestList_ = longest;
    lastPoolsFitted_ = poolsFitted;
    lastListTotal_ = listTotal;
    lastEntries_ = total;
    return res;
}

} // namespace

std::unique_ptr<CullBackend> makeVulkanBackend(const std::string& device) {
    return std::make_unique<VulkanBackend>(device);
}

std::vector<std::string> vulkanDeviceNames() { return vk::physicalDeviceNames(); }

} // namespace lc
