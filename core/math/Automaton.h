// The automaton's rules (SPEC 3) per voxel and on words of voxels, in one
// place. GLSL twin: core/math/automaton.glsl. The GPU backends pack 32 voxels
// a word and the CPU 64; both use CaGrowth and CaRowNeighbours on their words.
// The GPUs apply CaVoxelEvents bit by bit; the CPU's bit-parallel events
// (impl_cpu/CaKernels.h CaStepWord) are tested against it (tests/GlslTwinTest.cpp).
#pragma once

#include <cstdint>

#include "core/math/Random.h"
#include "core/math/Rules.h"

namespace cb {

// hum, act, cld: one bit per voxel in each word (or 0/1 for one voxel).
template <typename Word>
struct CaBits {
    Word hum, act, cld;
    friend constexpr bool operator==(const CaBits&, const CaBits&) = default;
};

// The in-row part of the growth neighbourhood f (SPEC 3, kGrowthNeighbours):
// act at i-1, i+1, i-2, i+2 for every bit of word `a`, with `prev` and `next`
// the words before and after it in the row (0 outside the row).
template <typename Word>
constexpr Word CaRowNeighbours(Word a, Word prev, Word next) {
    constexpr int kLast = 8 * sizeof(Word) - 1;
    return Word(a << 1 | prev >> kLast) | Word(a >> 1 | next << kLast) | Word(a << 2 | prev >> (kLast - 1)) |
           Word(a >> 2 | next << (kLast - 1));
}

// Step 1, growth: hum' = hum & !act, act' = !act & hum & f, cld' = cld | act.
// Words or single 0/1 voxels; no bit is set that hum, act or cld did not have.
template <typename Word>
constexpr CaBits<Word> CaGrowth(CaBits<Word> s, Word f) {
    return {Word(s.hum & ~s.act), Word(~s.act & s.hum & f), Word(s.cld | s.act)};
}

// The per-step keys and quantised probabilities of the three events.
struct CaEvents {
    uint32_t keyExt, keyHum, keyAct;  // StreamKey(seed, step, kStream...)
    uint32_t qExt, qHum, qAct;        // QuantizeProbability(p_...)
};

inline CaEvents MakeCaEvents(uint32_t seed, uint32_t step, uint32_t qExt, uint32_t qHum, uint32_t qAct) {
    return {StreamKey(seed, step, kStreamExtinction),
            StreamKey(seed, step, kStreamHumidity),
            StreamKey(seed, step, kStreamActivation),
            qExt,
            qHum,
            qAct};
}

// Steps 2-3 at voxel v of region value r, on the grown state g (0/1 each):
// extinction clears cld with P = (255 - r) q_ext, humidity and activation set
// hum and act with P = r q; r = 0 clears cld and draws nothing. A number is
// drawn only where its event could flip the bit (the result is the same).
constexpr CaBits<uint32_t> CaVoxelEvents(CaBits<uint32_t> g, uint32_t r, uint32_t v, const CaEvents& e) {
    if (r == 0) return {g.hum, g.act, 0};
    if (g.cld && e.qExt && RegionEventFires(Rand24FromKey(e.keyExt, v), 255u - r, e.qExt)) g.cld = 0;
    if (!g.hum && e.qHum && RegionEventFires(Rand24FromKey(e.keyHum, v), r, e.qHum)) g.hum = 1;
    if (!g.act && e.qAct && RegionEventFires(Rand24FromKey(e.keyAct, v), r, e.qAct)) g.act = 1;
    return g;
}

// The initial state (SPEC 3) at voxel v: hum with P = q_hum0, act with P = q_act0,
// no cloud. keyHum, keyAct: StreamKey(seed, kInitialStateStep, kStreamHumidity / kStreamActivation).
constexpr CaBits<uint32_t> CaInitialVoxel(uint32_t keyHum, uint32_t keyAct, uint32_t qHum0, uint32_t qAct0,
                                          uint32_t v) {
    return {uint32_t(Rand24FromKey(keyHum, v) < qHum0), uint32_t(Rand24FromKey(keyAct, v) < qAct0), 0};
}

}  // namespace cb
