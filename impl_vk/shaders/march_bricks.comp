#version 450
// Stage `render_march`, pass 2 (impl_cpu/RenderMarchCpu.cpp step 2): the brick
// skip structure, one invocation per brick (a 3-D grid of 64 x 1 x 1 workgroups,
// so that no axis needs more than 65535 groups). Brick (a, b, c) is empty (1)
// iff q_alpha = 0 over the brick grown by one voxel: padded indices
// a B .. (a+1) B + 1 per axis, clamped to the padded volume. Counts the empty bricks.
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Volume { float volume[]; };
layout(std430, binding = 1) writeonly buffer Bricks { uint empty[]; };
layout(std430, binding = 2) buffer Stats { uint stats[]; };  // words 8, 9: empty bricks (low, high)
layout(push_constant) uniform Params { uint px, py, pz, brick, bx, by, bz, qStride; } pc;

void main() {
    const uint a = gl_GlobalInvocationID.x, b = gl_GlobalInvocationID.y, c = gl_GlobalInvocationID.z;
    if (a >= pc.bx) return;
    const uint n = a + pc.bx * (b + pc.by * c);
    const uint B = pc.brick;
    const uint i1 = min((a + 1u) * B + 1u, pc.px - 1u);
    const uint j1 = min((b + 1u) * B + 1u, pc.py - 1u);
    const uint k1 = min((c + 1u) * B + 1u, pc.pz - 1u);
    bool isEmpty = true;
    for (uint k = c * B; k <= k1 && isEmpty; ++k)
        for (uint j = b * B; j <= j1 && isEmpty; ++j)
            for (uint i = a * B; i <= i1; ++i)
                if (volume[pc.qStride * (i + pc.px * (j + pc.py * k))] != 0.0) {
                    isEmpty = false;
                    break;
                }
    empty[n] = isEmpty ? 1u : 0u;
    if (isEmpty) atomicAdd(stats[8], 1u);
}
