// lightcull: --layout fixed:256 --lists tile
//
// DELIBERATELY FLAWED: tiled_fixed.comp with the tile's depth linearised by
// the [0,1] perspective formula from the camera's near and far (lc.planes),
// v = n f / (f - d (f - n)), or n / (1 - d) for an infinite far plane,
// instead of lcViewDepth. That is right for the standard depth the shader
// was written against (and for GL depth, whose window depth is the same, and
// for orthographic cameras, linear either way), and wrong once the camera
// goes reversed-Z, where near is 1 and far 0: a finite far plane turns the
// tile's depths inside out (a pixel at the near plane reads as the far
// plane), an infinite one squeezes them all to about the near distance. The
// tile's min/max bounds then miss the lights at the depth of its geometry.
// Seen when an engine switches its depth buffer to reversed-Z for precision
// and a LinearizeDepth helper in the culling pass is left as it was: lights
// vanish or pop in with distance, the shading passes being fine.
//   lightcull run --scene resources/scenes/reversed_z_corridor.json --shader flawed_reversed_z.comp --out out/flawed
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"

layout(local_size_x = 64) in;

shared uint sMinBits, sMaxBits; // view depths as float bits: positive floats order as uints

// Plane n.p + w >= 0 inside; n unit length.
vec4 sidePlane(vec3 n, float w) { return vec4(n, w) / length(n); }

// THE FLAW: view depth of window depth d for standard depth (near -> 0,
// far -> 1) whatever the projection's convention.
float linearDepth(float d) {
    const float n = lc.planes.x, f = lc.planes.y; // f = 0: infinite far plane
    if (lc.lens.z > 0.5) return n + d * (f - n);  // orthographic: linear in d
    return f == 0.0 ? n / (1.0 - d) : n * f / (f - d * (f - n));
}

void main() {
    const uvec2 tile = gl_WorkGroupID.xy;
    const uint tileIndex = tile.y * lc.size.z + tile.x;
    const uvec2 p0 = tile * uint(TILE_SIZE);
    const uvec2 p1 = min(p0 + uint(TILE_SIZE), lc.size.xy); // edge tiles are partial
    if (gl_LocalInvocationIndex == 0u) {
        sMinBits = 0x7f7fffffu;
        sMaxBits = 0u;
    }
    barrier();
    const uint w = p1.x - p0.x, h = p1.y - p0.y;
    for (uint i = gl_LocalInvocationIndex; i < w * h; i += 64u) {
        const float d = texelFetch(lcDepthTexture, ivec2(p0 + uvec2(i % w, i / w)), 0).r;
        if (!lcHasGeometry(d)) continue;
        const uint z = floatBitsToUint(linearDepth(d));
        atomicMin(sMinBits, z);
        atomicMax(sMaxBits, z);
    }
    barrier();
    if (sMaxBits == 0u) return; // no geometry in the tile: its list stays empty
    const float zMin = uintBitsToFloat(sMinBits), zMax = uintBitsToFloat(sMaxBits);

    // NDC of the tile's pixel edges (v down), then the side planes.
    const float u0 = 2.0 * float(p0.x) / float(lc.size.x) - 1.0, u1 = 2.0 * float(p1.x) / float(lc.size.x) - 1.0;
    const float v0 = 2.0 * float(p0.y) / float(lc.size.y) - 1.0, v1 = 2.0 * float(p1.y) / float(lc.size.y) - 1.0;
    vec4 planes[4];
    if (lc.lens.z > 0.5) { // orthographic: parallel planes
        planes[0] = vec4(1, 0, 0, -u0 * lc.lens.x);
        planes[1] = vec4(-1, 0, 0, u1 * lc.lens.x);
        planes[2] = vec4(0, -1, 0, -v0 * lc.lens.y);
        planes[3] = vec4(0, 1, 0, v1 * lc.lens.y);
    } else { // perspective: planes through the eye
        planes[0] = sidePlane(vec3(1, 0, u0 * lc.lens.x), 0.0);
        planes[1] = sidePlane(vec3(-1, 0, -u1 * lc.lens.x), 0.0);
        planes[2] = sidePlane(vec3(0, -1, v0 * lc.lens.y), 0.0);
        planes[3] = sidePlane(vec3(0, 1, -v1 * lc.lens.y), 0.0);
    }

    for (uint i = gl_LocalInvocationIndex; i < lc.counts.x; i += 64u) {
        const vec4 s = lcLights[i].positionRadius;
        // Widened a little so that float rounding never rejects a light the
        // exact (double) test keeps.
        const float r = s.w + 1e-5 * (abs(s.x) + abs(s.y) + abs(s.z) + s.w);
        bool inside = -s.z + r >= zMin && -s.z - r <= zMax;
        for (int k = 0; k < 4 && inside; ++k) inside = dot(planes[k].xyz, s.xyz) + planes[k].w >= -r;
        if (inside) lcAppend(tileIndex, i);
    }
}
