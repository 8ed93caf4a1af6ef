#pragma once
// Internal Vulkan plumbing of the backend: checked calls, move-only RAII owners
// with debug names, and the headless context (instance, physical device, one
// compute+graphics queue). Nothing here leaks into culling/include.
#include "culling/core/errors.hpp"

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace lc::vk {

const char* resultName(VkResult r);
[[noreturn]] void throwVkError(const char* call, VkResult r, const char* file, int line);

// One global memory barrier: `dstAccess` at `dstStage` waits for `srcAccess`
// at `srcStage` (this submission's commands and those submitted before).
void memoryBarrier(VkCommandBuffer cmd, VkPipelineStageFlags srcStage, VkAccessFlags srcAccess,
                   VkPipelineStageFlags dstStage, VkAccessFlags dstAccess);

// Every Vulkan call that returns a VkResult goes through this: failure throws
// lc::DeviceError naming the call, the result and the source position.
#define LC_VK(call)                                                       \
    do {                                                                  \
        VkResult lc_vk_result_ = (call);                                  \
        if (lc_vk_result_ != VK_SUCCESS)                                  \
            ::lc::vk::throwVkError(#call, lc_vk_result_, __FILE__, __LINE__); \
    } while (0)

// Move-only owner of a device-level handle destroyed by Destroy(device, h, nullptr).
template <typename T, void (*Destroy)(VkDevice, T, const VkAllocationCallbacks*)>
class DeviceHandle {
public:
    DeviceHandle() = default;
    DeviceHandle(VkDevice device, T handle) : device_(device), handle_(handle) {}
    DeviceHandle(const DeviceHandle&) = delete;
    DeviceHandle& operator=(const DeviceHandle&) = delete;
    DeviceHandle(DeviceHandle&& o) noexcept
        : device_(o.device_), handle_(std::exchange(o.handle_, VK_NULL_HANDLE)) {}
    DeviceHandle& operator=(DeviceHandle&& o) noexcept {
        if (this != &o) {
            reset();
            device_ = o.device_;
            handle_ = std::exchange(o.handle_, VK_NULL_HANDLE);
        }
        return *this;
    }
    ~DeviceHandle() { reset(); }
    void reset() {
        if (handle_ != VK_NULL_HANDLE) Destroy(device_, handle_, nullptr);
        handle_ = VK_NULL_HANDLE;
    }
    T get() const { return handle_; }
    operator T() const { return handle_; }
    explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }

private:
    VkDevice device_ = VK_NULL_HANDLE;
    T handle_ = VK_NULL_HANDLE;
};

using BufferHandle = DeviceHandle<VkBuffer, vkDestroyBuffer>;
using MemoryHandle = DeviceHandle<VkDeviceMemory, vkFreeMemory>;
using ImageHandle = DeviceHandle<VkImage, vkDestroyImage>;
using ImageViewHandle = DeviceHandle<VkImageView, vkDestroyImageView>;
using ShaderModuleHandle = DeviceHandle<VkShaderModule, vkDestroyShaderModule>;
using PipelineHandle = DeviceHandle<VkPipeline, vkDestroyPipeline>;
using PipelineLayoutHandle = DeviceHandle<VkPipelineLayout, vkDestroyPipelineLayout>;
using DescriptorSetLayoutHandle = DeviceHandle<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>;
using DescriptorPoolHandle = DeviceHandle<VkDescriptorPool, vkDestroyDescriptorPool>;
using CommandPoolHandle = DeviceHandle<VkCommandPool, vkDestroyCommandPool>;
using FenceHandle = DeviceHandle<VkFence, vkDestroyFence>;
using RenderPassHandle = DeviceHandle<VkRenderPass, vkDestroyRenderPass>;
using FramebufferHandle = DeviceHandle<VkFramebuffer, vkDestroyFramebuffer>;

class Context;

// Device memory a context has allocated: bytes alive now and the most alive
// at once since the last resetPeak() (VkMemoryRequirements sizes, so
// alignment padding counts).
struct MemoryStats {
    std::uint64_t live = 0, peak = 0;
    std::uint64_t allocations = 0; // vkAllocateMemory calls, all told
};

// Move-only share of MemoryStats.live held by one allocation: added when the
// memory is allocated, removed when its owner goes away. Shared ownership of
// the stats, so the order in which a context and its buffers die is free.
class TrackedBytes {
public:
    TrackedBytes() = default;
    TrackedBytes(std::shared_ptr<MemoryStats> stats, std::uint64_t bytes);
    TrackedBytes(const TrackedBytes&) = delete;
    TrackedBytes& operator=(const TrackedBytes&) = delete;
    TrackedBytes(TrackedBytes&& o) noexcept : stats_(std::move(o.stats_)), bytes_(std::exchange(o.bytes_, 0)) {}
    TrackedBytes& operator=(TrackedBytes&& o) noexcept;
    ~TrackedBytes() { release(); }

private:
    void release();
    std::shared_ptr<MemoryStats> stats_;
    std::uint64_t bytes_ = 0;
};

// A buffer with its own memory. `mapped` is the persistent host mapping, or
// null for device-local memory the host cannot see (copy through a staging
// buffer then).
struct Buffer {
    BufferHandle buffer;
    MemoryHandle memory;
    void* mapped = nullptr;
    VkDeviceSize size = 0;
    TrackedBytes tracked; // declared last: leaves the stats first
    template <typename T> T* as() const { return static_cast<T*>(mapped); }
};

struct Image {
    ImageHandle image;
    MemoryHandle memory;
    ImageViewHandle view;
    TrackedBytes tracked;
};

// GPU timestamps around a recorded span of commands (vkCmdWriteTimestamp at
// bottom of pipe at both ends). Queries 2i, 2i+1 time span i.
class TimestampPool {
public:
    TimestampPool() = default;
    TimestampPool(const Context& ctx, std::uint32_t spans, const std::string& name);
    void reset(VkCommandBuffer cmd) const;              // record before the first begin()
    void begin(VkCommandBuffer cmd, std::uint32_t span) const;
    void end(VkCommandBuffer cmd, std::uint32_t span) const;
    // Milliseconds of span `span` (after its submission completed).
    double milliseconds(std::uint32_t span) const;
    explicit operator bool() const { return bool(pool_); }

private:
    using QueryPoolHandle = DeviceHandle<VkQueryPool, vkDestroyQueryPool>;
    QueryPoolHandle pool_;
    VkDevice device_ = VK_NULL_HANDLE;
    std::uint32_t spans_ = 0;
    double nsPerTick_ = 1.0;
    std::uint64_t validMask_ = ~0ull;
};

// What a caller asks of the context (see vulkan_backend.hpp for `device`).
struct ContextOptions {
    std::string device;   // index or case-insensitive name substring; empty: default rule
    std::string purpose;  // prefix of debug names, e.g. "lc.render"
    bool validation = false;   // the validation layer even without LIGHTCULL_VALIDATION=1 (user shaders)
    bool robustAccess = false; // robustBufferAccess: out-of-range accesses of user shaders stay harmless
};

// Instance, chosen physical device, logical device and its one queue. The
// validation layer and messenger are enabled when LIGHTCULL_VALIDATION=1.
class Context {
public:
    explicit Context(const ContextOptions& opt);
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    VkDevice device() const { return device_; }
    VkPhysicalDevice physicalDevice() const { return physical_; }
    const VkPhysicalDeviceProperties& properties() const { return props_; }
    std::string deviceName() const { return props_.deviceName; }
    std::uint32_t subgroupSize() const { return subgroupSize_; }
    bool fullSubgroupsSupported() const { return fullSubgroups_; }
    // shaderInt64, enabled when the device has it (tile_bounds' pixel-pair loads).
    bool int64Supported() const { return int64_; }
    // Subgroup shuffles in compute shaders (subgroupShuffleXor).
    bool subgroupShuffleSupported() const { return shuffle_; }
    // storageBuffer16BitAccess (Vulkan 1.1), enabled when the device has it:
    // the GPU culling pass writes 16-bit light indices where they fit.
    bool index16Supported() const { return index16_; }
    // fragmentStoresAndAtomics, enabled when the device has it: the raster
    // pass's fragment shader sets its light bits with atomics.
    bool fragmentStoresSupported() const { return fragmentStores_; }
    // VK_EXT_conservative_rasterization, enabled when the device has it, and
    // its properties (the raster pass's overestimating coverage).
    bool conservativeRasterSupported() const { return conservative_; }
    float primitiveOverestimationSize() const { return overestimation_; }
    float maxExtraPrimitiveOverestimationSize() const { return maxExtraOverestimation_; }
    // A CPU implementation (lavapipe): device memory is host memory, so
    // buffers stay host-visible and mapped, and compute timestamps are not
    // trusted (DESIGN.md). Elsewhere: device-local buffers, GPU timestamps.
    // LIGHTCULL_VK_EMULATE_GPU=1 makes a CPU device take the GPU paths
    // (device-local buffers behind staging copies, subgroup work layout, GPU
    // timestamps) so that tests exercise them on lavapipe.
    VkInstance instance() const { return instance_; }
    bool isCpuDevice() const { return props_.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU && !emulateGpu_; }
    // The queue writes timestamps in compute and graphics (and the device
    // reports a tick period): GPU timing is possible.
    bool timestampsSupported() const { return timestamps_; }
    std::uint32_t timestampValidBits() const { return timestampValidBits_; }
    const MemoryStats& memoryStats() const { return *memory_; }
    void resetPeakMemory() const { memory_->peak = memory_->live; }

    // Gives `handle` the debug name `purpose.name` when VK_EXT_debug_utils is on.
    void name(VkObjectType type, std::uint64_t handle, const std::string& name) const;
    template <typename T> void name(VkObjectType type, T handle, const std::string& n) const {
        name(type, reinterpret_cast<std::uint64_t>(handle), n);
    }
    // Opens and closes a labelled region of `cmd` (a marker region in
    // RenderDoc's event browser) when VK_EXT_debug_utils is on.
    void beginLabel(VkCommandBuffer cmd, const char* label) const;
    void endLabel(VkCommandBuffer cmd) const;

    // Where a buffer's memory lies: Host (createBuffer), HostRead
    // (createReadbackBuffer), Device (createDeviceBuffer).
    enum class Placement { Host, HostRead, Device };
    // The create function of `where`.
    Buffer createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& name,
                        Placement where) const;
    // Host-visible, coherent, persistently mapped buffer (size 0 -> 4 bytes).
    Buffer createBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& name) const;
    // createBuffer for data the host reads back: host-cached memory where the
    // device has a coherent type of it (a GPU's plain host-visible memory is
    // write-combined, and the host reads it uncached).
    Buffer createReadbackBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& name) const;
    // Buffer for work on the device: device-local memory. On a CPU device
    // (lavapipe: device memory is host memory) it is mapped and used in
    // place; on a GPU `mapped` is null and data moves through staging copies
    // (usage gets TRANSFER_SRC | TRANSFER_DST for that): host reads of mapped
    // video memory (resizable BAR) are uncached and slow.
    Buffer createDeviceBuffer(VkDeviceSize size, VkBufferUsageFlags usage, const std::string& name) const;
    // A 2D image in device-local memory with a view of `aspect`, named `name`
    // (memory "name.memory", view "name.view").
    Image createImage(std::uint32_t w, std::uint32_t h, VkFormat format, VkImageUsageFlags usage,
                      VkImageAspectFlags aspect, const std::string& name) const;
    // createImage for a depth attachment the host reads back (transfer source).
    Image createDepthImage(std::uint32_t w, std::uint32_t h, VkFormat format, const std::string& name) const;
    ShaderModuleHandle createShader(const std::uint32_t* words, std::size_t wordCount,
                                    const std::string& name) const;
    // The layouts of a compute pass whose binding i has descriptor type
    // types[i]: one descriptor set layout and a pipeline layout over it (with
    // `pushConstantBytes` of compute push constants when not 0), named
    // "<name>.setLayout" and "<name>.pipelineLayout".
    struct PassLayouts {
        DescriptorSetLayoutHandle set;
        PipelineLayoutHandle pipeline;
    };
    PassLayouts createPassLayouts(const std::vector<VkDescriptorType>& types, const std::string& name,
                                  std::uint32_t pushConstantBytes = 0,
                                  VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT) const;
    // One binding of a descriptor set: a buffer's first `range` bytes, or
    // (image types) a sampled image.
    struct DescriptorWrite {
        VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        VkBuffer buffer = VK_NULL_HANDLE;
        VkDeviceSize range = VK_WHOLE_SIZE;
        VkDescriptorImageInfo image{};
    };
    // A descriptor pool with room for `sets` sets of `bindings`' types,
    // named "<name>", and a set of it written with binding i = bindings[i].
    DescriptorPoolHandle createDescriptorPool(const std::vector<DescriptorWrite>& bindings, std::uint32_t sets,
                                              const std::string& name) const;
    VkDescriptorSet writeDescriptorSet(VkDescriptorPool pool, VkDescriptorSetLayout layout,
                                       const std::vector<DescriptorWrite>& bindings, const std::string& name) const;

    // Records a one-time command buffer, submits it, waits. Returns the CPU
    // wall-clock milliseconds from submit to the fence signalling.
    double submitAndWait(const std::function<void(VkCommandBuffer)>& record, const std::string& name);
    // The same with a time limit: false when the work has not finished after
    // `timeoutMs`. The device is then still running it, and destroying what
    // it uses is undefined: the caller must leak this context and everything
    // created on it (never destroy them) and open a new one.
    bool submitAndWaitFor(const std::function<void(VkCommandBuffer)>& record, const std::string& name,
                          double timeoutMs, double& wallMs);

private:
    void release(); // destroys everything, in reverse order of creation
    std::uint32_t findMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags want) const;
    bool hasMemoryType(std::uint32_t typeBits, VkMemoryPropertyFlags want) const;

    VkInstance instance_ = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
    VkPhysicalDevice physical_ = VK_NULL_HANDLE;
    VkDevice device_ = VK_NULL_HANDLE;
    VkQueue queue_ = VK_NULL_HANDLE;
    std::uint32_t queueFamily_ = 0;
    VkPhysicalDeviceProperties props_{};
    VkPhysicalDeviceMemoryProperties memProps_{};
    std::uint32_t subgroupSize_ = 1;
    bool fullSubgroups_ = false;
    bool int64_ = false;
    bool shuffle_ = false;
    bool index16_ = false;
    bool fragmentStores_ = false;
    bool conservative_ = false;
    float overestimation_ = 0, maxExtraOverestimation_ = 0;
    bool timestamps_ = false;
    bool emulateGpu_ = false;
    std::uint32_t timestampValidBits_ = 0;
    std::shared_ptr<MemoryStats> memory_ = std::make_shared<MemoryStats>();
    bool debugUtils_ = false;
    std::string purpose_;
    PFN_vkSetDebugUtilsObjectNameEXT setName_ = nullptr;
    PFN_vkCmdBeginDebugUtilsLabelEXT beginLabel_ = nullptr;
    PFN_vkCmdEndDebugUtilsLabelEXT endLabel_ = nullptr;
    CommandPoolHandle commandPool_;
    FenceHandle fence_;
};

// A labelled region of a command buffer for the scope of this object.
class LabelScope {
public:
    LabelScope(const Context& ctx, VkCommandBuffer cmd, const char* label) : ctx_(ctx), cmd_(cmd) {
        ctx_.beginLabel(cmd_, label);
    }
    ~LabelScope() { ctx_.endLabel(cmd_); }
    LabelScope(const LabelScope&) = delete;
    LabelScope& operator=(const LabelScope&) = delete;

private:
    const Context& ctx_;
    VkCommandBuffer cmd_;
};

// Names of the physical devices the loader reports (empty when none / no ICD).
std::vector<std::string> physicalDeviceNames();

// Buffers kept from one call to the next, one per role ("cull.tiles",
// "staging.download.cull.counts"): a call gets its role's buffer back while
// it is of the same kind and usage and holds the bytes asked for without
// holding more than four times them, else a new one with a quarter more
// (the old one freed first). Creating and freeing device memory on every
// call was most of what a cull cost a caller on a GPU (the H100: 6.8 ms a
// P1 cull for 0.08 ms of submission). Every pass writes what it reads
// (nothing relies on fresh memory), and a buffer's bytes beyond what was
// asked are never bound (descriptor ranges are the asked sizes).
class BufferCache {
  public:
    using Kind = Context::Placement;
    explicit BufferCache(const Context& ctx) : ctx_(ctx) {}
    BufferCache(const BufferCache&) = delete;
    BufferCache& operator=(const BufferCache&) = delete;

    // One pass's use of the cache (a depth pre-pass, a cull, a shading):
    // buffers are asked for only while a frame is open, and each role once
    // in it, because asking again may replace the buffer an earlier
    // reference names. Either is a std::logic_error, not a dangling
    // reference.
    class Frame {
      public:
        explicit Frame(BufferCache& cache);
        ~Frame();
        Frame(const Frame&) = delete;
        Frame& operator=(const Frame&) = delete;

      private:
        BufferCache& cache_;
    };

    // Made by Context::createBuffer(..., kind). The buffer lives until the role asks again with a
    // size or kind it does not fit, or the cache goes.
    const Buffer& get(const std::string& role, VkDeviceSize bytes, VkBufferUsageFlags usage, Kind kind);

  private:
    struct Entry {
        Buffer buffer;
        VkBufferUsageFlags usage = 0;
        Kind kind = Kind::Host;
    };
    const Context& ctx_;
    std::map<std::string, Entry> entries_;
    bool inFrame_ = false;
    std::set<std::string> taken_; // the roles the open frame asked for
};

} // namespace lc::vk
