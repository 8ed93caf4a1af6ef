// lightcull: --layout fixed:256 --lists tile
//
// DELIBERATELY FLAWED: tiled_fixed.comp testing a spot light by the sphere
// through its apex and its rim instead of its range sphere, the bounding
// sphere of Bart Wronski's "Cull that cone!" (2017) with its second branch
// left out: centre apex + axis r / (2 cos a), radius r / (2 cos a), for
// range r and outer half-angle a. That sphere is the tightest up to a = 45
// degrees (a 90-degree cone); above, the tutorial switches to the sphere on
// the rim circle (centre r cos a along the axis, radius r sin a). Without
// that branch a wide spot's sphere still holds its cone, ever more loosely
// (radius r at 60 degrees, 5.7 r at 85), up to the hemisphere spot of
// a = 90 degrees: cos a is 0 there (-4.4e-8 for the float nearest pi / 2),
// the sphere's centre and radius blow up, the radius negative, and the
// light drops out of every tile. Point lights (angle 0) and spots short of
// 90 degrees are never missed (above 45 degrees only listed wastefully).
// Seen when a spot test is copied from a sample tuned for flashlights and a
// 180-degree ceiling spot is placed later.
// The hunt finds it without being told to vary spots (90-degree spots are
// among the angles it draws); its repro.sh shows it:
//   lightcull hunt --shader flawed_wide_spot.comp --backend cpu --out out/hunt && sh out/hunt/repro.sh
#version 450
#extension GL_GOOGLE_include_directive : require
#include "lightcull.glsl"

layout(local_size_x = 64) in;

shared uint sMinBits, sMaxBits; // view depths as float bits: positive floats order as uints

// Plane n.p + w >= 0 inside; n unit length.
vec4 sidePlane(vec3 n, float w) { return vec4(n, w) / length(n); }

// The sphere the light is tested by: a point light's range sphere, or for a
// spot (spotAxisAngle: unit axis, outer half-angle) the sphere through the
// apex and the rim of its cone.
vec4 boundingSphere(vec4 positionRadius, vec4 spotAxisAngle) {
    if (spotAxisAngle.w == 0.0) return positionRadius;
    // THE FLAW: Wronski's a <= 45 degrees branch for every angle.
    const float r = positionRadius.w / (2.0 * cos(spotAxisAngle.w));
    return vec4(positionRadius.xyz + spotAxisAngle.xyz * r, r);
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
        const uint z = floatBitsToUint(lcViewDepth(d));
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
        const vec4 s = boundingSphere(lcLights[i].positionRadius, lcLights[i].spotAxisAngle);
        // Widened a little so that float rounding never rejects a light the
        // exact (double) test keeps.
        const float r = s.w + 1e-5 * (abs(s.x) + abs(s.y) + abs(s.z) + s.w);
        bool inside = -s.z + r >= zMin && -s.z - r <= zMax;
        for (int k = 0; k < 4 && inside; ++k) inside = dot(planes[k].xyz, s.xyz) + planes[k].w >= -r;
        if (inside) lcAppend(tileIndex, i);
    }
}
