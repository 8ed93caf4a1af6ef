// lightcull: --layout compact --lists froxel:16:log
//
// Clustered culling into compact lists, the layout this project's own passes
// and many clustered renderers use: per froxel an offset and a count into one
// shared index array. One workgroup per tile walks the tile's depth slices
// (log slices of lc.planes.z..w, the froxel range the tool gives), gathers
// the slice's lights in shared memory, then reserves a block of the index
// array with one atomic and writes it. A froxel with more lights than the
// shared array holds is not cut short: its lights are tested again and
// written straight into the block (a cap would lose lights without a word).
//   lightcull run --builtin forest --shader clustered_compact.comp --out out/mine
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"

layout(local_size_x = 64) in;

const uint kMaxPerFroxel = 512u;
shared uint sCount;
shared uint sBase;
shared uint sCursor;
shared uint sList[kMaxPerFroxel];

float sliceBoundary(uint i) {
    const float lo = lc.planes.z, hi = lc.planes.w;
    const float t = float(i) / float(LC_LISTS_PER_TILE);
    return lc.mode.w == LC_SLICING_LOG && lo > 0.0 ? lo * pow(hi / lo, t) : lo + (hi - lo) * t;
}

// The tile's four side planes (view space, inward normals).
vec4 planes[4];

// Whether light i's sphere reaches the froxel between view depths z0 and z1
// behind the tile's side planes.
bool inFroxel(uint i, float z0, float z1) {
    const vec4 l = lcLights[i].positionRadius;
    // Widened a little so float rounding never drops a light the exact test keeps.
    const float r = l.w + 1e-5 * (abs(l.x) + abs(l.y) + abs(l.z) + l.w);
    bool inside = -l.z + r >= z0 * (1.0 - 1e-5) && -l.z - r <= z1 * (1.0 + 1e-5);
    for (int k = 0; k < 4 && inside; ++k) inside = dot(planes[k].xyz, l.xyz) + planes[k].w >= -r;
    return inside;
}

void main() {
    const uvec2 tile = gl_WorkGroupID.xy;
    const uint tileIndex = tile.y * lc.size.z + tile.x;
    const uvec2 p0 = tile * uint(TILE_SIZE);
    const uvec2 p1 = min(p0 + uint(TILE_SIZE), lc.size.xy);
    const float u0 = 2.0 * float(p0.x) / float(lc.size.x) - 1.0, u1 = 2.0 * float(p1.x) / float(lc.size.x) - 1.0;
    const float v0 = 2.0 * float(p0.y) / float(lc.size.y) - 1.0, v1 = 2.0 * float(p1.y) / float(lc.size.y) - 1.0;
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
    for (uint s = 0u; s < uint(LC_LISTS_PER_TILE); ++s) {
        // The first slice reaches to the eye, the last to infinity: pixels
        // outside the froxel range use them (the tool's rule).
        const float z0 = s == 0u ? 0.0 : sliceBoundary(s);
        const float z1 = s + 1u == uint(LC_LISTS_PER_TILE) ? 3.0e38 : sliceBoundary(s + 1u);
        if (gl_LocalInvocationIndex == 0u) {
            sCount = 0u;
            sCursor = 0u;
        }
        barrier();
        for (uint i = gl_LocalInvocationIndex; i < lc.counts.x; i += 64u)
            if (inFroxel(i, z0, z1)) {
                const uint k = atomicAdd(sCount, 1u);
                if (k < kMaxPerFroxel) sList[k] = i;
            }
        barrier();
        if (gl_LocalInvocationIndex == 0u) sBase = lcCompactReserve(lcListIndex(tileIndex, s), sCount);
        barrier();
        if (sBase != ~0u) {
            if (sCount <= kMaxPerFroxel) {
                for (uint k = gl_LocalInvocationIndex; k < sCount; k += 64u) lcOut[sBase + k] = sList[k];
            } else {
                // More than the shared array holds: the same test on the same
                // light by the same invocation again, each light written
                // straight into the block.
                for (uint i = gl_LocalInvocationIndex; i < lc.counts.x; i += 64u)
                    if (inFroxel(i, z0, z1)) lcOut[sBase + atomicAdd(sCursor, 1u)] = i;
            }
        }
        barrier();
    }
}
