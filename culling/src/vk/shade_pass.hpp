#pragma once
// Internal: the Vulkan Lambert shading pass (shaders/shade.comp) on a backend's
// context. Inputs are the CPU-built G-buffer (lc::ShadeInputs) so that both
// backends shade the same positions, normals and per-pixel lists.
#include "culling/truth/shade.hpp"
#include "vk/vk_context.hpp"

#include <array>

namespace lc::vk {

class ShadePass {
public:
    explicit ShadePass(Context& ctx);
    // RGB, 3 floats per pixel. `ms`: CPU wall-clock around submit + fence
    // wait of the shading dispatch (the backend's cull timing method); the
    // uploads into host-visible buffers and the readback are not included.
    std::vector<float> run(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled, double& ms);

private:
    VkPipeline pipeline(bool allLights, bool lightsInBlock);
    std::vector<float> runInBands(const ShadeInputs& in, const ViewLights& lights, const CullResult* culled, double& ms);

    Context& ctx_;
    // The shading's buffers, kept between calls while they fit (after ctx_:
    // freed before the device).
    BufferCache cache_{ctx_};
    DescriptorSetLayoutHandle setLayout_;
    PipelineLayoutHandle layout_;
    ShaderModuleHandle shader_;
    std::array<PipelineHandle, 4> pipelines_; // [2 x all lights + lights in the block]
    std::uint32_t blockLights_ = 0;           // lights per uniform block (shade.comp BLOCK_LIGHTS)
    // The G-buffer now in "shade.pixels": its maker's id, its arrays and the
    // buffer it went to (ShadeInputs::gbufferId; id 0: nothing known).
    struct Uploaded {
        std::uint64_t id = 0;
        const float *position = nullptr, *normal = nullptr;
        std::size_t pixels = 0;
        VkBuffer buffer = VK_NULL_HANDLE;
        bool operator==(const Uploaded&) const = default;
    } uploaded_;
};

} // namespace lc::vk
