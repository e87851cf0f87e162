#version 450
// Stage `shadow` (SPEC 7): one invocation per ground cell; D read bilinearly
// at the cell plus the offset to mid-height along the sun, 0 outside.
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer D { float d[]; };
layout(std430, binding = 1) writeonly buffer G { float g[]; };
layout(push_constant) uniform Params {
    uint nx, ny;
    int bx, by;        // floor of the offset
    float fx, fy;      // its fraction
    uint form;         // ShadowForm: 0 beer exp(-k D), 1 thesis 1 - clamp(kappa D), 2 wang (Wang, Ji and Zhang, eq. 19)
    float opticalDepthPerD, kappa;
    uint noSun;        // 1: G = 1
    float coverage, densityFactor;  // wang
} pc;

float TapD(int i, int j) {
    if (i < 0 || j < 0 || i >= int(pc.nx) || j >= int(pc.ny)) return 0.0;
    return d[uint(i) + pc.nx * uint(j)];
}

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.nx * pc.ny) return;
    if (pc.noSun != 0u) {
        g[id] = 1.0;
        return;
    }
    const int x = int(id % pc.nx) + pc.bx, y = int(id / pc.nx) + pc.by;
    const float dd = Bilinear(TapD(x, y), TapD(x + 1, y), TapD(x, y + 1), TapD(x + 1, y + 1), pc.fx, pc.fy);
    g[id] = pc.form == 2u ? WangShadow(pc.opticalDepthPerD, pc.coverage, pc.densityFactor, dd)
                          : GroundShadow(pc.form == 0u ? 1u : 0u, pc.opticalDepthPerD, pc.kappa, dd);
}
