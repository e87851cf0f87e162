#version 450
// render_splat's box visibility on the device (SPEC 8, core/pipeline/Backend.h
// SplatBoxVisibility): boxes holds the frustum's visible boxes (host geometry,
// uploaded in order with the recorded calls); a box stays visible only if
// either step's band occupancy has it. The buffers are bytes of 0 or 1, read
// four at a time (every storage buffer is padded to a multiple of 4 bytes);
// words past the last box are left as they were.
layout(local_size_x = 64) in;
layout(std430, binding = 0) buffer Boxes { uint boxes[]; };
layout(std430, binding = 1) readonly buffer BandsPrev { uint bandsPrev[]; };
layout(std430, binding = 2) readonly buffer BandsCur { uint bandsCur[]; };
layout(push_constant) uniform Params {
    uint words;  // ceil(boxes / 4)
} pc;

void main() {
    const uint id = gl_GlobalInvocationID.x;
    if (id >= pc.words) return;
    boxes[id] &= bandsPrev[id] | bandsCur[id];
}
