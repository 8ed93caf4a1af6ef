// Declarations shared, as text, by C++ and GLSL 450.
//
// GLSL includes this file through glslang's #include (GL_GOOGLE_include_directive);
// C++ includes it through projection.hpp. Keep to the common subset of both
// languages: plain structs of scalars and vec4/uvec4, and functions over them.
// Every struct the GPU reads is declared here once, and C++ checks its size and
// offsets with static_assert (std140/std430 rules: vec4-aligned members).
#ifndef LC_GPU_SHARED_H
#define LC_GPU_SHARED_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstdint>
#include <cstddef>
namespace lc {
using vec4 = glm::vec4;
using uvec4 = glm::uvec4;
using uint = std::uint32_t;
#define LC_INLINE inline
#else
#define LC_INLINE
#endif

// Linearisation of window depth for every projection kind.
//   perspective kinds: d = A + B / viewDepth   =>  viewDepth = B / (d - A)
//   orthographic kinds: d = A + B * viewDepth  =>  viewDepth = (d - A) / B
// (x, y) = (A, B); z = 1 for orthographic, 0 for perspective; w = clear depth.
struct DepthParams {
    vec4 ab_ortho_clear;
};

// The one depth-linearising formula, written once for both languages. C++
// evaluates it in double through projection.cpp's double overload below.
LC_INLINE float lcViewDepthFromWindowDepth(float d, vec4 p) {
    return (p.z > 0.5f) ? (d - p.x) / p.y : p.y / (d - p.x);
}

// ---------------------------------------------------------------------------
// Vulkan culling passes (shaders/*.comp, culling/src/vk/). The enumerations
// follow the C++ enums' order (Algorithm, SphereTest, Slicing).
const uint LC_ALG_ALL = 0u;
const uint LC_ALG_NAIVE = 1u;
const uint LC_ALG_MINMAX = 2u;
const uint LC_ALG_HALFZ = 3u;
const uint LC_ALG_25D = 4u;
const uint LC_ALG_CLUSTERED = 5u;
const uint LC_ALG_FPTL = 6u;
const uint LC_ALG_ZBIN = 7u;
const uint LC_ALG_RASTER = 8u;
const uint LC_TEST_PLANES = 0u;
const uint LC_TEST_PLANES_AABB = 1u;
const uint LC_TEST_EXACT = 2u;
const uint LC_SLICING_LOG = 0u;
const uint LC_SLICING_LINEAR = 1u;
// Depth bins (light_bins.comp, cull_lists.comp): slices of the lights' depth
// range, and two bin families of one bit per light each.
const uint LC_DEPTH_BINS = 32u;
// The count pass's test counters (status buffer, after the status word):
// list i adds its tests to counter i % LC_TEST_COUNTERS, the counters
// LC_TEST_COUNTER_STRIDE words (128 bytes) apart; the host adds them up.
const uint LC_TEST_COUNTERS = 32u;
const uint LC_TEST_COUNTER_STRIDE = 32u;
// GpuCullParams.flags bits.
const uint LC_FLAG_ORTHO = 1u;         // orthographic projection
const uint LC_FLAG_REVERSED = 2u;      // reversed-Z (nearer = larger window depth)
const uint LC_FLAG_FAR_INFINITE = 4u;  // camera far plane at +infinity: no far plane
const uint LC_FLAG_SKIP_EMPTY = 8u;    // clustered: clusters without geometry get no lights
// The spot cone refinement cull_lists runs (specialisation constant
// SPOT_TEST): none, or after the sphere test the cone against the chunk's
// bounding sphere or against each of its planes.
const uint LC_SPOT_NONE = 0u;
const uint LC_SPOT_CONE_SPHERE = 1u;
const uint LC_SPOT_CONE_PLANES = 2u;

// The stages one shader runs as (specialisation constant WRITE_PASS).
// cull_lists: count (and stash), write, both in one dispatch at ranges taken
// by atomic adds (GPUs), write at such ranges (clustered's tile walk).
const uint LC_PASS_COUNT = 0u;
const uint LC_PASS_WRITE = 1u;
const uint LC_PASS_FUSED = 2u;
const uint LC_PASS_WRITE_AT_RANGES = 3u;
// fine_prune: mark the pruned entries, then pack each list's kept ones.
const uint LC_PRUNE_MARK = 0u;
const uint LC_PRUNE_PACK = 1u;
// zbin: empty every bin, then bin the lights.
const uint LC_ZBIN_INIT = 0u;
const uint LC_ZBIN_BIN = 1u;
// Bits of the status word (binding 7) the passes OR in; the host turns each
// into an error (or, for the counters, into "not counted").
const uint LC_STATUS_SPLIT_WORKGROUP = 1u; // a device split a one-subgroup workgroup
const uint LC_STATUS_COUNT_MISMATCH = 2u;  // the write pass found a different count
const uint LC_STATUS_TESTS_OVERFLOW = 4u;  // a test counter wrapped around 2^32
// A loop ended before its condition did: lavapipe (gallivm) stops every loop
// of a shader invocation after 65,535 iterations in all, silently. The host
// sizes the work per invocation below that and turns this bit into an error.
const uint LC_STATUS_LOOP_LIMIT = 8u;

// Per-dispatch parameters of the culling passes (one read-only storage buffer,
// std430). Sizes and modes that shape the code (tile size, cells, slicing,
// sphere test, algorithm) are specialisation constants instead.
struct GpuCullParams {
    uvec4 size;       // width, height, tilesX, tilesY (pixels, tiles)
    uvec4 counts;     // lightCount, listsPerTile, listCount, flags (LC_FLAG_*)
    // Window depth -> view depth, split for precision: A = aHi + aLo exactly
    // enough that (d - aHi) - aLo keeps float precision near the far plane,
    // where d - A cancels. x = aHi, y = B, z = aLo, w = clear depth.
    vec4 depth;
    // Perspective: x = tan(fovX/2), y = tan(fovY/2) (view position at depth z
    // of NDC (u,v): (u*x*z, -v*y*z, -z)). Orthographic: half width/height.
    // z = camera near, w = the far depth of `naive`: the camera's far plane,
    // or with an infinite far plane the farthest depth any light reaches (as
    // the CPU reference does; LC_FLAG_FAR_INFINITE then records the fact).
    vec4 lens;
    // x = clusterNear, y = clusterFar (clustered slicing range, view depth),
    // z = relative epsilon, w = absolute epsilon (view units) by which depth
    // bounds and radii are widened so the GPU lists are a superset of the
    // double-precision reference's.
    vec4 cluster;
    // Light binning (light_bins.comp): x = mask words per bin (one bit per
    // light, padded to a multiple of 4: ceil(lightCount / 128) x 4), y = index
    // of the first row mask in the bin buffer (= x * tilesX); z = stash slots
    // per list (the count pass keeps
    // each list's first z entries; 0: no stash); w = index of the first depth
    // bin word (after the row masks).
    uvec4 bins;
    // Depth bins: the bin coordinate of view depth d is (log2(d) - x) * y for
    // log slices (z = 1), (d - x) * y for linear ones (z = 0); bin s takes
    // coordinates [s, s + 1), the first and the last bin reach to infinity.
    // w unused.
    vec4 depthBins;
};

// One light as the culling passes read it (std430, 16 bytes per light; binding
// 3). View-space centre and bounding radius. Extend by appending members (and
// updating the static_asserts below); the passes read lights by index only.
struct GpuLight {
    vec4 centerRadius; // xyz: view-space centre, w: bounding-sphere radius
};

// A spot light's cone for the cone refinements (binding 9, one per light, read
// only under LC_SPOT_CONE_*; docs/SPOT_LIGHTS.md). A separate buffer so
// that GpuLight, which every pass streams, stays 16 bytes.
struct GpuSpotCone {
    vec4 apexRange; // xyz: view-space apex, w: range; w = 0 marks a point light (no cone)
    vec4 axisCos;   // xyz: unit axis (view space), w: cos(outer angle)
    vec4 sinAngle;  // x: sin(outer angle), yzw unused
};

// Per-tile output of the bounds pass (std430, 16 bytes). View depths of the
// tile's geometry pixels (float): depthMin > depthMax marks an empty tile.
struct GpuTileBounds {
    float depthMin;
    float depthMax;
    float split;      // halfz: (depthMin + depthMax) / 2, computed in float
    uint cellMask;    // 2.5d: occupied cells; clustered: occupied slices
};

// The raster pass (shaders/proxy_setup.comp, proxy_raster.vert/.frag, vk/raster_pass.cpp):
// each light's proxy mesh drawn at one pixel per tile.
struct GpuRasterParams {
    // View -> clip, then scaled so that the viewport of tilesX x tilesY
    // pixels covers the grid one pixel per tile, z = w / 2 (no depth clip).
    vec4 clip[4];          // columns
    uvec4 grid;            // x: tilesX, y: tilesY, z: mask words per tile, w: LC_RASTER_* flags
    // (LC_RASTER_SLICES: ranges[2 (tile x 32 grid.z + light)] holds the float
    // bits of the least depth the light's fragments span there, and + 1 the
    // inverted bits of the greatest; both by atomicMin from all ones.)
    vec4 cover;            // x: tilesX' (width / tile), y: tilesY', z: w below which a triangle covers the screen, w: push
    // The triangles (proxy_setup.comp): x of a sphere proxy, y of a cone
    // proxy; z spheres, w cones (the proxies, in that order, then boxes).
    uvec4 setup;
};
const uint LC_RASTER_PUSH_EDGES = 1u; // conservative by pushing the edges out in the vertex shader
const uint LC_RASTER_ORTHO = 2u;      // orthographic: the eye direction is +z
const uint LC_RASTER_TRIM = 4u;       // conservative: the fragment shader keeps a tile by the exact overlap test
const uint LC_RASTER_SLICES = 8u;     // proxy-depth slices: each fragment's depth range into the tile's ranges

// One proxy, an instance: its unit mesh placed by origin + basis * v, the
// light it stands for and the view-depth range the tile test uses.
struct GpuProxy {
    vec4 origin;           // xyz: origin (view space)
    vec4 basisXDepthMin;   // xyz: basis column x, w: depth range low
    vec4 basisYDepthMax;   // xyz: basis column y, w: depth range high
    vec4 basisZ;           // xyz: basis column z
    uvec4 light;           // x: the light's index, y: 1 = a box (origin: tile centres), z: 1 = front faces only
};

// One proxy triangle as proxy_setup.comp works it out for the draw: its
// corners (clip space) and the fragment shader's trim.
struct GpuProxyTriangle {
    vec4 corner[3];        // clip space (w = 0: dropped)
    vec4 box;              // the tile centres allowed, tile units
    vec4 edge[4];          // xyz: the pushed edges, n.centre + d >= 0 inside; w of 0..2: the depth plane (slices)
    vec4 range;            // slices: x, y the corners' view depths, z how the plane is given (0 none, 1 1/depth, 2 depth)
    float depthMin;        // the proxy's view-depth range (the tile test)
    float depthMax;
    uint light;            // the light's index
    uint pad;
};

#ifdef __cplusplus
static_assert(sizeof(GpuCullParams) == 112, "GpuCullParams must match std430");
static_assert(sizeof(GpuRasterParams) == 112, "GpuRasterParams must match std430");
static_assert(sizeof(GpuProxyTriangle) == 160, "GpuProxyTriangle must match std430");
static_assert(sizeof(GpuProxy) == 80, "GpuProxy must match std430");
static_assert(offsetof(GpuCullParams, counts) == 16, "GpuCullParams.counts offset");
static_assert(offsetof(GpuCullParams, depth) == 32, "GpuCullParams.depth offset");
static_assert(offsetof(GpuCullParams, lens) == 48, "GpuCullParams.lens offset");
static_assert(offsetof(GpuCullParams, cluster) == 64, "GpuCullParams.cluster offset");
static_assert(offsetof(GpuCullParams, bins) == 80, "GpuCullParams.bins offset");
static_assert(offsetof(GpuCullParams, depthBins) == 96, "GpuCullParams.depthBins offset");
static_assert(sizeof(GpuLight) == 16, "GpuLight must match std430");
static_assert(sizeof(GpuSpotCone) == 48, "GpuSpotCone must match std430");
static_assert(offsetof(GpuSpotCone, axisCos) == 16, "GpuSpotCone.axisCos offset");
static_assert(offsetof(GpuSpotCone, sinAngle) == 32, "GpuSpotCone.sinAngle offset");
static_assert(sizeof(GpuTileBounds) == 16, "GpuTileBounds must match std430");
static_assert(offsetof(GpuTileBounds, cellMask) == 12, "GpuTileBounds.cellMask offset");
#endif

#ifdef __cplusplus
inline double lcViewDepthFromWindowDepthD(double d, double a, double b, bool ortho) {
    return ortho ? (d - a) / b : b / (d - a);
}
static_assert(sizeof(DepthParams) == 16, "DepthParams must match std140/std430 layout");
} // namespace lc
#endif

#endif
