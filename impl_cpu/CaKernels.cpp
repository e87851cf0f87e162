// The automaton's kernels on every SIMD target: event bits and the region's
// nonzero mask in Highway vectors, and the row loop that uses them.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/CaKernels.cpp"
#include "impl_cpu/CaKernels.h"

#include <hwy/foreach_target.h>  // includes this file again, once per target
#include <hwy/highway.h>

#include <cstring>

#include "core/math/Random.h"
#include "core/math/Rules.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// The mask's lanes as bits 0 .. N-1 of a word (N <= 64).
template <class D>
HWY_INLINE uint64_t MaskWord(D d, hn::Mask<D> m) {
    uint8_t bytes[8] = {};
    hn::StoreMaskBits(d, m, bytes);
    uint64_t word;
    std::memcpy(&word, bytes, sizeof word);
    return word;
}

uint64_t EventBits(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    const hn::ScalableTag<uint32_t> d;
    const hn::Rebind<uint8_t, decltype(d)> d8;
    const size_t N = hn::Lanes(d);
    const auto keyV = hn::Set(d, key), qV = hn::Set(d, q), c255 = hn::Set(d, 255u), c127 = hn::Set(d, 127u);
    const auto one = hn::Set(d, 1u);
    // Iota once: Highway 1.0.3 builds it through memory, and a load from
    // narrow stores just made stalls (store forwarding fails).
    const auto lane = hn::Iota(d, 0u);
    uint64_t bits = 0;
    for (size_t chunk = 0; chunk < 64; chunk += N) {
        // Rand24FromKey: LowBias32(v ^ key) >> 8, in wrapping 32-bit lanes.
        auto x = hn::Xor(hn::Add(lane, hn::Set(d, v0 + uint32_t(chunk))), keyV);
        x = hn::Xor(x, hn::ShiftRight<16>(x));
        x = hn::Mul(x, hn::Set(d, 0x7feb352du));
        x = hn::Xor(x, hn::ShiftRight<15>(x));
        x = hn::Mul(x, hn::Set(d, 0x846ca68bu));
        x = hn::Xor(x, hn::ShiftRight<16>(x));
        const auto rnd = hn::ShiftRight<8>(x);
        auto region = hn::PromoteTo(d, hn::LoadU(d8, r + chunk));
        if (invert) region = hn::Sub(c255, region);
        // RegionEventFires: 255 (rand24 + 1) <= R q + 127.
        const auto lhs = hn::Mul(hn::Add(rnd, one), c255);
        const auto rhs = hn::Add(hn::Mul(region, qV), c127);
        bits |= MaskWord(d, hn::Not(hn::Lt(rhs, lhs))) << chunk;
    }
    return bits;
}

uint64_t NonZeroMask(const uint8_t* r) {
    const hn::ScalableTag<uint8_t> d;
    const size_t N = hn::Lanes(d);
    uint64_t bits = 0;
    for (size_t chunk = 0; chunk < 64; chunk += N)
        bits |= MaskWord(d, hn::Ne(hn::LoadU(d, r + chunk), hn::Zero(d))) << chunk;
    return bits;
}

HWY_INLINE CaBits<uint64_t> StepWord(CaBits<uint64_t> s, uint64_t f, const uint8_t* r, uint64_t valid, uint32_t v0,
                                     const CaEvents& e) {
    const CaBits<uint64_t> grown = CaGrowth(s, f);  // no bits past nx, as s has none
    // Where R = 0 no event can change the result (P_hum = P_act = 0 and cld is
    // cleared), so only voxels with R > 0 that an event could flip draw numbers.
    const uint64_t inRegion = NonZeroMask(r) & valid;
    CaBits<uint64_t> next{grown.hum, grown.act, grown.cld & inRegion};
    if (next.cld && e.qExt) next.cld &= ~(EventBits(e.keyExt, v0, r, e.qExt, /*invert=*/true) & next.cld);
    if (const uint64_t candidates = ~grown.hum & inRegion; candidates && e.qHum)
        next.hum |= EventBits(e.keyHum, v0, r, e.qHum, false) & candidates;
    if (const uint64_t candidates = ~grown.act & inRegion; candidates && e.qAct)
        next.act |= EventBits(e.keyAct, v0, r, e.qAct, false) & candidates;
    return next;
}

CaBits<uint64_t> StepWordOnce(CaBits<uint64_t> s, uint64_t f, const uint8_t* r, uint64_t valid, uint32_t v0,
                              const CaEvents& e) {
    return StepWord(s, f, r, valid, v0, e);
}

void StepRows(const CaStepRowsJob& job, uint32_t r0, uint32_t r1) {
    const BitField &hum = *job.hum, &act = *job.act, &cld = *job.cld;
    const Extent3 e = hum.Extent();
    const uint32_t words = hum.WordsPerRow();
    const uint64_t lastMask = hum.LastWordMask();
    for (uint32_t row = r0; row != r1; ++row) {
        const uint32_t j = row % e.ny, k = row / e.ny;
        const uint64_t* a = act.Row(j, k);
        const uint64_t* h = hum.Row(j, k);
        const uint64_t* c = cld.Row(j, k);
        // The 7 neighbour rows of the growth rule that are not in this row.
        const uint64_t* across[7] = {act.RowOrNull(j + 1, k),         act.RowOrNull(int64_t(j) - 1, k),
                                     act.RowOrNull(j + 2, k),         act.RowOrNull(int64_t(j) - 2, k),
                                     act.RowOrNull(j, k + 1),         act.RowOrNull(j, int64_t(k) - 1),
                                     act.RowOrNull(j, int64_t(k) - 2)};
        const uint8_t* rRow = job.region + size_t(e.nx) * (j + size_t(e.ny) * k);
        uint64_t* hOut = job.humOut->Row(j, k);
        uint64_t* aOut = job.actOut->Row(j, k);
        uint64_t* cOut = job.cldOut->Row(j, k);
        const uint32_t rowBase = VoxelIndex(e, 0, j, k);
        for (uint32_t w = 0; w < words; ++w) {
            const uint64_t aw = a[w];
            const uint64_t prev = w > 0 ? a[w - 1] : 0;
            const uint64_t next = w + 1 < words ? a[w + 1] : 0;
            uint64_t f = CaRowNeighbours(aw, prev, next);
            for (const uint64_t* n : across)
                if (n) f |= n[w];
            const uint32_t i0 = 64 * w;
            const CaBits<uint64_t> s =
                StepWord({h[w], aw, c[w]}, f, rRow + i0, w == words - 1 ? lastMask : ~0ull, rowBase + i0, job.events);
            hOut[w] = s.hum;
            aOut[w] = s.act;
            cOut[w] = s.cld;
        }
    }
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(EventBits);
HWY_EXPORT(NonZeroMask);
HWY_EXPORT(StepWordOnce);
HWY_EXPORT(StepRows);

uint64_t EventBitsScalar(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    uint64_t bits = 0;
    for (uint32_t b = 0; b < 64; ++b) {
        uint32_t region = invert ? 255u - r[b] : r[b];
        bool fires = Rand24FromKey(key, v0 + b) < RegionProbability(region, q);
        bits |= uint64_t(fires) << b;
    }
    return bits;
}

uint64_t NonZeroMaskScalar(const uint8_t* r) {
    uint64_t bits = 0;
    for (uint32_t b = 0; b < 64; ++b) bits |= uint64_t(r[b] != 0) << b;
    return bits;
}

uint64_t EventBitsVector(uint32_t key, uint32_t v0, const uint8_t* r, uint32_t q, bool invert) {
    return HWY_DYNAMIC_DISPATCH(EventBits)(key, v0, r, q, invert);
}

uint64_t NonZeroMaskVector(const uint8_t* r) { return HWY_DYNAMIC_DISPATCH(NonZeroMask)(r); }

CaBits<uint64_t> CaStepWord(CaBits<uint64_t> s, uint64_t f, const uint8_t* r, uint64_t valid, uint32_t v0,
                            const CaEvents& e) {
    return HWY_DYNAMIC_DISPATCH(StepWordOnce)(s, f, r, valid, v0, e);
}

void CaStepRows(const CaStepRowsJob& job, uint32_t r0, uint32_t r1) { HWY_DYNAMIC_DISPATCH(StepRows)(job, r0, r1); }

}  // namespace cb::cpu
#endif  // HWY_ONCE
