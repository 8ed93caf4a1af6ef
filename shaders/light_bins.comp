#version 450
// Pass 1b of the culling: bins the lights by tile column and tile row. One
// invocation per (mask word, column) or (mask word, row) tests that word's 32
// lights against the column's left/right (row's top/bottom) side planes, the
// same planes and the same reject rule (signed distance < -radius) as the
// chunk test, with the radius widened once more so that a light the chunk
// test keeps always has its bit set. cull_lists then tests only the lights set
// in both its column's and its row's word: candidates come out of a word in
// ascending order, and the work is (tilesX + tilesY) x lights plane tests here
// instead of tiles x lights chunk tests there. No subgroup operations, no
// barrier(): any local size.
#extension GL_GOOGLE_include_directive : require
#include "cull_common.glsl"

void main() {
    loadParams();
    uint idx = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
               gl_LocalInvocationIndex;
    uint words = P.bins.x, tilesX = P.size.z, tilesY = P.size.w;
    uint columnWords = words * tilesX;
    if (idx >= columnWords + words * tilesY) return;
    bool column = idx < columnWords;
    uint j = column ? idx : idx - columnWords;
    uint lines = column ? tilesX : tilesY;
    uint w = j / lines, line = j % lines;
    vec4 a, b;
    if (column) columnPlanes(columnNdc(line), a, b);
    else rowPlanes(rowNdc(line), a, b);
    uint lightCount = P.counts.x;
    uint first = w * 32u, end = min(first + 32u, lightCount);
    uint mask = 0u;
    for (uint i = first; i < end; ++i) {
        vec4 L = lights[i].centerRadius;
        // Twice the chunk test's widening: the two evaluations of the same
        // plane distance may round differently (contraction), never by 2e-5.
        float r = widenedRadius(L) + (length(L.xyz) + L.w) * P.cluster.z;
        float da = dot(a.xyz, L.xyz) + a.w, db = dot(b.xyz, L.xyz) + b.w;
        if (da >= -r && db >= -r) mask |= 1u << (i - first);
    }
    binMask[idx] = mask;
}
