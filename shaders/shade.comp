#version 450
// The Lambert shading pass: one invocation per pixel (8x8 pixels per
// workgroup), each looping over the lights of its pixel's list, or per two
// pixels of a row for the all-lights image. The formula
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
// All lights: x: the first light of this dispatch, y: how many (the image is
// shaded in chunks of at most BLOCK_LIGHTS lights, in index order), z: 1 when
// an earlier chunk's sums are in rgb to add to (the same float additions in
// the same order as one loop). Lists from the block go in the same chunks.
layout(push_constant) uniform Chunk { uvec4 C; };

#define LIGHT(li, field) (LIGHTS_IN_BLOCK != 0u ? blockLights[(li) - C.x].field : lights[li].field)

// One light's term at one pixel, the CPU reference's float operations in its
// order (shade.cpp).
vec3 lightTerm(vec3 p, vec3 n, vec3 lightPos, vec3 power, vec4 s) {
    precise vec3 d = lightPos - p;
    precise float d2 = (d.x * d.x + d.y * d.y) + d.z * d.z;
    // A light exactly at the pixel has no direction: clamp the length.
    precise float len = sqrt(max(d2, 1e-30));
    precise float ndl = ((n.x * d.x + n.y * d.y) + n.z * d.z) / len;
    precise float f = max(ndl, 0.0) / max(d2, 1e-4);
    // Spot cone (shade.cpp): inside when -(axis.d) >= len cos a.
    precise float axial = 0.0 - ((s.x * d.x + s.y * d.y) + s.z * d.z);
    if (!(axial >= len * s.w)) f = 0.0;
    precise vec3 term = power * f;
    return term;
}

vec3 storedSum(uint i) { return vec3(rgb[3u * i + 0u], rgb[3u * i + 1u], rgb[3u * i + 2u]); }
void store(uint i, vec3 v) {
    rgb[3u * i + 0u] = v.x;
    rgb[3u * i + 1u] = v.y;
    rgb[3u * i + 2u] = v.z;
}

// All lights: two horizontally adjacent pixels an invocation, so that each
// light loaded serves both (the loads are most of this loop on lavapipe).
void shadeAllLights() {
    uint x = 2u * gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x >= P.size.x || y >= P.size.y) return;
    bool second = x + 1u < P.size.x;
    uint i0 = y * P.size.x + x, i1 = second ? i0 + 1u : i0;
    bool lit0 = pixelList[i0] != LC_SHADE_NO_LIST, lit1 = pixelList[i1] != LC_SHADE_NO_LIST;
    vec3 p0 = pixels[i0].position.xyz, n0 = pixels[i0].normal.xyz;
    vec3 p1 = pixels[i1].position.xyz, n1 = pixels[i1].normal.xyz;
    precise vec3 acc0 = C.z != 0u ? storedSum(i0) : vec3(0.0);
    precise vec3 acc1 = C.z != 0u ? storedSum(i1) : vec3(0.0);
    if (lit0 || lit1) {
        for (uint k = 0u; k < C.y; ++k) {
            uint li = C.x + k;
            vec3 lp = LIGHT(li, position.xyz), pw = LIGHT(li, power.xyz);
            vec4 s = LIGHT(li, spot);
            acc0 += lightTerm(p0, n0, lp, pw, s);
            acc1 += lightTerm(p1, n1, lp, pw, s);
        }
    }
    store(i0, lit0 ? acc0 : vec3(0.0));
    if (second) store(i1, lit1 ? acc1 : vec3(0.0));
}

void main() {
    if (ALL_LIGHTS != 0u) {
        shadeAllLights();
        return;
    }
    uint x = gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x >= P.size.x || y >= P.size.y) return;
    uint i = y * P.size.x + x;
    uint l = pixelList[i];
    precise vec3 acc = C.z != 0u ? storedSum(i) : vec3(0.0);
    if (l != LC_SHADE_NO_LIST) {
        vec3 p = pixels[i].position.xyz, n = pixels[i].normal.xyz;
        uint first = listOffset[l], count = listCount[l];
        for (uint k = 0u; k < count; ++k) {
            uint li = lightIndices[first + k];
            // From the block: only the lights of this chunk (ascending lists,
            // so the chunks add them in the list's order).
            if (LIGHTS_IN_BLOCK == 0u || li - C.x < C.y)
                acc += lightTerm(p, n, LIGHT(li, position.xyz), LIGHT(li, power.xyz), LIGHT(li, spot));
        }
    }
    store(i, acc);
}
