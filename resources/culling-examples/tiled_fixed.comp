// lightcull: --layout fixed:256 --lists tile
//
// Tiled light culling as most Forward+ tutorials and many shipped engines do
// it: one workgroup per tile finds the tile's min/max view depth in shared
// memory, builds the four side planes through the tile's pixel edges, and
// appends every light whose bounding sphere is inside all of them and
// overlaps [min, max] to the tile's fixed-size list (count + 256 indices).
// Copy it, swap in your engine's code, and run:
//   lightcull run --builtin atrium --shader tiled_fixed.comp --out out/mine
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"

layout(local_size_x = 64) in;

shared uint sMinBits, sMaxBits; // view depths as float bits: positive floats order as uints

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
        if (inside) lcAppend(tileIndex, i);
    }
}
