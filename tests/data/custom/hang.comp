// lightcull: --layout fixed:4 --lists tile
// A culling shader that runs far longer than any culling pass should: the
// tests give it a short time limit, expect the hang error, and then run a
// correct shader on a fresh device. lavapipe stops every loop after 65,535
// iterations (gallivm's guard against endless loops), so this one spins that
// long in every invocation of every tile: about 1e9 atomic adds at 320x180.
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"
layout(local_size_x = 64) in;
void main() {
    const uint tileIndex = gl_WorkGroupID.y * lc.size.z + gl_WorkGroupID.x;
    for (uint i = 0u; i < 0xFFFFFFFFu; ++i) atomicAdd(lcOut[tileIndex * 5u], 1u);
}
