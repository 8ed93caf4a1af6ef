// The mini engine's Forward+ light culling, written as a renderer would
// write it, not to lightcull's contract: its own light struct (world space,
// colour first), its own constants, the depth attachment sampled, and lists
// as a count per tile plus MAX_LIGHTS indices per tile in another buffer.
#version 450
#define TILE 16
#define MAX_LIGHTS 32
layout(local_size_x = TILE, local_size_y = TILE) in;
layout(constant_id = 0) const uint BUG_HALF_RADIUS = 0; // a deliberate bug: test with half the range

layout(set = 0, binding = 0, row_major, std140) uniform FrameConstants {
    mat4 view;
    mat4 proj;
    uvec4 screen; // width, height, tile size, light count
} frame;
struct EngineLight {
    vec4 color;
    vec3 positionWS;
    float range;
};
layout(set = 0, binding = 1, std430) readonly buffer LightBuffer { EngineLight lights[]; };
layout(set = 0, binding = 2) uniform sampler2D sceneDepth;
layout(set = 0, binding = 3, std430) writeonly buffer TileLightCounts { uint tileCounts[]; };
layout(set = 0, binding = 4, std430) writeonly buffer TileLightIndices { uint tileIndices[]; };

shared uint minDepthBits, maxDepthBits, hasGeometry, count;

// View depth (positive in front) of window depth d, from the projection.
float viewDepth(float d) {
    vec4 v = inverse(frame.proj) * vec4(0.0, 0.0, d, 1.0);
    return -v.z / v.w;
}
vec3 viewPoint(vec2 ndc) {
    vec4 v = inverse(frame.proj) * vec4(ndc, 0.5, 1.0);
    return v.xyz / v.w;
}

void main() {
    uvec2 size = uvec2(frame.screen.xy);
    bool reversed = frame.proj[3][2] > 0.0; // GLSL indexes [column][row] whatever the storage
    float clearDepth = reversed ? 0.0 : 1.0;
    if (gl_LocalInvocationIndex == 0) {
        minDepthBits = 0x7F7FFFFFu;
        maxDepthBits = 0u;
        hasGeometry = 0u;
        count = 0u;
    }
    barrier();
    uvec2 px = gl_GlobalInvocationID.xy;
    if (px.x < size.x && px.y < size.y) {
        float d = texelFetch(sceneDepth, ivec2(px), 0).r;
        if (d != clearDepth) {
            float t = viewDepth(d);
            atomicMin(minDepthBits, floatBitsToUint(t));
            atomicMax(maxDepthBits, floatBitsToUint(t));
            atomicOr(hasGeometry, 1u);
        }
    }
    barrier();
    uint tile = gl_WorkGroupID.y * gl_NumWorkGroups.x + gl_WorkGroupID.x;
    if (hasGeometry != 0u) {
        // A margin for the float inverse projection (as engines keep one).
        float tMin = uintBitsToFloat(minDepthBits) * 0.999, tMax = uintBitsToFloat(maxDepthBits) * 1.001;
        // The tile's side planes through the eye, from its pixel rectangle
        // (clipped to the screen), normals pointing into the tile.
        vec2 lo = vec2(gl_WorkGroupID.xy * TILE), hi = min(lo + TILE, vec2(size));
        vec2 ndcLo = lo / vec2(size) * 2.0 - 1.0, ndcHi = hi / vec2(size) * 2.0 - 1.0;
        vec3 c00 = viewPoint(ndcLo), c10 = viewPoint(vec2(ndcHi.x, ndcLo.y));
        vec3 c01 = viewPoint(vec2(ndcLo.x, ndcHi.y)), c11 = viewPoint(ndcHi);
        vec3 centre = (c00 + c11) * 0.5;
        vec3 planes[4] = vec3[4](cross(c00, c01), cross(c11, c10), cross(c10, c00), cross(c01, c11));
        for (int i = 0; i < 4; ++i) {
            planes[i] = normalize(planes[i]);
            if (dot(planes[i], centre) < 0.0) planes[i] = -planes[i];
        }
        uint lightCount = frame.screen.w;
        for (uint l = gl_LocalInvocationIndex; l < lightCount; l += TILE * TILE) {
            vec3 c = (frame.view * vec4(lights[l].positionWS, 1.0)).xyz;
            float r = lights[l].range * (BUG_HALF_RADIUS != 0u ? 0.5 : 1.0);
            float t = -c.z;
            bool inside = t + r >= tMin && t - r <= tMax;
            for (int i = 0; i < 4; ++i) inside = inside && dot(planes[i], c) >= -r * 1.001;
            if (inside) {
                uint slot = atomicAdd(count, 1u);
                if (slot < MAX_LIGHTS) tileIndices[tile * MAX_LIGHTS + slot] = l;
            }
        }
    }
    barrier();
    if (gl_LocalInvocationIndex == 0) tileCounts[tile] = count;
}
