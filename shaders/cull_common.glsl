// Shared by the culling compute shaders: bindings, specialisation constants,
// depth linearisation, slicing and the sphere-versus-chunk tests.
//
// Spaces: depth buffer = window depth in [0,1]; everything else is VIEW space
// (right-handed, y up, camera looks down -z, view depth = -z > 0).
//
// Conservative float: every comparison that decides whether a light enters a
// list is widened by eps = params.cluster.z (relative) + params.cluster.w
// (absolute), so a light the double-precision CPU reference keeps is always
// kept here too; the GPU lists may only hold MORE entries near a bound.
#include "culling/vk/gpu_shared.h"
#include "spot_tests.glsl"

// Local size is a specialisation constant. tile_bounds and prefix_sum run one
// workgroup = one subgroup (local size = the device's subgroup size) and reduce
// with subgroup operations only: no shared memory and no barrier() (each costs
// tens of ms on lavapipe); a device that splits such a workgroup is reported
// through status bit 1. light_bins uses one invocation per mask word; with
// LANES > 1, tile_bounds and cull_lists give each tile / list one subgroup
// (gl_SubgroupID within a workgroup of several subgroups).
layout(local_size_x_id = 0) in;
layout(constant_id = 1) const uint TILE_SIZE = 16u;
layout(constant_id = 2) const uint CELLS = 32u;
layout(constant_id = 3) const uint SLICING = 0u;      // LC_SLICING_*
layout(constant_id = 4) const uint ALGORITHM = 0u;    // LC_ALG_*
layout(constant_id = 5) const uint SPHERE_TEST = 0u;  // LC_TEST_*
layout(constant_id = 6) const uint WRITE_PASS = 0u;   // LC_PASS_* (cull_lists), LC_PRUNE_*, LC_ZBIN_*
// Lanes sharing one tile (tile_bounds) or one list (cull_lists): 1 (an
// invocation each: CPU devices), or the subgroup size (a subgroup each: GPUs).
layout(constant_id = 7) const uint LANES = 1u;
// tile_bounds: pixels per depth load, 2 or 8 with LC_WIDE_DEPTH_LOADS (an
// invocation per tile), 4 or 1 without (4: a vec4 a lane, on GPUs).
layout(constant_id = 8) const uint DEPTH_LOAD = 2u;
// light_bins and cull_lists: 1 when the lists filter their candidates through
// the depth bins (binding 8, after the row masks).
layout(constant_id = 9) const uint DEPTH_BINS = 0u;
// cull_lists, clustered on a CPU device: 0, or the slices (at most 32) one
// invocation takes: an invocation per tile and TILE_WALK slices instead of
// one per list.
layout(constant_id = 10) const uint TILE_WALK = 0u;
// cull_lists: the spot cone refinement after the sphere test (LC_SPOT_*).
layout(constant_id = 11) const uint SPOT_TEST = 0u;
// light_bins: invocations sharing one mask word (1; a power of 2 up to 32 in
// the build with subgroup shuffles), each testing 32 / BIN_LANES of its lights.
layout(constant_id = 12) const uint BIN_LANES = 1u;
// tile_bounds and 2.5d's light test: 1 where the host knows every cell range
// starts beyond 0 (log slicing, a perspective camera, clustered's near > 0),
// so pixels and lights take the log cell formula alone: lavapipe runs both sides of a
// varying branch, and the linear one's division cost P1 0.3 ms. A tile whose
// range does not start beyond 0 all the same is marked whole (conservative).
layout(constant_id = 13) const uint CELL_LOG = 0u;
// 1 for an orthographic camera (the flag LC_FLAG_ORTHO records the same):
// compiled in, so lavapipe, which runs both sides of a varying branch, does
// not build every chunk's planes and corners for both projections.
layout(constant_id = 14) const uint ORTHO = 0u;
// cull_lists on GPUs: mask words per lane a list's walk keeps in registers
// (1 to 4; see KEPT_WORDS' use there).
layout(constant_id = 15) const uint KEPT_WORDS = 4u;
// cull_lists: 1 when a test counter could wrap around 2^32 (the host's bound:
// the items adding to one counter x the lights each tests): the add then
// returns the old value to check it; else a plain add, which nothing waits
// for (P1 on the H100: 0.0201 -> 0.0200 ms).
layout(constant_id = 16) const uint TESTS_WRAP = 1u;

layout(std430, binding = 0) readonly buffer Params { GpuCullParams params; };
// A private copy of the parameters, filled by loadParams() at the top of every
// main(): lavapipe does not hoist storage-buffer loads out of loops, and a
// load per pixel or per light is a per-lane scalar loop there (measured: the
// 2.5d cell walk over 1080p went from ~50 ms to a few ms).
GpuCullParams P;
void loadParams() { P = params; }
layout(std430, binding = 1) readonly buffer DepthBuf { float depthBuf[]; };
layout(std430, binding = 2) buffer TileBuf { GpuTileBounds tiles[]; };
layout(std430, binding = 3) readonly buffer LightBuf { GpuLight lights[]; };
layout(std430, binding = 4) buffer CountBuf { uint listCount[]; };
layout(std430, binding = 5) buffer OffsetBuf { uint listOffset[]; };    // listCount + 1 (total)
#ifdef LC_INDEX16
// cull_lists.comp built with LC_INDEX16 (the GPU's fused pass while the
// lights fit 16 bits): the index array holds 16-bit light indices.
layout(std430, binding = 6) buffer IndexBuf { uint16_t lightIndices[]; };
#define LC_INDEX(l) uint16_t(l)
#else
layout(std430, binding = 6) buffer IndexBuf { uint lightIndices[]; };
#define LC_INDEX(l) (l)
#endif
// status: LC_STATUS_* bits (gpu_shared.h); candidateTests: light-versus-volume tests the count
// pass performed (the write pass repeats them), for the benchmarks, in
// LC_TEST_COUNTERS counters (countTests in cull_lists.comp).
layout(std430, binding = 7) buffer StatusBuf { uint status; uint candidateTests[]; };
// Light bins (light_bins.comp): one bit per light, P.bins.x words per bin
// (padded with zero words to a multiple of 4). Column tx's words start at
// binMask[tx * P.bins.x], row ty's at binMask[P.bins.y + ty * P.bins.x]; a
// set bit means the light's sphere is not outside either side plane of that
// tile column / row. With DEPTH_BINS, near bin s's words start at P.bins.w +
// s * P.bins.x (a set bit: the light's near end is at or before bin s), far
// bin s's at P.bins.w + (LC_DEPTH_BINS + s) * P.bins.x (its far end is at or
// beyond bin s). Every bin's words are contiguous and start on a uvec4.
layout(std430, binding = 8) buffer BinBuf { uint binMask[]; };
layout(std430, binding = 8) readonly buffer BinQuads { uvec4 binQuads[]; }; // the same, 4 words a load
// Spot cones (one per light; a 1-element placeholder without cone tests).
layout(std430, binding = 9) readonly buffer SpotBuf { GpuSpotCone spots[]; };
// The count pass's stash: the first P.bins.z entries of every list, at
// stash[list * P.bins.z + i] (cull_lists.comp). A list the stash holds whole
// is copied, not culled again, by the write pass, and when it holds every
// list the host reads the entries from here and skips the write pass.
layout(std430, binding = 10) buffer StashBuf { uint stash[]; };

// Status bits: LC_STATUS_* in gpu_shared.h.

bool isOrtho() { return ORTHO != 0u; }

// Depth-bin coordinate of view depth d (GpuCullParams.depthBins): its bin is
// the floor, clamped to [0, LC_DEPTH_BINS - 1]. Non-decreasing in d up to
// the rounding of log2, far below DEPTH_BIN_MARGIN; d <= 0 under log slices
// reads as a depth before every bin.
float depthBinCoord(float d) {
    return P.depthBins.z > 0.5 ? (log2(max(d, 1e-30)) - P.depthBins.x) * P.depthBins.y
                               : (d - P.depthBins.x) * P.depthBins.y;
}
// A light's depth extent is binned with this much to spare (in bins), so that
// rounding never leaves out a bin the chunk test reaches.
const float DEPTH_BIN_MARGIN = 0.01;
uint depthBinOf(float d) { return uint(clamp(depthBinCoord(d), 0.0, float(LC_DEPTH_BINS - 1u))); }

// View depth of window depth d, float. A = aHi + aLo so that d - A keeps its
// precision where it cancels (perspective, d near A at the far plane).
float viewDepthOf(float d) {
    precise float t = (d - P.depth.x) - P.depth.z;
    // One division, its operands selected (a per-lane choice costs both
    // divisions on lavapipe, which runs both sides of a varying branch).
    bool ortho = isOrtho();
    return (ortho ? t : P.depth.y) / (ortho ? P.depth.y : t);
}

float widenDown(float v) { return v - (abs(v) * P.cluster.z + P.cluster.w); }
float widenUp(float v) { return v + (abs(v) * P.cluster.z + P.cluster.w); }

// Slice of view depth d among `cells` slices over [lo, hi] (tile_math.hpp's
// sliceOfDepth in float): clamped to [0, cells-1], lo == hi -> 0, no NaN cast.
uint sliceOf(float lo, float hi, float d) {
    if (!(hi > lo)) return 0u;
    float t;
    if (SLICING == LC_SLICING_LOG && lo > 0.0) {
        if (!(d > lo)) return 0u;
        t = log(d / lo) / log(hi / lo);
    } else {
        t = (d - lo) / (hi - lo);
    }
    t = clamp(t * float(CELLS), 0.0, float(CELLS - 1u));
    return uint(t);
}

// Cells that [a, b] overlaps (a <= b), 0 when it misses [lo, hi]; callers
// widen a and b first.
uint sliceRangeMask(float lo, float hi, float a, float b) {
    if (b < lo || a > hi) return 0u;
    uint c0 = sliceOf(lo, hi, a), c1 = sliceOf(lo, hi, b);
    uint n = c1 - c0 + 1u;
    uint bits = (n >= 32u) ? 0xffffffffu : ((1u << n) - 1u);
    return bits << c0;
}

// View position seen at NDC (u, v) (x right, y DOWN) at view depth z.
vec3 viewAt(float u, float v, float z) {
    return isOrtho() ? vec3(u * P.lens.x, -v * P.lens.y, -z)
                     : vec3(u * P.lens.x * z, -v * P.lens.y * z, -z);
}

// A tile's frustum cut at view depths [zlo, zhi]: six inward planes n.p + w >= 0
// (left, right, top, bottom, near, far; unit normals) and eight corners (near:
// tl, tr, br, bl; far: tl, tr, br, bl), as tile_math.hpp's FrustumChunk.
struct Chunk {
    vec4 planes[6];
    vec3 corners[8];
    vec3 boxLo, boxHi; // the corners' bounding box (SPHERE_TEST planes+aabb)
};

// NDC of a tile column's left/right edges (x) or a tile row's top/bottom
// edges (y), clipped to the image (partial edge tiles).
vec2 columnNdc(uint tx) {
    float W = float(P.size.x);
    return vec2(2.0 * float(tx * TILE_SIZE) / W - 1.0, 2.0 * float(min((tx + 1u) * TILE_SIZE, P.size.x)) / W - 1.0);
}
vec2 rowNdc(uint ty) {
    float H = float(P.size.y);
    return vec2(2.0 * float(ty * TILE_SIZE) / H - 1.0, 2.0 * float(min((ty + 1u) * TILE_SIZE, P.size.y)) / H - 1.0);
}

// Inward side planes (unit normals) of a column: [0] left, [1] right; of a
// row: [0] top, [1] bottom. The one place these planes are computed, so the
// binning pass and the chunk test agree.
void columnPlanes(vec2 u, out vec4 left, out vec4 right) {
    if (isOrtho()) {
        left = vec4(1, 0, 0, -u.x * P.lens.x);   // x >= ul*halfW
        right = vec4(-1, 0, 0, u.y * P.lens.x);  // x <= ur*halfW
    } else {
        // x = u*tanX*depth = -u*tanX*z  =>  left: x + kl*z >= 0 with kl = ul*tanX.
        left = vec4(normalize(vec3(1, 0, u.x * P.lens.x)), 0);
        right = vec4(normalize(vec3(-1, 0, -u.y * P.lens.x)), 0);
    }
}
void rowPlanes(vec2 v, out vec4 top, out vec4 bottom) {
    if (isOrtho()) {
        top = vec4(0, -1, 0, -v.x * P.lens.y);   // y <= -vt*halfH
        bottom = vec4(0, 1, 0, v.y * P.lens.y);  // y >= -vb*halfH
    } else {
        // y = -v*tanY*depth = v*tanY*z: top (v = vt) keeps y <= kt*z.
        top = vec4(normalize(vec3(0, -1, v.x * P.lens.y)), 0);
        bottom = vec4(normalize(vec3(0, 1, -v.y * P.lens.y)), 0);
    }
}

// A light's radius widened for float rounding (see the top of this file).
float widenedRadius(vec4 L) { return L.w + (length(L.xyz) + L.w) * P.cluster.z + P.cluster.w; }

Chunk makeChunk(uint tileIndex, float zlo, float zhi) {
    uint tx = tileIndex % P.size.z, ty = tileIndex / P.size.z;
    vec2 u = columnNdc(tx), v = rowNdc(ty);
    float ul = u.x, ur = u.y, vt = v.x, vb = v.y;
    Chunk c;
    columnPlanes(u, c.planes[0], c.planes[1]);
    rowPlanes(v, c.planes[2], c.planes[3]);
    c.planes[4] = vec4(0, 0, -1, -zlo); // depth >= zlo
    c.planes[5] = vec4(0, 0, 1, zhi);   // depth <= zhi
    c.corners[0] = viewAt(ul, vt, zlo);
    c.corners[1] = viewAt(ur, vt, zlo);
    c.corners[2] = viewAt(ur, vb, zlo);
    c.corners[3] = viewAt(ul, vb, zlo);
    c.corners[4] = viewAt(ul, vt, zhi);
    c.corners[5] = viewAt(ur, vt, zhi);
    c.corners[6] = viewAt(ur, vb, zhi);
    c.corners[7] = viewAt(ul, vb, zhi);
    // Once per chunk, not per light (a per-light loop over the corner array
    // cost lavapipe ~25x the whole planes test).
    c.boxLo = min(min(min(c.corners[0], c.corners[1]), min(c.corners[2], c.corners[3])),
                  min(min(c.corners[4], c.corners[5]), min(c.corners[6], c.corners[7])));
    c.boxHi = max(max(max(c.corners[0], c.corners[1]), max(c.corners[2], c.corners[3])),
                  max(max(c.corners[4], c.corners[5]), max(c.corners[6], c.corners[7])));
    return c;
}

float dist2ToSegment(vec3 p, vec3 a, vec3 b) {
    vec3 ab = b - a;
    float t = clamp(dot(p - a, ab) / max(dot(ab, ab), 1e-30), 0.0, 1.0);
    vec3 q = a + t * ab - p;
    return dot(q, q);
}

// Squared distance from p to the planar convex quad q0 q1 q2 q3 (in cyclic
// order): the plane distance when p projects inside, else the nearest edge.
float dist2ToQuad(vec3 p, vec3 q0, vec3 q1, vec3 q2, vec3 q3) {
    vec3 n = cross(q1 - q0, q2 - q1) + cross(q3 - q2, q0 - q3);
    float nn = dot(n, n);
    if (nn > 0.0) {
        bool inside = dot(cross(q1 - q0, p - q0), n) >= 0.0 && dot(cross(q2 - q1, p - q1), n) >= 0.0 &&
                      dot(cross(q3 - q2, p - q2), n) >= 0.0 && dot(cross(q0 - q3, p - q3), n) >= 0.0;
        if (inside) {
            float h = dot(p - q0, n);
            return h * h / nn;
        }
    }
    return min(min(dist2ToSegment(p, q0, q1), dist2ToSegment(p, q1, q2)),
               min(dist2ToSegment(p, q2, q3), dist2ToSegment(p, q3, q0)));
}

// Sphere (centre s, radius r, already widened) against the chunk, per
// SPHERE_TEST: planes; planes + the corners' bounding box; exact distance
// (the nearest point of a convex polytope to an outside point lies on a face
// whose plane the point is outside of, so the minimum over those faces is exact).
bool sphereHitsChunk(Chunk c, vec3 s, float r) {
    float sd[6];
    bool inside = true;
    for (int i = 0; i < 6; ++i) {
        sd[i] = dot(c.planes[i].xyz, s) + c.planes[i].w;
        if (sd[i] < -r) return false;
        inside = inside && sd[i] >= 0.0;
    }
    if (SPHERE_TEST == LC_TEST_PLANES || inside) return true;
    if (SPHERE_TEST == LC_TEST_PLANES_AABB) {
        vec3 d = max(max(c.boxLo - s, s - c.boxHi), vec3(0.0));
        return dot(d, d) <= r * r;
    }
    // Exact: faces in plane order left, right, top, bottom, near, far.
    float best = 3.4e38;
    if (sd[0] < 0.0) best = min(best, dist2ToQuad(s, c.corners[0], c.corners[3], c.corners[7], c.corners[4]));
    if (sd[1] < 0.0) best = min(best, dist2ToQuad(s, c.corners[1], c.corners[2], c.corners[6], c.corners[5]));
    if (sd[2] < 0.0) best = min(best, dist2ToQuad(s, c.corners[0], c.corners[1], c.corners[5], c.corners[4]));
    if (sd[3] < 0.0) best = min(best, dist2ToQuad(s, c.corners[3], c.corners[2], c.corners[6], c.corners[7]));
    if (sd[4] < 0.0) best = min(best, dist2ToQuad(s, c.corners[0], c.corners[1], c.corners[2], c.corners[3]));
    if (sd[5] < 0.0) best = min(best, dist2ToQuad(s, c.corners[4], c.corners[5], c.corners[6], c.corners[7]));
    return best <= r * r;
}
