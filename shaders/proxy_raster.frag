#version 450
// The raster algorithm's fragment shader: a fragment is a tile the proxy
// triangle (proxy_setup.comp's record) covers. The light is listed there (its bit ORed into the tile's mask) when
// the tile holds geometry and the proxy's view-depth range reaches the
// tile's min/max (the bounds pass's, float; the range comes widened from
// the host).
#extension GL_GOOGLE_include_directive : require
#include "culling/vk/gpu_shared.h"

layout(std430, set = 0, binding = 0) readonly buffer Params { GpuRasterParams params; };
layout(std430, set = 0, binding = 1) readonly buffer Tiles { GpuTileBounds tiles[]; };
layout(std430, set = 0, binding = 4) buffer Masks { uint masks[]; };
layout(std430, set = 0, binding = 5) buffer Ranges { uint ranges[]; };
layout(std430, set = 0, binding = 6) readonly buffer Triangles { GpuProxyTriangle triangles[]; };

layout(location = 0) flat in uint inTriangle; // proxy_setup.comp's record

// LC_RASTER_SLICES: the view depths this fragment's triangle spans over its
// tile (conservative coverage: the plane at the tile's corners; centre
// sampling: at its centre), within its corners' range, widened for float;
// light_proxy.hpp's proxyTriangleTileDepth in double.
vec2 tileDepthRange(const GpuProxyTriangle tri) {
    vec2 r = tri.range.xy;
    if (tri.range.z != 0.0) {
        const vec3 plane = vec3(tri.edge[0].w, tri.edge[1].w, tri.edge[2].w);
        float gmin, gmax;
        if ((params.grid.w & (LC_RASTER_PUSH_EDGES | LC_RASTER_TRIM)) != 0u) {
            const vec2 c = floor(gl_FragCoord.xy);
            const vec4 g = vec4(dot(plane, vec3(c, 1.0)), dot(plane, vec3(c.x + 1.0, c.y, 1.0)),
                                dot(plane, vec3(c.x, c.y + 1.0, 1.0)), dot(plane, vec3(c + 1.0, 1.0)));
            gmin = min(min(g.x, g.y), min(g.z, g.w));
            gmax = max(max(g.x, g.y), max(g.z, g.w));
        } else {
            gmin = gmax = dot(plane, vec3(gl_FragCoord.xy, 1.0));
        }
        vec2 q = r;
        if (tri.range.z == 2.0) {
            q = vec2(max(r.x, gmin), min(r.y, gmax));
        } else if (gmax > 0.0) {
            q.x = max(r.x, 1.0 / gmax);
            if (gmin > 0.0) q.y = min(r.y, 1.0 / gmin);
        }
        // The plane comes from float corners: a thousandth to spare.
        if (q.x <= q.y) r = vec2(max(r.x, q.x - 1e-3 * abs(q.x)), min(r.y, q.y + 1e-3 * abs(q.y)));
    }
    return vec2(r.x - (1e-5 * abs(r.x) + 1e-6), r.y + (1e-5 * abs(r.y) + 1e-6));
}

// Edge (n, d) pushed by half a tile: the rectangle's corner farthest along
// n passes n.p + d - (|nx| + |ny|) / 2 >= 0 (a whole tile: its centre, n.c + d >= 0).
bool keeps(vec3 e, vec2 lo, vec2 hi) {
    const vec2 far = vec2(e.x >= 0.0 ? hi.x : lo.x, e.y >= 0.0 ? hi.y : lo.y);
    return dot(e.xy, far) + e.z - 0.5 * (abs(e.x) + abs(e.y)) >= 0.0;
}

void main() {
    // The tile as far as the screen reaches (a partial edge tile is
    // narrower: params.cover.xy is the screen in tile units), against the
    // box and the edges, each pushed out by half a tile and the slack
    // (params.cover.w): the CPU reference's separating-axis test on the
    // tile's own rectangle.
    const GpuProxyTriangle tri = triangles[inTriangle];
    const vec2 lo = floor(gl_FragCoord.xy), hi = min(lo + 1.0, params.cover.xy);
    if (any(lessThan(hi, tri.box.xy + 0.5)) || any(greaterThan(lo, tri.box.zw - 0.5))) return;
    if (!keeps(tri.edge[0].xyz, lo, hi) || !keeps(tri.edge[1].xyz, lo, hi) || !keeps(tri.edge[2].xyz, lo, hi) ||
        !keeps(tri.edge[3].xyz, lo, hi))
        return;
    const uint light = tri.light;
    const uvec2 t = uvec2(gl_FragCoord.xy);
    if (t.x >= params.grid.x || t.y >= params.grid.y) return;
    const uint tile = t.y * params.grid.x + t.x;
    if ((params.grid.w & LC_RASTER_SLICES) != 0u) {
        // Clusters: no tile test here (the host applies the slices, the
        // near and far rule and skip-empty); every covered tile keeps the
        // depths the light's fragments span there.
        const vec2 r = max(tileDepthRange(tri), vec2(0.0));
        const uint at = 2u * (tile * params.grid.z * 32u + light);
        atomicMin(ranges[at], floatBitsToUint(r.x));
        atomicMin(ranges[at + 1u], ~floatBitsToUint(r.y));
        atomicOr(masks[tile * params.grid.z + (light >> 5u)], 1u << (light & 31u));
        return;
    }
    const GpuTileBounds b = tiles[tile];
    if (!(b.depthMin <= b.depthMax) || tri.depthMin > b.depthMax || tri.depthMax < b.depthMin) return;
    atomicOr(masks[tile * params.grid.z + (light >> 5u)], 1u << (light & 31u));
}
