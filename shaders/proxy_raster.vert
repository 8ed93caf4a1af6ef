#version 450
// The raster algorithm's vertex shader (vk/raster_pass.cpp): corner k of
// triangle t of the batch is record t's corner k, which proxy_setup.comp
// worked out (the proxy placed in view space, projected onto the grid one
// pixel per tile, its edges pushed out where the device has no conservative
// rasteriser). The fragment shader gets the record's index alone.
#extension GL_GOOGLE_include_directive : require
#include "culling/vk/gpu_shared.h"

layout(std430, set = 0, binding = 6) readonly buffer Triangles { GpuProxyTriangle triangles[]; };

layout(location = 0) flat out uint outTriangle;

void main() {
    const uint t = uint(gl_VertexIndex) / 3u;
    outTriangle = t;
    gl_Position = triangles[t].corner[uint(gl_VertexIndex) - 3u * t];
}
