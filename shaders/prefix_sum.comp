#version 450
// Pass 3: exclusive scan of the per-list counts into offsets; listOffset[N]
// receives the total entry count, which the host reads back to size the index
// buffer exactly. One workgroup; each invocation scans a contiguous run of
// lists and the runs are joined by subgroup scans.
//   LANES == 1 (CPU devices): the workgroup is one subgroup: no shared
//   memory, no barrier() (expensive on lavapipe).
//   LANES > 1 (GPUs, and CPU devices with many lists): a wide workgroup of
//   up to 128 subgroups; invocation 0 scans the subgroup totals in shared
//   memory between two barriers (cheap once per dispatch), and each
//   invocation's run is short (lavapipe caps an invocation at 65,535 loop
//   iterations: see LC_STATUS_LOOP_LIMIT).
#extension GL_GOOGLE_include_directive : require
#extension GL_KHR_shader_subgroup_basic : require
#extension GL_KHR_shader_subgroup_arithmetic : require
#include "cull_common.glsl"

shared uint subgroupBase[128];

void main() {
    loadParams();
    uint N = P.counts.z;
    uint stride = gl_WorkGroupSize.x, tid = gl_LocalInvocationIndex;
    uint per = (N + stride - 1u) / stride;
    uint b = min(tid * per, N), e = min(b + per, N);
    uint sum = 0u, i = b;
    for (; i < e; ++i) sum += listCount[i];
    bool cut = i < e;
    uint run, total;
    if (LANES == 1u) {
        if (gl_NumSubgroups != 1u) atomicOr(status, LC_STATUS_SPLIT_WORKGROUP);
        run = subgroupExclusiveAdd(sum);
        total = subgroupAdd(sum);
    } else {
        if (gl_NumSubgroups > 128u) atomicOr(status, LC_STATUS_SPLIT_WORKGROUP);
        uint inclusive = subgroupInclusiveAdd(sum);
        if (gl_SubgroupInvocationID == gl_SubgroupSize - 1u) subgroupBase[gl_SubgroupID] = inclusive;
        // Invocation 0 reads every subgroup's total written above.
        barrier();
        if (tid == 0u) {
            uint acc = 0u;
            for (uint g = 0u; g < gl_NumSubgroups; ++g) {
                uint t = subgroupBase[g];
                subgroupBase[g] = acc;
                acc += t;
            }
        }
        // Every subgroup reads its base written by invocation 0 above.
        barrier();
        run = subgroupBase[gl_SubgroupID] + inclusive - sum;
        total = 0u; // only the last invocation's run end is the total
    }
    for (i = b; i < e; ++i) {
        listOffset[i] = run;
        run += listCount[i];
    }
    if (cut || i < e) atomicOr(status, LC_STATUS_LOOP_LIMIT);
    if (LANES == 1u) {
        if (subgroupElect()) listOffset[N] = total;
    } else if (tid == stride - 1u) {
        listOffset[N] = run;
    }
}
