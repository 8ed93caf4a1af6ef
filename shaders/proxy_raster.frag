#version 450
// The raster algorithm's fragment shader: a fragment is a tile the proxy
// covers. The light is listed there (its bit ORed into the tile's mask) when
// the tile holds geometry and the proxy's view-depth range reaches the
// tile's min/max (the bounds pass's, float; the range comes widened from
// the host).
#extension GL_GOOGLE_include_directive : require
#include "culling/vk/gpu_shared.h"

layout(std430, set = 0, binding = 0) readonly buffer Params { GpuRasterParams params; };
layout(std430, set = 0, binding = 1) readonly buffer Tiles { GpuTileBounds tiles[]; };
layout(std430, set = 0, binding = 4) buffer Masks { uint masks[]; };

layout(location = 0) flat in uint inLight;
layout(location = 1) flat in vec2 inDepth;
layout(location = 2) flat in vec4 inBox; // tile centres allowed (tile units), see the vertex shader
layout(location = 3) flat in vec3 inEdge0; // the pushed edges: n.centre + d >= 0 inside
layout(location = 4) flat in vec3 inEdge1;
layout(location = 5) flat in vec3 inEdge2;

void main() {
    if (any(lessThan(gl_FragCoord.xy, inBox.xy)) || any(greaterThan(gl_FragCoord.xy, inBox.zw))) return;
    const vec3 c = vec3(gl_FragCoord.xy, 1.0);
    if (dot(inEdge0, c) < 0.0 || dot(inEdge1, c) < 0.0 || dot(inEdge2, c) < 0.0) return;
    const uvec2 t = uvec2(gl_FragCoord.xy);
    if (t.x >= params.grid.x || t.y >= params.grid.y) return;
    const uint tile = t.y * params.grid.x + t.x;
    const GpuTileBounds b = tiles[tile];
    if (!(b.depthMin <= b.depthMax) || inDepth.x > b.depthMax || inDepth.y < b.depthMin) return;
    atomicOr(masks[tile * params.grid.z + (inLight >> 5u)], 1u << (inLight & 31u));
}
