// Stage `smooth` (SPEC 4) as a fragment pass: one fragment per voxel of slice
// `layer`; the integer binomial sum over the neighbourhood of the packed bit
// field (32 voxels per R32UI texel), scaled by 1/W (exact).
layout(binding = 0) uniform usampler2DArray cld;
uniform int layer;
uniform int radius;
uniform float invW;
uniform ivec3 size;
layout(location = 0) out float q;

uint Bit(int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= size.x || j >= size.y || k >= size.z) return 0u;
    return (texelFetch(cld, ivec3(i >> 5, j, k), 0).r >> uint(i & 31)) & 1u;
}

void main() {
    const ivec2 p = ivec2(gl_FragCoord.xy);
    int sum = 0;
    for (int dk = -radius; dk <= radius; ++dk)
        for (int dj = -radius; dj <= radius; ++dj) {
            const int wjk = SmoothWeight(radius, dj) * SmoothWeight(radius, dk);
            for (int di = -radius; di <= radius; ++di)
                sum += wjk * SmoothWeight(radius, di) * int(Bit(p.x + di, p.y + dj, layer + dk));
        }
    q = float(sum) * invW;
}
