// lightcull: --layout fixed:256 --lists tile
//
// 2.5D culling (Harada et al.): tiled_fixed.comp plus a 32-cell occupancy
// mask of the tile's depth range. Each geometry pixel sets the bit of its
// cell (linear slices of [min, max]); a light that passes the side planes is
// kept only if the cells its depth range [z - r, z + r] spans hold geometry.
// One list per tile, tighter than min/max where a tile holds both near and
// far surfaces.
//   lightcull run --builtin forest --shader twofived_fixed.comp --out out/mine
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"

layout(local_size_x = 64) in;

const uint kCells = 32u;
shared uint sMinBits, sMaxBits, sMask;

uint cellOf(float z, float zMin, float zMax) {
    if (zMax <= zMin) return 0u;
    return min(uint(max((z - zMin) / (zMax - zMin), 0.0) * float(kCells)), kCells - 1u);
}

void main() {
    const uvec2 tile = gl_WorkGroupID.xy;
    const uint tileIndex = tile.y * lc.size.z + tile.x;
    const uvec2 p0 = tile * uint(TILE_SIZE);
    const uvec2 p1 = min(p0 + uint(TILE_SIZE), lc.size.xy);
    if (gl_LocalInvocationIndex == 0u) {
        sMinBits = 0x7f7fffffu;
        sMaxBits = 0u;
        sMask = 0u;
    }
    barrier();
    const uint w = p1.x - p0.x, h = p1.y - p0.y;
    for (uint i = gl_LocalInvocationIndex; i < w * h; i += 64u) {
        const float d = texelFetch(lcDepthTexture, ivec2(p0 + uvec2(i % w, i / w)), 0).r;
        if (!lcHasGeometry(d)) continue;
        const uint z = floatBitsToUint(lcViewDepth(d));
        atomicMin(sMinBits, z);
        atomicMax(sMaxBits, z);
    }
    barrier();
    if (sMaxBits == 0u) return;
    const float zMin = uintBitsToFloat(sMinBits), zMax = uintBitsToFloat(sMaxBits);
    for (uint i = gl_LocalInvocationIndex; i < w * h; i += 64u) {
        const float d = texelFetch(lcDepthTexture, ivec2(p0 + uvec2(i % w, i / w)), 0).r;
        if (lcHasGeometry(d)) atomicOr(sMask, 1u << cellOf(lcViewDepth(d), zMin, zMax));
    }
    barrier();
    const uint tileMask = sMask;

    const float u0 = 2.0 * float(p0.x) / float(lc.size.x) - 1.0, u1 = 2.0 * float(p1.x) / float(lc.size.x) - 1.0;
    const float v0 = 2.0 * float(p0.y) / float(lc.size.y) - 1.0, v1 = 2.0 * float(p1.y) / float(lc.size.y) - 1.0;
    vec4 planes[4];
    if (lc.lens.z > 0.5) {
        planes[0] = vec4(1, 0, 0, -u0 * lc.lens.x);
        planes[1] = vec4(-1, 0, 0, u1 * lc.lens.x);
        planes[2] = vec4(0, -1, 0, -v0 * lc.lens.y);
        planes[3] = vec4(0, 1, 0, v1 * lc.lens.y);
    } else {
        planes[0] = vec4(normalize(vec3(1, 0, u0 * lc.lens.x)), 0.0);
        planes[1] = vec4(normalize(vec3(-1, 0, -u1 * lc.lens.x)), 0.0);
        planes[2] = vec4(normalize(vec3(0, -1, v0 * lc.lens.y)), 0.0);
        planes[3] = vec4(normalize(vec3(0, 1, -v1 * lc.lens.y)), 0.0);
    }
    for (uint i = gl_LocalInvocationIndex; i < lc.counts.x; i += 64u) {
        const vec4 s = lcLights[i].positionRadius;
        const float r = s.w + 1e-5 * (abs(s.x) + abs(s.y) + abs(s.z) + s.w);
        const float a = -s.z - r, b = -s.z + r;
        if (b < zMin || a > zMax) continue;
        bool inside = true;
        for (int k = 0; k < 4 && inside; ++k) inside = dot(planes[k].xyz, s.xyz) + planes[k].w >= -r;
        if (!inside) continue;
        // Cells the light's depth range spans (one cell wider on each side:
        // the pixels' cells were found in float too).
        const uint c0 = cellOf(a, zMin, zMax), c1 = cellOf(b, zMin, zMax);
        const uint lo = c0 > 0u ? c0 - 1u : 0u, hi = min(c1 + 1u, kCells - 1u);
        const uint span = hi - lo + 1u;
        const uint lightMask = (span >= 32u ? ~0u : ((1u << span) - 1u)) << lo;
        if ((lightMask & tileMask) != 0u) lcAppend(tileIndex, i);
    }
}
