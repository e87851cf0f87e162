// GLSL twin of core/math/Automaton.h (SPEC 3): the automaton's rules per voxel and
// on 32-voxel words. Needs random.glsl before it. Must stay in step with the C++.
#ifndef CLOUDBENCH_AUTOMATON_GLSL
#define CLOUDBENCH_AUTOMATON_GLSL

// The in-row part of the growth neighbourhood: act at i-1, i+1, i-2, i+2 for
// every bit of word a, with prev and next the row's neighbouring words (0 outside).
uint CaRowNeighbours(uint a, uint prev, uint next) {
    return ((a << 1) | (prev >> 31)) | ((a >> 1) | (next << 31)) | ((a << 2) | (prev >> 30)) |
           ((a >> 2) | (next << 30));
}

// Growth on (hum, act, cld) words or 0/1 voxels: hum & !act, !act & hum & f, cld | act.
uvec3 CaGrowth(uvec3 s, uint f) { return uvec3(s.x & ~s.y, ~s.y & s.x & f, s.z | s.y); }

struct CaEvents {
    uint keyExt, keyHum, keyAct;
    uint qExt, qHum, qAct;
};

CaEvents MakeCaEvents(uint seed, uint step, uint qExt, uint qHum, uint qAct) {
    return CaEvents(StreamKey(seed, step, 0u), StreamKey(seed, step, 1u), StreamKey(seed, step, 2u), qExt, qHum, qAct);
}

// Events at voxel v of region r on the grown state g (0/1 each); r = 0 clears cld.
uvec3 CaVoxelEvents(uvec3 g, uint r, uint v, CaEvents e) {
    if (r == 0u) return uvec3(g.x, g.y, 0u);
    if (g.z != 0u && e.qExt != 0u && RegionEventFires(Rand24FromKey(e.keyExt, v), 255u - r, e.qExt)) g.z = 0u;
    if (g.x == 0u && e.qHum != 0u && RegionEventFires(Rand24FromKey(e.keyHum, v), r, e.qHum)) g.x = 1u;
    if (g.y == 0u && e.qAct != 0u && RegionEventFires(Rand24FromKey(e.keyAct, v), r, e.qAct)) g.y = 1u;
    return g;
}

// The initial (hum, act, cld) at voxel v; keys from StreamKey(seed, 0xFFFFFFFF, 1 and 2).
uvec3 CaInitialVoxel(uint keyHum, uint keyAct, uint qHum0, uint qAct0, uint v) {
    return uvec3(Rand24FromKey(keyHum, v) < qHum0 ? 1u : 0u, Rand24FromKey(keyAct, v) < qAct0 ? 1u : 0u, 0u);
}

#endif
