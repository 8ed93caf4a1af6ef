#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"
layout(local_size_x = 64) in;
void main() {
    uint x = undeclaredThing + 1u;
}
