#version 450
// Stage `shade` (SPEC 6): one slice of the inverse shear-warp; one invocation
// per (u, v). Dispatched once per slice, from the sun's side, with a barrier
// between slices. Taps outside the previous slice read T = 1, q = 0. The
// reference path, and the default on a CPU device (BackendVk::ShadeSweep);
// shade_block.comp, 16 slices a dispatch, must give the same T bit for bit.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) buffer T { float t[]; };
layout(push_constant) uniform Params {
    uint nu, nv;                // slice size
    uint strideU, strideV;      // element strides of u and v
    uint sliceBase, prevBase;   // first element of this slice and of the previous one
    int u0, v0;                 // tap offset of the previous slice
    float fu, fv;
    uint first;                 // 1: the slice nearest the sun (T = 1)
    uint beer;                  // 1: beer, 0: thesis
    float depthPerQ, thesisAr, scatterGain;
    uint storage;
} pc;

float TapT(int a, int b) {
    if (a < 0 || b < 0 || a >= int(pc.nu) || b >= int(pc.nv)) return 1.0;
    return t[pc.prevBase + uint(a) * pc.strideU + uint(b) * pc.strideV];
}
float TapQ(int a, int b) {
    if (a < 0 || b < 0 || a >= int(pc.nu) || b >= int(pc.nv)) return 0.0;
    return q[pc.prevBase + uint(a) * pc.strideU + uint(b) * pc.strideV];
}

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.nu * pc.nv) return;
    const uint a = id % pc.nu, b = id / pc.nu;
    const uint target = pc.sliceBase + a * pc.strideU + b * pc.strideV;
    if (pc.first != 0u) {
        t[target] = 1.0;
        return;
    }
    const int ua = int(a) + pc.u0, vb = int(b) + pc.v0;
    const float tt = Bilinear(TapT(ua, vb), TapT(ua + 1, vb), TapT(ua, vb + 1), TapT(ua + 1, vb + 1), pc.fu, pc.fv);
    const float qs = Bilinear(TapQ(ua, vb), TapQ(ua + 1, vb), TapQ(ua, vb + 1), TapQ(ua + 1, vb + 1), pc.fu, pc.fv);
    t[target] = StoreTransmittance(pc.storage, tt, SliceFactor(pc.beer, pc.depthPerQ, pc.thesisAr, pc.scatterGain, qs));
}
