#version 450
// Pass 1b of the culling: bins the lights by tile column and tile row. One
// invocation per (mask word, column) or (mask word, row) (BIN_LANES of them,
// on GPUs, each with 32 / BIN_LANES of the lights) tests that word's 32
// lights against the column's left/right (row's top/bottom) side planes, the
// same planes and the same reject rule (signed distance < -radius) as the
// chunk test, with the radius widened once more so that a light the chunk
// test keeps always has its bit set. cull_lists then tests only the lights set
// in both its column's and its row's word: candidates come out of a word in
// ascending order, and the work is (tilesX + tilesY) x lights plane tests here
// instead of tiles x lights chunk tests there.
//
// With DEPTH_BINS, one more invocation per (mask word, depth bin) writes that
// word of the near bin and of the far bin (cull_common.glsl, binding 8): the
// lights whose near end a = depth - r is at or before the bin, and those
// whose far end b = depth + r is at or beyond it, r widened as above and the
// bin coordinates moved out by DEPTH_BIN_MARGIN. A list whose (widened) depth
// range [zlo, zhi] lies in bins t0..t1 takes only lights in near bin t1 and
// far bin t0: a light the chunk test keeps has a <= zhi and b >= zlo, so it
// is in both (the last near bin and the first far bin hold every light, for
// depths clamped into them). No barrier(); subgroup shuffles only in the
// build with LC_WORD_SHUFFLE (wordOr), whose pipeline asks for full
// subgroups.
#extension GL_GOOGLE_include_directive : require
#ifdef LC_WORD_SHUFFLE
#extension GL_KHR_shader_subgroup_shuffle : require
#endif
#include "cull_common.glsl"

// A light's radius as the bins take it: twice the chunk test's widening, as
// the two evaluations of the same distance may round differently
// (contraction), never by 2e-5.
float binRadius(vec4 L) { return widenedRadius(L) + (length(L.xyz) + L.w) * P.cluster.z; }

// The OR of a mask over the BIN_LANES (a power of 2) invocations sharing its
// word: neighbours in the subgroup, all active or all returned. Built without
// LC_WORD_SHUFFLE, BIN_LANES is 1.
uint wordOr(uint m) {
#ifdef LC_WORD_SHUFFLE
    for (uint s = 1u; s < BIN_LANES; s <<= 1u) m |= subgroupShuffleXor(m, s);
#endif
    return m;
}

void main() {
    loadParams();
    uint idx = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
               gl_LocalInvocationIndex;
    // BIN_LANES neighbouring invocations share a word, part p testing its
    // lights p x 32 / BIN_LANES ..; their masks are ORed. They return
    // together (the exits below depend on idx only); their light loops take
    // different turns only in a last, partial word, and meet again after
    // them as the list walk's lanes do after their candidate loops. (The
    // same turns in every part, a light past the last skipped inside, cost
    // P1 on the H100 0.1-0.2 us.)
    uint part = idx % BIN_LANES, partLights = 32u / BIN_LANES;
    idx /= BIN_LANES;
    uint words = P.bins.x, tilesX = P.size.z, tilesY = P.size.w;
    uint columnWords = words * tilesX, planeWords = columnWords + words * tilesY;
    uint lightCount = P.counts.x;
    if (DEPTH_BINS != 0u && idx >= planeWords) {
        uint j = idx - planeWords;
        if (j >= LC_DEPTH_BINS * words) return;
        uint bin = j / words, w = j % words;
        uint first = w * 32u, end = min(first + 32u, lightCount);
        uint nearMask = 0u, farMask = 0u;
        float binF = float(bin);
        for (uint i = first + part * partLights; i < min(first + (part + 1u) * partLights, end); ++i) {
            vec4 L = lights[i].centerRadius;
            float r = binRadius(L);
            float depth = -L.z;
            if (depthBinCoord(depth - r) - DEPTH_BIN_MARGIN < binF + 1.0) nearMask |= 1u << (i - first);
            if (depthBinCoord(depth + r) + DEPTH_BIN_MARGIN >= binF) farMask |= 1u << (i - first);
        }
        nearMask = wordOr(nearMask);
        farMask = wordOr(farMask);
        if (part != 0u) return;
        uint all = end > first ? (0xffffffffu >> (32u - (end - first))) : 0u;
        binMask[P.bins.w + j] = bin == LC_DEPTH_BINS - 1u ? all : nearMask;
        binMask[P.bins.w + LC_DEPTH_BINS * words + j] = bin == 0u ? all : farMask;
        return;
    }
    if (idx >= planeWords) return;
    // Invocations run across the lines of one word (so on a GPU a subgroup
    // reads the same 32 lights) and write each line's words contiguously.
    bool column = idx < columnWords;
    uint j = column ? idx : idx - columnWords;
    uint lines = column ? tilesX : tilesY;
    uint w = j / lines, line = j % lines;
    uint at = (column ? 0u : P.bins.y) + line * words + w;
    vec4 a, b;
    if (column) columnPlanes(columnNdc(line), a, b);
    else rowPlanes(rowNdc(line), a, b);
    uint first = w * 32u, end = min(first + 32u, lightCount);
    uint mask = 0u;
    for (uint i = first + part * partLights; i < min(first + (part + 1u) * partLights, end); ++i) {
        vec4 L = lights[i].centerRadius;
        float r = binRadius(L);
        float da = dot(a.xyz, L.xyz) + a.w, db = dot(b.xyz, L.xyz) + b.w;
        if (da >= -r && db >= -r) mask |= 1u << (i - first);
    }
    mask = wordOr(mask);
    if (part == 0u) binMask[at] = mask;
}
