// lightcull: --layout bitmask --lists cells:8:linear
// A list per cell of the tile's own min/max view depth (the cells:N rule):
// the tile's depth range in shared memory, then for each cell the lights
// whose sphere meets the tile's side planes and the cell's depth range. The
// first and the last cell reach past min and max (the tool's rule for depths
// outside). Slicing follows lc.mode.w, so --lists cells:N:log works too.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"
layout(local_size_x = 64) in;
shared uint sMinBits, sMaxBits;

float cellBoundary(uint i, float lo, float hi) {
    const float t = float(i) / float(LC_LISTS_PER_TILE);
    return lc.mode.w == LC_SLICING_LOG && lo > 0.0 ? lo * pow(hi / lo, t) : lo + (hi - lo) * t;
}

void main() {
    const uvec2 tile = gl_WorkGroupID.xy;
    const uint tileIndex = tile.y * lc.size.z + tile.x;
    const uvec2 p0 = tile * uint(TILE_SIZE);
    const uvec2 p1 = min(p0 + uint(TILE_SIZE), lc.size.xy);
    if (gl_LocalInvocationIndex == 0u) {
        sMinBits = 0x7f7fffffu;
        sMaxBits = 0u;
    }
    barrier();
    const uint w = p1.x - p0.x, h = p1.y - p0.y;
    for (uint i = gl_LocalInvocationIndex; i < w * h; i += 64u) {
        const float d = lcDepth[(p0.y + i / w) * lc.size.x + p0.x + i % w];
        if (!lcHasGeometry(d)) continue;
        atomicMin(sMinBits, floatBitsToUint(lcViewDepth(d)));
        atomicMax(sMaxBits, floatBitsToUint(lcViewDepth(d)));
    }
    barrier();
    if (sMaxBits == 0u) return;
    const float zMin = uintBitsToFloat(sMinBits), zMax = uintBitsToFloat(sMaxBits);
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
        bool inside = true;
        for (int k = 0; k < 4 && inside; ++k) inside = dot(planes[k].xyz, s.xyz) + planes[k].w >= -r;
        if (!inside) continue;
        for (uint c = 0u; c < uint(LC_LISTS_PER_TILE); ++c) {
            const float z0 = c == 0u ? 0.0 : cellBoundary(c, zMin, zMax) * (1.0 - 1e-5);
            const float z1 = c + 1u == uint(LC_LISTS_PER_TILE) ? 3.0e38 : cellBoundary(c + 1u, zMin, zMax) * (1.0 + 1e-5);
            if (-s.z + r >= z0 && -s.z - r <= z1) lcAppend(lcListIndex(tileIndex, c), i);
        }
    }
}
