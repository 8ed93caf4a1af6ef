// lightcull: --layout fixed:8 --lists tile
// Writes light indices past the light count and far past its buffer (robust
// buffer access keeps the writes harmless; the tool reports the indices).
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"
layout(local_size_x = 1) in;
void main() {
    const uint tileIndex = gl_WorkGroupID.y * lc.size.z + gl_WorkGroupID.x;
    lcAppend(tileIndex, lc.counts.x + 7u);      // not a light
    lcAppend(tileIndex, 0u);
    lcAppend(tileIndex, 0u);                    // duplicate
    lcOut[lc.counts.z * 100u + tileIndex] = 5u; // past the end of the buffer
}
