// The raster algorithm's graphics pipeline (raster_pass.hpp).
#include "vk/raster_pass.hpp"

#include "culling/core/errors.hpp"
#include "embedded_spirv.hpp"

#include <algorithm>
#include <array>
#include <cstdio>

// Vulkan create-info structs are value-initialised as {VK_STRUCTURE_TYPE_...}:
// the remaining members are zero on purpose.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

namespace lc::vk {

namespace {
// The setup pass's push constants: the batch's first triangle and its count.
constexpr std::uint32_t kPushBytes = 8;
constexpr VkShaderStageFlags kStages =
    VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
constexpr std::uint32_t kSetupGroup = 64; // proxy_setup.comp's local_size_x
} // namespace

RasterPass::RasterPass(Context& ctx) : ctx_(ctx) {
    if (!ctx_.fragmentStoresSupported())
        throw DeviceError("Vulkan device '" + ctx_.deviceName() +
                          "' lacks fragmentStoresAndAtomics, which the raster algorithm's fragment shader needs");
    layouts_ = ctx_.createPassLayouts(std::vector<VkDescriptorType>(kBindings, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER),
                                      "raster", kPushBytes, kStages);
    const spirv::Code sc = spirv::proxySetupComp(), v = spirv::proxyRasterVert(), f = spirv::proxyRasterFrag();
    setup_ = ctx_.createShader(sc.words, sc.wordCount, "shader.proxy_setup_comp");
    VkComputePipelineCreateInfo cci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    cci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    cci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
    cci.stage.module = setup_;
    cci.stage.pName = "main";
    cci.layout = layouts_.pipeline;
    VkPipeline sp;
    LC_VK(vkCreateComputePipelines(ctx_.device(), VK_NULL_HANDLE, 1, &cci, nullptr, &sp));
    ctx_.name(VK_OBJECT_TYPE_PIPELINE, sp, "raster.pipeline.setup");
    setupPipeline_ = PipelineHandle(ctx_.device(), sp);
    vert_ = ctx_.createShader(v.words, v.wordCount, "shader.proxy_raster_vert");
    frag_ = ctx_.createShader(f.words, f.wordCount, "shader.proxy_raster_frag");

    // No attachments: the fragment shader's atomics are the output. The
    // barriers around the pass are the backend's (outside the instance).
    VkSubpassDescription sub{};
    sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
    VkRenderPassCreateInfo ci{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
    ci.subpassCount = 1;
    ci.pSubpasses = &sub;
    VkRenderPass rp;
    LC_VK(vkCreateRenderPass(ctx_.device(), &ci, nullptr, &rp));
    ctx_.name(VK_OBJECT_TYPE_RENDER_PASS, rp, "raster.renderPass");
    renderPass_ = RenderPassHandle(ctx_.device(), rp);
}

RasterPass::Coverage RasterPass::coverage(bool conservative) const {
    if (!conservative) return Coverage::Centre;
    return ctx_.conservativeRasterSupported() ? Coverage::Hardware : Coverage::PushedEdges;
}

std::string RasterPass::describe(Coverage c) const {
    switch (c) {
    case Coverage::Centre: return "every tile whose centre a proxy triangle covers (the device's rasteriser)";
    case Coverage::Hardware: {
        char extra[64];
        std::snprintf(extra, sizeof extra, "%.4g", double(ctx_.primitiveOverestimationSize()));
        return std::string("VK_EXT_conservative_rasterization, overestimating (the device's own ") + extra +
               " pixel, plus 1/64), trimmed to the exact overlap in the fragment shader";
    }
    case Coverage::PushedEdges:
        return "edges pushed out by half a tile's diagonal before the draw ('" + ctx_.deviceName() +
               "' has no VK_EXT_conservative_rasterization)";
    }
    return {};
}

VkPipeline RasterPass::pipeline(Coverage c) {
    auto it = pipelines_.find(c);
    if (it != pipelines_.end()) return it->second;
    std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
    stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vert_;
    stages[0].pName = "main";
    stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = frag_;
    stages[1].pName = "main";
    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = 1;
    vp.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = VK_CULL_MODE_NONE; // both faces: a proxy around the camera shows only its inside
    rs.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    rs.lineWidth = 1.0f;
    VkPipelineRasterizationConservativeStateCreateInfoEXT cons{
        VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_CONSERVATIVE_STATE_CREATE_INFO_EXT};
    if (c == Coverage::Hardware) {
        cons.conservativeRasterizationMode = VK_CONSERVATIVE_RASTERIZATION_MODE_OVERESTIMATE_EXT;
        // A little more than the device's own, for the vertices' float rounding.
        cons.extraPrimitiveOverestimationSize = std::min(1.0f / 64.0f, ctx_.maxExtraPrimitiveOverestimationSize());
        rs.pNext = &cons;
    }
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    std::array<VkDynamicState, 2> dyn{VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dsi{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dsi.dynamicStateCount = std::uint32_t(dyn.size());
    dsi.pDynamicStates = dyn.data();
    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.stageCount = std::uint32_t(stages.size());
    ci.pStages = stages.data();
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vp;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pDynamicState = &dsi;
    ci.layout = layouts_.pipeline;
    ci.renderPass = renderPass_;
    VkPipeline p;
    LC_VK(vkCreateGraphicsPipelines(ctx_.device(), VK_NULL_HANDLE, 1, &ci, nullptr, &p));
    const char* names[] = {"raster.pipeline.centre", "raster.pipeline.hardware", "raster.pipeline.pushedEdges"};
    ctx_.name(VK_OBJECT_TYPE_PIPELINE, p, names[int(c)]);
    return pipelines_.emplace(c, PipelineHandle(ctx_.device(), p)).first->second;
}

VkFramebuffer RasterPass::framebuffer(std::uint32_t w, std::uint32_t h) {
    if (framebuffer_ && fbSize_ == std::make_pair(w, h)) return framebuffer_;
    framebuffer_ = FramebufferHandle();
    VkFramebufferCreateInfo fci{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fci.renderPass = renderPass_;
    fci.width = w;
    fci.height = h;
    fci.layers = 1;
    VkFramebuffer fb;
    LC_VK(vkCreateFramebuffer(ctx_.device(), &fci, nullptr, &fb));
    ctx_.name(VK_OBJECT_TYPE_FRAMEBUFFER, fb, "raster.framebuffer");
    framebuffer_ = FramebufferHandle(ctx_.device(), fb);
    fbSize_ = {w, h};
    return framebuffer_;
}

void RasterPass::record(VkCommandBuffer cmd, Coverage c, VkDescriptorSet set, std::uint32_t tilesX,
                        std::uint32_t tilesY, std::uint64_t triangles, std::uint32_t batch) {
    const VkPipeline pipe = pipeline(c);
    VkRenderPassBeginInfo rbi{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rbi.renderPass = renderPass_;
    rbi.framebuffer = framebuffer(tilesX, tilesY);
    rbi.renderArea = {{0, 0}, {tilesX, tilesY}};
    const VkViewport viewport{0.0f, 0.0f, float(tilesX), float(tilesY), 0.0f, 1.0f};
    const VkRect2D scissor{{0, 0}, {tilesX, tilesY}};
    for (std::uint64_t first = 0; first < triangles; first += batch) {
        const std::uint32_t push[2] = {std::uint32_t(first),
                                       std::uint32_t(std::min<std::uint64_t>(batch, triangles - first))};
        if (first) // the previous batch's draw has read the records this one overwrites
            memoryBarrier(cmd, VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT, 0,
                          VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, 0);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, setupPipeline_);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layouts_.pipeline, 0, 1, &set, 0, nullptr);
        vkCmdPushConstants(cmd, layouts_.pipeline, kStages, 0, kPushBytes, push);
        vkCmdDispatch(cmd, (push[1] + kSetupGroup - 1) / kSetupGroup, 1, 1);
        memoryBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                      VK_PIPELINE_STAGE_VERTEX_SHADER_BIT | VK_PIPELINE_STAGE_FRAGMENT_SHADER_BIT,
                      VK_ACCESS_SHADER_READ_BIT);
        vkCmdBeginRenderPass(cmd, &rbi, VK_SUBPASS_CONTENTS_INLINE);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipe);
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, layouts_.pipeline, 0, 1, &set, 0, nullptr);
        vkCmdSetViewport(cmd, 0, 1, &viewport);
        vkCmdSetScissor(cmd, 0, 1, &scissor);
        vkCmdDraw(cmd, 3 * push[1], 1, 0, 0);
        vkCmdEndRenderPass(cmd);
    }
}

} // namespace lc::vk
