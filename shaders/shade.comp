#version 450
// The Lambert shading pass: one invocation per pixel (8x8 pixels per
// workgroup), each looping over the lights of its pixel's list. The formula
// and the order of float operations are those of the CPU reference
// (culling/src/truth/shade.cpp): `precise` keeps the compiler from contracting them
// into FMAs, so the two differ only by the device's sqrt/division rounding.
//
// Spaces: every position is VIEW space (right-handed, y up, camera looks down -z).
#extension GL_GOOGLE_include_directive : require
#include "culling/vk/gpu_shade.h"

layout(local_size_x = 8, local_size_y = 8) in;
// 1: every light in index order (no list arrays read); 0: the pixel's list.
layout(constant_id = 0) const uint ALL_LIGHTS = 0u;
// 1: the lights come from the uniform block (binding 8), which holds lights
// C.x .. C.x + BLOCK_LIGHTS - 1; 0: from the storage buffer (binding 3).
// lavapipe loads a storage buffer lane by lane in a loop with a bounds check,
// a uniform block with one branch-free gather: the all-lights image, every
// light at every pixel, is mostly these loads.
layout(constant_id = 1) const uint LIGHTS_IN_BLOCK = 0u;
layout(constant_id = 2) const uint BLOCK_LIGHTS = 1u;

layout(std430, binding = 0) readonly buffer Params { GpuShadeParams P; };
layout(std430, binding = 1) readonly buffer PixelBuf { GpuShadePixel pixels[]; };
layout(std430, binding = 2) readonly buffer PixelListBuf { uint pixelList[]; };
layout(std430, binding = 3) readonly buffer LightBuf { GpuShadeLight lights[]; };
layout(std430, binding = 4) readonly buffer OffsetBuf { uint listOffset[]; };
layout(std430, binding = 5) readonly buffer CountBuf { uint listCount[]; };
layout(std430, binding = 6) readonly buffer IndexBuf { uint lightIndices[]; };
layout(std430, binding = 7) buffer OutBuf { float rgb[]; };
layout(std140, binding = 8) uniform LightBlock { GpuShadeLight blockLights[BLOCK_LIGHTS]; };
// x: the first light of this dispatch, y: how many (all lights: the image is
// shaded in chunks of at most BLOCK_LIGHTS lights, in index order), z: 1 when
// an earlier chunk's sums are in rgb to add to (the same float additions in
// the same order as one loop).
layout(push_constant) uniform Chunk { uvec4 C; };

#define LIGHT(li, field) (LIGHTS_IN_BLOCK != 0u ? blockLights[(li) - C.x].field : lights[li].field)

void main() {
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x >= P.size.x || y >= P.size.y) return;
    uint i = y * P.size.x + x;
    uint l = pixelList[i];
    precise vec3 acc = vec3(0.0);
    if (ALL_LIGHTS != 0u && C.z != 0u) acc = vec3(rgb[3u * i + 0u], rgb[3u * i + 1u], rgb[3u * i + 2u]);
    if (l != LC_SHADE_NO_LIST) {
        vec3 p = pixels[i].position.xyz, n = pixels[i].normal.xyz;
        uint first = (ALL_LIGHTS != 0u) ? C.x : listOffset[l];
        uint count = (ALL_LIGHTS != 0u) ? C.y : listCount[l];
        for (uint k = 0u; k < count; ++k) {
            uint li = (ALL_LIGHTS != 0u) ? first + k : lightIndices[first + k];
            precise vec3 d = LIGHT(li, position.xyz) - p;
            precise float d2 = (d.x * d.x + d.y * d.y) + d.z * d.z;
            // A light exactly at the pixel has no direction: clamp the length.
            precise float len = sqrt(max(d2, 1e-30));
            precise float ndl = ((n.x * d.x + n.y * d.y) + n.z * d.z) / len;
            precise float f = max(ndl, 0.0) / max(d2, 1e-4);
            // Spot cone (shade.cpp): inside when -(axis.d) >= len cos a.
            vec4 s = LIGHT(li, spot);
            precise float axial = 0.0 - ((s.x * d.x + s.y * d.y) + s.z * d.z);
            if (!(axial >= len * s.w)) f = 0.0;
            acc += LIGHT(li, power.xyz) * f;
        }
    }
    rgb[3u * i + 0u] = acc.x;
    rgb[3u * i + 1u] = acc.y;
    rgb[3u * i + 2u] = acc.z;
}
