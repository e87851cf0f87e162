#version 450
// Stage `shade` at resolution f > 1: the mean of each f^3 block (partial
// blocks: of the voxels present), one invocation per coarse cell.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Q { float q[]; };
layout(std430, binding = 1) writeonly buffer C { float coarse[]; };
layout(push_constant) uniform Params { uint nx, ny, nz, cx, cy, cz, f; } pc;

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.cx * pc.cy * pc.cz) return;
    const uint I = id % pc.cx, J = (id / pc.cx) % pc.cy, K = id / (pc.cx * pc.cy);
    float sum = 0.0;
    uint count = 0u;
    for (uint k = K * pc.f; k < min(pc.nz, (K + 1u) * pc.f); ++k)
        for (uint j = J * pc.f; j < min(pc.ny, (J + 1u) * pc.f); ++j)
            for (uint i = I * pc.f; i < min(pc.nx, (I + 1u) * pc.f); ++i, ++count) sum += q[i + pc.nx * (j + pc.ny * k)];
    coarse[id] = sum / float(count);
}
