// Spot-light cone tests for the culling compute shaders, the float twins of
// culling/src/math/spot_tests.cpp (docs/SPOT_LIGHTS.md). View space. A spot
// light's volume is the spherical sector of points within `range` of the apex
// whose angle to the unit `axis` is at most the outer angle (cos/sin given).
//
// Conservative float: every rejection compares against a distance widened by
// `eps` (view units, the caller's widening of the light's radius), so a light
// the double-precision CPU reference keeps is always kept here too.

// Cone against a sphere (Bart Wronski, "Cull that cone!"): false only when the
// sphere (c, r) lies outside the range sphere, behind the apex plane, or
// farther than r from the infinite cone's lateral surface.
bool spotConeHitsSphere(vec3 apex, vec3 axis, float range, float cosA, float sinA, vec3 c, float r,
                        float eps) {
    vec3 v = c - apex;
    float rr = r + eps;
    float vLen2 = dot(v, v);
    if (vLen2 > (range + rr) * (range + rr)) return false;
    float vAxial = dot(v, axis);
    if (vAxial < -rr) return false;
    float vRadial = sqrt(max(0.0, vLen2 - vAxial * vAxial));
    return cosA * vRadial - sinA * vAxial <= rr;
}

// Largest signed distance n.p + w over the sector: the apex, or the cap point
// farthest along n (|n| = 1 or not).
float spotConeMaxSignedDistance(vec3 apex, vec3 axis, float range, float cosA, float sinA, vec4 plane) {
    vec3 n = plane.xyz;
    float nLen = length(n);
    float nAxial = dot(n, axis);
    float nRadial = sqrt(max(0.0, nLen * nLen - nAxial * nAxial));
    float reach = nAxial >= nLen * cosA ? nLen : nAxial * cosA + nRadial * sinA;
    return dot(n, apex) + plane.w + range * max(0.0, reach);
}

// The sector is outside the plane n.p + w >= 0 (by more than eps).
bool spotConeOutsidePlane(vec3 apex, vec3 axis, float range, float cosA, float sinA, vec4 plane,
                          float eps) {
    return spotConeMaxSignedDistance(apex, axis, range, cosA, sinA, plane) < -eps;
}
