#version 450
// The Lambert shading pass: one invocation per four pixels of a row (8x8
// invocations per workgroup), each pixel looping over the lights of its
// list, or over every light for the all-lights image. The formula
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
// lightPos.w: 1 / range^2 of a light with a shading range, else 0 (no window).
vec3 lightTerm(vec3 p, vec3 n, vec4 lightPos, vec3 power, vec4 s) {
    precise vec3 d = lightPos.xyz - p;
    precise float d2 = (d.x * d.x + d.y * d.y) + d.z * d.z;
    // A light exactly at the pixel has no direction: clamp the length.
    precise float len = sqrt(max(d2, 1e-30));
    precise float ndl = ((n.x * d.x + n.y * d.y) + n.z * d.z) / len;
    precise float f = max(ndl, 0.0) / max(d2, 1e-4);
    // Spot cone (shade.cpp): inside when -(axis.d) >= len cos a.
    precise float axial = 0.0 - ((s.x * d.x + s.y * d.y) + s.z * d.z);
    if (!(axial >= len * s.w)) f = 0.0;
    // KHR_lights_punctual's range window: max(0, 1 - (d^2/r^2)^2)^2.
    precise float t = d2 * lightPos.w;
    precise float w = max(1.0 - t * t, 0.0);
    f = f * (w * w);
    precise vec3 term = power * f;
    return term;
}

vec3 storedSum(uint i) { return vec3(rgb[3u * i + 0u], rgb[3u * i + 1u], rgb[3u * i + 2u]); }
void store(uint i, vec3 v) {
    rgb[3u * i + 0u] = v.x;
    rgb[3u * i + 1u] = v.y;
    rgb[3u * i + 2u] = v.z;
}

// The first position in lightIndices[b, e) (ascending) holding a light of
// at least v.
uint lowerBound(uint b, uint e, uint v) {
    while (b < e) {
        uint m = b + (e - b) / 2u;
        if (lightIndices[m] < v) b = m + 1u;
        else e = m;
    }
    return b;
}

// Where list l's lights of this dispatch lie in lightIndices: the whole list
// from the storage buffer; from the block, the part within this chunk's
// lights, one run of an ascending list (found by bisection rather than
// walking the list once per chunk).
uvec2 listRange(uint l) {
    uint first = listOffset[l], end = first + listCount[l];
    if (LIGHTS_IN_BLOCK == 0u || (C.x == 0u && C.y >= P.size.z)) return uvec2(first, end);
    uint b = lowerBound(first, end, C.x);
    return uvec2(b, lowerBound(b, end, C.x + C.y));
}

// One pixel's list, in the list's order.
vec3 shadeList(uint l, vec3 p, vec3 n, vec3 sum) {
    precise vec3 acc = sum;
    uvec2 r = listRange(l);
    for (uint k = r.x; k < r.y; ++k) {
        uint li = lightIndices[k];
        acc += lightTerm(p, n, LIGHT(li, position), LIGHT(li, power.xyz), LIGHT(li, spot));
    }
    return acc;
}

// Four pixels of a row an invocation, so that each light loaded (and each
// index, where the four share a list: a tile's) serves all four; on lavapipe
// these loads are most of the loop. The last group of a row may be short:
// its missing pixels repeat the row's last one and are not stored.
const uint PX = 4u;

void main() {
    uint x = PX * gl_GlobalInvocationID.x, y = gl_GlobalInvocationID.y;
    if (x >= P.size.x || y >= P.size.y) return;
    uint i[PX], l[PX];
    vec3 p[PX], n[PX];
    precise vec3 acc[PX];
    bool same = true, lit = false;
    for (uint j = 0u; j < PX; ++j) {
        i[j] = y * P.size.x + min(x + j, P.size.x - 1u);
        l[j] = pixelList[i[j]];
        same = same && l[j] == l[0];
        lit = lit || l[j] != LC_SHADE_NO_LIST;
        p[j] = pixels[i[j]].position.xyz;
        n[j] = pixels[i[j]].normal.xyz;
        acc[j] = C.z != 0u ? storedSum(i[j]) : vec3(0.0);
    }
    if ((ALL_LIGHTS != 0u || same) && lit) {
        // One loop for the group: this chunk's lights, or the shared list.
        uvec2 r = ALL_LIGHTS != 0u ? uvec2(0u, C.y) : listRange(l[0]);
        for (uint k = r.x; k < r.y; ++k) {
            uint li = ALL_LIGHTS != 0u ? C.x + k : lightIndices[k];
            vec4 lp = LIGHT(li, position);
            vec3 pw = LIGHT(li, power.xyz);
            vec4 s = LIGHT(li, spot);
            for (uint j = 0u; j < PX; ++j) acc[j] += lightTerm(p[j], n[j], lp, pw, s);
        }
    } else if (ALL_LIGHTS == 0u && !same) {
        for (uint j = 0u; j < PX; ++j)
            if (l[j] != LC_SHADE_NO_LIST) acc[j] = shadeList(l[j], p[j], n[j], acc[j]);
    }
    for (uint j = 0u; j < PX; ++j)
        if (x + j < P.size.x) store(i[j], l[j] != LC_SHADE_NO_LIST ? acc[j] : vec3(0.0));
}
