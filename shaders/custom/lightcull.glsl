// lightcull.glsl: the contract between LightCull Studio and a custom culling
// compute shader (docs/CUSTOM_CULLING.md). `#include "lightcull.glsl"` from a
// GLSL shader; the tool serves this file to the compiler, and the defines
// below come from the command line (--layout, --lists) before it.
//
// Defines the tool sets (every shader sees them, GLSL and HLSL):
//   TILE_SIZE             tile edge in pixels
//   MAX_LIGHTS_PER_TILE   fixed:N -> N (0 for the other layouts)
//   LC_LAYOUT             LC_LAYOUT_FIXED (0), LC_LAYOUT_COMPACT (1), LC_LAYOUT_BITMASK (2)
//   LC_LISTS              LC_LISTS_TILE (0), LC_LISTS_HALFZ (1), LC_LISTS_FROXEL (2), LC_LISTS_CELLS (3)
//   LC_LISTS_PER_TILE     1 (tile), 2 (halfz), N (froxel:N, cells:N)
//   LC_MASK_WORDS         bitmask: 32-bit words per list
//   LC_COMPACT_ENTRIES    compact: capacity of the index array
// Dispatch: one workgroup per tile, (tilesX, tilesY, 1); the local size is
// the shader's own (TILE_SIZE x TILE_SIZE is usual).
#ifndef LIGHTCULL_GLSL
#define LIGHTCULL_GLSL

#define LC_LAYOUT_FIXED 0
#define LC_LAYOUT_COMPACT 1
#define LC_LAYOUT_BITMASK 2
#define LC_LISTS_TILE 0
#define LC_LISTS_HALFZ 1
#define LC_LISTS_FROXEL 2
#define LC_LISTS_CELLS 3
#define LC_PROJ_PERSPECTIVE 0     // [0,1] depth, near -> 0
#define LC_PROJ_PERSPECTIVE_GL 1  // [-1,1] NDC depth stored as (ndc + 1) / 2
#define LC_PROJ_REVERSED_Z 2      // near -> 1, far -> 0 (far may be infinite)
#define LC_PROJ_ORTHOGRAPHIC 3
#define LC_PROJ_ORTHOGRAPHIC_GL 4
#define LC_SLICING_LOG 0
#define LC_SLICING_LINEAR 1

// binding 0: the frame's parameters (std140).
layout(set = 0, binding = 0, std140) uniform LcParamsBlock {
    uvec4 size;        // width, height, tilesX, tilesY
    uvec4 counts;      // lightCount, listsPerTile, listCount, capacity (fixed: N; compact: entries; bitmask: words per list)
    uvec4 mode;        // x: LC_PROJ_*, y: LC_LAYOUT_*, z: LC_LISTS_*, w: froxel / cells LC_SLICING_*
    vec4 depthParams;  // x: A, y: B, z: 1 orthographic / 0 perspective, w: clear depth (no geometry)
    vec4 planes;       // x: camera near, y: camera far (0: infinite), z: froxel near, w: froxel far (view depth)
    // The view-space point of NDC (u, v) (v down, [-1, 1]) at view depth z:
    // perspective (u * lens.x * z, -v * lens.y * z, -z), lens.xy = tan(fov/2)
    // in x and y; orthographic (u * lens.x, -v * lens.y, -z), lens.xy = half
    // the view's width and height. lens.z = 1 orthographic, 0 perspective.
    vec4 lens;
    mat4 proj;         // view -> Vulkan clip space: y down, depth as mode.x says
    mat4 invProj;      // clip -> view
} lc;

// binding 1: the depth buffer as engines read it: window depth, R32F,
// texelFetch(lcDepthTexture, ivec2(x, y), 0) with y = 0 the top row.
layout(set = 0, binding = 1) uniform sampler2D lcDepthTexture;

// binding 2: the same depth as a storage buffer, row-major, y = 0 the top row.
layout(set = 0, binding = 2, std430) readonly buffer LcDepthBuffer { float lcDepth[]; };

// binding 3: the lights in view space (right-handed, the camera looks down
// -Z, so a light in front has positionRadius.z < 0). w: bounding radius.
// spotAxisAngle: unit cone axis and outer half-angle in radians; angle 0 for
// point lights.
struct LcLight {
    vec4 positionRadius;
    vec4 spotAxisAngle;
};
layout(set = 0, binding = 3, std430) readonly buffer LcLights { LcLight lcLights[]; };

// binding 4: the lists, laid out as LC_LAYOUT says (zeroed before dispatch):
//   fixed:N   list l at word l * (N + 1): count, then N indices
//   compact   word 0: entries allocated; list l: offset at 1 + 2l, count at
//             2 + 2l; indices from word 1 + 2 * listCount (offsets count from there)
//   bitmask   list l at word l * LC_MASK_WORDS, bit i of the list = light i
layout(set = 0, binding = 4, std430) buffer LcOutput { uint lcOut[]; };

// View depth (positive in front) of window depth d.
float lcViewDepth(float d) {
    return lc.depthParams.z > 0.5 ? (d - lc.depthParams.x) / lc.depthParams.y : lc.depthParams.y / (d - lc.depthParams.x);
}
bool lcHasGeometry(float d) { return d != lc.depthParams.w; }
// The list of tile `tile`, sub-list `sub` (halfz: 0 near, 1 far; froxel:
// slice; cells: cell of the tile's min/max view depth).
uint lcListIndex(uint tile, uint sub) { return tile * LC_LISTS_PER_TILE + sub; }

// Appends `light` to list `list` in the fixed or bitmask layout (atomic; any
// order: the tool sorts). Fixed lists past N count the overflow and drop it.
void lcAppend(uint list, uint light) {
#if LC_LAYOUT == LC_LAYOUT_FIXED
    uint base = list * (uint(MAX_LIGHTS_PER_TILE) + 1u);
    uint slot = atomicAdd(lcOut[base], 1u);
    if (slot < uint(MAX_LIGHTS_PER_TILE)) lcOut[base + 1u + slot] = light;
#elif LC_LAYOUT == LC_LAYOUT_BITMASK
    atomicOr(lcOut[list * uint(LC_MASK_WORDS) + light / 32u], 1u << (light % 32u));
#endif
}
// Compact layout: reserves `count` entries for list `list` and records its
// offset and count; returns the word index of its first entry, or ~0u when
// the index array is full (the tool reports the overflow).
uint lcCompactReserve(uint list, uint count) {
    uint offset = atomicAdd(lcOut[0], count);
    lcOut[1u + 2u * list] = offset;
    lcOut[2u + 2u * list] = count;
    if (offset + count > uint(LC_COMPACT_ENTRIES)) return ~0u;
    return 1u + 2u * lc.counts.z + offset;
}

#endif
