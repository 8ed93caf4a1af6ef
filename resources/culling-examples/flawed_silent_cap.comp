// lightcull: --layout fixed:256 --lists tile
//
// DELIBERATELY FLAWED: tiled_fixed.comp gathering each tile's lights in
// shared memory first, as many Forward+ samples do (one atomic on a shared
// counter per light, then one copy of the whole list to the buffer), into
// an array of 64 while the buffer holds 256 per list. Lights past the 64th
// are dropped and the count written is clamped to 64, so the list looks
// complete and well formed: no overflow is reported, and the lights that did not
// fit show up only as false negatives where pixels needed them. Seen when
// the shared array is sized for the scenes of the day (or for the shared
// memory budget of one GPU) and the declared list size is raised later.
// The atrium's default 512 lights put at most 56 in one tile, so it passes
// there; 1024 lights fill tiles past 64:
//   lightcull run --builtin atrium --lights 1024 --shader flawed_silent_cap.comp --out out/flawed
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"

layout(local_size_x = 64) in;

// THE FLAW: the tile's list in shared memory holds fewer lights than the
// declared fixed:256.
#define SHARED_LIST_SIZE 64u

shared uint sMinBits, sMaxBits; // view depths as float bits: positive floats order as uints
shared uint sCount;
shared uint sLights[SHARED_LIST_SIZE];

// Plane n.p + w >= 0 inside; n unit length.
vec4 sidePlane(vec3 n, float w) { return vec4(n, w) / length(n); }

void main() {
    const uvec2 tile = gl_WorkGroupID.xy;
    const uint tileIndex = tile.y * lc.size.z + tile.x;
    const uvec2 p0 = tile * uint(TILE_SIZE);
    const uvec2 p1 = min(p0 + uint(TILE_SIZE), lc.size.xy); // edge tiles are partial
    if (gl_LocalInvocationIndex == 0u) {
        sMinBits = 0x7f7fffffu;
        sMaxBits = 0u;
        sCount = 0u;
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
    if (sMaxBits == 0u) return; // no geometry in the tile: its list stays empty
    const float zMin = uintBitsToFloat(sMinBits), zMax = uintBitsToFloat(sMaxBits);

    // NDC of the tile's pixel edges (v down), then the side planes.
    const float u0 = 2.0 * float(p0.x) / float(lc.size.x) - 1.0, u1 = 2.0 * float(p1.x) / float(lc.size.x) - 1.0;
    const float v0 = 2.0 * float(p0.y) / float(lc.size.y) - 1.0, v1 = 2.0 * float(p1.y) / float(lc.size.y) - 1.0;
    vec4 planes[4];
    if (lc.lens.z > 0.5) { // orthographic: parallel planes
        planes[0] = vec4(1, 0, 0, -u0 * lc.lens.x);
        planes[1] = vec4(-1, 0, 0, u1 * lc.lens.x);
        planes[2] = vec4(0, -1, 0, -v0 * lc.lens.y);
        planes[3] = vec4(0, 1, 0, v1 * lc.lens.y);
    } else { // perspective: planes through the eye
        planes[0] = sidePlane(vec3(1, 0, u0 * lc.lens.x), 0.0);
        planes[1] = sidePlane(vec3(-1, 0, -u1 * lc.lens.x), 0.0);
        planes[2] = sidePlane(vec3(0, -1, v0 * lc.lens.y), 0.0);
        planes[3] = sidePlane(vec3(0, 1, -v1 * lc.lens.y), 0.0);
    }

    for (uint i = gl_LocalInvocationIndex; i < lc.counts.x; i += 64u) {
        const vec4 s = lcLights[i].positionRadius;
        // Widened a little so that float rounding never rejects a light the
        // exact (double) test keeps.
        const float r = s.w + 1e-5 * (abs(s.x) + abs(s.y) + abs(s.z) + s.w);
        bool inside = -s.z + r >= zMin && -s.z - r <= zMax;
        for (int k = 0; k < 4 && inside; ++k) inside = dot(planes[k].xyz, s.xyz) + planes[k].w >= -r;
        if (inside) {
            const uint slot = atomicAdd(sCount, 1u);
            if (slot < SHARED_LIST_SIZE) sLights[slot] = i; // THE FLAW: the rest are dropped here
        }
    }
    barrier();

    // The list to the buffer: count, then indices (fixed:N, lcAppend's layout).
    const uint count = min(sCount, SHARED_LIST_SIZE); // THE FLAW: clamped, so no overflow shows
    const uint base = tileIndex * (uint(MAX_LIGHTS_PER_TILE) + 1u);
    if (gl_LocalInvocationIndex == 0u) lcOut[base] = count;
    for (uint k = gl_LocalInvocationIndex; k < count; k += 64u) lcOut[base + 1u + k] = sLights[k];
}
