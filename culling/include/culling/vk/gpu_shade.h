// Declarations of the Vulkan shading pass (shaders/shade.comp,
// culling/src/vk/shade_pass.cpp), shared as text by C++ and GLSL 450 like
// gpu_shared.h: plain structs of vec4/uvec4, std430, checked by static_assert.
#ifndef LC_GPU_SHADE_H
#define LC_GPU_SHADE_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstddef>
#include <cstdint>
namespace lc {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using uint = std::uint32_t;
#endif

// No list: a background pixel, shaded 0 (ShadeInputs::kNoList).
const uint LC_SHADE_NO_LIST = 0xffffffffu;

// Per-dispatch parameters (binding 0).
struct GpuShadeParams {
    uvec4 size; // width, height, light count, list count
};

// One light (binding 3): view-space centre, colour * intensity and cone.
struct GpuShadeLight {
    vec4 position; // xyz view space, w: 1 / range^2 (shadingInvRange2), 0 without a range
    vec4 power;    // rgb linear, w unused
    vec4 spot;     // xyz: a spot light's unit axis (view space), w: cos(outer angle);
                   // a point light: (0, 0, 0, -2), which every pixel passes
};

// One pixel of the G-buffer (binding 1): view position and shading normal
// (ShadeInputs). Its list is a separate uint array (binding 2).
struct GpuShadePixel {
    vec4 position; // xyz view space, w unused
    vec4 normal;   // xyz unit, facing the camera, w unused
};

#ifdef __cplusplus
static_assert(sizeof(GpuShadeParams) == 16, "GpuShadeParams must match std430");
static_assert(sizeof(GpuShadeLight) == 48, "GpuShadeLight must match std430");
static_assert(offsetof(GpuShadeLight, spot) == 32, "GpuShadeLight.spot offset");
static_assert(offsetof(GpuShadeLight, power) == 16, "GpuShadeLight.power offset");
static_assert(sizeof(GpuShadePixel) == 32, "GpuShadePixel must match std430");
static_assert(offsetof(GpuShadePixel, normal) == 16, "GpuShadePixel.normal offset");
} // namespace lc
#endif

#endif
