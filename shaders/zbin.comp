#version 450
// zbin's depth bins (Drobot, "Improved Culling for Tiled and Clustered
// Rendering", SIGGRAPH 2017). The lights arrive sorted by the view depth of
// their culling sphere's centre, so light k is sorted position k. Bin b of
// the P.depthBins.z linear bins over [P.lens.z, P.lens.w] (scale
// P.depthBins.y bins per unit of view depth) keeps the lowest and highest
// position whose widened depth extent reaches it, at binMask[base + 2b] and
// binMask[base + 2b + 1] (base = P.bins.w, the words after the plane bins).
//   WRITE_PASS LC_ZBIN_INIT: an invocation per bin sets the empty range (lo > hi).
//   WRITE_PASS LC_ZBIN_BIN: an invocation per light takes the bins its extent spans
//     (at most 16,384: under lavapipe's loop cap).
#extension GL_GOOGLE_include_directive : require
#include "cull_common.glsl"

uint binOfDepth(float d, uint bins) {
    float t = (d - P.lens.z) * P.depthBins.y;
    return uint(clamp(t, 0.0, float(bins - 1u))); // NaN clamps to 0 on every driver we run; t < 0 -> 0
}

void main() {
    loadParams();
    uint id = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
              gl_LocalInvocationIndex;
    uint bins = uint(P.depthBins.z);
    uint base = P.bins.w;
    if (WRITE_PASS == LC_ZBIN_INIT) {
        if (id >= bins) return;
        binMask[base + 2u * id] = 0xffffffffu;
        binMask[base + 2u * id + 1u] = 0u;
        return;
    }
    if (id >= P.counts.x) return;
    vec4 L = lights[id].centerRadius;
    float r = widenedRadius(L);
    float a = widenDown(-L.z - r), b = widenUp(-L.z + r);
    if (b < P.lens.z || a > P.lens.w) return; // reaches no bin
    uint b0 = binOfDepth(a, bins), b1 = binOfDepth(b, bins);
    for (uint k = b0; k <= b1; ++k) {
        atomicMin(binMask[base + 2u * k], id);
        atomicMax(binMask[base + 2u * k + 1u], id);
    }
}
