#pragma once
// Internal: the raster algorithm's graphics work on a backend's context
// (shaders/proxy_setup.comp, proxy_raster.vert/.frag): a compute pass that
// works out each proxy triangle's corners and trim once, then the pipeline
// that draws those triangles into a render pass with no attachments, one
// pixel per tile, whose fragment shader sets each covered tile's light bit. The backend (vulkan_backend.cpp)
// runs the tile bounds pass before it in the same submission and decodes the
// masks into lists.
#include "vk/vk_context.hpp"

#include <map>
#include <string>
#include <utility>

namespace lc::vk {

class RasterPass {
public:
    // params, tiles, proxies, mesh, masks, depth ranges (slices), triangles
    static constexpr std::uint32_t kBindings = 7;
    // Triangles set up and drawn per batch: the triangles buffer holds one
    // batch (GpuProxyTriangle, 160 bytes each: 40 MiB).
    static constexpr std::uint32_t kBatchTriangles = 1u << 18;
    explicit RasterPass(Context& ctx);
    // How the coverage is made: the device's conservative rasteriser, the
    // edges pushed out by the setup pass (and why), or centre sampling.
    enum class Coverage { Centre, Hardware, PushedEdges };
    Coverage coverage(bool conservative) const;
    std::string describe(Coverage c) const;
    VkDescriptorSetLayout setLayout() const { return layouts_.set; }
    // Records the pass over `triangles` proxy triangles (GpuRasterParams.setup
    // says which is which) in batches of at most `batch`: per batch the
    // setup dispatch, then the draw into the viewport tilesX x tilesY.
    void record(VkCommandBuffer cmd, Coverage c, VkDescriptorSet set, std::uint32_t tilesX, std::uint32_t tilesY,
                std::uint64_t triangles, std::uint32_t batch);

private:
    VkPipeline pipeline(Coverage c);
    VkFramebuffer framebuffer(std::uint32_t w, std::uint32_t h);

    Context& ctx_;
    Context::PassLayouts layouts_;
    ShaderModuleHandle setup_, vert_, frag_;
    PipelineHandle setupPipeline_;
    RenderPassHandle renderPass_;
    std::map<Coverage, PipelineHandle> pipelines_;
    std::pair<std::uint32_t, std::uint32_t> fbSize_{0, 0};
    FramebufferHandle framebuffer_;
};

} // namespace lc::vk
