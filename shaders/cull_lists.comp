#version 450
// Passes 2 and 4 of the culling: LANES invocations per list (1 on CPU
// devices, a subgroup on GPUs). They walk the mask words of the tile's column
// and row bins (light_bins.comp), lane i taking words i, i + LANES, ..., and
// test only the lights set in both against the list's volume. Each lane keeps
// the lights that pass as a 32-bit mask of its word; a subgroup exclusive add
// of the masks' bit counts places them, so the words go out in order and each
// list comes out ascending and deterministic, without a sort and without
// barriers. With DEPTH_BINS a word is also ANDed with the words of the
// depth bins that hold the list's depth range (light_bins.comp), so lights
// in front of or behind the tile's geometry are not tested at all.
// WRITE_PASS == LC_PASS_COUNT stores the count and stashes the list's first
// P.bins.z entries (cull_common.glsl, binding 10); WRITE_PASS == LC_PASS_WRITE copies a
// list the stash holds whole, else tests again and writes the indices at the
// scanned offset and checks that the count matches; a list that would end
// beyond the index array is left out (the host sees the total and reruns).
// WRITE_PASS == LC_PASS_WRITE_AT_RANGES (clustered's tile walk, CPU devices) is the write pass
// without a scan before it: a tile walk's lists take their ranges with one
// atomic add on the total, as below.
// WRITE_PASS == LC_PASS_FUSED (GPUs, a subgroup per list) does both in one dispatch: the
// count pass, then the list takes its range of the index array with one
// atomic add on the total (listOffset[lists]) and is written there at once,
// from the walk's masks kept in registers, the stash or a second walk; the
// ranges come in no fixed order (the host reads each list at its offset),
// the entries of each list ascending as ever. `all` has one list of every
// light: its count pass is one invocation, its write pass one invocation
// per light.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#ifdef LC_INDEX16
#extension GL_EXT_shader_16bit_storage : require
#endif
#include "cull_common.glsl"

// Adds a list's (or a tile walk's) tests to its counter, flagging a wrap.
// Spread over LC_TEST_COUNTERS addresses: one address for every list's
// atomic add cost P1 on the H100 about 0.4 us of its 20.
void countTests(uint item, uint tested) {
    if (tested == 0u) return;
    uint at = (item % LC_TEST_COUNTERS) * LC_TEST_COUNTER_STRIDE;
    if (TESTS_WRAP == 0u) {
        atomicAdd(candidateTests[at], tested);
    } else if (atomicAdd(candidateTests[at], tested) + tested < tested) {
        atomicOr(status, LC_STATUS_TESTS_OVERFLOW);
    }
}

float sliceBoundary(float lo, float hi, uint i) {
    float t = float(i) / float(CELLS);
    if (SLICING == LC_SLICING_LOG && lo > 0.0) return lo * pow(hi / lo, t);
    return lo + (hi - lo) * t;
}

bool spotConeOutsideChunkPlane(GpuSpotCone s, vec4 plane, float eps) {
    return spotConeOutsidePlane(s.apexRange.xyz, s.axisCos.xyz, s.apexRange.w, s.axisCos.w, s.sinAngle.x, plane, eps);
}

// An invocation's walk over its bins' candidates (CPU devices), four words
// at a time: while quad (the candidates left of quad q - 1) is empty, the next
// four words of the column, row and depth bins ANDed (q counts the quads
// taken; the bins' words are padded to whole quads). Returns the next
// candidate's light and clears it from quad; ~0u when none is left. Four
// words a turn, not one: gallivm runs an if's body whatever its condition
// (masked), so a quad loaded "every fourth word" was loaded on every word.
const uint NO_CANDIDATE = 0xffffffffu;
uint nextCandidate(inout uint q, inout uvec4 quad, uint quads, uint columnBase, uint rowBase, bool depthBins,
                   uint nearBase, uint farBase) {
    while (all(equal(quad, uvec4(0u))) && q < quads) {
        quad = binQuads[(columnBase >> 2u) + q] & binQuads[(rowBase >> 2u) + q];
        if (depthBins) quad &= binQuads[(nearBase >> 2u) + q] & binQuads[(farBase >> 2u) + q];
        ++q;
    }
    if (all(equal(quad, uvec4(0u)))) return NO_CANDIDATE;
    uint i = quad.x != 0u ? 0u : (quad.y != 0u ? 1u : (quad.z != 0u ? 2u : 3u));
    uint m = quad[i];
    quad[i] = m & (m - 1u);
    return ((q - 1u) * 4u + i) * 32u + uint(findLSB(m));
}

// The chunk's bounding sphere for the spot cone-sphere test: centroid of the
// corners, farthest corner, widened. Unrolled: lavapipe caps the loop
// iterations of an invocation (vulkan_backend.cpp, kLoopLimit), so no loops
// per list or light.
void chunkSphere(Chunk ch, out vec3 cellCentre, out float cellRadius) {
    cellCentre = 0.125 * (((ch.corners[0] + ch.corners[1]) + (ch.corners[2] + ch.corners[3])) +
                          ((ch.corners[4] + ch.corners[5]) + (ch.corners[6] + ch.corners[7])));
    cellRadius = max(max(max(distance(ch.corners[0], cellCentre), distance(ch.corners[1], cellCentre)),
                         max(distance(ch.corners[2], cellCentre), distance(ch.corners[3], cellCentre))),
                     max(max(distance(ch.corners[4], cellCentre), distance(ch.corners[5], cellCentre)),
                         max(distance(ch.corners[6], cellCentre), distance(ch.corners[7], cellCentre))));
    cellRadius += (length(cellCentre) + cellRadius) * P.cluster.z + P.cluster.w;
}

// Whether light l (a candidate of the list's bins) goes into the list: the
// sphere against the list's chunk, then the spot cone refinements and the
// 2.5d cell test, as the CPU reference.
bool lightKept(uint l, Chunk ch, vec3 cellCentre, float cellRadius, bool cellLog, float cellLog0,
               float cellScale, float maskLo, float maskHi, uint geomMask) {
    vec4 L = lights[l].centerRadius;
    float r = widenedRadius(L);
    bool pass = sphereHitsChunk(ch, L.xyz, r);
    if (pass && SPOT_TEST != LC_SPOT_NONE) {
        GpuSpotCone s = spots[l];
        if (s.apexRange.w > 0.0) {
            float eps = (length(s.apexRange.xyz) + s.apexRange.w) * P.cluster.z + P.cluster.w;
            if (SPOT_TEST == LC_SPOT_CONE_SPHERE) {
                pass = spotConeHitsSphere(s.apexRange.xyz, s.axisCos.xyz, s.apexRange.w, s.axisCos.w,
                                          s.sinAngle.x, cellCentre, cellRadius, eps);
            } else {
                pass = !(spotConeOutsideChunkPlane(s, ch.planes[0], eps) ||
                         spotConeOutsideChunkPlane(s, ch.planes[1], eps) ||
                         spotConeOutsideChunkPlane(s, ch.planes[2], eps) ||
                         spotConeOutsideChunkPlane(s, ch.planes[3], eps) ||
                         spotConeOutsideChunkPlane(s, ch.planes[4], eps) ||
                         spotConeOutsideChunkPlane(s, ch.planes[5], eps));
            }
        }
    }
    if (pass && ALGORITHM == LC_ALG_25D) {
        float depth = -L.z;
        float a = widenDown(depth - r), b = widenUp(depth + r);
        uint cells;
        if (cellLog) {
            // As sliceRangeMask: no cell when [a, b] misses [lo, hi];
            // cell 0 for depths at or before lo.
            float cellMax = float(CELLS - 1u);
            uint c0 = a > maskLo ? uint(clamp((log2(a) - cellLog0) * cellScale, 0.0, cellMax)) : 0u;
            uint c1 = b > maskLo ? uint(clamp((log2(b) - cellLog0) * cellScale, 0.0, cellMax)) : 0u;
            cells = (b < maskLo || a > maskHi) ? 0u : ((2u << (c1 - c0)) - 1u) << c0;
            // (CELL_LOG: a range that does not start beyond 0 all the same
            // has every cell, as tile_bounds marks it.)
            if (CELL_LOG != 0u && !(maskLo > 0.0)) cells = (b < maskLo || a > maskHi) ? 0u : 0xffffffffu;
        } else {
            cells = sliceRangeMask(maskLo, maskHi, a, b);
        }
        pass = (cells & geomMask) != 0u;
    }
    return pass;
}

// What a subgroup's walk over one list's candidates needs (GPUs).
struct ListWalk {
    Chunk ch;
    vec3 cellCentre;
    float cellRadius;
    bool cellLog;
    float cellLog0, cellScale, maskLo, maskHi;
    uint geomMask, words, columnBase, rowBase;
    bool depthBins;
    uint nearBase, farBase;
};

// Copies a list the stash holds whole (count entries) to lightIndices[base ..]:
// entries first, first + step, ... (step LANES for a subgroup, 1 alone).
void copyStashed(uint list, uint base, uint count, uint first, uint step) {
    uint stashSlots = P.bins.z;
    for (uint i = first; i < count; i += step) lightIndices[base + i] = LC_INDEX(stash[list * stashSlots + i]);
}

// Writes the lights of word w set in mask at lightIndices[at ..], ascending.
void writeWord(uint w, uint mask, uint at, inout bool cut) {
    while (mask != 0u) {
        uint bit = uint(findLSB(mask));
        mask &= mask - 1u;
        lightIndices[at] = LC_INDEX(w * 32u + bit);
        ++at;
    }
    cut = cut || mask != 0u;
}

// One step of a subgroup's walk over a list's candidates (GPUs): lane i
// tests word w0 + i. The lights it keeps go, ascending, to
// lightIndices[base + n ..] when writing, else the list's first P.bins.z to
// the stash; n (the same in every lane) counts them. Returns the lane's
// mask of kept lights.
uint walkWords(ListWalk wk, uint list, uint w0, uint lane, bool writing, uint base, inout uint n, inout uint tested,
               inout bool cut) {
    uint stashSlots = P.bins.z;
    uint w = w0 + lane;
    uint m = w < wk.words ? binMask[wk.columnBase + w] & binMask[wk.rowBase + w] : 0u;
    if (wk.depthBins && w < wk.words) m &= binMask[wk.nearBase + w] & binMask[wk.farBase + w];
    uint passMask = 0u;
    tested += uint(bitCount(m));
    while (m != 0u) {
        uint bit = uint(findLSB(m));
        m &= m - 1u;
        if (lightKept(w * 32u + bit, wk.ch, wk.cellCentre, wk.cellRadius, wk.cellLog, wk.cellLog0,
                      wk.cellScale, wk.maskLo, wk.maskHi, wk.geomMask))
            passMask |= 1u << bit;
    }
    cut = cut || m != 0u;
    uint cnt = uint(bitCount(passMask));
    uint at = n + subgroupExclusiveAdd(cnt);
    if (!writing && n < stashSlots) {
        // After the scan. At most 32 iterations a word, as the write loop.
        uint stashMask = passMask;
        for (uint a = at; stashMask != 0u && a < stashSlots; ++a) {
            uint bit = uint(findLSB(stashMask));
            stashMask &= stashMask - 1u;
            stash[list * stashSlots + a] = w * 32u + bit;
        }
    }
    if (writing) writeWord(w, passMask, base + at, cut);
    n += subgroupAdd(cnt);
    return passMask;
}

// KEPT_WORDS (cull_common.glsl, 1 to 4): words per lane whose masks a
// subgroup's walk keeps in registers (the first KEPT_WORDS x LANES words: up
// to 4,096 lights with 32 lanes); the host sets as many as the bins have per
// lane. The fused pass writes such a list from them once it has its range,
// instead of walking it again where the stash cannot hold it (on the H100,
// against the build before: the Live scene, 73 entries a list, 0.030
// against 0.035 ms; P3, 256 a list, 0.173 against 0.249).

// A subgroup's walk over a list's candidates (GPUs): lane i takes words i,
// i + LANES, ... (walkWords). Returns the list's count (the same in every
// lane), the lane's kept masks of its first KEPT_WORDS words in kept; the
// lane's tests add to tested.
uint subgroupListWalk(ListWalk wk, uint list, uint lane, bool writing, uint base, out uint kept[KEPT_WORDS],
                      inout uint tested, inout bool cut) {
    uint n = 0u, w0 = 0u;
    for (uint k = 0u; k < KEPT_WORDS; ++k) kept[k] = 0u;
    for (uint i = 0u; w0 < wk.words; w0 += LANES, ++i) {
        uint mask = walkWords(wk, list, w0, lane, writing, base, n, tested, cut);
        // kept[i] by constant indices, so the masks stay in registers.
        for (uint k = 0u; k < KEPT_WORDS; ++k)
            if (k == i) kept[k] = mask;
    }
    cut = cut || w0 < wk.words;
    return n;
}

// Writes a list from the kept masks of its walk (at most KEPT_WORDS words
// per lane) at lightIndices[base ..], ascending.
void writeKept(uint kept[KEPT_WORDS], uint words, uint lane, uint base, inout bool cut) {
    uint at = base;
    for (uint i = 0u; i < KEPT_WORDS; ++i) {
        if (i * LANES >= words) break;
        uint cnt = uint(bitCount(kept[i]));
        writeWord(i * LANES + lane, kept[i], at + subgroupExclusiveAdd(cnt), cut);
        at += subgroupAdd(cnt);
    }
}

// Clustered on a CPU device (TILE_WALK slices an invocation): the lists of
// slices q * TILE_WALK .. of one tile in one walk over the tile's candidates,
// each candidate tested only against the slices its depth range reaches. An
// invocation per list cost lavapipe one SIMD pass per 8 of the tile's 32
// lists, most of them empty, and the same candidate words read by every
// list. The lists are the per-list walk's: the same chunks (same
// expressions) and the same test; a light goes into its slices' lists in
// ascending order. The slice range of a light is found from the chunks'
// own widened bounds (the chunk test's near and far planes can keep no
// slice outside it), so it is exact whatever the slicing.
// The count pass stashes a walk's entries in one pool, its lists' stash slots
// together ((endCell - firstCell) x P.bins.z from list firstList + firstCell's
// slot 0 on), each entry (slice << 24) | light in walk order, so a slice's
// entries come ascending. A walk whose entries all fit is written from there
// (the host does it when every walk fitted, without a write pass); else
// walked again. (Lights stay below 2^24: a CPU device takes at most ~258,000.)
float walkChunkLo(uint c) { return max(widenDown(sliceBoundary(P.cluster.x, P.cluster.y, c)), isOrtho() ? -3.4e38 : 0.0); }
float walkChunkHi(uint c) { return widenUp(sliceBoundary(P.cluster.x, P.cluster.y, c + 1u)); }

void clusteredTileWalk(uint id) {
    uint groups = (CELLS + TILE_WALK - 1u) / TILE_WALK;
    uint tile = id / groups, q = id % groups;
    if (tile >= P.size.z * P.size.w) return;
    uint firstCell = q * TILE_WALK, endCell = min(firstCell + TILE_WALK, CELLS);
    uint firstList = tile * P.counts.y;
    uint stashSlots = P.bins.z;
    GpuTileBounds tb = tiles[tile];
    // The invocation's slices, and those it walks.
    uint slices = ((endCell - firstCell >= 32u) ? 0xffffffffu : ((1u << (endCell - firstCell)) - 1u)) << firstCell;
    uint walk = slices;
    if ((P.counts.w & LC_FLAG_SKIP_EMPTY) != 0u) walk = tb.depthMin <= tb.depthMax ? walk & tb.cellMask : 0u;
    uint n[32]; // the counts of slices firstCell .. endCell - 1
    for (uint k = 0u; k < TILE_WALK; ++k) n[k] = 0u;
    uint poolBase = (firstList + firstCell) * stashSlots, poolSlots = (endCell - firstCell) * stashSlots;
    uint pooled = 0u; // entries the count pass met (and pooled while they fit)
    if (WRITE_PASS != LC_PASS_COUNT) {
        uint sum = 0u;
        for (uint c = firstCell; c < endCell; ++c) sum += listCount[firstList + c];
        if (WRITE_PASS == LC_PASS_WRITE_AT_RANGES) {
            // No scan before: the invocation's lists take their ranges, in
            // slice order, with one atomic add on the total (listOffset[lists]).
            uint at = sum != 0u ? atomicAdd(listOffset[P.counts.z], sum) : 0u;
            for (uint c = firstCell; c < endCell; ++c) {
                listOffset[firstList + c] = at;
                at += listCount[firstList + c];
            }
        }
        // Lists that do not fit the index array are left to the host (as the
        // per-list walk); a pool that holds the walk's entries is written out.
        uint lists = walk;
        while (lists != 0u) {
            uint c = uint(findLSB(lists));
            lists &= lists - 1u;
            uint list = firstList + c;
            if (listOffset[list] + listCount[list] > uint(lightIndices.length())) walk &= ~(1u << c);
        }
        if (sum <= poolSlots) {
            for (uint i = 0u; i < sum; ++i) {
                uint e = stash[poolBase + i], c = e >> 24u;
                if (((walk >> c) & 1u) != 0u) {
                    lightIndices[listOffset[firstList + c] + n[c - firstCell]] = LC_INDEX(e & 0xffffffu);
                    n[c - firstCell] += 1u;
                }
            }
            walk = 0u; // written (the counts checked below)
            lists = slices;
            while (lists != 0u) {
                uint c = uint(findLSB(lists));
                lists &= lists - 1u;
                uint list = firstList + c;
                if (listOffset[list] + listCount[list] <= uint(lightIndices.length()) &&
                    n[c - firstCell] != listCount[list])
                    atomicOr(status, LC_STATUS_COUNT_MISMATCH);
            }
        }
    }
    uint tested = 0u;
    bool cut = false;
    if (walk != 0u) {
        uint cLo = uint(findLSB(walk)), cHi = uint(findMSB(walk));
        float rangeLo = walkChunkLo(cLo), rangeHi = walkChunkHi(cHi);
        uint tilesX = P.size.z, words = P.bins.x;
        uint columnBase = (tile % tilesX) * words, rowBase = P.bins.y + (tile / tilesX) * words;
        bool depthBins = DEPTH_BINS != 0u;
        uint nearBase = P.bins.w + depthBinOf(rangeHi) * words;
        uint farBase = P.bins.w + (LC_DEPTH_BINS + depthBinOf(rangeLo)) * words;
        bool logSlices = SLICING == LC_SLICING_LOG && P.cluster.x > 0.0 && P.cluster.y > P.cluster.x;
        float sliceScale = logSlices ? float(CELLS) / log2(P.cluster.y / P.cluster.x)
                                     : float(CELLS) / max(P.cluster.y - P.cluster.x, 1e-30);
        uint q = 0u, quads = words / 4u;
        uvec4 quad = uvec4(0u);
        while (true) { // as the per-list walk (LANES == 1 in main)
            uint l = nextCandidate(q, quad, quads, columnBase, rowBase, depthBins, nearBase, farBase);
            if (l == NO_CANDIDATE) break;
            vec4 L = lights[l].centerRadius;
            float r = widenedRadius(L);
            float a = widenDown(-L.z - r), b = widenUp(-L.z + r);
            // The first slice whose chunk reaches a: a guess from the
            // slicing's inverse, moved down by one where the slice below
            // still reaches a, or to cLo where the guess is off by more. The
            // walk goes up from there until a chunk starts beyond b: one loop
            // of at most the walk's slices, no loop to find the range
            // (lavapipe's cap counts every loop turn: so 32 slices a walk fit
            // it at 1,024 lights).
            float ta = logSlices ? (a > P.cluster.x ? (log2(a) - log2(P.cluster.x)) * sliceScale : 0.0)
                                 : (a - P.cluster.x) * sliceScale;
            uint c0 = uint(clamp(ta, float(cLo), float(cHi)));
            if (c0 > cLo && walkChunkHi(c0 - 1u) >= a) c0 = c0 - 1u > cLo && walkChunkHi(c0 - 2u) >= a ? cLo : c0 - 1u;
            uint cand = walk & (0xffffffffu << c0);
            while (cand != 0u) {
                uint c = uint(findLSB(cand));
                cand &= cand - 1u;
                float chunkLo = walkChunkLo(c);
                if (chunkLo > b) break;
                ++tested;
                Chunk ch = makeChunk(tile, chunkLo, walkChunkHi(c));
                vec3 cellCentre = vec3(0.0);
                float cellRadius = 0.0;
                if (SPOT_TEST == LC_SPOT_CONE_SPHERE) chunkSphere(ch, cellCentre, cellRadius);
                if (lightKept(l, ch, cellCentre, cellRadius, false, 0.0, 0.0, 0.0, 0.0, 0u)) {
                    uint list = firstList + c, k = n[c - firstCell];
                    if (WRITE_PASS != LC_PASS_COUNT) lightIndices[listOffset[list] + k] = LC_INDEX(l);
                    else if (pooled < poolSlots) stash[poolBase + pooled] = (c << 24u) | l;
                    pooled += 1u;
                    n[c - firstCell] = k + 1u;
                }
            }
        }
        cut = q < quads || any(notEqual(quad, uvec4(0u))); // a loop ended by the driver's cap, not by the candidates
    }
    if (cut) atomicOr(status, LC_STATUS_LOOP_LIMIT);
    if (WRITE_PASS == LC_PASS_COUNT) {
        for (uint c = firstCell; c < endCell; ++c) listCount[firstList + c] = n[c - firstCell];
        countTests(id, tested);
    } else {
        uint lists = walk;
        while (lists != 0u) {
            uint c = uint(findLSB(lists));
            lists &= lists - 1u;
            if (n[c - firstCell] != listCount[firstList + c]) atomicOr(status, LC_STATUS_COUNT_MISMATCH);
        }
    }
}

void main() {
    loadParams();
    uint id = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_WorkGroupSize.x +
              gl_LocalInvocationIndex;
    uint lightCount = P.counts.x;
    if (ALGORITHM == LC_ALG_ALL) {
        if (WRITE_PASS == LC_PASS_COUNT) {
            if (id == 0u) listCount[0] = lightCount;
        } else if (id < lightCount && id < uint(lightIndices.length())) {
            lightIndices[id] = LC_INDEX(id);
        }
        return;
    }
    if (TILE_WALK != 0u) {
        clusteredTileWalk(id);
        return;
    }
    uint stashSlots = P.bins.z;
    uint list = id, lane = 0u;
    if (LANES != 1u) {
        if (gl_SubgroupSize != LANES) atomicOr(status, LC_STATUS_SPLIT_WORKGROUP);
        list = (gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x) * gl_NumSubgroups + gl_SubgroupID;
        lane = gl_SubgroupInvocationID;
    }
    // Uniform per list (so per subgroup): the early exits keep subgroups whole.
    if (list >= P.counts.z) return;
    if (WRITE_PASS == LC_PASS_WRITE) {
        uint count = listCount[list];
        // The index array may be smaller than the lists (a first submission
        // sized from the previous cull): then the host writes them again.
        if (listOffset[list] + count > uint(lightIndices.length())) return;
        if (count <= stashSlots) { // the count pass stashed the whole list
            copyStashed(list, listOffset[list], count, lane, LANES);
            return;
        }
    }

    uint tile = list / P.counts.y, sub = list % P.counts.y;
    // The list's depth range [zlo, zhi] (view depth) and which lights it takes.
    GpuTileBounds tb = tiles[tile];
    // A tile without geometry gets no lights, except for the two volumes that
    // do not come from the depth buffer (as the CPU reference): naive, and
    // clustered without skip-empty.
    // zbin's tile masks are naive's test (the lights arrive depth-sorted,
    // so a list holds sorted positions; zbin.comp bins them in depth).
    bool screenSpace = ALGORITHM == LC_ALG_NAIVE || ALGORITHM == LC_ALG_ZBIN;
    bool depthDriven = !screenSpace &&
                       !(ALGORITHM == LC_ALG_CLUSTERED && (P.counts.w & LC_FLAG_SKIP_EMPTY) == 0u);
    bool listLive = !depthDriven || tb.depthMin <= tb.depthMax;
    uint geomMask = 0u;
    float maskLo = 0.0, maskHi = 0.0; // 2.5d: the cells' range, the tile's own bounds
    float zlo = tb.depthMin, zhi = tb.depthMax;
    if (screenSpace) {
        zlo = P.lens.z;
        zhi = P.lens.w;
    } else if (ALGORITHM == LC_ALG_HALFZ) {
        if (sub == 0u) zhi = tb.split; else zlo = tb.split;
    } else if (ALGORITHM == LC_ALG_25D) {
        geomMask = tb.cellMask;
        maskLo = tb.depthMin;
        maskHi = tb.depthMax;
    } else if (ALGORITHM == LC_ALG_CLUSTERED) {
        if ((P.counts.w & LC_FLAG_SKIP_EMPTY) != 0u) listLive = listLive && ((tb.cellMask >> sub) & 1u) != 0u;
        zlo = sliceBoundary(P.cluster.x, P.cluster.y, sub);
        zhi = sliceBoundary(P.cluster.x, P.cluster.y, sub + 1u);
    }
    uint n = 0u, tested = 0u, base = 0u;
    if (listLive) {
        float chunkLo = max(widenDown(zlo), isOrtho() ? -3.4e38 : 0.0), chunkHi = widenUp(zhi);
        Chunk ch = makeChunk(tile, chunkLo, chunkHi);
        // Spot cone refinements (spot_tests.glsl), as the CPU reference runs
        // them after the (tight) sphere test. The chunk's bounding sphere once
        // per list: centroid of the corners, farthest corner, widened.
        vec3 cellCentre = vec3(0.0);
        float cellRadius = 0.0;
        if (SPOT_TEST == LC_SPOT_CONE_SPHERE) {
            chunkSphere(ch, cellCentre, cellRadius);
        }
        // 2.5d: the cell of view depth d is (log2(d) - cellLog0) * cellScale
        // (log slicing; sliceOf's log(d / lo) / log(hi / lo) x CELLS with the
        // per-list terms taken out of the light loop; the rounding of the two
        // logs, ~1e-6 in log2 units, is far inside the light's 2e-5 relative
        // widening, as for tile_bounds' 2e-5 allowance), else sliceOf's own.
        // With CELL_LOG (ranges start beyond 0) always the log form, so that
        // lavapipe does not run sliceOf's beside it: a tile of one depth
        // takes scale 0, cell 0, as sliceOf.
        bool cellLog = SLICING == LC_SLICING_LOG && (CELL_LOG != 0u || (maskLo > 0.0 && maskHi > maskLo));
        float cellLog0 = cellLog ? log2(maskLo) : 0.0;
        float cellScale = cellLog && maskLo > 0.0 && maskHi > maskLo ? float(CELLS) / log2(maskHi / maskLo) : 0.0;
        if (WRITE_PASS == LC_PASS_WRITE) base = listOffset[list];
        uint tilesX = P.size.z, words = P.bins.x;
        uint tx = tile % tilesX, ty = tile / tilesX;
        uint columnBase = tx * words, rowBase = P.bins.y + ty * words;
        // The depth bins (light_bins.comp): lights that reach no deeper than
        // the chunk's far end and no nearer than its near end. naive's chunk
        // spans every light's depth.
        bool depthBins = DEPTH_BINS != 0u && !screenSpace;
        uint nearBase = P.bins.w + depthBinOf(chunkHi) * words;
        uint farBase = P.bins.w + (LC_DEPTH_BINS + depthBinOf(chunkLo)) * words;
        bool cut = false;
        if (LANES == 1u) {
            // An invocation per list (CPU devices): one loop over the list's
            // candidates, each turn fetching words until one has a candidate
            // left. (gallivm runs a loop's body at least once per entry, with
            // no lane active if need be, so a bit loop nested in a word loop
            // would run the whole test once per word even where no list of
            // the SIMD group has a candidate: measured, the empty entries cost
            // more than the tests.) lavapipe loads a storage buffer lane by
            // lane in a loop, one pass of it per load whatever its width, so
            // the words come four at a time.
            uint q = 0u, quads = words / 4u;
            uvec4 quad = uvec4(0u);
            while (true) {
                uint l = nextCandidate(q, quad, quads, columnBase, rowBase, depthBins, nearBase, farBase);
                if (l == NO_CANDIDATE) break;
                ++tested;
                if (lightKept(l, ch, cellCentre, cellRadius, cellLog, cellLog0, cellScale, maskLo, maskHi,
                              geomMask)) {
                    if (WRITE_PASS != LC_PASS_COUNT) lightIndices[base + n] = LC_INDEX(l);
                    else if (n < stashSlots) stash[list * stashSlots + n] = l;
                    ++n;
                }
            }
            cut = q < quads || any(notEqual(quad, uvec4(0u))); // a loop ended by the driver's cap, not by the list
        } else {
            // A subgroup per list (GPUs).
            ListWalk wk = ListWalk(ch, cellCentre, cellRadius, cellLog, cellLog0, cellScale, maskLo, maskHi,
                                   geomMask, words, columnBase, rowBase, depthBins, nearBase, farBase);
            uint kept[KEPT_WORDS];
            n = subgroupListWalk(wk, list, lane, WRITE_PASS == LC_PASS_WRITE, base, kept, tested, cut);
            if (WRITE_PASS == LC_PASS_FUSED && n != 0u) {
                // The list's range: one atomic add on the total, by one lane.
                uint at = lane == 0u ? atomicAdd(listOffset[P.counts.z], n) : 0u;
                base = subgroupMax(at);
                // Ranges beyond the index array are left out, as in the write
                // pass (the host reruns into one sized exactly; the stash is
                // written for it whatever the path here).
                if (base + n <= uint(lightIndices.length())) {
                    if (words <= KEPT_WORDS * LANES) {
                        writeKept(kept, words, lane, base, cut);
                    } else if (n <= stashSlots) {
                        // The lanes read what other lanes stashed.
                        subgroupBarrier();
                        copyStashed(list, base, n, lane, LANES);
                    } else {
                        uint testedAgain = 0u;
                        if (subgroupListWalk(wk, list, lane, true, base, kept, testedAgain, cut) != n)
                            atomicOr(status, LC_STATUS_COUNT_MISMATCH);
                    }
                }
            }
        }
        if (cut) atomicOr(status, LC_STATUS_LOOP_LIMIT);
    }
    if (WRITE_PASS == LC_PASS_COUNT || WRITE_PASS == LC_PASS_FUSED) {
        if (LANES != 1u) tested = subgroupAdd(tested);
        if (lane == 0u) {
            listCount[list] = n;
            if (WRITE_PASS == LC_PASS_FUSED) listOffset[list] = base;
            countTests(list, tested);
        }
    } else if (n != listCount[list]) {
        atomicOr(status, LC_STATUS_COUNT_MISMATCH);
    }
}
