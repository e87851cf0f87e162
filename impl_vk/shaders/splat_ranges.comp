#version 450
// Per screen tile t (and t = tiles): bases[t] = the first sorted pair whose
// tile is >= t, by binary search, so that tile t's splats are
// values[bases[t] .. bases[t + 1]) (splat_composite.comp).
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer Keys { uint keys[]; };  // sorted
layout(std430, binding = 1) writeonly buffer Bases { uint bases[]; };
layout(push_constant) uniform Params { uint pairs, tiles; } pc;

void main() {
    const uint t = gl_GlobalInvocationID.x;
    if (t > pc.tiles) return;
    uint lo = 0u, hi = pc.pairs;
    while (lo < hi) {
        const uint mid = lo + (hi - lo) / 2u;
        if (keys[mid] < t) lo = mid + 1u;
        else hi = mid;
    }
    bases[t] = lo;
}
