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
//   5. fine_prune, an invocation per entry (a subgroup on GPUs while the
//      entries are few): the light against its tile's
//      geometry pixels, pruned entries marked;
//   6. fine_prune pack, an invocation per list: kept entries to the front
//      of the list's range, the new count; the host packs the ranges.
//   zbin uploads the lights sorted by depth and culls naive's screen-space
//   volume (its tile masks, as sorted positions, mapped back by the host),
//   and zbin.comp bins the sorted lights in depth after light_bins.
// So memory is the entries the scene produces, with no per-list cap and no
// tiles x lights x cells allocation.
//
// Which of these run, in which layout and with which constants, and where
// the host then takes the lists from, is decided by the plan
// (vk/cull_plan.cpp: a named strategy, testable without a device); this file
// records the passes it names and decodes the lists the way it says.
#include "vk/vulkan_backend.hpp"

#include "scene/closed_solids.hpp"

#include "culling/core/content_hash.hpp"
#include "culling/core/errors.hpp"
#include "culling/vk/gpu_shared.h"
#include "embedded_spirv.hpp"
#include "vk/cull_plan.hpp"
#include "vk/vk_context.hpp"
#include "vk/raster_pass.hpp"
#include "vk/shade_pass.hpp"
#include "culling/math/light_proxy.hpp"

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
// Culling pipelines made by this process's Vulkan backends, and held now.
std::atomic<std::uint64_t> g_cullPipelinesMade{0}, g_cullPipelinesHeld{0};
} // namespace

VulkanPipelineCount vulkanCullPipelines() { return {g_cullPipelinesMade, g_cullPipelinesHeld}; }

namespace {

using namespace vk;

constexpr double kInf = std::numeric_limits<double>::infinity();
// Widening of every float comparison (see cull_common.glsl): relative 2e-5 is
// ~170 float ulps, far above the rounding of the float passes and far below any
// distance a scene cares about; the absolute term covers values near zero.
constexpr float kRelEps = 2e-5f;
constexpr float kAbsEps = 1e-6f;
constexpr float kInfF = std::numeric_limits<float>::infinity();

constexpr std::uint32_t kBindings = 11; // cull_common.glsl bindings 0..10
// The largest region of one staged download copy (Staging::recordDownloads).
constexpr VkDeviceSize kDownloadRegion = 512 * 1024;


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


// A 64-bit digest of a mesh's positions and indices (not its transform):
// the key of its closed solids, which depend on nothing else.
std::uint64_t meshContentKey(const Mesh& m) { return ContentHash().add(m.positions).add(m.indices).value(); }

struct Counted;
struct CullInputs;

class VulkanBackend final : public CullBackend {
public:
    explicit VulkanBackend(const std::string& device) : ctx_(ContextOptions{device, "lc"}), profile_(profileOf(ctx_)) {
        createComputeObjects();
    }
    ~VulkanBackend() override { g_cullPipelinesHeld -= computePipelines_.size(); }
    std::string name() const override { return "vulkan"; }
    std::string deviceName() const override { return ctx_.deviceName(); }
    // Per device. Compute timestamps read wrong on lavapipe once the device
    // has rendered (DESIGN.md), and this device renders the depth pre-pass:
    // there, CPU time around submit + fence wait. A GPU with timestamps in
    // compute and graphics: device time between timestamps written around
    // the passes (uploads and readbacks excluded).
    std::string timingMethod() const override {
        return profile_.gpuTimestamps() ? "gpu-timestamps (vkCmdWriteTimestamp around the passes, sum of submissions)"
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
    static DeviceProfile profileOf(const Context& ctx);
    void createComputeObjects();
    // `oneSubgroup`: the local size is the subgroup size and the pass relies on
    // the workgroup being one subgroup (REQUIRE_FULL_SUBGROUPS where supported).
    VkPipeline computePipeline(const char* what, VkShaderModule module, const CullSpec& spec, bool oneSubgroup);

    // The pipelines a cull's plan runs (null where it runs none).
    struct CullPipelines {
        VkPipeline bounds = VK_NULL_HANDLE, bins = VK_NULL_HANDLE, count = VK_NULL_HANDLE, write = VK_NULL_HANDLE,
                   scan = VK_NULL_HANDLE, prune = VK_NULL_HANDLE, pack = VK_NULL_HANDLE, zbinInit = VK_NULL_HANDLE,
                   zbin = VK_NULL_HANDLE, atomicWrite = VK_NULL_HANDLE, fused = VK_NULL_HANDLE,
                   pruneWide = VK_NULL_HANDLE;
    };
    // The first submission's (`listPasses` false: the bounds pass alone, for
    // raster), and the second submission's added to them.
    CullPipelines cullPipelines(const CullPlan& plan, bool listPasses = true);
    void addWritePipelines(const CullPlan& plan, CullPipelines& pipes);
    // The write and scan passes, which either submission may run.
    VkPipeline writePipeline(const CullPlan& plan) {
        return computePipeline("cull_lists.write", cullShader_, plan.write, plan.lanes > 1);
    }
    VkPipeline scanPipeline(const CullPlan& plan) { return computePipeline("prefix_sum", scanShader_, plan.scan, true); }
    // One cull's buffers (the cache's, each role acquired once), the bytes
    // each was asked for, its descriptors, staging and clocks.
    struct CullRun {
        BufferCache* cache = nullptr;
        std::map<VkBuffer, VkDeviceSize> asked;
        const Buffer *params = nullptr, *depth = nullptr, *tiles = nullptr, *lights = nullptr, *bins = nullptr,
                     *counts = nullptr, *offsets = nullptr, *status = nullptr, *spots = nullptr, *stash = nullptr;
        bool residentDepth = false;
        Staging* staging = nullptr;
        DescriptorPoolHandle pool;
        VkDescriptorSet countSet = VK_NULL_HANDLE;
        TimestampPool* stamps = nullptr; // null: wall clock
        double wallMs = 0, gpuMs = 0;
        const Buffer& deviceBuffer(const std::string& role, std::size_t bytes);
    };
    // Where the first submission's results are read (mapped or staged).
    struct CullReadback {
        const std::uint32_t *counts = nullptr, *offs = nullptr, *status = nullptr, *stashed = nullptr,
                            *binWordsOut = nullptr;
        const GpuTileBounds* tb = nullptr;
        const void* firstOut = nullptr;
    };
    CullReadback setUpBuffers(const CullPlan& plan, const CullInputs& in, const DepthImage& depth, Staging& staging,
                              CullRun& run);
    VkDescriptorSet cullSet(const CullRun& run, const Buffer& indices, const char* name);
    void recordFirstSubmission(VkCommandBuffer cmd, const CullPlan& plan, const CullPipelines& pipes,
                               const CullRun& run);
    void writeListsAgain(const CullPlan& plan, const CullPipelines& pipes, CullRun& run, const Counted& c,
                         CullResult& res);
    // raster: minmax's tile bounds pass, then the light proxies drawn
    // (vk/raster_pass.cpp) into per-tile light masks, decoded into lists.
    CullResult cullRaster(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                          const ViewLights& lights, const CullSettings& settings);
    VkPipeline depthPipeline(bool reversed);
    VkRenderPass depthRenderPass(bool reversed);
    // The depth pre-pass's draws: one per mesh, into one vertex and one index buffer.
    struct Draw {
        glm::mat4 clipFromModel;
        std::uint32_t firstIndex, indexCount;
        std::int32_t vertexOffset;
    };
    struct DepthDraws {
        std::vector<Draw> draws;
        std::vector<float> vertices;        // each mesh's relative to its centre
        std::vector<std::uint32_t> indices; // the faces that can win a pixel
        std::size_t sceneTriangles = 0;
    };
    DepthDraws gatherDepthDraws(const Scene& scene, const Projection& proj);
    void keepDepthTarget(std::uint32_t width, std::uint32_t height, bool reversed, VkRenderPass rp);

    Context ctx_;
    DeviceProfile profile_;
    // The buffers of the depth pre-pass and the cull, kept between calls
    // (after ctx_: freed before the device).
    BufferCache cache_{ctx_};
    DescriptorSetLayoutHandle setLayout_;
    PipelineLayoutHandle computeLayout_;
    ShaderModuleHandle boundsShader_, boundsWideShader_, binsShader_, binsShuffleShader_, cullShader_, cullShader16_,
        scanShader_, pruneShader_, zbinShader_, vertShader_;
    CullHistory history_; // the previous cull's: sizes the next one
    // The culling pipelines, by shader and specialisation, each with the
    // cullPipelines call that last used it. At most kHeldPipelines are kept,
    // the least recently used going first (never one the current call uses):
    // lavapipe's compiled code is megabytes a pipeline. The report sweep of
    // forest's 352 configurations makes 359 (each cull makes only the passes
    // it runs, keyed by the constants each reads); kept to 128 it makes one
    // of them again and peaks at 596 MB resident, kept to 256 at 874 MB.
    struct HeldPipeline {
        PipelineHandle pipeline;
        std::uint64_t lastUse = 0;
    };
    static constexpr std::size_t kHeldPipelines = 128;
    std::map<std::string, HeldPipeline> computePipelines_;
    std::map<VkShaderModule, std::uint32_t> specIds_; // specConstantIds of each culling shader
    std::uint64_t pipelineUse_ = 0; // cullPipelines calls
    PipelineLayoutHandle depthLayout_;
    RenderPassHandle renderPass_[2];
    PipelineHandle depthPipeline_[2];
    std::unique_ptr<ShadePass> shadePass_;
    std::unique_ptr<RasterPass> rasterPass_; // created on the first raster cull
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

    auto mk = [&](spirv::Code c, const char* n) {
        ShaderModuleHandle m = ctx_.createShader(c.words, c.wordCount, n);
        specIds_[m] = specConstantIds(c.words, c.wordCount);
        return m;
    };
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

// A culling pipeline, cached per shader and specialisation (CullSpec).
VkPipeline VulkanBackend::computePipeline(const char* what, VkShaderModule module, const CullSpec& spec,
                                          bool oneSubgroup) {
    const CullSpec used = spec.only(specIds_.at(module));
    const std::string key = what + used.key();
    auto it = computePipelines_.find(key);
    if (it != computePipelines_.end()) {
        it->second.lastUse = pipelineUse_;
        return it->second.pipeline;
    }
    while (computePipelines_.size() >= kHeldPipelines) {
        auto oldest = computePipelines_.end();
        for (auto i = computePipelines_.begin(); i != computePipelines_.end(); ++i)
            if (i->second.lastUse < pipelineUse_ &&
                (oldest == computePipelines_.end() || i->second.lastUse < oldest->second.lastUse))
                oldest = i;
        if (oldest == computePipelines_.end()) break; // all in this call's use
        computePipelines_.erase(oldest);
        --g_cullPipelinesHeld;
    }
    std::array<VkSpecializationMapEntry, CullSpec::kCount> entries{};
    for (std::uint32_t i = 0; i < CullSpec::kCount; ++i) entries[i] = {i, i * 4u, 4u};
    VkSpecializationInfo si{};
    si.mapEntryCount = CullSpec::kCount;
    si.pMapEntries = entries.data();
    si.dataSize = sizeof(used);
    si.pData = &used;
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
    ++g_cullPipelinesMade;
    ++g_cullPipelinesHeld;
    return computePipelines_.emplace(key, HeldPipeline{PipelineHandle(ctx_.device(), p), pipelineUse_})
        .first->second.pipeline;
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

VulkanBackend::DepthDraws VulkanBackend::gatherDepthDraws(const Scene& scene, const Projection& proj) {
    // All meshes in one vertex and one index buffer; one draw per mesh. The
    // index buffer leaves out the faces of closed solids turned away from the
    // camera (scene/closed_solids.hpp): they never win a pixel, and lavapipe
    // pays per fragment rasterised.
    DepthDraws out;
    std::vector<Draw>& draws = out.draws;
    std::vector<std::uint32_t>& ix = out.indices;
    std::vector<glm::dvec3> centres; // per drawn mesh, model space
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
    out.sceneTriangles = sceneIndices / 3;
    // The vertices, each mesh's relative to its centre.
    out.vertices.reserve(vertexFloats);
    std::size_t drawn = 0;
    for (const Mesh& m : scene.meshes) {
        if (m.triangleCount() == 0) continue;
        const glm::dvec3 c = centres[drawn++];
        for (std::size_t i = 0; i < m.vertexCount() * 3; ++i)
            out.vertices.push_back(float(double(m.positions[i]) - c[int(i % 3)]));
    }
    return out;
}

void VulkanBackend::keepDepthTarget(std::uint32_t W, std::uint32_t H, bool reversed, VkRenderPass rp) {
    // The depth image, its framebuffer and the storage buffer the depth goes
    // to (the cull reads it in place, no readback and upload between the
    // passes; the host gets it from there) are kept while the resolution and
    // the depth direction stay: fresh ones cost lavapipe a page fault per
    // 4 KiB page touched, milliseconds at 1080p.
    if (depthTarget_.width == W && depthTarget_.height == H && depthTarget_.reversed == reversed &&
        depthTarget_.framebuffer)
        return;
    VkDevice dev = ctx_.device();
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

    const DepthDraws dd = gatherDepthDraws(scene, proj);
    const std::vector<Draw>& draws = dd.draws;
    pass.triangles = dd.sceneTriangles;
    pass.trianglesDrawn = dd.indices.size() / 3;
    BufferCache::Frame cacheFrame(cache_);
    // Device-local vertex and index buffers (staged on a discrete GPU), the
    // index buffer sized for every triangle so that turning the camera does
    // not resize it.
    const Buffer& vbuf = cache_.get("depth.vertices", dd.vertices.size() * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT,
                                    BufferCache::Kind::Device);
    const Buffer& ibuf = cache_.get("depth.indices", dd.sceneTriangles * 12, VK_BUFFER_USAGE_INDEX_BUFFER_BIT,
                                    BufferCache::Kind::Device);
    Staging staging(cache_);
    staging.upload(vbuf, dd.vertices.data(), dd.vertices.size() * 4, "depth.vertices");
    staging.upload(ibuf, dd.indices.data(), dd.indices.size() * 4, "depth.indices");
    VkRenderPass rp = depthRenderPass(reversed);
    VkPipeline pipe = depthPipeline(reversed);
    keepDepthTarget(W, H, reversed, rp);
    residentId_ = 0; // rewritten below: no earlier image names it any more
    const Buffer& resident = depthTarget_.depth;
    const Image& img = depthTarget_.image;
    VkFramebuffer fb = depthTarget_.framebuffer;
    Staging back(cache_);
    const void* pixels = back.download(resident, std::size_t(W) * H * 4, "depth.resident");

    const bool gpuClock = profile_.gpuTimestamps();
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

// ---------------------------------------------------------------------------
// One cull: planned (vk/cull_plan.cpp: the strategy, the work layout, the
// specialisation constants), its inputs prepared and its buffers acquired,
// the first submission recorded, then its lists decoded from where the plan
// says they are (ListsFrom), a second submission writing them when needed.

// The status word and the test counters (gpu_shared.h), zeroed.
constexpr std::size_t kStatusWords = 1 + std::size_t(LC_TEST_COUNTERS) * LC_TEST_COUNTER_STRIDE;

// The inputs of one cull as the passes read them: parameters, lights (in
// upload order: zbin's sorted by depth) and spot cones (one per light under
// a cone test or fptl, range 0 for a point light; else one unused element).
struct CullInputs {
    GpuCullParams params{};
    std::vector<GpuLight> lights;
    std::vector<GpuSpotCone> spots;
};

CullInputs prepareInputs(const CullPlan& plan, const CullFrame& frame, const CullResult& res,
                         const DepthImage& depth, const Projection& proj, const ViewLights& lights,
                         const CullSettings& settings, const std::vector<std::uint32_t>& upOrder,
                         bool spotCones) {
    const TileGrid& grid = frame.grid;
    const std::uint32_t n = plan.lights;
    const std::vector<BoundingSphere>& cullSpheres = frame.cullSpheres; // range spheres, or each spot test's
    double lightFar = 0.0, lightNear = kInf; // the light bins' depth span
    for (std::size_t l = 0; l < n; ++l) {
        lightFar = std::max(lightFar, -cullSpheres[l].center.z + cullSpheres[l].radius);
        lightNear = std::min(lightNear, -cullSpheres[l].center.z - cullSpheres[l].radius);
    }
    const double camNear = frame.cameraNear, naiveFar = frame.cameraFar;
    CullInputs in;
    GpuCullParams& p = in.params;
    std::uint32_t flags = 0;
    if (proj.orthographic()) flags |= LC_FLAG_ORTHO;
    if (isReversed(proj.kind())) flags |= LC_FLAG_REVERSED;
    if (!std::isfinite(proj.farPlane())) flags |= LC_FLAG_FAR_INFINITE;
    if (settings.skipEmpty) flags |= LC_FLAG_SKIP_EMPTY;
    p.size = glm::uvec4(grid.width, grid.height, grid.tilesX, grid.tilesY);
    p.counts = glm::uvec4(n, res.listsPerTile, plan.listTotal, flags);
    // Window depth d = A + B / v (perspective) or A + B * v (orthographic),
    // A split in two floats (GpuCullParams.depth).
    const glm::dvec2 ab = proj.windowDepthAB();
    const float aHi = float(ab.x);
    p.depth = glm::vec4(aHi, float(ab.y), float(ab.x - double(aHi)), depth.clearDepth);
    const glm::dvec3 corner = proj.viewPositionAt({double(proj.width()), 0.0}, 1.0);
    p.lens = glm::vec4(float(corner.x), float(corner.y), float(camNear), float(naiveFar));
    p.cluster = glm::vec4(float(res.clusterNear), float(res.clusterFar), kRelEps, kAbsEps);
    p.bins = glm::uvec4(plan.binWords, plan.binWords * grid.tilesX, plan.stashSlots, std::uint32_t(plan.planeBinWords));
    p.depthBins = depthBinSlicing(proj, camNear, lightNear, lightFar);
    if (plan.zbin)
        p.depthBins = glm::vec4(float(camNear), naiveFar > camNear ? float(settings.bins / (naiveFar - camNear)) : 0.0f,
                                float(settings.bins), 0.0f);
    in.lights.resize(n);
    for (std::uint32_t k = 0; k < n; ++k) {
        const BoundingSphere& s = cullSpheres[upOrder[k]];
        in.lights[k].centerRadius = glm::vec4(glm::vec3(s.center), float(s.radius));
    }
    in.spots.assign(spotCones ? n : 1, GpuSpotCone{});
    if (spotCones)
        for (std::uint32_t k = 0; k < n; ++k) {
            const std::uint32_t l = upOrder[k];
            if (!lights.isSpot(l)) continue;
            const SpotCone c = lights.spotCone(l);
            in.spots[k].apexRange = glm::vec4(glm::vec3(c.apex), float(c.range));
            in.spots[k].axisCos = glm::vec4(glm::vec3(c.axis), float(c.cosAngle));
            in.spots[k].sinAngle = glm::vec4(float(c.sinAngle), 0.0f, 0.0f, 0.0f);
        }
    return in;
}

// What the first submission's count pass found: the lists' offsets in order
// (the device's scan, or added up here where the lists took atomic ranges or
// no scan ran), the ranges the atomic adds gave, the total, the longest list
// and whether every tile walk's pool held its entries.
struct Counted {
    const std::uint32_t* counts = nullptr;
    const std::uint32_t* offs = nullptr;
    const std::uint32_t* rangeOffs = nullptr; // atomic ranges: where each list was written
    std::vector<std::uint32_t> hostOffs;
    std::uint32_t total = 0, longest = 0;
    bool poolsFitted = false;
};

// The offsets of the lists in order, added up here (atomic ranges or no
// scan on the device). (Locals in the loop: a store to the offsets might
// otherwise alias c's own words, and P1 / clustered's 261,120 lists paid
// 0.3 ms for it.)
void addUpOffsets(const CullPlan& plan, Counted& c) {
    if (!c.hostOffs.empty() || !plan.hostOffsets()) return;
    const std::uint32_t listTotal = plan.listTotal;
    c.hostOffs.resize(std::size_t(listTotal) + 1);
    std::uint32_t* hostOffs = c.hostOffs.data();
    const std::uint32_t* counts = c.counts;
    std::uint32_t at = 0; // (the total was checked to fit 32 bits)
    for (std::uint32_t l = 0; l < listTotal; ++l) {
        hostOffs[l] = at;
        at += counts[l];
    }
    hostOffs[listTotal] = at;
    c.offs = hostOffs;
}

// The count pass's totals. Where the host adds up the offsets, it does so
// only when the lists' decoding needs them (addUpOffsets): the lists taken
// from their atomic ranges are laid out with their offsets in one pass
// (decodeRanges); walking P1 / clustered's 261,120 counts once more cost the
// H200's host 0.3 ms.
Counted readCounts(const CullPlan& plan, const std::uint32_t* counts, const std::uint32_t* deviceOffs,
                   const std::uint32_t* stashed) {
    Counted c;
    c.counts = counts;
    const std::uint32_t listTotal = plan.listTotal;
    const bool hostOffsets = plan.hostOffsets();
    c.offs = hostOffsets ? nullptr : deviceOffs;
    std::uint64_t total64 = 0;
    std::uint32_t longest = 0;
    for (std::uint32_t l = 0; l < listTotal; ++l) {
        total64 += counts[l];
        longest = std::max(longest, counts[l]);
    }
    c.longest = longest;
    if (plan.atomicRanges()) {
        c.rangeOffs = deviceOffs;
        if (total64 <= std::numeric_limits<std::uint32_t>::max() && total64 != deviceOffs[listTotal])
            throw DeviceError("Vulkan culling's lists took " + std::to_string(deviceOffs[listTotal]) +
                              " entries of the index array for " + std::to_string(total64) + " counted");
    }
    const std::uint64_t total = hostOffsets ? total64 : deviceOffs[listTotal];
    if (total64 != total || total64 * 4 > plan.profile.maxStorageBufferRange)
        throw DeviceError("culling produced " + std::to_string(total64) +
                          " list entries, more than one storage buffer of this device holds (" +
                          std::to_string(plan.profile.maxStorageBufferRange / 4) + ")");
    c.total = std::uint32_t(total64);
    // A tile walk's pools (cull_lists.comp): whether each held its walk's
    // entries, so that the host can take the lists from there.
    bool fitted = plan.walk != 0 && stashed;
    if (fitted) addUpOffsets(plan, c);
    const std::uint32_t* offs = c.offs;
    for (std::uint32_t t = 0; fitted && t < plan.tiles; ++t)
        for (std::uint32_t q = 0; q < plan.walkGroups; ++q) {
            const auto [first, end] = plan.walkLists(t, q);
            if (offs[end] - offs[first] > (end - first) * plan.stashSlots) fitted = false;
        }
    c.poolsFitted = fitted;
    return c;
}

// ListsFrom::Pools: every walk's pool holds its entries, (slice << 24) |
// light in walk order: each goes to the end of its slice's list.
void decodePools(const CullPlan& plan, const Counted& c, const std::uint32_t* stashed, CullResult& res) {
    res.lightIndices.resize(c.total);
    const std::uint32_t *counts = c.counts, *offs = c.offs;
    std::vector<std::uint32_t> at(offs, offs + plan.listTotal);
    const std::uint32_t cells = plan.count.cells, tiles = plan.tiles, walks = plan.walkGroups,
                        slots = plan.stashSlots;
    for (std::uint32_t t = 0; t < tiles; ++t)
        for (std::uint32_t q = 0; q < walks; ++q) {
            const auto [first, end] = plan.walkLists(t, q);
            const std::uint32_t* pool = stashed + std::size_t(first) * slots;
            for (std::uint32_t i = 0, m = offs[end] - offs[first]; i < m; ++i) {
                const std::uint32_t slice = pool[i] >> 24, list = t * cells + slice;
                if (list < first || list >= end || at[list] >= offs[list] + counts[list])
                    throw DeviceError("Vulkan clustered walk pooled an entry outside its lists");
                res.lightIndices[at[list]++] = pool[i] & 0xffffffu;
            }
        }
}

// ListsFrom::Stash: the stash holds every list whole.
void decodeStash(const CullPlan& plan, const Counted& c, const std::uint32_t* stashed, CullResult& res) {
    const std::uint32_t lists = plan.listTotal, slots = plan.stashSlots;
    const std::uint32_t *counts = c.counts, *offs = c.offs;
    res.lightIndices.resize(c.total);
    for (std::uint32_t l = 0; l < lists; ++l)
        std::copy_n(stashed + std::size_t(l) * slots, counts[l], res.lightIndices.begin() + offs[l]);
}

// ListsFrom::Ranges: every list was written, each at the range it took;
// appended in list order, so no zero fill first (16-bit entries widened).
// The counts and the offsets in order are laid out in the same pass.
template <class Index>
void decodeRanges(const CullPlan& plan, const Counted& c, const Index* written, CullResult& res) {
    // (Locals: the entries' stores could alias the structs' words.)
    const std::uint32_t lists = plan.listTotal, total = c.total;
    const std::uint32_t *counts = c.counts, *ranges = c.rangeOffs;
    res.listCount.assign(counts, counts + lists);
    res.listOffset.resize(lists);
    std::uint32_t* offs = res.listOffset.data();
    res.lightIndices.reserve(total);
    std::uint32_t at = 0;
    for (std::uint32_t l = 0; l < lists; ++l) {
        const std::uint32_t n = counts[l];
        offs[l] = at;
        if (n == 0) continue;
        if (ranges[l] > total - n)
            throw DeviceError("Vulkan culling placed list " + std::to_string(l) + " beyond the index array");
        res.lightIndices.insert(res.lightIndices.end(), written + ranges[l], written + ranges[l] + n);
        at += n;
    }
}

// zbin: the masks hold sorted positions, ascending: back to light indices,
// ascending. A list of more than one light in 512 is read out of a bitmask
// of the lights (its bits set, then the words read in order: one pass over
// n / 64 words, where sorting P3's 21 million zbin entries, 650 a list, took
// the host 880 ms on the H100's machine); shorter lists are sorted. Then the
// bins' ranges, after the plane bins' words.
void decodeZbin(const CullPlan& plan, const std::uint32_t* counts, const std::uint32_t* offs,
                const std::uint32_t* binWordsOut, std::uint32_t bins, CullResult& res) {
    const std::uint32_t n = plan.lights, lists = plan.listTotal;
    const std::size_t maskWords = (std::size_t(n) + 63) / 64;
    std::vector<std::uint64_t> seen(maskWords, 0);
    for (std::uint32_t l = 0; l < lists; ++l) {
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
        for (auto it = b; it != e; ++it) seen[*it >> 6] |= std::uint64_t(1) << (*it & 63);
        auto out = b;
        for (std::size_t w = 0; w < maskWords; ++w) {
            for (std::uint64_t m = seen[w]; m != 0; m &= m - 1)
                *out++ = std::uint32_t(w * 64 + std::size_t(std::countr_zero(m)));
            seen[w] = 0;
        }
    }
    const std::uint32_t* ranges = binWordsOut + plan.planeBinWords;
    res.zbinLo.resize(bins);
    res.zbinHi.resize(bins);
    for (std::uint32_t b = 0; b < bins; ++b) {
        res.zbinLo[b] = ranges[2 * std::size_t(b)];
        res.zbinHi[b] = ranges[2 * std::size_t(b) + 1];
    }
}

// The bounds pass's per-tile output: depth range, halfz's split, 2.5d's and
// clustered's occupied cells.
void decodeTileBounds(const CullPlan& plan, const GpuTileBounds* tb, CullResult& res) {
    const Algorithm algo = plan.algorithm;
    const std::uint32_t tiles = plan.tiles;
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
}

// The status word a submission left: a device fault is an error, a wrapped
// test counter leaves the tests uncounted.
void checkStatus(const std::uint32_t* status, const std::string& device) {
    if (*status & LC_STATUS_SPLIT_WORKGROUP)
        throw DeviceError("Vulkan device '" + device +
                          "' split a subgroup-sized workgroup into several subgroups; the culling passes need one");
    if (*status & LC_STATUS_LOOP_LIMIT)
        throw DeviceError("Vulkan device '" + device +
                          "' ended a culling shader loop early (a driver loop cap); result discarded");
    if (*status & LC_STATUS_COUNT_MISMATCH)
        throw DeviceError("Vulkan write pass found a different entry count than the count pass");
}

// A dispatch that reads (or ORs into) what the dispatches before it wrote.
void dispatchAfter(VkCommandBuffer cmd, VkPipeline pipe, Groups groups) {
    computeBarrier(cmd, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
    vkCmdDispatch(cmd, groups.x, groups.y, 1);
}

DeviceProfile VulkanBackend::profileOf(const Context& ctx) {
    DeviceProfile d;
    const auto& lim = ctx.properties().limits;
    d.name = ctx.deviceName();
    d.cpu = ctx.isCpuDevice();
    d.subgroupSize = ctx.subgroupSize();
    d.int64 = ctx.int64Supported();
    d.index16 = ctx.index16Supported();
    d.subgroupShuffle = ctx.subgroupShuffleSupported();
    d.timestamps = ctx.timestampsSupported();
    d.maxGroupCountX = lim.maxComputeWorkGroupCount[0];
    d.maxGroupCountY = lim.maxComputeWorkGroupCount[1];
    d.maxWorkGroupInvocations = lim.maxComputeWorkGroupInvocations;
    d.maxWorkGroupSizeX = lim.maxComputeWorkGroupSize[0];
    d.maxStorageBufferRange = lim.maxStorageBufferRange;
    return d;
}

VulkanBackend::CullPipelines VulkanBackend::cullPipelines(const CullPlan& plan, bool listPasses) {
    // `oneSubgroup`: the pass relies on its workgroup being whole subgroups.
    const bool subgroupLanes = plan.lanes > 1;
    ++pipelineUse_;
    CullPipelines p;
    p.bounds = plan.wideBounds ? computePipeline("tile_bounds.wide", boundsWideShader_, plan.bounds, false)
                               : computePipeline("tile_bounds", boundsShader_, plan.bounds, subgroupLanes);
    if (!listPasses) return p;
    if (!plan.all && plan.lights > 0)
        p.bins = plan.binLanes > 1 ? computePipeline("light_bins.shuffle", binsShuffleShader_, plan.bins, true)
                                   : computePipeline("light_bins", binsShader_, plan.bins, false);
    if (plan.zbin) {
        p.zbinInit = computePipeline("zbin.init", zbinShader_, plan.zbinInit, false);
        p.zbin = computePipeline("zbin", zbinShader_, plan.zbinBins, false);
    }
    // Only what the first submission's strategy dispatches: the second's
    // come in addWritePipelines when it runs (a lavapipe pipeline of
    // cull_lists is 25 to 40 ms of compiling).
    const CullStrategy st = plan.strategy;
    if (st == CullStrategy::Fused)
        p.fused = plan.index16 ? computePipeline("cull_lists.fused.index16", cullShader16_, plan.fusedSpec, true)
                               : computePipeline("cull_lists.fused", cullShader_, plan.fusedSpec, true);
    else
        p.count = computePipeline("cull_lists.count", cullShader_, plan.count, subgroupLanes);
    if (st == CullStrategy::WalkAtomicWrite)
        p.atomicWrite = computePipeline("cull_lists.write.atomic", cullShader_, plan.atomicWriteSpec, false);
    if (st == CullStrategy::CountScan || st == CullStrategy::CountScanWrite) p.scan = scanPipeline(plan);
    if (st == CullStrategy::CountScanWrite) p.write = writePipeline(plan);
    return p;
}

void VulkanBackend::addWritePipelines(const CullPlan& plan, CullPipelines& p) {
    if (!p.write) p.write = writePipeline(plan);
    if (!p.scan && plan.hostOffsets()) p.scan = scanPipeline(plan);
    if (plan.fptl) {
        p.prune = computePipeline("fine_prune", pruneShader_, plan.prune, false);
        if (plan.pruneWide.lanes > 1) p.pruneWide = computePipeline("fine_prune.wide", pruneShader_, plan.pruneWide, true);
        p.pack = computePipeline("fine_prune.pack", pruneShader_, plan.pack, false);
    }
}

// The first submission: uploads, the bins and bounds passes (zbin's bins),
// then count and, as the strategy says, scan and write.
void VulkanBackend::recordFirstSubmission(VkCommandBuffer cmd, const CullPlan& plan, const CullPipelines& pipes,
                                          const CullRun& run) {
    if (run.stamps) run.stamps->reset(cmd);
    // The total the lists' atomic adds start from, zeroed with the uploads
    // and under their barrier: as a transfer command between the passes,
    // with a barrier of its own, it cost P1 on the H100 4 us of 29.
    if (plan.atomicRanges()) vkCmdFillBuffer(cmd, run.offsets->buffer, VkDeviceSize(plan.listTotal) * 4, 4, 0);
    run.staging->recordUploads(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                               VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, plan.atomicRanges());
    // The passes read the depth the depth submission's copy wrote.
    if (run.residentDepth)
        memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                      VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    if (run.stamps) run.stamps->begin(cmd, 0);
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, computeLayout_, 0, 1, &run.countSet, 0, nullptr);
    if (!plan.all && plan.lights > 0) {
        // The bins pass first, with no barrier between it and the bounds
        // pass: it reads only params and lights and writes only the bins,
        // which the bounds pass never touches. Dispatched first, its few
        // workgroups (a loop over a word's lights) start before the bounds
        // pass's fill the GPU, instead of waiting for them (P1 on the H100:
        // 0.024-0.025 -> 0.022 ms).
        LabelScope label(ctx_, cmd, "light bins");
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipes.bins);
        vkCmdDispatch(cmd, plan.binGroups.x, plan.binGroups.y, 1);
    }
    {
        LabelScope label(ctx_, cmd, "tile bounds");
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipes.bounds);
        vkCmdDispatch(cmd, plan.boundsGroups.x, plan.boundsGroups.y, 1);
    }
    if (plan.zbin) {
        // The bins' words follow the plane bins' in one buffer: ordered
        // after light_bins, then the empty ranges before the lights.
        LabelScope label(ctx_, cmd, "z bins");
        dispatchAfter(cmd, pipes.zbinInit, plan.zbinInitGroups);
        if (plan.lights > 0) dispatchAfter(cmd, pipes.zbin, plan.zbinGroups);
    }
    // The count pass reads the tile bounds and bins the two passes above
    // wrote (and ORs status after the bounds pass did).
    {
        LabelScope label(ctx_, cmd, "light lists");
        switch (plan.strategy) {
        case CullStrategy::Fused:
            dispatchAfter(cmd, pipes.fused, plan.countGroups);
            break;
        case CullStrategy::WalkAtomicWrite:
            dispatchAfter(cmd, pipes.count, plan.countGroups);
            // The write pass reads the counts the count pass wrote.
            dispatchAfter(cmd, pipes.atomicWrite, plan.writeGroups);
            break;
        case CullStrategy::CountPools:
            dispatchAfter(cmd, pipes.count, plan.countGroups);
            break;
        case CullStrategy::CountScan:
        case CullStrategy::CountScanWrite:
            dispatchAfter(cmd, pipes.count, plan.countGroups);
            // The scan reads the counts the count pass wrote.
            dispatchAfter(cmd, pipes.scan, Groups{1, 1});
            // The write pass reads the offsets the scan wrote.
            if (plan.strategy == CullStrategy::CountScanWrite) dispatchAfter(cmd, pipes.write, plan.writeGroups);
            break;
        }
    }
    if (run.stamps) run.stamps->end(cmd, 0);
    run.staging->recordDownloads(cmd);
}

// ListsFrom::SecondSubmission: the write pass again into an index array
// sized exactly (after the scan where the first submission ran none), then
// fptl's prune and pack, whose packed ranges the host lays out in order.
void VulkanBackend::writeListsAgain(const CullPlan& plan, const CullPipelines& first, CullRun& run,
                                    const Counted& c, CullResult& res) {
    CullPipelines pipes = first;
    addWritePipelines(plan, pipes);
    const std::uint32_t listTotal = plan.listTotal, total = c.total;
    // The coarse counts and offsets, before fptl's pack rewrites the counts
    // (in place when the buffer is mapped).
    const std::vector<std::uint32_t> counts0 =
        plan.fptl ? std::vector<std::uint32_t>(c.counts, c.counts + listTotal) : std::vector<std::uint32_t>();
    const std::vector<std::uint32_t> offs0 =
        plan.fptl ? std::vector<std::uint32_t>(c.offs, c.offs + listTotal) : std::vector<std::uint32_t>();
    const Buffer& indexBuf = run.deviceBuffer("cull.indices", std::size_t(total) * 4);
    VkDescriptorSet set2 = cullSet(run, indexBuf, "cull.set.write");
    Staging back(cache_);
    const auto* idx =
        static_cast<const std::uint32_t*>(back.download(indexBuf, std::size_t(total) * 4, "cull.indices"));
    const auto* status2 = static_cast<const std::uint32_t*>(back.download(*run.status, 4, "cull.status.write"));
    // fptl: the packed counts (mapped: the same memory as the counts).
    const auto* packed = plan.fptl ? static_cast<const std::uint32_t*>(back.download(
                                         *run.counts, std::size_t(listTotal) * 4, "cull.counts.packed"))
                                   : nullptr;
    const Groups pruneGroups = plan.pruneGroups(total);
    const bool hostOffsets = plan.hostOffsets();
    run.wallMs += ctx_.submitAndWait(
        [&](VkCommandBuffer cmd) {
            // The write pass reads counts/offsets/bounds written by the previous submission.
            computeBarrier(cmd, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT);
            if (run.stamps) run.stamps->begin(cmd, 1);
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, computeLayout_, 0, 1, &set2, 0, nullptr);
            if (!hostOffsets) {
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipes.write);
                vkCmdDispatch(cmd, plan.writeGroups.x, plan.writeGroups.y, 1);
            } else {
                // The offsets in order, scanned on the device from the counts
                // the host added up the same way, then the write pass (the
                // stash as the count pass left it).
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipes.scan);
                vkCmdDispatch(cmd, 1, 1, 1);
                dispatchAfter(cmd, pipes.write, plan.writeGroups);
            }
            if (plan.fptl) {
                // The prune reads the entries the write pass wrote, and the
                // pack the marks the prune wrote over them.
                dispatchAfter(cmd, plan.pruneLanes(total) > 1 ? pipes.pruneWide : pipes.prune, pruneGroups);
                dispatchAfter(cmd, pipes.pack, plan.packGroups);
            }
            if (run.stamps) run.stamps->end(cmd, 1);
            back.recordDownloads(cmd);
        },
        "cull.commands.write");
    if (run.stamps) run.gpuMs += run.stamps->milliseconds(1);
    checkStatus(status2, ctx_.deviceName());
    if (!plan.fptl) {
        res.lightIndices.assign(idx, idx + total);
        return;
    }
    // Each list's kept entries lead its range: pack the ranges.
    std::uint32_t at = 0;
    res.listOffset.resize(listTotal);
    res.listCount.assign(packed, packed + listTotal);
    for (std::uint32_t l = 0; l < listTotal; ++l) {
        if (res.listCount[l] > counts0[l]) throw DeviceError("Vulkan fine prune kept more entries than the list had");
        res.listOffset[l] = at;
        res.lightIndices.insert(res.lightIndices.end(), idx + offs0[l], idx + offs0[l] + res.listCount[l]);
        at += res.listCount[l];
    }
}

// A descriptor set of the culling passes' eleven bindings, the index array
// (binding 6) as given, each buffer's range the bytes this cull asked for.
VkDescriptorSet VulkanBackend::cullSet(const CullRun& run, const Buffer& indices, const char* name) {
    const Buffer* bufs[kBindings] = {run.params,  run.depth,   run.tiles,  run.lights, run.counts, run.offsets,
                                     &indices,    run.status,  run.bins,   run.spots,  run.stash};
    std::vector<Context::DescriptorWrite> bindings(kBindings);
    for (std::uint32_t i = 0; i < kBindings; ++i) {
        bindings[i].buffer = bufs[i]->buffer;
        bindings[i].range = run.asked.at(bufs[i]->buffer);
    }
    return ctx_.writeDescriptorSet(run.pool, setLayout_, bindings, name);
}

const Buffer& VulkanBackend::CullRun::deviceBuffer(const std::string& role, std::size_t bytes) {
    const Buffer& b = cache->get(role, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, BufferCache::Kind::Device);
    asked[b.buffer] = std::max<VkDeviceSize>(bytes, 4);
    return b;
}

// The cull's buffers acquired (each role once in the open cache frame),
// its inputs staged and its read-backs named.
VulkanBackend::CullReadback VulkanBackend::setUpBuffers(const CullPlan& plan, const CullInputs& in,
                                                        const DepthImage& depth, Staging& staging, CullRun& run) {
    const std::uint32_t n = plan.lights, listTotal = plan.listTotal;
    static const std::array<std::uint32_t, kStatusWords> statusZero{};
    CullReadback out;

    // Device buffers (sizes from the inputs; the index array comes after the
    // count). Descriptor ranges: the bytes each buffer was asked for (a kept
    // buffer may be larger; the passes see only this call's part).
    run.cache = &cache_;
    run.params = &run.deviceBuffer("cull.params", sizeof(GpuCullParams));
    // The depth this backend rendered is on the device already.
    run.residentDepth = isResident(depth);
    if (run.residentDepth) {
        run.depth = &depthTarget_.depth;
        run.asked[run.depth->buffer] = run.depth->size;
    } else {
        run.depth = &run.deviceBuffer("cull.depth", depth.depth.size() * 4);
    }
    run.tiles = &run.deviceBuffer("cull.tiles", std::size_t(plan.tiles) * sizeof(GpuTileBounds));
    run.lights = &run.deviceBuffer("cull.lights", std::size_t(n) * sizeof(GpuLight));
    run.bins = &run.deviceBuffer("cull.bins", plan.binTotalWords * 4);
    run.counts = &run.deviceBuffer("cull.counts", std::size_t(listTotal) * 4);
    run.offsets = &run.deviceBuffer("cull.offsets", (std::size_t(listTotal) + 1) * 4);
    run.status = &run.deviceBuffer("cull.status", kStatusWords * 4); // status bits, test counters
    const Buffer& placeholder = run.deviceBuffer("cull.indices.placeholder", 4);
    run.spots = &run.deviceBuffer("cull.spots", in.spots.size() * sizeof(GpuSpotCone));
    run.stash = &run.deviceBuffer("cull.stash", plan.stashBytes());
    const Buffer& firstIndices =
        plan.writeFirst ? run.deviceBuffer("cull.indices.first", (plan.firstCapacity * plan.entryBytes() + 3) / 4 * 4)
                        : placeholder;

    run.staging = &staging;
    staging.upload(*run.params, &in.params, sizeof in.params, "cull.params");
    if (!run.residentDepth) staging.upload(*run.depth, depth.depth.data(), depth.depth.size() * 4, "cull.depth");
    staging.upload(*run.lights, in.lights.data(), in.lights.size() * sizeof(GpuLight), "cull.lights");
    staging.upload(*run.spots, in.spots.data(), in.spots.size() * sizeof(GpuSpotCone), "cull.spots");
    staging.upload(*run.status, statusZero.data(), kStatusWords * 4, "cull.status");
    out.counts = static_cast<const std::uint32_t*>(
        staging.download(*run.counts, std::size_t(listTotal) * 4, "cull.counts"));
    out.offs = static_cast<const std::uint32_t*>(
        staging.download(*run.offsets, (std::size_t(listTotal) + 1) * 4, "cull.offsets"));
    out.tb = static_cast<const GpuTileBounds*>(
        staging.download(*run.tiles, std::size_t(plan.tiles) * sizeof(GpuTileBounds), "cull.tiles"));
    out.status =
        static_cast<const std::uint32_t*>(staging.download(*run.status, kStatusWords * 4, "cull.status"));
    out.stashed =
        plan.readStash
            ? static_cast<const std::uint32_t*>(staging.download(*run.stash, plan.stashBytes(), "cull.stash"))
            : nullptr;
    out.binWordsOut =
        plan.zbin ? static_cast<const std::uint32_t*>(staging.download(*run.bins, plan.binTotalWords * 4, "cull.bins"))
                  : nullptr;
    out.firstOut =
        plan.writeFirst ? staging.download(firstIndices, plan.firstCapacity * plan.entryBytes(), "cull.indices.first")
                        : nullptr;

    // Descriptor sets: one for the first submission, one with the sized
    // index array for a second.
    run.pool = ctx_.createDescriptorPool(std::vector<Context::DescriptorWrite>(kBindings), 2, "cull.descriptorPool");
    run.countSet = cullSet(run, firstIndices, "cull.set.count");
    return out;
}

CullResult VulkanBackend::cullFrame(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                                    const ViewLights& lights, const CullSettings& settings) {
    const Algorithm algo = settings.algorithm;
    if (algo == Algorithm::Raster) return cullRaster(frame, depth, proj, lights, settings);
    // Spot lights: the sphere tests need only the chosen sphere; the cone
    // tests (and fptl's fine prune, whatever the spot test) also upload each
    // spot's cone (binding 9).
    const bool coneTests = settings.spotTest == SpotTest::ConeSphere || settings.spotTest == SpotTest::ConePlanes;
    CullPlanInputs planIn;
    planIn.settings = settings;
    planIn.grid = frame.grid;
    planIn.listTotal = frame.listTotal;
    planIn.lights = std::uint32_t(lights.size());
    planIn.depthPixels = depth.depth.size();
    planIn.orthographic = proj.orthographic();
    planIn.spotCones = !lights.spotAngles.empty() && (coneTests || algo == Algorithm::Fptl);
    planIn.clusterNear = algo == Algorithm::Clustered ? frame.clusterNear : 0.0;
    const CullPlan plan = planCull(profile_, history_, planIn);
    const std::uint32_t n = plan.lights, listTotal = plan.listTotal;

    CullResult res;
    res.algorithm = algo;
    res.settings = settings;
    res.grid = frame.grid;
    res.listsPerTile = frame.listsPerTile;
    if (algo == Algorithm::Clustered) {
        res.clusterNear = frame.clusterNear;
        res.clusterFar = frame.clusterFar;
    }
    // zbin: the lights go up sorted by depth (as the CPU reference sorts them).
    std::vector<std::uint32_t> upOrder(n);
    for (std::uint32_t l = 0; l < n; ++l) upOrder[l] = l;
    if (plan.zbin) {
        std::vector<double> centreDepth(n);
        for (std::uint32_t l = 0; l < n; ++l) centreDepth[l] = -frame.cullSpheres[l].center.z;
        zbinSortLights(centreDepth, res.zbinOrder, res.zbinRank);
        upOrder = res.zbinOrder;
        res.zbinNear = frame.cameraNear;
        res.zbinFar = frame.cameraFar;
    }
    const CullInputs in = prepareInputs(plan, frame, res, depth, proj, lights, settings, upOrder, planIn.spotCones);
    BufferCache::Frame cacheFrame(cache_);
    CullRun run;
    Staging staging(cache_);
    const CullReadback out = setUpBuffers(plan, in, depth, staging, run);
    const CullPipelines pipes = cullPipelines(plan);
    TimestampPool stamps = profile_.gpuTimestamps() ? TimestampPool(ctx_, 2, "cull.timestamps") : TimestampPool();
    if (profile_.gpuTimestamps()) run.stamps = &stamps;
    run.wallMs = ctx_.submitAndWait([&](VkCommandBuffer cmd) { recordFirstSubmission(cmd, plan, pipes, run); },
                                    "cull.commands.count");
    if (run.stamps) run.gpuMs = stamps.milliseconds(0);

    checkStatus(out.status, ctx_.deviceName());
    std::uint64_t tests = 0;
    for (std::uint32_t c = 0; c < LC_TEST_COUNTERS; ++c) tests += out.status[1 + c * LC_TEST_COUNTER_STRIDE];
    res.volumeTests = (out.status[0] & LC_STATUS_TESTS_OVERFLOW) ? 0 : tests; // wrapped: not counted
    Counted c = readCounts(plan, out.counts, out.offs, out.stashed);

    lastIndexBits_ = 32; // unless the lists come from the 16-bit index array
    const ListsFrom from = plan.listsFrom(c.total, c.longest, c.poolsFitted);
    // Every way but the ranges' needs the offsets in order.
    const bool laidOut = from == ListsFrom::Ranges; // decodeRanges lays out the counts and offsets
    if (!laidOut) addUpOffsets(plan, c);
    switch (from) {
    case ListsFrom::Nothing:
        break;
    case ListsFrom::Pools:
        decodePools(plan, c, out.stashed, res);
        break;
    case ListsFrom::Stash:
        decodeStash(plan, c, out.stashed, res);
        break;
    case ListsFrom::Ranges:
        if (plan.index16) {
            decodeRanges(plan, c, static_cast<const std::uint16_t*>(out.firstOut), res);
            lastIndexBits_ = 16;
        } else {
            decodeRanges(plan, c, static_cast<const std::uint32_t*>(out.firstOut), res);
        }
        break;
    case ListsFrom::Written: {
        const auto* written = static_cast<const std::uint32_t*>(out.firstOut);
        res.lightIndices.assign(written, written + c.total);
        break;
    }
    case ListsFrom::SecondSubmission:
        writeListsAgain(plan, pipes, run, c, res);
        break;
    }
    if (!laidOut && (!plan.fptl || c.total == 0)) {
        res.listCount.assign(out.counts, out.counts + listTotal);
        res.listOffset.assign(c.offs, c.offs + listTotal);
    }
    if (plan.zbin) decodeZbin(plan, out.counts, res.listOffset.data(), out.binWordsOut, settings.bins, res);
    decodeTileBounds(plan, out.tb, res);

    res.backend = name();
    res.device = deviceName();
    res.timingMethod = timingMethod();
    res.timings.cullMs = run.stamps ? run.gpuMs : run.wallMs;
    lastCullWallMs_ = run.wallMs;
    history_ = CullHistory{c.longest, c.poolsFitted, listTotal, c.total};
    return res;
}


// ---------------------------------------------------------------------------
// raster: one submission: the tile bounds pass as minmax plans it, then the
// render pass drawing every light's proxy (spheres, then cones: two instanced
// draws of the unit meshes), whose fragments OR each covered tile's light
// bit; the host turns the masks into lists.

namespace {

// View -> clip of the raster pass: the projection's clip matrix, then x and y
// scaled so that a viewport of tilesX x tilesY pixels has one pixel per tile
// (the screen's width / tile of them across: a partial edge tile is a whole
// pixel), and z = w - nearW (perspective; orthographic: w / 2) so that only
// the plane w = nearW clips (no far plane).
glm::mat4 rasterClip(const Projection& proj, const TileGrid& grid, double nearW) {
    const double sx = double(grid.width) / grid.tileSize / grid.tilesX;
    const double sy = double(grid.height) / grid.tileSize / grid.tilesY;
    glm::dmat4 s(1.0); // column-major: s[col][row]
    s[0][0] = sx;
    s[3][0] = sx - 1.0;
    s[1][1] = sy;
    s[3][1] = sy - 1.0;
    glm::dmat4 m = s * proj.clipFromView();
    for (int col = 0; col < 4; ++col) m[col][2] = proj.orthographic() ? 0.5 * m[col][3] : m[col][3];
    if (!proj.orthographic()) m[3][2] -= nearW;
    return glm::mat4(m);
}

} // namespace

CullResult VulkanBackend::cullRaster(const CullFrame& frame, const DepthImage& depth, const Projection& proj,
                                     const ViewLights& lights, const CullSettings& settings) {
    if (!rasterPass_) rasterPass_ = std::make_unique<RasterPass>(ctx_);
    const TileGrid& grid = frame.grid;
    const std::uint32_t n = std::uint32_t(lights.size());
    const std::uint32_t tiles = grid.tileCount();
    const std::uint32_t words = (n + 31) / 32;
    const std::size_t maskBytes = std::size_t(tiles) * words * 4;
    if (maskBytes > profile_.maxStorageBufferRange)
        throw SettingsError("algorithm", "raster needs a light bit per tile: " + std::to_string(tiles) + " tiles x " +
                                             std::to_string(n) + " lights is " + std::to_string(maskBytes >> 20) +
                                             " MiB of masks, more than '" + ctx_.deviceName() +
                                             "' binds at once; use larger tiles or fewer lights");
    // proxy-depth slices: two depths per tile and light (padded to the mask's words).
    const bool slices = settings.proxySlices;
    const std::size_t rangeBytes = slices ? maskBytes * 64 : 0;
    if (rangeBytes > profile_.maxStorageBufferRange)
        throw SettingsError("proxy-depth", "raster's slices need two depths per tile and light: " +
                                               std::to_string(tiles) + " tiles x " + std::to_string(n) + " lights is " +
                                               std::to_string(rangeBytes >> 20) + " MiB, more than '" +
                                               ctx_.deviceName() +
                                               "' binds at once; use larger tiles, fewer lights or proxy-depth tile");
    // The bounds pass: minmax's tile bounds, or with slices clustered's
    // (its occupied slices are skip-empty's).
    CullSettings boundsSettings = settings;
    boundsSettings.algorithm = slices ? Algorithm::Clustered : Algorithm::MinMax;
    CullPlanInputs planIn;
    planIn.settings = boundsSettings;
    planIn.grid = grid;
    planIn.listTotal = frame.listTotal;
    planIn.lights = n;
    planIn.depthPixels = depth.depth.size();
    planIn.orthographic = proj.orthographic();
    planIn.clusterNear = slices ? frame.clusterNear : 0.0;
    const CullPlan plan = planCull(profile_, history_, planIn);

    CullResult res;
    res.algorithm = Algorithm::Raster;
    res.settings = settings;
    res.grid = grid;
    res.listsPerTile = frame.listsPerTile;
    if (slices) {
        res.clusterNear = frame.clusterNear;
        res.clusterFar = frame.clusterFar;
    }
    std::vector<std::uint32_t> upOrder(n);
    for (std::uint32_t l = 0; l < n; ++l) upOrder[l] = l;
    const CullInputs in = prepareInputs(plan, frame, res, depth, proj, lights, boundsSettings, upOrder, false);

    // The proxies: spheres, cones, then boxes. A proxy too large for float
    // where it comes nearest the camera (its corners' rounding, carried to
    // the grid, would pass 1/512 tile: a light around the camera, or one of
    // a radius past float's range) is drawn as the box of the tiles the CPU
    // reference's coverage of it spans, worked out here in double.
    const glm::dmat4 clipD = proj.clipFromView();
    const double tilesPerUnit = std::max(std::abs(clipD[0][0]) * grid.width / grid.tileSize,
                                         std::abs(clipD[1][1]) * grid.height / grid.tileSize) * 0.5;
    std::vector<LightProxy> proxy(n);
    std::vector<char> boxed(n, 0);
    std::uint32_t spheres = 0, cones = 0, boxes = 0;
    for (std::uint32_t l = 0; l < n; ++l) {
        proxy[l] = makeLightProxy(lights, l, settings);
        const LightProxy& p = proxy[l];
        const double reach = glm::length(p.origin) + lights.radii[l] * p.overfit * (p.cone ? std::max(1.0, glm::length(p.basis[0]) / lights.radii[l]) : 1.0);
        const double perUnit = proj.orthographic() ? tilesPerUnit : tilesPerUnit / std::max(p.depthMin, proj.nearPlane());
        const double errTiles = 5e-7 * reach * perUnit;
        boxed[l] = !(errTiles < 1.0 / 512.0);
        (boxed[l] ? boxes : p.cone ? cones : spheres)++;
    }
    std::vector<GpuProxy> proxies(n);
    std::uint32_t nextSphere = 0, nextCone = spheres, nextBox = spheres + cones;
    // A proxy drawn as a box: the tiles it covers and (proxy-depth slices)
    // their depth ranges, worked out here in double as the CPU reference
    // does (the box alone would list every tile of its bounding box, with the
    // proxy's whole depth range); by light, then tile.
    struct BoxRange {
        std::uint32_t light, tile;
        double lo, hi;
        bool operator<(const BoxRange& o) const { return light != o.light ? light < o.light : tile < o.tile; }
    };
    std::vector<BoxRange> boxRanges;
    for (std::uint32_t l = 0; l < n; ++l) {
        const LightProxy& p = proxy[l];
        // The depth range widened past the CPU reference's slack and the
        // bounds pass's float rounding, rounded outwards.
        const double slack = 2.0 * p.slack() +
                             double(kRelEps) * (std::abs(p.depthMax) + lights.radii[l] * p.overfit) + kAbsEps;
        GpuProxy& g = proxies[boxed[l] ? nextBox++ : p.cone ? nextCone++ : nextSphere++];
        g.basisXDepthMin = vec4(glm::vec3(p.basis[0]), std::nextafter(float(p.depthMin - slack), -kInfF));
        g.basisYDepthMax = vec4(glm::vec3(p.basis[1]), std::nextafter(float(p.depthMax + slack), kInfF));
        g.basisZ = vec4(glm::vec3(p.basis[2]), 0.0f);
        // Wholly beyond the near plane (a margin for float): front faces
        // only (slices need the far side's depths too).
        const bool frontOnly = !slices && p.depthMin > proj.nearPlane() * 1.001 + 1e-6 * std::abs(p.depthMin);
        g.light = uvec4(l, 0, frontOnly ? 1u : 0u, 0);
        g.origin = vec4(glm::vec3(p.origin), 0.0f);
        if (boxed[l]) {
            // The tiles' centres the box keeps, in tile units (none: an empty box).
            std::uint32_t x0 = ~0u, y0 = ~0u, x1 = 0, y1 = 0;
            auto spans = [&](std::uint32_t tx, std::uint32_t ty) {
                x0 = std::min(x0, tx), x1 = std::max(x1, tx);
                y0 = std::min(y0, ty), y1 = std::max(y1, ty);
            };
            const std::size_t first = boxRanges.size();
            if (slices) {
                proxySliceTiles(proj, grid, p, settings.conservative, [&](std::uint32_t t, double lo, double hi) {
                    spans(t % grid.tilesX, t / grid.tilesX);
                    boxRanges.push_back({l, t, lo, hi});
                });
            } else { // the tiles alone (the tile test takes the proxy's whole depth range)
                for (const auto& tri : p.mesh->triangles)
                    proxyTriangleTiles(proj, grid, {p.vertex(tri[0]), p.vertex(tri[1]), p.vertex(tri[2])},
                                       settings.conservative, [&](std::uint32_t tx, std::uint32_t ty) {
                                           spans(tx, ty);
                                           boxRanges.push_back({l, grid.tileIndex(tx, ty), 0.0, 0.0});
                                       });
            }
            std::sort(boxRanges.begin() + std::ptrdiff_t(first), boxRanges.end());
            boxRanges.erase(std::unique(boxRanges.begin() + std::ptrdiff_t(first), boxRanges.end(),
                                        [](const BoxRange& a, const BoxRange& b) { return !(a < b) && !(b < a); }),
                            boxRanges.end());
            // (The fragment shader keeps a tile whose rectangle reaches past
            // x0 + 0.5 from this box's low side and past x1 + 0.5 from its
            // high side, a partial edge tile's too.)
            g.origin = x0 > x1 ? vec4(1.0f, 1.0f, 0.0f, 0.0f)
                               : vec4(float(x0) - 0.49f, float(y0) - 0.49f, float(x1) + 1.49f, float(y1) + 1.49f);
            g.light.y = 1;
        }
    }
    const ProxyMesh& sphereMesh = unitIcosphere(settings.proxyLevel);
    const ProxyMesh& coneMesh = unitCone(settings.proxySegments);
    std::vector<vec4> corners;
    corners.reserve(3 * (sphereMesh.triangles.size() + coneMesh.triangles.size()));
    for (const ProxyMesh* m : {&sphereMesh, &coneMesh})
        for (const auto& t : m->triangles)
            for (std::uint32_t k : t) corners.push_back(vec4(glm::vec3(m->vertices[k]), 1.0f));
    const std::uint32_t sphereTris = std::uint32_t(sphereMesh.triangles.size());
    const std::uint32_t coneTris = std::uint32_t(coneMesh.triangles.size());
    // The proxies' triangles, each set up once (proxy_setup.comp) and drawn
    // in batches the triangles buffer holds.
    const std::uint64_t triangles = std::uint64_t(spheres) * sphereTris + std::uint64_t(cones) * coneTris + boxes;
    if (triangles > 0xffffffffull)
        throw SettingsError("proxy-level", "raster's proxies have " + std::to_string(triangles) +
                                               " triangles, more than 2^32 - 1; use a lower proxy level or fewer lights");
    const std::uint32_t batch = std::uint32_t(std::max<std::uint64_t>(
        1, std::min<std::uint64_t>({triangles, RasterPass::kBatchTriangles,
                                    profile_.maxStorageBufferRange / sizeof(GpuProxyTriangle)})));

    const RasterPass::Coverage coverage = rasterPass_->coverage(settings.conservative);
    GpuRasterParams rp{};
    // Clipped a hair before the near plane, where the CPU reference clips:
    // the float pass keeps a little more, never less.
    const double nearW = proj.orthographic() ? -1.0 : proj.nearPlane() * (1.0 - 1e-5);
    const glm::mat4 clip = rasterClip(proj, grid, nearW);
    for (int c = 0; c < 4; ++c) rp.clip[c] = clip[c];
    rp.grid = uvec4(grid.tilesX, grid.tilesY, words,
                    (coverage == RasterPass::Coverage::PushedEdges ? LC_RASTER_PUSH_EDGES : 0u) |
                        (coverage != RasterPass::Coverage::Centre ? LC_RASTER_TRIM : 0u) |
                        (proj.orthographic() ? LC_RASTER_ORTHO : 0u) | (slices ? LC_RASTER_SLICES : 0u));
    rp.cover = vec4(float(double(grid.width) / grid.tileSize), float(double(grid.height) / grid.tileSize),
                    float(nearW), 0.5f + 1.0f / 256.0f);
    rp.setup = uvec4(sphereTris, coneTris, spheres, cones);

    BufferCache::Frame cacheFrame(cache_);
    CullRun run;
    Staging staging(cache_);
    const CullReadback out = setUpBuffers(plan, in, depth, staging, run);
    const CullPipelines pipes = cullPipelines(plan, false);
    auto storage = [&](const char* role, std::size_t bytes, VkBufferUsageFlags extra = 0) -> const Buffer& {
        const Buffer& b = cache_.get(role, std::max<std::size_t>(bytes, 16),
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | extra, BufferCache::Kind::Device);
        run.asked[b.buffer] = std::max<std::size_t>(bytes, 16);
        return b;
    };
    const Buffer& params = storage("raster.params", sizeof rp);
    const Buffer& proxyBuf = storage("raster.proxies", proxies.size() * sizeof(GpuProxy));
    const Buffer& meshBuf = storage("raster.mesh", corners.size() * sizeof(vec4));
    const Buffer& masks = storage("raster.masks", maskBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    const Buffer& ranges = storage("raster.ranges", rangeBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    const Buffer& triangleBuf = storage("raster.triangles", std::size_t(batch) * sizeof(GpuProxyTriangle));
    staging.upload(params, &rp, sizeof rp, "raster.params");
    staging.upload(proxyBuf, proxies.data(), proxies.size() * sizeof(GpuProxy), "raster.proxies");
    staging.upload(meshBuf, corners.data(), corners.size() * sizeof(vec4), "raster.mesh");
    const auto* maskWords = static_cast<const std::uint32_t*>(staging.download(masks, maskBytes, "raster.masks"));
    const auto* rangeWords =
        slices ? static_cast<const std::uint32_t*>(staging.download(ranges, rangeBytes, "raster.ranges")) : nullptr;
    const Buffer* bound[RasterPass::kBindings] = {&params,  run.tiles, &proxyBuf,    &meshBuf,
                                                  &masks,   &ranges,   &triangleBuf};
    std::vector<Context::DescriptorWrite> bindings(RasterPass::kBindings);
    for (std::uint32_t i = 0; i < RasterPass::kBindings; ++i) {
        bindings[i].buffer = bound[i]->buffer;
        bindings[i].range = run.asked.at(bound[i]->buffer);
    }
    DescriptorPoolHandle pool = ctx_.createDescriptorPool(bindings, 1, "raster.descriptorPool");
    const VkDescriptorSet set = ctx_.writeDescriptorSet(pool, rasterPass_->setLayout(), bindings, "raster.set");

    TimestampPool stamps = profile_.gpuTimestamps() ? TimestampPool(ctx_, 1, "raster.timestamps") : TimestampPool();
    const double wallMs = ctx_.submitAndWait(
        [&](VkCommandBuffer cmd) {
            if (stamps) stamps.reset(cmd);
            if (maskBytes) vkCmdFillBuffer(cmd, masks.buffer, 0, maskBytes, 0); // none without lights
            if (rangeBytes) vkCmdFillBuffer(cmd, ranges.buffer, 0, rangeBytes, ~0u);
            staging.recordUploads(cmd,
                                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_VERTEX_SHADER_BIT |
                                      VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT, true);
            if (run.residentDepth)
                memoryBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                              VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
            if (stamps) stamps.begin(cmd, 0);
            {
                LabelScope label(ctx_, cmd, "tile bounds");
                vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, computeLayout_, 0, 1, &run.countSet, 0,
                                        nullptr);
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipes.bounds);
                vkCmdDispatch(cmd, plan.boundsGroups.x, plan.boundsGroups.y, 1);
            }
            // The fragment shader reads the bounds the pass above wrote.
            memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                          VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
            {
                LabelScope label(ctx_, cmd, "light proxies");
                rasterPass_->record(cmd, coverage, set, grid.tilesX, grid.tilesY, triangles, batch);
            }
            if (stamps) stamps.end(cmd, 0);
            // The read-back (a copy, or the host in place) reads the masks.
            memoryBarrier(cmd, VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                          VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                          VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_HOST_READ_BIT);
            staging.recordDownloads(cmd);
        },
        "raster.commands");
    checkStatus(out.status, ctx_.deviceName());

    decodeTileBounds(plan, out.tb, res);
    // A proxy drawn as a box lists only the tiles the host found it covers.
    auto boxCovers = [&](std::uint32_t l, std::uint32_t t) -> const BoxRange* {
        const auto it = std::lower_bound(boxRanges.begin(), boxRanges.end(), BoxRange{l, t, 0, 0});
        return it != boxRanges.end() && it->light == l && it->tile == t ? &*it : nullptr;
    };
    // Masks -> lists, in light order; with slices each covered tile's depth
    // range -> the light's slices there (LightProxy::sliceMask, as the CPU
    // reference).
    res.listOffset.resize(std::size_t(tiles) * res.listsPerTile);
    res.listCount.resize(std::size_t(tiles) * res.listsPerTile);
    std::vector<std::vector<std::uint32_t>> sliceLists(slices ? res.listsPerTile : 0);
    const SliceLocator clusterSlices(settings.slicing, res.clusterNear, res.clusterFar,
                                     slices ? std::min<std::uint32_t>(settings.cells, 32) : 0);
    // The ranges of the set bits first, in one tight pass: scattered over
    // the tiles x lights buffer (67 MB at P1), they are a cache and TLB miss
    // each, which this loop overlaps and the decode below would not.
    std::vector<std::pair<float, float>> setRanges;
    for (std::uint32_t t = 0; slices && t < tiles; ++t) {
        const std::uint32_t* m = maskWords + std::size_t(t) * words;
        const std::uint32_t* r = rangeWords + 2 * std::size_t(t) * words * 32;
        for (std::uint32_t w = 0; w < words; ++w)
            for (std::uint32_t bits = m[w]; bits; bits &= bits - 1) {
                const std::uint32_t l = w * 32 + std::uint32_t(std::countr_zero(bits));
                setRanges.emplace_back(std::bit_cast<float>(r[2 * l]), std::bit_cast<float>(~r[2 * l + 1]));
            }
    }
    std::size_t nextRange = 0;
    for (std::uint32_t t = 0; slices && t < tiles; ++t) {
        for (auto& s : sliceLists) s.clear();
        const std::uint32_t* m = maskWords + std::size_t(t) * words;
        for (std::uint32_t w = 0; w < words; ++w)
            for (std::uint32_t bits = m[w]; bits; bits &= bits - 1) {
                const std::uint32_t l = w * 32 + std::uint32_t(std::countr_zero(bits));
                double lo = double(setRanges[nextRange].first), hi = double(setRanges[nextRange].second);
                ++nextRange;
                if (boxed[l]) { // the host's own ranges (the box only marks the tiles they span)
                    const BoxRange* b = boxCovers(l, t);
                    if (!b) continue;
                    lo = b->lo, hi = b->hi;
                }
                for (std::uint32_t k = proxy[l].sliceMask(clusterSlices, settings.skipEmpty, lo, hi, res.cellMask[t]);
                     k; k &= k - 1)
                    sliceLists[std::size_t(std::countr_zero(k))].push_back(l);
            }
        for (std::uint32_t k = 0; k < res.listsPerTile; ++k) {
            const std::size_t list = std::size_t(t) * res.listsPerTile + k;
            res.listOffset[list] = std::uint32_t(res.lightIndices.size());
            res.listCount[list] = std::uint32_t(sliceLists[k].size());
            res.lightIndices.insert(res.lightIndices.end(), sliceLists[k].begin(), sliceLists[k].end());
        }
    }
    for (std::uint32_t t = 0; !slices && t < tiles; ++t) {
        res.listOffset[t] = std::uint32_t(res.lightIndices.size());
        const std::uint32_t* m = maskWords + std::size_t(t) * words;
        for (std::uint32_t w = 0; w < words; ++w)
            for (std::uint32_t bits = m[w]; bits; bits &= bits - 1) {
                const std::uint32_t l = w * 32 + std::uint32_t(std::countr_zero(bits));
                if (!boxed[l] || boxCovers(l, t)) res.lightIndices.push_back(l);
            }
        res.listCount[t] = std::uint32_t(res.lightIndices.size()) - res.listOffset[t];
    }
    res.coverage = rasterPass_->describe(coverage);
    if (boxes)
        res.coverage += "; " + std::to_string(boxes) + (boxes == 1 ? " proxy" : " proxies") +
                        " too large for float near the camera drawn as the box of tiles the host's double-precision "
                        "coverage found, listed only there";
    res.backend = name();
    res.device = deviceName();
    res.timingMethod = timingMethod();
    res.timings.cullMs = stamps ? stamps.milliseconds(0) : wallMs;
    lastCullWallMs_ = wallMs;
    return res;
}
} // namespace

std::unique_ptr<CullBackend> makeVulkanBackend(const std::string& device) {
    return std::make_unique<VulkanBackend>(device);
}

std::vector<std::string> vulkanDeviceNames() { return vk::physicalDeviceNames(); }

} // namespace lc
