#version 450
// The raster algorithm's triangle setup (vk/raster_pass.cpp): one invocation
// per proxy triangle works out, once, what the vertex and fragment shaders
// of proxy_raster.vert/.frag need of it, into a GpuProxyTriangle record: its
// three corners on the grid (clip space) and the fragment shader's trim. The
// draw then passes one flat index from vertex to fragment: on lavapipe the
// vertex shader runs on one thread and each flat output costs every vertex,
// so the old per-corner setup with nine outputs (each corner working out its
// whole triangle) was most of the pass (docs/PERFORMANCE.md).
//
// Triangle r of the pass: proxies are spheres, then cones, then boxes
// (params.setup), a sphere or cone listing its mesh's triangles in order, a
// box one triangle. The records of a batch (push constants: its first
// triangle and how many) start at record 0.
//
// With VK_EXT_conservative_rasterization (LC_RASTER_TRIM alone) the corners
// stay where they are and only the fragment shader's trim below applies: the
// extension lets a device overestimate more than it must, and an H200 did
// (65% more tiles than the exact overlap on the hard cases).
//
// Conservative coverage without VK_EXT_conservative_rasterization
// (LC_RASTER_PUSH_EDGES): every corner moves to where the triangle's edges,
// each pushed out by half a tile's diagonal measured along its normal (0.5
// (|nx| + |ny|) tiles, plus 1/256 for float rounding), meet. A tile the
// triangle overlaps then has its centre inside the pushed triangle, so the
// ordinary rasteriser covers it. A triangle of less than 1/64 tile of area (a
// sliver, or far away), or one the near plane cuts (w below params.cover.z;
// its part in front is up to four corners), is drawn as a triangle around the
// bounding box of what is in front, grown by the same amount: a superset of
// what it overlaps. A proxy too large for float near the camera comes as a
// box of tiles the host worked out in double (GpuProxy.light.y = 1): one
// triangle around it. The fragment shader then keeps a tile only when its
// centre lies in the bounding box grown by the push and passes the pushed
// edges: the separating-axis test of the tile's square against the triangle,
// as the CPU reference makes it (what the pushed corners of a sharp
// triangle, or a box's triangle, reach beyond is dropped).
#extension GL_GOOGLE_include_directive : require
#include "culling/vk/gpu_shared.h"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Params { GpuRasterParams params; };
layout(std430, set = 0, binding = 2) readonly buffer Proxies { GpuProxy proxies[]; };
layout(std430, set = 0, binding = 3) readonly buffer Mesh { vec4 corners[]; };
layout(std430, set = 0, binding = 6) writeonly buffer Triangles { GpuProxyTriangle triangles[]; };
layout(push_constant) uniform Batch { uvec2 batch; }; // x: the batch's first triangle, y: its triangles

const vec4 kDropped = vec4(0.0, 0.0, 0.5, 0.0); // w = 0: clipped away

vec4 clipOf(vec3 v) {
    return mat4(params.clip[0], params.clip[1], params.clip[2], params.clip[3]) * vec4(v, 1.0);
}

void main() {
    if (gl_GlobalInvocationID.x >= batch.y) return;
    const uint r = batch.x + gl_GlobalInvocationID.x;
    // Which proxy, and its triangle's first corner in the mesh.
    const uint sphereTris = params.setup.x, coneTris = params.setup.y;
    const uint sphereEnd = params.setup.z * sphereTris, coneEnd = sphereEnd + params.setup.w * coneTris;
    uint proxy, first;
    if (r < sphereEnd) {
        proxy = r / sphereTris;
        first = 3u * (r - proxy * sphereTris);
    } else if (r < coneEnd) {
        const uint k = (r - sphereEnd) / coneTris;
        first = 3u * (sphereTris + (r - sphereEnd - k * coneTris));
        proxy = params.setup.z + k;
    } else {
        proxy = params.setup.z + params.setup.w + (r - coneEnd);
        first = 0u;
    }
    const GpuProxy p = proxies[proxy];
    GpuProxyTriangle t;
    t.depthMin = p.basisXDepthMin.w;
    t.depthMax = p.basisYDepthMax.w;
    t.light = p.light.x;
    t.pad = 0u;
    t.box = vec4(-1e30, -1e30, 1e30, 1e30);
    for (uint k = 0u; k < 4u; ++k) t.edge[k] = vec4(0.0, 0.0, 1.0, 0.0);
    t.range = vec4(p.basisXDepthMin.w, p.basisYDepthMax.w, 0.0, 0.0);
    if (p.light.y != 0u) {
        // A box the host worked out (origin, tile units: the fragment shader
        // keeps the tiles it spans): one triangle around it, trimmed to it.
        t.box = p.origin;
        const vec2 lo = p.origin.xy, size = max(p.origin.zw - p.origin.xy, vec2(0.0));
        const vec2 box[3] = vec2[3](lo, lo + vec2(2.0 * size.x, 0.0), lo + vec2(0.0, 2.0 * size.y));
        for (uint k = 0u; k < 3u; ++k) t.corner[k] = vec4(box[k] / vec2(params.grid.xy) * 2.0 - 1.0, 0.5, 1.0);
        triangles[gl_GlobalInvocationID.x] = t;
        return;
    }
    const mat3 basis = mat3(p.basisXDepthMin.xyz, p.basisYDepthMax.xyz, p.basisZ.xyz);
    vec3 v[3];
    for (uint k = 0u; k < 3u; ++k) v[k] = p.origin.xyz + basis * corners[first + k].xyz;
    vec4 c[3];
    for (uint k = 0u; k < 3u; ++k) c[k] = clipOf(v[k]);
    if ((params.grid.w & LC_RASTER_SLICES) != 0u) {
        // The view depths of the corners (least, greatest) and how the
        // triangle's plane is given (range.z: 0 none, 1 1/depth, 2 depth,
        // orthographic; edge[0..2].w: that value as a x + b y + c over the
        // grid, tile units). The fragment shader narrows the corners' range
        // to what the plane takes over its tile, as light_proxy.hpp's
        // proxyTriangleTileDepth does in double.
        const bool ortho = (params.grid.w & LC_RASTER_ORTHO) != 0u;
        vec3 d = -vec3(v[0].z, v[1].z, v[2].z);
        t.range = vec4(min(d.x, min(d.y, d.z)), max(d.x, max(d.y, d.z)), 0.0, 0.0);
        vec2 s[3];
        bool front = true;
        for (uint k = 0u; k < 3u; ++k) {
            front = front && (ortho || c[k].w >= params.cover.z);
            s[k] = (c[k].xy / c[k].w * 0.5 + 0.5) * vec2(params.grid.xy);
        }
        const vec2 u = s[1] - s[0], w = s[2] - s[0];
        const float det = u.x * w.y - u.y * w.x;
        // A plane only where float fits it well (the CPU reference fits
        // any): in front of the near plane, at least 1/10,000 tile of area,
        // and not thin on screen (a face near the silhouette, seen almost
        // edge-on, has a steep plane that float's rounding tilts); else
        // the corners' range, wider and safe.
        const float len2 = max(dot(u, u), max(dot(w, w), dot(w - u, w - u)));
        if (front && abs(det) > 2e-4 && abs(det) > 0.01 * len2) {
            const vec3 f = ortho ? d : 1.0 / d;
            const float fu = f.y - f.x, fw = f.z - f.x;
            const float a = (fu * w.y - fw * u.y) / det, b = (fw * u.x - fu * w.x) / det;
            t.edge[0].w = a;
            t.edge[1].w = b;
            t.edge[2].w = f.x - a * s[0].x - b * s[0].y;
            t.range.z = ortho ? 2.0 : 1.0;
        }
    }
    if (p.light.z != 0u) {
        // Wholly beyond the near plane: the faces turned to the camera cover
        // all the (convex) proxy covers; one clearly turned away is dropped.
        const vec3 n = cross(v[1] - v[0], v[2] - v[0]);
        const vec3 toEye = (params.grid.w & LC_RASTER_ORTHO) != 0u ? vec3(0.0, 0.0, 1.0) : -v[0];
        if (dot(n, toEye) < -1e-4 * length(n) * length(toEye)) {
            t.corner[0] = t.corner[1] = t.corner[2] = kDropped;
            triangles[gl_GlobalInvocationID.x] = t;
            return;
        }
    }
    t.corner[0] = c[0];
    t.corner[1] = c[1];
    t.corner[2] = c[2];
    if ((params.grid.w & (LC_RASTER_PUSH_EDGES | LC_RASTER_TRIM)) == 0u) {
        triangles[gl_GlobalInvocationID.x] = t;
        return;
    }
    const vec2 tiles = vec2(params.grid.xy);
    const float h = params.cover.w, nearW = params.cover.z;
    // The triangle's part in front of the near plane (w >= nearW), on the grid.
    vec2 q[4];
    uint m = 0u;
    bool clipped = false;
    for (uint k = 0u; k < 3u; ++k) {
        const vec4 a = c[k], b = c[(k + 1u) % 3u];
        if (a.w >= nearW) q[m++] = (a.xy / a.w * 0.5 + 0.5) * tiles;
        else clipped = true;
        if ((a.w >= nearW) != (b.w >= nearW)) {
            const vec4 x = mix(a, b, (nearW - a.w) / (b.w - a.w));
            q[m++] = (x.xy / x.w * 0.5 + 0.5) * tiles;
        }
    }
    if (m < 3u) { // all behind the near plane: nothing
        t.corner[0] = t.corner[1] = t.corner[2] = kDropped;
        triangles[gl_GlobalInvocationID.x] = t;
        return;
    }
    vec2 lo = q[0], hi = q[0];
    for (uint k = 1u; k < m; ++k) lo = min(lo, q[k]), hi = max(hi, q[k]);
    t.box = vec4(lo - h, hi + h);
    // The polygon's signed area (twice): its part in front, up to four corners.
    float poly = 0.0;
    for (uint k = 0u; k < m; ++k) poly += q[k].x * q[(k + 1u) % m].y - q[(k + 1u) % m].x * q[k].y;
    const float area = clipped ? poly : (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
    // The pushed edges, counter-clockwise (the inside left of each): the
    // triangle's three, or the four of what the near plane leaves of it; a
    // segment's two sides for one seen edge-on.
    vec3 line[4];
    line[3] = vec3(0.0, 0.0, 1.0);
    // Seen edge-on: flat to float's rounding, too thin to orient. It is a
    // segment (its longest side; the third corner within 1/512 tile of it):
    // drawn as its bounding box, trimmed by the box and by the segment's line
    // pushed out to both sides, the separating-axis test of a segment (its
    // bounding box alone covered tiles off it: an orthographic camera sees an
    // icosphere's silhouette faces exactly edge-on).
    float len2 = 0.0;
    uint longest = 0u;
    for (uint k = 0u; k < m; ++k) {
        const vec2 e = q[(k + 1u) % m] - q[k];
        if (dot(e, e) > len2) len2 = dot(e, e), longest = k;
    }
    const bool edgeOn = abs(area) <= 1e-4 * len2 && abs(area) < sqrt(len2) / 512.0;
    if (edgeOn) {
        const vec2 a = q[longest], n = vec2(a.y - q[(longest + 1u) % m].y, q[(longest + 1u) % m].x - a.x);
        const float push = h * (abs(n.x) + abs(n.y)) + length(n) / 512.0;
        t.edge[0].xyz = vec3(n, -dot(n, a) + push);
        t.edge[1].xyz = vec3(-n, dot(n, a) + push);
    }
    const bool edges = !edgeOn && abs(area) > 0.0;
    bool reversed = false;
    if (edges) {
        if (area < 0.0) { // reverse the corners
            reversed = true;
            for (uint k = 0u; k < m / 2u; ++k) {
                const vec2 s = q[k];
                q[k] = q[m - 1u - k];
                q[m - 1u - k] = s;
            }
        }
        for (uint k = 0u; k < m; ++k) { // n.p + d >= 0 inside, d grown by the push
            const vec2 a = q[k], b = q[(k + 1u) % m];
            const vec2 n = vec2(a.y - b.y, b.x - a.x);
            line[k] = vec3(n, -dot(n, a) + h * (abs(n.x) + abs(n.y)));
        }
        for (uint k = 0u; k < 4u; ++k) t.edge[k].xyz = line[k];
    }
    if ((params.grid.w & LC_RASTER_PUSH_EDGES) == 0u) {
        // The device's conservative rasteriser covers the triangle (it may
        // overestimate more than it must: NVIDIA's covered tiles a sharp
        // corner only nears); the fragment shader trims to the same test.
        triangles[gl_GlobalInvocationID.x] = t;
        return;
    }
    if (clipped || !edges || abs(area) < 1.0 / 64.0) {
        const vec2 size = t.box.zw - t.box.xy;
        const vec2 box[3] = vec2[3](t.box.xy, t.box.xy + vec2(2.0 * size.x, 0.0), t.box.xy + vec2(0.0, 2.0 * size.y));
        for (uint k = 0u; k < 3u; ++k) t.corner[k] = vec4(box[k] / tiles * 2.0 - 1.0, 0.5, 1.0);
    } else {
        // Each corner: where the pushed edges before and after it meet (the
        // corners' order reversed above for a clockwise triangle).
        for (uint k = 0u; k < 3u; ++k) {
            const uint me = reversed ? (k == 0u ? 2u : k == 2u ? 0u : 1u) : k;
            const vec3 l1 = line[(me + 2u) % 3u], l2 = line[me];
            const float det = l1.x * l2.y - l1.y * l2.x;
            const vec2 at = vec2(-l1.z * l2.y + l2.z * l1.y, -l2.z * l1.x + l1.z * l2.x) / det;
            t.corner[k] = vec4(at / tiles * 2.0 - 1.0, 0.5, 1.0);
        }
    }
    triangles[gl_GlobalInvocationID.x] = t;
}
