#version 450
// Passes 2 and 4 of the culling: one workgroup (= one subgroup) per list
// tests every light against the list's volume, looping over the lights in
// strides of the subgroup size (so any light count works, not one light per
// invocation). WRITE_PASS == 0 stores the count; WRITE_PASS == 1 writes the
// indices at the scanned offset. Within a stride, lanes hold consecutive light
// indices and the ballot's exclusive bit count orders them, so every list
// comes out ascending and deterministic, without a sort and without barriers.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_ballot : require
#include "cull_common.glsl"

float sliceBoundary(float lo, float hi, uint i) {
    float t = float(i) / float(CELLS);
    if (SLICING == LC_SLICING_LOG && lo > 0.0) return lo * pow(hi / lo, t);
    return lo + (hi - lo) * t;
}

void main() {
    if (gl_NumSubgroups != 1u) atomicOr(status, STATUS_SPLIT_WORKGROUP);
    uint list = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    uint lightCount = P.counts.x;
    if (list >= P.counts.z) return;
    if (WRITE_PASS != 0u && listCount[list] == 0u) return;

    uint tile = list / P.counts.y, sub = list % P.counts.y;
    // The list's depth range [zlo, zhi] (view depth) and which lights it takes.
    bool testChunk = ALGORITHM != LC_ALG_ALL;
    bool listLive = true;
    uint geomMask = 0u;
    float maskLo = 0.0, maskHi = 0.0; // 2.5d: the cells' range, the tile's own bounds
    float zlo = 0.0, zhi = 0.0;
    if (ALGORITHM != LC_ALG_ALL) {
        GpuTileBounds tb = tiles[tile];
        // A tile without geometry gets no lights, except for the two volumes that
        // do not come from the depth buffer (as the CPU reference): naive, and
        // clustered without skip-empty.
        bool depthDriven = ALGORITHM != LC_ALG_NAIVE &&
                           !(ALGORITHM == LC_ALG_CLUSTERED && (P.counts.w & LC_FLAG_SKIP_EMPTY) == 0u);
        listLive = !depthDriven || tb.depthMin <= tb.depthMax;
        zlo = tb.depthMin;
        zhi = tb.depthMax;
        if (ALGORITHM == LC_ALG_NAIVE) {
            zlo = P.lens.z;
            zhi = P.lens.w;
        } else if (ALGORITHM == LC_ALG_HALFZ) {
            if (sub == 0u) zhi = tb.split; else zlo = tb.split;
        } else if (ALGORITHM == LC_ALG_25D) {
            geomMask = tb.cellMask;
            maskLo = tb.depthMin;
            maskHi = tb.depthMax;
        } else if (ALGORITHM == LC_ALG_CLUSTERED) {
            if ((P.counts.w & LC_FLAG_SKIP_EMPTY) != 0u)
                listLive = listLive && ((tb.cellMask >> sub) & 1u) != 0u;
            zlo = sliceBoundary(P.cluster.x, P.cluster.y, sub);
            zhi = sliceBoundary(P.cluster.x, P.cluster.y, sub + 1u);
        }
    }
    uint n = 0u;
    if (listLive) {
        Chunk ch = makeChunk(tile, max(widenDown(zlo), isOrtho() ? -3.4e38 : 0.0), widenUp(zhi));
        uint base = (WRITE_PASS != 0u) ? listOffset[list] : 0u;
        for (uint i0 = 0u; i0 < lightCount; i0 += gl_WorkGroupSize.x) {
            uint i = i0 + gl_LocalInvocationIndex;
            bool pass = i < lightCount;
            if (pass && testChunk) {
                vec4 L = lights[i];
                float r = L.w + (length(L.xyz) + L.w) * P.cluster.z + P.cluster.w;
                pass = sphereHitsChunk(ch, L.xyz, r);
                if (pass && ALGORITHM == LC_ALG_25D) {
                    float depth = -L.z;
                    pass = (sliceRangeMask(maskLo, maskHi, widenDown(depth - r), widenUp(depth + r)) &
                            geomMask) != 0u;
                }
            }
            uvec4 ballot = subgroupBallot(pass);
            if (WRITE_PASS != 0u && pass) lightIndices[base + n + subgroupBallotExclusiveBitCount(ballot)] = i;
            n += subgroupBallotBitCount(ballot);
        }
    }
    if (WRITE_PASS == 0u) {
        if (subgroupElect()) listCount[list] = n;
    } else if (n != listCount[list]) {
        atomicOr(status, STATUS_COUNT_MISMATCH);
    }
}
