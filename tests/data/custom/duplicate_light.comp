// lightcull: --layout fixed:64 --lists tile
// Lists every light in every tile (no culling, so no light is ever missed)
// and light 0 a second time: a shading pass reading the list adds light 0
// twice. The hunt and `run` judge that a failure (exit 3).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"
layout(local_size_x = 1) in;
void main() {
    const uint tileIndex = gl_WorkGroupID.y * lc.size.z + gl_WorkGroupID.x;
    for (uint i = 0u; i < lc.counts.x; ++i) lcAppend(tileIndex, i);
    if (lc.counts.x > 0u) lcAppend(tileIndex, 0u);
}
