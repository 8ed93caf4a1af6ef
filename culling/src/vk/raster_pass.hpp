#pragma once
// Internal: the raster algorithm's graphics work on a backend's context
// (shaders/proxy_raster.vert/.frag): the pipeline that draws light proxies
// into a render pass with no attachments, one pixel per tile, whose fragment
// shader sets each covered tile's light bit. The backend (vulkan_backend.cpp)
// runs the tile bounds pass before it in the same submission and decodes the
// masks into lists.
#include "vk/vk_context.hpp"

#include <map>
#include <string>
#include <utility>

namespace lc::vk {

class RasterPass {
public:
    static constexpr std::uint32_t kBindings = 6; // params, tiles, proxies, mesh, masks, depth ranges (slices)
    explicit RasterPass(Context& ctx);
    // How the coverage is made: the device's conservative rasteriser, the
    // edges pushed out in the vertex shader (and why), or centre sampling.
    enum class Coverage { Centre, Hardware, PushedEdges };
    Coverage coverage(bool conservative) const;
    std::string describe(Coverage c) const;
    VkDescriptorSetLayout setLayout() const { return layouts_.set; }
    // Records the render pass: `draws` as (first corner, corners, first
    // instance, instances), the viewport tilesX x tilesY.
    struct Draw {
        std::uint32_t firstVertex, vertexCount, firstInstance, instanceCount;
    };
    void record(VkCommandBuffer cmd, Coverage c, VkDescriptorSet set, std::uint32_t tilesX, std::uint32_t tilesY,
                const std::vector<Draw>& draws);

private:
    VkPipeline pipeline(Coverage c);
    VkFramebuffer framebuffer(std::uint32_t w, std::uint32_t h);

    Context& ctx_;
    Context::PassLayouts layouts_;
    ShaderModuleHandle vert_, frag_;
    RenderPassHandle renderPass_;
    std::map<Coverage, PipelineHandle> pipelines_;
    std::pair<std::uint32_t, std::uint32_t> fbSize_{0, 0};
    FramebufferHandle framebuffer_;
};

} // namespace lc::vk
