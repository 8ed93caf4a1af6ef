// The Vulkan shading pass: one dispatch of shaders/shade.comp over the image
// per chunk of lights, 8x8 invocations of four pixels each per workgroup,
// every buffer host-visible (as the culling passes; docs/VULKAN.md).
#include "vk/shade_pass.hpp"

#include "culling/core/errors.hpp"
#include "culling/vk/gpu_shade.h"
#include "embedded_spirv.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

// Vulkan create-info structs are value-initialised as {VK_STRUCTURE_TYPE_...}:
// the remaining members are zero on purpose.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace lc::vk {

namespace {
constexpr std::uint32_t kBindings = 9; // shade.comp bindings 0..8: storage buffers, then the light block
constexpr std::uint32_t kGroup = 8;    // shade.comp local size, x and y
constexpr std::uint32_t kPushBytes = 16; // shade.comp's Chunk
} // namespace

ShadePass::ShadePass(Context& ctx) : ctx_(ctx) {
    std::vector<VkDescriptorType> types(kBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER);
    types[8] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC; // one chunk of lights per dispatch
    auto layouts = ctx_.createPassLayouts(types, "shade", kPushBytes);
    setLayout_ = std::move(layouts.set);
    layout_ = std::move(layouts.pipeline);
    const spirv::Code code = spirv::shade();
    shader_ = ctx_.createShader(code.words, code.wordCount, "shader.shade");
    // The lights a uniform block holds: as many as the device's range
    // allows, a multiple of 16 so that every chunk's offset (48 bytes a
    // light) is a multiple of 256, the largest offset alignment Vulkan allows.
    const std::uint32_t range = std::min<std::uint32_t>(ctx_.properties().limits.maxUniformBufferRange, 1u << 16);
    blockLights_ = std::max<std::uint32_t>(range / sizeof(GpuShadeLight) / 16 * 16, 16);
}

VkPipeline ShadePass::pipeline(bool allLights, bool lightsInBlock) {
    PipelineHandle& pipe = pipelines_[(allLights ? 2 : 0) + (lightsInBlock ? 1 : 0)];
    if (pipe) return pipe;
    const std::uint32_t spec[3] = {allLights ? 1u : 0u, lightsInBlock ? 1u : 0u, blockLights_};
    const VkSpecializationMapEntry entries[3] = {{0, 0, 4}, {1, 4, 4}, {2, 8, 4}};
    VkSpecializationInfo si{};
    si.mapEntryCount = 3;
    si.pMapEntries = entries;
    si.dataSize = sizeof spec;
    si.pData = spec;
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
    ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    ci.stage.module = shader_;
    ci.stage.pName = "main";
    ci.stage.pSpecializationInfo = &si;
    ci.layout = layout_;
    VkPipeline p;
    LC_VK(vkCreateComputePipelines(ctx_.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &p));
    ctx_.name(VK_OBJECT_TYPE_PIPELINE, p,
              std::string(allLights ? "pipeline.shade.all" : "pipeline.shade.lists") + (lightsInBlock ? ".block" : ""));
    pipe = PipelineHandle(ctx_.device(), p);
    return pipe;
}

// A G-buffer past one storage buffer's range (lavapipe's 128 MiB holds
// 2048x2048 of 32-byte pixels, not 4K): shaded in bands of whole rows, each
// in range. A pixel's shading reads only its own G-buffer entry and its
// list, so the bands add up to the same image.
std::vector<float> ShadePass::runInBands(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled,
                                         double& ms) {
    const std::size_t pixels = std::size_t(in.width) * in.height;
    const auto& lim = ctx_.properties().limits;
    const std::size_t rowBytes = std::size_t(in.width) * sizeof(GpuShadePixel);
    const std::uint32_t bandRows = std::uint32_t(lim.maxStorageBufferRange / rowBytes);
    if (bandRows == 0)
        throw DeviceError("shading: one " + std::to_string(in.width) +
                          "-pixel row exceeds this device's storage buffer range");
    std::vector<float> rgb;
    rgb.reserve(pixels * 3);
    ms = 0;
    for (std::uint32_t y0 = 0; y0 < in.height; y0 += bandRows) {
        const std::uint32_t rows = std::min(bandRows, in.height - y0);
        const std::size_t first = std::size_t(y0) * in.width, count = std::size_t(rows) * in.width;
        ShadeInputs band;
        band.width = in.width;
        band.height = rows;
        band.position.assign(in.position.begin() + 3 * first, in.position.begin() + 3 * (first + count));
        band.normal.assign(in.normal.begin() + 3 * first, in.normal.begin() + 3 * (first + count));
        band.list.assign(in.list.begin() + first, in.list.begin() + first + count);
        band.perPixelLists = in.perPixelLists;
        double bandMs = 0;
        const std::vector<float> part = run(band, lights, culled, bandMs);
        rgb.insert(rgb.end(), part.begin(), part.end());
        ms += bandMs;
    }
    return rgb;
}

std::vector<float> ShadePass::run(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled,
                                  double& ms) {
    if (in.perPixelLists && culled) culled = in.perPixelLists.get(); // zbin: the lists `in.list` indexes
    const std::size_t pixels = std::size_t(in.width) * in.height;
    if (in.position.size() != 3 * pixels || in.normal.size() != 3 * pixels || in.list.size() != pixels)
        throw Error("shading: inconsistent shading inputs");
    const std::size_t lightCount = lights.size();
    const std::size_t listTotal = culled ? culled->listCount.size() : 1;
    // The shader trusts its indices: check every one here (typed errors, never
    // an out-of-bounds read on the device). On the way, whether every list is
    // in ascending light order: such lists go in the chunks of lights below.
    bool ascending = culled != nullptr;
    if (culled) {
        if (culled->listOffset.size() != listTotal) throw Error("shading: cull result offsets and counts differ");
        for (std::size_t l = 0; l < listTotal; ++l) {
            if (std::size_t(culled->listOffset[l]) + culled->listCount[l] > culled->lightIndices.size())
                throw Error("shading: list " + std::to_string(l) + " overruns the index array");
            const std::uint32_t* list = culled->lightIndices.data() + culled->listOffset[l];
            for (std::uint32_t k = 1; ascending && k < culled->listCount[l]; ++k) ascending = list[k - 1] < list[k];
        }
        for (std::uint32_t i : culled->lightIndices)
            if (i >= lightCount)
                throw Error("shading: a list names light " + std::to_string(i) + " of " + std::to_string(lightCount));
    }
    for (std::size_t i = 0; i < pixels; ++i)
        if (in.list[i] != ShadeInputs::kNoList && in.list[i] >= listTotal)
            throw Error("shading: pixel " + std::to_string(i) + " uses list " + std::to_string(in.list[i]) + " of " +
                        std::to_string(listTotal));
    const auto& lim = ctx_.properties().limits;
    if (pixels * sizeof(GpuShadePixel) > lim.maxStorageBufferRange) return runInBands(in, lights, culled, ms);
    // Four pixels of a row an invocation (shade.comp).
    const std::uint32_t columns = (in.width + 3) / 4;
    const std::uint32_t gx = (columns + kGroup - 1) / kGroup, gy = (in.height + kGroup - 1) / kGroup;
    if (gx > lim.maxComputeWorkGroupCount[0] || gy > lim.maxComputeWorkGroupCount[1])
        throw DeviceError("shading: too many workgroups for one dispatch on this device");

    // Host-visible buffers kept between calls (fresh ones cost a page fault
    // per 4 KiB touched), each bound at the bytes this call asked for.
    BufferCache::Frame cacheFrame(cache_);
    std::vector<Context::DescriptorWrite> bindings(kBindings);
    auto buffer = [&](std::uint32_t binding, const char* role, std::size_t bytes,
                      BufferCache::Kind kind = BufferCache::Kind::Host) -> const Buffer& {
        const VkBufferUsageFlags usage =
            binding == 8 ? VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT : VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
        const Buffer& b = cache_.get(role, bytes, usage, kind);
        bindings[binding].buffer = b.buffer;
        bindings[binding].range = std::max<std::size_t>(bytes, 4);
        return b;
    };
    const Buffer& params = buffer(0, "shade.params", sizeof(GpuShadeParams));
    const Buffer& pixelBuf = buffer(1, "shade.pixels", pixels * sizeof(GpuShadePixel));
    const Buffer& listBuf = buffer(2, "shade.pixelLists", pixels * 4);
    const Buffer& lightBuf = buffer(3, "shade.lights", lightCount * sizeof(GpuShadeLight));
    const Buffer& offsetBuf = buffer(4, "shade.listOffsets", culled ? listTotal * 4 : 4);
    const Buffer& countBuf = buffer(5, "shade.listCounts", culled ? listTotal * 4 : 4);
    const Buffer& indexBuf = buffer(6, "shade.lightIndices", culled ? culled->lightIndices.size() * 4 : 4);
    const Buffer& outBuf = buffer(7, "shade.rgb", pixels * 3 * 4, BufferCache::Kind::HostRead);
    // The lights again as uniform blocks of blockLights_ each (the last one
    // padded): every chunk of the all-lights image, and a list image's lights
    // when one block holds them all.
    // A list image goes in chunks too when every list is in ascending light
    // order: each chunk then adds its lights in the list's own order. Other
    // lists (a custom shader's, say) read the storage buffer in one pass.
    const bool allLights = culled == nullptr;
    const bool inBlock = allLights || lightCount <= blockLights_ || ascending;
    const std::size_t chunks = inBlock ? std::max<std::size_t>((lightCount + blockLights_ - 1) / blockLights_, 1) : 1;
    const std::size_t blockBytes = std::size_t(blockLights_) * sizeof(GpuShadeLight);
    const Buffer& blockBuf = buffer(8, "shade.lightBlocks", inBlock ? chunks * blockBytes : 4);
    bindings[8].type = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER_DYNAMIC;
    bindings[8].range = inBlock ? blockBytes : 4;

    params.as<GpuShadeParams>()->size =
        glm::uvec4(in.width, in.height, std::uint32_t(lightCount), std::uint32_t(listTotal));
    const Uploaded now{in.gbufferId, in.position.data(), in.normal.data(), pixels, pixelBuf.buffer};
    if (now.id == 0 || !(now == uploaded_)) {
        uploaded_ = {};
        GpuShadePixel* px = pixelBuf.as<GpuShadePixel>();
        for (std::size_t i = 0; i < pixels; ++i) {
            px[i].position = glm::vec4(in.position[3 * i], in.position[3 * i + 1], in.position[3 * i + 2], 0.0f);
            px[i].normal = glm::vec4(in.normal[3 * i], in.normal[3 * i + 1], in.normal[3 * i + 2], 0.0f);
        }
        uploaded_ = now;
    }
    std::memcpy(listBuf.mapped, in.list.data(), pixels * 4);
    GpuShadeLight* L = lightBuf.as<GpuShadeLight>();
    for (std::size_t i = 0; i < lightCount; ++i) {
        L[i].position = glm::vec4(glm::vec3(lights.centers[i]), shadingInvRange2(lights.shadingRange(i)));
        L[i].power = glm::vec4(glm::vec3(lights.power[i]), 0.0f);
        L[i].spot = lights.isSpot(i) ? glm::vec4(glm::vec3(lights.spotAxes[i]), float(std::cos(lights.spotAngles[i])))
                                     : glm::vec4(0.0f, 0.0f, 0.0f, -2.0f);
    }
    if (inBlock && lightCount) std::memcpy(blockBuf.mapped, L, lightCount * sizeof(GpuShadeLight));
    if (culled) {
        std::memcpy(offsetBuf.mapped, culled->listOffset.data(), listTotal * 4);
        std::memcpy(countBuf.mapped, culled->listCount.data(), listTotal * 4);
        if (!culled->lightIndices.empty())
            std::memcpy(indexBuf.mapped, culled->lightIndices.data(), culled->lightIndices.size() * 4);
    }

    DescriptorPoolHandle pool = ctx_.createDescriptorPool(bindings, 1, "shade.descriptorPool");
    VkDescriptorSet set = ctx_.writeDescriptorSet(pool, setLayout_, bindings, "shade.set");

    VkPipeline pipe = pipeline(allLights, inBlock);
    ms = ctx_.submitAndWait(
        [&](VkCommandBuffer cmd) {
            vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipe);
            for (std::size_t c = 0; c < chunks; ++c) {
                const std::uint32_t first = std::uint32_t(c * blockLights_);
                const std::uint32_t chunk[4] = {
                    inBlock ? first : 0u, std::uint32_t(std::min<std::size_t>(blockLights_, lightCount - first)),
                    c > 0 ? 1u : 0u, 0u};
                const std::uint32_t offset = std::uint32_t(c * blockBytes);
                if (c > 0) // Hazard: this chunk adds to the sums the previous one wrote.
                    memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                                  VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                                  VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
                vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_, 0, 1, &set, 1, &offset);
                vkCmdPushConstants(cmd, layout_, VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushBytes, chunk);
                vkCmdDispatch(cmd, gx, gy, 1);
            }
            // The host reads the shaded image the dispatches wrote.
            memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                          VK_ACCESS_HOST_READ_BIT);
        },
        "shade.commands");
    const float* out = outBuf.as<float>();
    return std::vector<float>(out, out + pixels * 3);
}

} // namespace lc::vk
