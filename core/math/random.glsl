// GLSL twin of core/math/Random.h (SPEC 1). Must stay identical to the C++.
#ifndef CLOUDBENCH_RANDOM_GLSL
#define CLOUDBENCH_RANDOM_GLSL

uint LowBias32(uint x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

uint StreamKey(uint seed, uint step, uint stream) { return LowBias32(seed ^ LowBias32(step * 4u + stream + 0x9E3779B9u)); }

uint Rand24FromKey(uint key, uint voxel) { return LowBias32(voxel ^ key) >> 8; }

// rand24 < (R*q + 127)/255 (core/math/Rules.h RegionProbability), exact in uint32.
bool RegionEventFires(uint rand24, uint region, uint q) { return rand24 < (region * q + 127u) / 255u; }

#endif
