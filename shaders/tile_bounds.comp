#version 450
// Pass 1 of the culling: per tile, the view-depth bounds of the pixels holding
// geometry (clear-valued pixels skipped), the halfz split, and the occupancy
// mask of the 2.5d cells / clustered slices.
//
// LANES lanes share a tile. On a GPU: a subgroup per tile (several tiles per
// workgroup, by gl_SubgroupID), several pixels per lane, reductions by
// subgroup operations; the lanes cover a row's loads (DEPTH_LOAD 4: a vec4
// of 4 pixels each where the width and the tile size are multiples of 4,
// else 1 pixel) x the rest rows at a time, so no pixel address needs an
// integer division. On a
// CPU device (lavapipe): one invocation per tile walks all its pixels, so the
// SIMD lanes are tiles and a workgroup holds many tiles (measured: 8 lanes
// per tile cost more, a workgroup per tile far more). Either way the column
// loop has a constant trip count (unrolled; x < tw masks partial edge tiles).
//
// Built twice (shaders/CMakeLists.txt): with LC_WIDE_DEPTH_LOADS, for an
// invocation per tile on devices with shaderInt64, each storage-buffer load
// fetches DEPTH_LOAD neighbouring pixels: 8 as a u64vec4 when the width and
// the tile size are multiples of 8, else 2 as one 64-bit word (even widths
// and tile sizes). lavapipe loads a storage buffer lane by lane in a loop,
// one pass of it per load whatever its width, so fewer, wider loads cost
// less (measured: pairs took the min/max walk of 1080p from 4.0 to 2.4 ms of
// CPU; 8 pixels a load took P1's whole cull from 8.6-9.1 to 7.8-8.2 ms
// against pairs, the fastest of 21 culls in each of three runs).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#ifdef LC_WIDE_DEPTH_LOADS
#extension GL_ARB_gpu_shader_int64 : require
#endif
#include "cull_common.glsl"

// DEPTH_LOAD pixels of a tile row from column x on (row: the row's first
// pixel); clear depth at and past column tw. Unused lanes of Pixels read clear.
struct Pixels {
    vec4 a, b; // pixels x .. x + 3, x + 4 .. x + 7
};
#ifdef LC_WIDE_DEPTH_LOADS
// The depth buffer (binding 1) as 2- and 8-pixel words; LANES == 1, and W and
// TILE_SIZE multiples of DEPTH_LOAD, so every load is aligned.
layout(std430, binding = 1) readonly buffer DepthPairs { uint64_t depthPairs[]; };
layout(std430, binding = 1) readonly buffer DepthOctets { u64vec4 depthOctets[]; };
const uint STEP = DEPTH_LOAD;
Pixels depthAt(uint row, uint x, uint tw, float clearDepth) {
    Pixels p;
    p.a = vec4(clearDepth);
    p.b = vec4(clearDepth);
    if (x < tw) { // no load past the image's last pixel
        if (DEPTH_LOAD == 8u) {
            u64vec4 q = depthOctets[(row + x) >> 3u];
            p.a = vec4(uintBitsToFloat(unpackUint2x32(q.x)), uintBitsToFloat(unpackUint2x32(q.y)));
            p.b = vec4(uintBitsToFloat(unpackUint2x32(q.z)), uintBitsToFloat(unpackUint2x32(q.w)));
        } else {
            p.a.xy = uintBitsToFloat(unpackUint2x32(depthPairs[(row + x) >> 1u]));
        }
    }
    p.a = mix(vec4(clearDepth), p.a, lessThan(uvec4(x) + uvec4(0u, 1u, 2u, 3u), uvec4(tw)));
    p.b = mix(vec4(clearDepth), p.b, lessThan(uvec4(x) + uvec4(4u, 5u, 6u, 7u), uvec4(tw)));
    return p;
}
#else
// GPUs, DEPTH_LOAD 4 (the width and the tile size multiples of 4): a lane
// loads 4 neighbouring pixels of a row as one vec4 (P3 on the H100: the
// cull's GPU time 0.165-0.166 ms -> 0.153-0.155), else 1.
layout(std430, binding = 1) readonly buffer DepthQuads { vec4 depthQuads[]; };
const uint STEP = DEPTH_LOAD == 4u ? 4u : 1u;
Pixels depthAt(uint row, uint x, uint tw, float clearDepth) {
    Pixels p;
    p.b = vec4(clearDepth);
    if (STEP == 4u) {
        p.a = x < tw ? depthQuads[(row + x) >> 2u] : vec4(clearDepth);
    } else {
        p.a = vec4(x < tw ? depthBuf[row + x] : clearDepth, clearDepth, clearDepth, clearDepth);
    }
    return p;
}
#endif
// Pixel i (a constant after unrolling) of a load.
float pixelOf(Pixels p, uint i) { return i < 4u ? p.a[i] : p.b[i - 4u]; }

// The lanes sharing a tile take LANE_COLS loads of a row side by side and
// LANE_ROWS rows at a time, so each makes KEEP_ROWS x KEEP_COLS loads (some
// past the tile's edge, read as clear). Where a subgroup shares the tile and
// those are at most KEEP_MAX, a lane keeps them in registers from the bounds'
// walk for 2.5d's cell walk instead of loading them again (P1: 2 loads a
// lane; its cull on the H100 0.0199 -> 0.0196 ms).
const uint LANE_COLS = LANES < TILE_SIZE / STEP ? LANES : TILE_SIZE / STEP;
const uint LANE_ROWS = LANES / LANE_COLS;
const uint KEEP_ROWS = (TILE_SIZE + LANE_ROWS - 1u) / LANE_ROWS;
const uint KEEP_COLS = (TILE_SIZE / STEP + LANE_COLS - 1u) / LANE_COLS;
const uint KEEP_MAX = 8u;
const bool KEEP = LANES != 1u && KEEP_ROWS * KEEP_COLS <= KEEP_MAX;

// Where a pixel's view depth falls among the CELLS cells of [lo, hi] (hi >
// lo). Cell coordinate of view depth v: c = k * (log2(v) - log2(lo)) (log
// slicing) or k * (v - lo) (linear). With log slicing, v = B / w
// (perspective) or w / B (orthographic) for the window offset w = d - A, so
// c = s * k * (log2(|w|) - L0) with L0 = log2(|B| / lo) (or log2(lo |B|)),
// s = -1 (or +1): one log and no division per pixel, and no cancellation of
// large terms. The pixel marks every cell of [c - dc, c + dc] clamped to the
// range, where dc covers the widening of v (relative eps + absolute eps / v
// <= eps + abs / lo, in log2 units / ln 2, x 1.5 for second-order terms and
// rounding), float rounding of the two logs (2e-5 in log2 units) and of c
// (1e-4 of a cell).
struct CellMap {
    bool useLog;
    float lo, k, dc, sk, L0;
};
CellMap cellMapOf(float lo, float hi) {
    CellMap m;
    m.useLog = SLICING == LC_SLICING_LOG && (CELL_LOG != 0u || lo > 0.0);
    m.lo = lo;
    m.k = float(CELLS) / (m.useLog ? log2(hi / lo) : (hi - lo));
    m.dc = m.useLog ? m.k * ((P.cluster.z + P.cluster.w / lo) * 2.17 + 2e-5) + 1e-4
                    : m.k * (max(abs(lo), abs(hi)) * P.cluster.z + P.cluster.w) * 1.01 + 1e-4;
    bool ortho = isOrtho();
    m.sk = ortho ? m.k : -m.k;
    m.L0 = ortho ? log2(lo * abs(P.depth.y)) : log2(abs(P.depth.y) / lo);
    return m;
}
// The cells window depth d (not the clear depth) marks.
uint cellsOf(CellMap m, float d) {
    float c;
    if (m.useLog) {
        precise float w = (d - P.depth.x) - P.depth.z;
        c = m.sk * (log2(abs(w)) - m.L0);
    } else {
        c = m.k * (viewDepthOf(d) - m.lo);
    }
    float cellMax = float(CELLS - 1u);
    uint c0 = uint(int(clamp(c - m.dc, 0.0, cellMax)));
    uint c1 = uint(int(clamp(c + m.dc, 0.0, cellMax)));
    // (2 << (c1 - c0)) - 1: c1 - c0 + 1 ones (all 32: 0 - 1).
    return ((2u << (c1 - c0)) - 1u) << c0;
}

// A load's pixels holding geometry (not the clear depth) into the window
// depth extremes and, for clustered, the slices they mark.
void addBounds(Pixels px, float clearDepth, bool slicesInWalk, CellMap slices, inout float wLo, inout float wHi,
               inout uint walkMask) {
    for (uint pix = 0u; pix < STEP; ++pix) {
        float d = pixelOf(px, pix);
        if (d != clearDepth) {
            wLo = min(wLo, d);
            wHi = max(wHi, d);
            if (slicesInWalk) walkMask |= cellsOf(slices, d);
        }
    }
}

// The cells a load's pixels holding geometry mark.
uint cellsOfLoad(Pixels px, float clearDepth, CellMap cells) {
    uint mask = 0u;
    for (uint pix = 0u; pix < STEP; ++pix) {
        float d = pixelOf(px, pix);
        if (d != clearDepth) mask |= cellsOf(cells, d);
    }
    return mask;
}

void main() {
    loadParams();
    uint tx, ty, lane;
    if (LANES == 1u) {
        tx = gl_GlobalInvocationID.x;
        ty = gl_WorkGroupID.y;
        lane = 0u;
        if (tx >= P.size.z) return;
    } else {
        // A subgroup per tile, gl_NumSubgroups tiles per workgroup along x.
        if (gl_SubgroupSize != LANES) atomicOr(status, LC_STATUS_SPLIT_WORKGROUP);
        tx = gl_WorkGroupID.x * gl_NumSubgroups + gl_SubgroupID;
        ty = gl_WorkGroupID.y;
        lane = gl_SubgroupInvocationID; // of LANES, the subgroup size
        if (tx >= P.size.z) return;
    }
    uint W = P.size.x;
    uint x0 = tx * TILE_SIZE, y0 = ty * TILE_SIZE;
    uint tw = min(x0 + TILE_SIZE, W) - x0, th = min(y0 + TILE_SIZE, P.size.y) - y0;
    // Lanes across a row (each taking STEP pixels a load) and rows at a time.
    uint lx = lane % LANE_COLS, ly = lane / LANE_COLS;
    float clearDepth = P.depth.w;

    // Window depth extremes: linearising only the two extremes is exact
    // because window depth is monotonic in view depth for every kind.
    // clustered's slices span the fixed range [P.cluster.x, P.cluster.y], so
    // its mask comes from the same walk over the pixels (one read of the
    // depth instead of two: P1 / clustered on lavapipe, the cull 5.3-5.4 -> 4.8 ms);
    // 2.5d's cells span the tile's own bounds and take a second walk below.
    bool slicesInWalk = ALGORITHM == LC_ALG_CLUSTERED && P.cluster.y > P.cluster.x;
    CellMap slices = cellMapOf(P.cluster.x, P.cluster.y); // used only when slicesInWalk
    uint walkMask = 0u;
    float wLo = 2.0, wHi = -1.0;
    Pixels kept[KEEP_MAX];
    if (KEEP) {
        for (uint i = 0u; i < KEEP_ROWS; ++i) {
            uint y = ly + i * LANE_ROWS;
            for (uint j = 0u; j < KEEP_COLS; ++j) {
                Pixels px;
                px.a = vec4(clearDepth);
                px.b = vec4(clearDepth);
                if (y < th) px = depthAt((y0 + y) * W + x0, (lx + j * LANE_COLS) * STEP, tw, clearDepth);
                kept[i * KEEP_COLS + j] = px;
                addBounds(px, clearDepth, slicesInWalk, slices, wLo, wHi, walkMask);
            }
        }
    } else {
        for (uint y = ly; y < th; y += LANE_ROWS) {
            uint row = (y0 + y) * W + x0;
            for (uint x = lx * STEP; x < TILE_SIZE; x += LANE_COLS * STEP)
                addBounds(depthAt(row, x, tw, clearDepth), clearDepth, slicesInWalk, slices, wLo, wHi, walkMask);
        }
    }
    if (LANES != 1u) {
        wLo = subgroupMin(wLo);
        wHi = subgroupMax(wHi);
        if (slicesInWalk) walkMask = subgroupOr(walkMask);
    }

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
        if (ALGORITHM == LC_ALG_CLUSTERED) {
            // (A range of one depth: every pixel in slice 0, as sliceOf.)
            tb.cellMask = !slicesInWalk                             ? 1u
                          : CELL_LOG != 0u && !(P.cluster.x > 0.0) ? 0xffffffffu
                                                                   : walkMask;
        } else if (ALGORITHM == LC_ALG_25D) {
            float lo = tb.depthMin, hi = tb.depthMax;
            uint mask = 0u;
            if (!(hi > lo)) {
                mask = 1u; // one depth: every pixel in cell 0 (as sliceOf)
            } else if (CELL_LOG != 0u && !(lo > 0.0)) {
                mask = 0xffffffffu;
            } else {
                CellMap cells = cellMapOf(lo, hi);
                if (KEEP) {
                    for (uint k = 0u; k < KEEP_ROWS * KEEP_COLS; ++k) mask |= cellsOfLoad(kept[k], clearDepth, cells);
                } else {
                    for (uint y = ly; y < th; y += LANE_ROWS) {
                        uint row = (y0 + y) * W + x0;
                        for (uint x = lx * STEP; x < TILE_SIZE; x += LANE_COLS * STEP)
                            mask |= cellsOfLoad(depthAt(row, x, tw, clearDepth), clearDepth, cells);
                    }
                }
            }
            if (LANES != 1u) mask = subgroupOr(mask);
            tb.cellMask = mask;
        }
    }
    if (LANES == 1u || subgroupElect()) tiles[ty * P.size.z + tx] = tb;
}
