// lightcull: --layout fixed:256 --lists tile --entry CSMain
//
// The tiled culling of tiled_fixed.comp in HLSL (compiled by glslang), as an
// engine with an HLSL code base writes it: depth read from the storage buffer
// (binding 2), lights from binding 3, the fixed-size lists written to
// binding 4 as count + MAX_LIGHTS_PER_TILE indices per tile.
//   lightcull run --builtin atrium --shader tiled_fixed.hlsl --out out/mine

struct LcParams {
    uint4 size;        // width, height, tilesX, tilesY
    uint4 counts;      // lightCount, listsPerTile, listCount, capacity
    uint4 mode;
    float4 depthParams; // A, B, orthographic, clear depth
    float4 planes;
    float4 lens;       // tan(fov/2) x, y (or ortho half extents); z: orthographic
    float4x4 proj;
    float4x4 invProj;
};
[[vk::binding(0, 0)]] cbuffer LcParamsBlock { LcParams lc; };
struct LcLight {
    float4 positionRadius; // view space; w: radius
    float4 spotAxisAngle;
};
[[vk::binding(2, 0)]] StructuredBuffer<float> lcDepth;
[[vk::binding(3, 0)]] StructuredBuffer<LcLight> lcLights;
[[vk::binding(4, 0)]] RWStructuredBuffer<uint> lcOut;

groupshared uint sMinBits;
groupshared uint sMaxBits;

float ViewDepth(float d) {
    return lc.depthParams.z > 0.5 ? (d - lc.depthParams.x) / lc.depthParams.y : lc.depthParams.y / (d - lc.depthParams.x);
}

float4 SidePlane(float3 n) { return float4(n / length(n), 0.0); }

[numthreads(64, 1, 1)]
void CSMain(uint3 group : SV_GroupID, uint local : SV_GroupIndex) {
    const uint tileIndex = group.y * lc.size.z + group.x;
    const uint2 p0 = group.xy * TILE_SIZE;
    const uint2 p1 = min(p0 + TILE_SIZE, lc.size.xy);
    if (local == 0) {
        sMinBits = 0x7f7fffff;
        sMaxBits = 0;
    }
    GroupMemoryBarrierWithGroupSync();
    const uint w = p1.x - p0.x, h = p1.y - p0.y;
    for (uint i = local; i < w * h; i += 64) {
        const uint2 px = p0 + uint2(i % w, i / w);
        const float d = lcDepth[px.y * lc.size.x + px.x];
        if (d == lc.depthParams.w) continue;
        uint ignored;
        InterlockedMin(sMinBits, asuint(ViewDepth(d)), ignored);
        InterlockedMax(sMaxBits, asuint(ViewDepth(d)), ignored);
    }
    GroupMemoryBarrierWithGroupSync();
    if (sMaxBits == 0) return;
    const float zMin = asfloat(sMinBits), zMax = asfloat(sMaxBits);

    const float u0 = 2.0 * p0.x / lc.size.x - 1.0, u1 = 2.0 * p1.x / lc.size.x - 1.0;
    const float v0 = 2.0 * p0.y / lc.size.y - 1.0, v1 = 2.0 * p1.y / lc.size.y - 1.0;
    float4 planes[4];
    if (lc.lens.z > 0.5) {
        planes[0] = float4(1, 0, 0, -u0 * lc.lens.x);
        planes[1] = float4(-1, 0, 0, u1 * lc.lens.x);
        planes[2] = float4(0, -1, 0, -v0 * lc.lens.y);
        planes[3] = float4(0, 1, 0, v1 * lc.lens.y);
    } else {
        planes[0] = SidePlane(float3(1, 0, u0 * lc.lens.x));
        planes[1] = SidePlane(float3(-1, 0, -u1 * lc.lens.x));
        planes[2] = SidePlane(float3(0, -1, v0 * lc.lens.y));
        planes[3] = SidePlane(float3(0, 1, -v1 * lc.lens.y));
    }

    const uint base = tileIndex * (MAX_LIGHTS_PER_TILE + 1);
    for (uint l = local; l < lc.counts.x; l += 64) {
        const float4 s = lcLights[l].positionRadius;
        const float r = s.w + 1e-5 * (abs(s.x) + abs(s.y) + abs(s.z) + s.w);
        bool inside = -s.z + r >= zMin && -s.z - r <= zMax;
        for (int k = 0; k < 4; ++k) inside = inside && dot(planes[k].xyz, s.xyz) + planes[k].w >= -r;
        if (inside) {
            uint slot;
            InterlockedAdd(lcOut[base], 1, slot);
            if (slot < MAX_LIGHTS_PER_TILE) lcOut[base + 1 + slot] = l;
        }
    }
}
