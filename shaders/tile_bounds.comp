#version 450
// Pass 1 of the culling: per tile, the view-depth bounds of the pixels holding
// geometry (clear-valued pixels skipped), the halfz split, and the occupancy
// mask of the 2.5d cells / clustered slices. One workgroup (= one subgroup)
// per tile, several pixels per invocation, reductions by subgroup operations.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "cull_common.glsl"

void main() {
    if (gl_NumSubgroups != 1u) atomicOr(status, STATUS_SPLIT_WORKGROUP);
    uint tx = gl_WorkGroupID.x, ty = gl_WorkGroupID.y;
    uint W = P.size.x;
    uint x0 = tx * TILE_SIZE, y0 = ty * TILE_SIZE;
    uint tw = min(x0 + TILE_SIZE, W) - x0, th = min(y0 + TILE_SIZE, P.size.y) - y0;
    uint n = tw * th;
    uint lane = gl_LocalInvocationIndex, stride = gl_WorkGroupSize.x;
    float clearDepth = P.depth.w;

    // Window depth extremes: linearising only the two extremes is exact
    // because window depth is monotonic in view depth for every kind.
    float wLo = 2.0, wHi = -1.0;
    for (uint i = lane; i < n; i += stride) {
        float d = depthBuf[(y0 + i / tw) * W + x0 + i % tw];
        if (d != clearDepth) {
            wLo = min(wLo, d);
            wHi = max(wHi, d);
        }
    }
    wLo = subgroupMin(wLo);
    wHi = subgroupMax(wHi);

    GpuTileBounds tb;
    tb.cellMask = 0u;
    if (wLo > wHi) { // no geometry in the tile
        tb.depthMin = uintBitsToFloat(0x7f800000u);   // +inf
        tb.depthMax = uintBitsToFloat(0xff800000u);   // -inf
        tb.split = tb.depthMin;
    } else {
        float va = viewDepthOf(wLo), vb = viewDepthOf(wHi);
        tb.depthMin = min(va, vb);
        tb.depthMax = max(va, vb);
        tb.split = (tb.depthMin + tb.depthMax) * 0.5;
        if (ALGORITHM == LC_ALG_25D || ALGORITHM == LC_ALG_CLUSTERED) {
            float lo = (ALGORITHM == LC_ALG_25D) ? tb.depthMin : P.cluster.x;
            float hi = (ALGORITHM == LC_ALG_25D) ? tb.depthMax : P.cluster.y;
            uint mask = 0u;
            for (uint i = lane; i < n; i += stride) {
                float d = depthBuf[(y0 + i / tw) * W + x0 + i % tw];
                if (d != clearDepth) {
                    float v = viewDepthOf(d);
                    // Widened: a pixel within rounding of a cell boundary marks both cells.
                    mask |= sliceRangeMask(lo, hi, widenDown(v), widenUp(v));
                }
            }
            tb.cellMask = subgroupOr(mask);
        }
    }
    if (subgroupElect()) tiles[ty * P.size.z + tx] = tb;
}
