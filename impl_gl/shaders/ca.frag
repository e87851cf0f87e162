// Stage `ca` (SPEC 3), packed layout (the thesis's section 9.2): one fragment
// per 32-voxel word of slice `layer`; bitwise rules, random numbers drawn only
// where an event can flip a bit. Reads the step-t textures, writes step t+1
// (before advection) into three R32UI targets.
layout(binding = 0) uniform usampler2DArray humIn;
layout(binding = 1) uniform usampler2DArray actIn;
layout(binding = 2) uniform usampler2DArray cldIn;
layout(binding = 3) uniform usampler2DArray region;  // R8UI, one texel per voxel
uniform int layer;
uniform ivec3 size;   // nx, ny, nz
uniform int words;    // ceil(nx / 32)
uniform uint seed, step, qExt, qHum, qAct;
layout(location = 0) out uint humOut;
layout(location = 1) out uint actOut;
layout(location = 2) out uint cldOut;

uint ActWord(int w, int j, int k) {
    if (w < 0 || w >= words || j < 0 || k < 0 || j >= size.y || k >= size.z) return 0u;
    return texelFetch(actIn, ivec3(w, j, k), 0).r;
}

void main() {
    const int w = int(gl_FragCoord.x), j = int(gl_FragCoord.y), k = layer;
    const uint a = ActWord(w, j, k), prev = ActWord(w - 1, j, k), next = ActWord(w + 1, j, k);
    uint f = ((a << 1) | (prev >> 31)) | ((a >> 1) | (next << 31)) | ((a << 2) | (prev >> 30)) | ((a >> 2) | (next << 30));
    f |= ActWord(w, j + 1, k) | ActWord(w, j - 1, k) | ActWord(w, j + 2, k) | ActWord(w, j - 2, k);
    f |= ActWord(w, j, k + 1) | ActWord(w, j, k - 1) | ActWord(w, j, k - 2);

    const uint h = texelFetch(humIn, ivec3(w, j, k), 0).r, c = texelFetch(cldIn, ivec3(w, j, k), 0).r;
    const uint hum1 = h & ~a, cld1 = c | a, act1 = ~a & h & f;

    const uint keyExt = StreamKey(seed, step, 0u), keyHum = StreamKey(seed, step, 1u), keyAct = StreamKey(seed, step, 2u);
    const uint i0 = 32u * uint(w), count = min(32u, uint(size.x) - i0);
    const uint v0 = i0 + uint(size.x) * (uint(j) + uint(size.y) * uint(k));
    uint inRegion = 0u, ext = 0u, hum = 0u, act = 0u;
    for (uint b = 0u; b < count; ++b) {
        const uint r = texelFetch(region, ivec3(int(i0 + b), j, k), 0).r;
        if (r == 0u) continue;  // P_hum = P_act = 0 and cld is cleared: nothing to draw
        const uint bit = 1u << b;
        inRegion |= bit;
        if ((cld1 & bit) != 0u && qExt != 0u && RegionEventFires(Rand24FromKey(keyExt, v0 + b), 255u - r, qExt)) ext |= bit;
        if ((hum1 & bit) == 0u && qHum != 0u && RegionEventFires(Rand24FromKey(keyHum, v0 + b), r, qHum)) hum |= bit;
        if ((act1 & bit) == 0u && qAct != 0u && RegionEventFires(Rand24FromKey(keyAct, v0 + b), r, qAct)) act |= bit;
    }
    humOut = hum1 | hum;
    actOut = act1 | act;
    cldOut = cld1 & inRegion & ~ext;
}
