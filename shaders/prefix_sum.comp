#version 450
// Pass 3: exclusive scan of the per-list counts into offsets; listOffset[N]
// receives the total entry count, which the host reads back to size the index
// buffer exactly. One workgroup (= one subgroup): each invocation scans a
// contiguous run of lists, the runs are joined by a subgroup scan.
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "cull_common.glsl"

void main() {
    loadParams();
    if (gl_NumSubgroups != 1u) atomicOr(status, STATUS_SPLIT_WORKGROUP);
    uint N = P.counts.z;
    uint stride = gl_WorkGroupSize.x, lane = gl_LocalInvocationIndex;
    uint per = (N + stride - 1u) / stride;
    uint b = min(lane * per, N), e = min(b + per, N);
    uint sum = 0u;
    for (uint i = b; i < e; ++i) sum += listCount[i];
    uint run = subgroupExclusiveAdd(sum);
    uint total = subgroupAdd(sum);
    for (uint i = b; i < e; ++i) {
        listOffset[i] = run;
        run += listCount[i];
    }
    if (subgroupElect()) listOffset[N] = total;
}
