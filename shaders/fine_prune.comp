#version 450
// fptl's fine prune (culling/cpu/fine_prune.hpp), run after cull_lists wrote the
// coarse (minmax) lists into the index array:
//   WRITE_PASS LC_PRUNE_MARK: an invocation (LANES > 1: a subgroup, its lanes over
//     the pixels) per entry of the index array. It finds its
//     list (a binary search of the offsets), walks the geometry pixels of
//     that list's tile and overwrites the entry with PRUNED when no pixel lies
//     inside the light's volume: its range sphere and, for a spot light, its
//     cone (binding 9 holds every spot's cone for fptl), both widened by the
//     backend's float margin (cull_common.glsl) so that every light the
//     double-precision reference keeps stays.
//   WRITE_PASS LC_PRUNE_PACK: an invocation per list moves its kept entries, in order, to
//     the front of its range and writes the new count. Offsets stay: a list
//     keeps its slot, its tail unused (the host packs them on read-back).
// Loops per invocation: at most a tile's pixels plus the search (pass 0),
// a list's entries (pass 1); the host keeps both under lavapipe's cap.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_vote : require
#include "cull_common.glsl"

const uint PRUNED = 0xffffffffu;

// The light's volume as the prune tests it: its range sphere (centre c,
// radius r widened by eps: reach) and, for a spot, its cone.
struct PruneVolume {
    vec3 c;
    float reach, eps;
    bool spot;
    vec3 axis;
    float cosAngle;
};

// Whether pixel (x, y) holds geometry inside the volume.
bool pixelInside(uint x, uint y, PruneVolume vol) {
    float depth = depthBuf[y * P.size.x + x];
    if (depth == P.depth.w) return false; // clear depth: no geometry
    float v = viewDepthOf(depth);
    if (isnan(v) || isinf(v)) return false;
    vec3 d = viewAt(2.0 * (float(x) + 0.5) / float(P.size.x) - 1.0, 2.0 * (float(y) + 0.5) / float(P.size.y) - 1.0, v) -
             vol.c;
    float len = length(d);
    return len <= vol.reach && (!vol.spot || dot(d, vol.axis) >= len * vol.cosAngle - vol.eps);
}

void main() {
    loadParams();
    uint id = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
              gl_LocalInvocationIndex;
    uint lists = P.counts.z;
    if (WRITE_PASS == LC_PRUNE_MARK) {
        // LANES > 1 (GPUs): a subgroup per entry, its lanes over the tile's
        // pixels; else an invocation per entry.
        uint lane = 0u;
        if (LANES > 1u) {
            id = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_NumSubgroups + gl_SubgroupID;
            lane = gl_SubgroupInvocationID;
        }
        if (id >= listOffset[lists]) return;
        // offset[lo] <= id < offset[hi]: ends on the one non-empty list holding id.
        uint lo = 0u, hi = lists;
        while (hi - lo > 1u) {
            uint mid = (lo + hi) >> 1u;
            if (listOffset[mid] <= id) lo = mid; else hi = mid;
        }
        uint l = lightIndices[id];
        uint tx = lo % P.size.z, ty = lo / P.size.z;
        uint x0 = tx * TILE_SIZE, y0 = ty * TILE_SIZE;
        uint w = min(x0 + TILE_SIZE, P.size.x) - x0, h = min(y0 + TILE_SIZE, P.size.y) - y0;
        // The light's volume, loaded once for the walk: its range sphere and,
        // for a spot light (its range sphere centred on the apex), its cone,
        // both widened by eps.
        vec4 L = lights[l].centerRadius;
        PruneVolume vol;
        vol.c = L.xyz;
        float r = L.w;
        vol.spot = false;
        vol.axis = vec3(0.0);
        vol.cosAngle = 0.0;
        if (uint(spots.length()) > l && spots[l].apexRange.w > 0.0) {
            vol.c = spots[l].apexRange.xyz;
            r = spots[l].apexRange.w;
            vol.axis = spots[l].axisCos.xyz;
            vol.cosAngle = spots[l].axisCos.w;
            vol.spot = true;
        }
        vol.eps = (length(vol.c) + r) * P.cluster.z + P.cluster.w;
        vol.reach = r + vol.eps;
        bool keep = false;
        if (LANES > 1u) {
            // The subgroup steps over the tile's pixels a lane each and stops
            // at the first pixel any lane finds inside.
            for (uint first = 0u; first < w * h; first += LANES) {
                uint i = first + lane;
                keep = i < w * h && pixelInside(x0 + i % w, y0 + i / w, vol);
                if (subgroupAny(keep)) break;
            }
            keep = subgroupAny(keep);
            if (!keep && lane == 0u) lightIndices[id] = PRUNED;
            return;
        }
        // One flat loop over the tile's pixels (one loop, so its iterations
        // are the only ones lavapipe counts here), the pixel stepped along
        // its row: no division per pixel.
        uint x = x0, y = y0;
        for (uint i = 0u; i < w * h && !keep; ++i) {
            keep = pixelInside(x, y, vol);
            if (++x == x0 + w) {
                x = x0;
                ++y;
            }
        }
        if (!keep) lightIndices[id] = PRUNED;
    } else {
        if (id >= lists) return;
        uint base = listOffset[id], count = listCount[id], n = 0u;
        for (uint i = 0u; i < count; ++i) {
            uint l = lightIndices[base + i];
            if (l != PRUNED) {
                lightIndices[base + n] = l;
                ++n;
            }
        }
        listCount[id] = n;
    }
}
