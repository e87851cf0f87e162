// The algorithm: random numbers (SPEC 1, docs/contract.md). Every implementation draws
// the same numbers from this stateless hash; the GLSL twin is core/math/random.glsl
// (added with the GPU backends) and must stay identical.
#pragma once

#include <cmath>
#include <cstdint>

namespace cb {

enum RandomStream : uint32_t {
    kStreamExtinction = 0,
    kStreamHumidity = 1,
    kStreamActivation = 2,
    kStreamOther = 3,  // documented per use in docs/pipeline.md
};

// The step value used for the automaton's initial state (SPEC 3).
inline constexpr uint32_t kInitialStateStep = 0xFFFFFFFFu;

constexpr uint32_t LowBias32(uint32_t x) {
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

constexpr uint32_t StreamKey(uint32_t seed, uint32_t step, uint32_t stream) {
    return LowBias32(seed ^ LowBias32(step * 4u + stream + 0x9E3779B9u));
}

// rand24 with the key already folded: 0 .. 2^24-1.
constexpr uint32_t Rand24FromKey(uint32_t key, uint32_t voxel) { return LowBias32(voxel ^ key) >> 8; }

constexpr uint32_t Rand24(uint32_t seed, uint32_t step, uint32_t stream, uint32_t voxel) {
    return Rand24FromKey(StreamKey(seed, step, stream), voxel);
}

// Q(p) = round(p * 2^24) for p in [0, 1]; the event fires iff rand24 < Q.
inline uint32_t QuantizeProbability(double p) { return static_cast<uint32_t>(std::llround(p * 16777216.0)); }

// Host-side seeded generator (PCG-XSH-RR 64/32, O'Neill 2014). Used for the
// ellipsoid list and jitter so that every standard library gives the same values.
class Pcg32 {
  public:
    explicit Pcg32(uint64_t seed, uint64_t sequence = 0xda3e39cb94b95bdbull) {
        mIncrement = (sequence << 1u) | 1u;
        NextU32();
        mState += seed;
        NextU32();
    }

    uint32_t NextU32() {
        uint64_t old = mState;
        mState = old * 6364136223846793005ull + mIncrement;
        uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
        uint32_t rot = static_cast<uint32_t>(old >> 59u);
        return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
    }

    // Uniform in [0, 1) with 53 random bits.
    double NextDouble() {
        uint64_t hi = NextU32() >> 5;  // 27 bits
        uint64_t lo = NextU32() >> 6;  // 26 bits
        return static_cast<double>((hi << 26) | lo) * (1.0 / 9007199254740992.0);
    }

    // Uniform in [lo, hi).
    double Uniform(double lo, double hi) { return lo + (hi - lo) * NextDouble(); }

    // Uniform integer in [0, bound) without modulo bias (bound > 0).
    uint32_t Below(uint32_t bound) {
        uint32_t threshold = (0u - bound) % bound;
        for (;;) {
            uint32_t r = NextU32();
            if (r >= threshold) return r % bound;
        }
    }

    // The whole generator state, to save and restore a run (harness/run/SimulationState.h).
    uint64_t StateWord() const { return mState; }
    uint64_t Increment() const { return mIncrement; }
    void Restore(uint64_t state, uint64_t increment) {
        mState = state;
        mIncrement = increment;
    }

  private:
    uint64_t mState = 0;
    uint64_t mIncrement = 0;
};

}  // namespace cb
