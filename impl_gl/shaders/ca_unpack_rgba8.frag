// Stage `ca`, the thesis's layout: RGBA8UI voxels back to the three packed
// R32UI fields the other stages read; one fragment per 32-voxel word.
layout(binding = 0) uniform usampler2DArray state;
uniform int layer;
uniform ivec3 size;
layout(location = 0) out uint hum;
layout(location = 1) out uint act;
layout(location = 2) out uint cld;

void main() {
    const int i0 = 32 * int(gl_FragCoord.x), j = int(gl_FragCoord.y);
    const int count = min(32, size.x - i0);
    uvec3 bits = uvec3(0u);
    for (int b = 0; b < count; ++b) bits |= (texelFetch(state, ivec3(i0 + b, j, layer), 0).rgb & 1u) << uint(b);
    hum = bits.x;
    act = bits.y;
    cld = bits.z;
}
