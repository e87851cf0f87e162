// Stage `smooth` on the CPU (SPEC 4): the separable binomial filter on integer
// numerators, scaled by 1/W once at the end, so the float result is exact.
//
// Schedule: each task owns a run of output slices. It expands the bit rows of
// the slices it needs (its own plus `radius` either side) to bytes, filters
// them in x and then y into a small ring of slices that stays in L2, and sums
// that ring in z straight into the float output. Every inner loop runs over a
// whole row of bytes or integers, which the compiler vectorises.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/SmoothCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <cstring>

#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/SmoothCpuState.h"

HWY_BEFORE_NAMESPACE();
// GCC vectorises these loops to 256-bit vectors on AVX-512 too: smooth took
// 0.46 ms so and 0.55 at 512 bits (thesis-medium, medians of 4 interleaved
// runs; the other stages gained nothing, shade lost 50 %).
#if HWY_COMPILER_GCC_ACTUAL
#pragma GCC target("prefer-vector-width=256")
#endif
namespace cb::cpu::HWY_NAMESPACE {
namespace {

// Eight bits -> eight bytes of 0/1, little-endian: entry b has byte n = bit n of b.
constexpr std::array<uint64_t, 256> MakeExpandTable() {
    std::array<uint64_t, 256> table{};
    for (uint32_t b = 0; b < 256; ++b)
        for (uint32_t n = 0; n < 8; ++n) table[b] |= uint64_t((b >> n) & 1) << (8 * n);
    return table;
}
constexpr std::array<uint64_t, 256> kExpand = MakeExpandTable();

// bytes[0 .. 8*ceil(nx/8)) = cld bits of one row (0/1).
void ExpandRow(const uint64_t* row, uint32_t nx, uint8_t* bytes) {
    const uint32_t octets = CeilDiv(nx, 8);
    for (uint32_t o = 0; o < octets; ++o) {
        uint64_t eight = kExpand[(row[o >> 3] >> (8 * (o & 7))) & 0xff];
        std::memcpy(bytes + 8 * o, &eight, 8);
    }
}

// Numerator type after the y pass: r = 1 fits bytes (<= 16, <= 64 after z);
// r = 2 needs 16 bits (<= 256, <= 4096 after z).
template <int R>
using Acc = std::conditional_t<R == 1, uint8_t, uint16_t>;

template <int R>
constexpr int W(int d) {
    return SmoothWeight(R, d);
}

// x pass of rows [j0, j1) of slice k into xs (nx bytes per row, the slice's
// layout); `padded` is scratch of (nx + 2R + 8) bytes, zero in the R bytes at
// the start.
template <int R>
void FilterRowsX(const BitField& cld, uint32_t k, uint32_t j0, uint32_t j1, uint8_t* xs,
                 std::vector<uint8_t>& padded) {
    const uint32_t nx = cld.Extent().nx;
    for (uint32_t j = j0; j < j1; ++j) {
        ExpandRow(cld.Row(j, k), nx, padded.data() + R);
        std::fill(padded.begin() + R + nx, padded.end(), 0);  // the expansion writes up to 7 bytes past nx
        uint8_t* x = xs + size_t(nx) * j;
        const uint8_t* p = padded.data() + R;
        // Shifted row pointers: i - 1 on an unsigned index would wrap.
        const uint8_t *m2 = p - R, *m1 = p - 1, *p1 = p + 1, *p2 = p + R;
        if constexpr (R == 1) {
            for (uint32_t i = 0; i < nx; ++i) x[i] = uint8_t(m1[i] + 2 * p[i] + p1[i]);
        } else {
            for (uint32_t i = 0; i < nx; ++i) x[i] = uint8_t(m2[i] + 4 * m1[i] + 6 * p[i] + 4 * p1[i] + p2[i]);
        }
    }
}

// y pass of rows [j0, j1) from the x sums of the whole slice into `out`.
template <int R>
void FilterRowsY(const Extent3 e, const uint8_t* xs, uint32_t j0, uint32_t j1, Acc<R>* out) {
    const uint32_t nx = e.nx;
    for (uint32_t j = j0; j < j1; ++j) {
        Acc<R>* o = out + size_t(nx) * j;
        std::fill(o, o + nx, Acc<R>(0));
        for (int d = -R; d <= R; ++d) {
            const int64_t jj = int64_t(j) + d;
            if (jj < 0 || jj >= e.ny) continue;
            const uint8_t* x = xs + size_t(nx) * jj;
            const Acc<R> w = Acc<R>(W<R>(d));
            for (uint32_t i = 0; i < nx; ++i) o[i] = Acc<R>(o[i] + w * x[i]);
        }
    }
}

// x then y pass of slice k into `out` (nx*ny numerators); `xs` is scratch of a slice.
template <int R>
void FilterSliceXY(const BitField& cld, uint32_t k, std::vector<uint8_t>& xs, std::vector<uint8_t>& padded,
                   Acc<R>* out) {
    FilterRowsX<R>(cld, k, 0, cld.Extent().ny, xs.data(), padded);
    FilterRowsY<R>(cld.Extent(), xs.data(), 0, cld.Extent().ny, out);
}

// z pass of rows [j0, j1) of output slice k; slot(kk) gives slice kk's numerators.
template <int R, typename Slot>
void SumRowsZ(const Extent3 e, uint32_t k, uint32_t j0, uint32_t j1, const Slot& slot, uint32_t* acc, float* q) {
    // `e` by value: stores through acc must not be able to alias its fields,
    // or the loops below would not vectorise.
    const size_t sliceSize = size_t(e.nx) * e.ny;
    const float invW = 1.0f / float(SmoothNormaliser(R));  // a power of two: exact
    for (uint32_t j = j0; j < j1; ++j) {
        float* out = q + sliceSize * k + size_t(e.nx) * j;
        std::fill(acc, acc + e.nx, 0u);
        for (int d = -R; d <= R; ++d) {
            const int64_t kk = int64_t(k) + d;
            if (kk < 0 || kk >= e.nz) continue;
            const Acc<R>* in = slot(kk) + size_t(e.nx) * j;
            const uint32_t w = uint32_t(W<R>(d));
            for (uint32_t i = 0; i < e.nx; ++i) acc[i] += w * in[i];
        }
        for (uint32_t i = 0; i < e.nx; ++i) out[i] = float(acc[i]) * invW;
    }
}

template <int R>
void SmoothSlices(const BitField& cld, float* q, uint32_t k0, uint32_t k1) {
    const Extent3 e = cld.Extent();
    const size_t sliceSize = size_t(e.nx) * e.ny;
    constexpr int kRing = 2 * R + 1;
    // ring[k mod kRing] holds the xy numerators of slice k.
    std::vector<Acc<R>> ring(sliceSize * kRing);
    std::vector<uint8_t> xs(sliceSize), padded(e.nx + 2 * R + 8, 0);
    std::vector<uint32_t> acc(e.nx);
    auto slot = [&](int64_t k) { return ring.data() + sliceSize * size_t(k % kRing); };

    const int64_t first = std::max<int64_t>(0, int64_t(k0) - R);
    int64_t filtered = first;  // next slice to filter
    for (uint32_t k = k0; k < k1; ++k) {
        const int64_t need = std::min<int64_t>(int64_t(k) + R, int64_t(e.nz) - 1);
        for (; filtered <= need; ++filtered) FilterSliceXY<R>(cld, uint32_t(filtered), xs, padded, slot(filtered));
        SumRowsZ<R>(e, k, 0, e.ny, slot, acc.data(), q);
    }
}

// A share [k0, k1) of a sweep of shares in ascending order: one ring, kept in
// `state` between the calls, so that the slices a share has filtered in x and
// y for its last outputs serve the next share's first ones, and each slice is
// filtered once per sweep as in the whole call. Rows of each slice are spread
// over the arena. The numerators are integers, so the result does not depend
// on how the work is split.
template <int R>
void SmoothShare(const BitField& cld, float* q, uint32_t k0, uint32_t k1, SmoothShareState& state,
                 tbb::task_arena& arena) {
    const Extent3 e = cld.Extent();
    const size_t sliceSize = size_t(e.nx) * e.ny;
    constexpr int kRing = 2 * R + 1;
    const bool resume = k0 > 0 && state.cld == &cld && state.radius == R && state.next == k0 &&
                        state.extent == e;
    if (!resume) {
        state.ring.resize(sizeof(Acc<R>) * sliceSize * kRing);
        state.xs.resize(sliceSize);
        state.filtered = uint32_t(std::max<int64_t>(0, int64_t(k0) - R));
    }
    state.cld = nullptr;  // not resumable until this share has finished
    Acc<R>* ring = reinterpret_cast<Acc<R>*>(state.ring.data());
    auto slot = [&](int64_t k) { return ring + sliceSize * size_t(k % kRing); };
    const uint32_t rowGrain = std::max<uint32_t>(1, 16384 / std::max<uint32_t>(e.nx, 1));
    const tbb::blocked_range<uint32_t> rows(0, e.ny, rowGrain);
    arena.execute([&] {
        for (uint32_t k = k0; k < k1; ++k) {
            const uint32_t need = std::min(k + R, e.nz - 1);
            for (; state.filtered <= need; ++state.filtered) {
                const uint32_t kk = state.filtered;
                tbb::parallel_for(rows, [&](const tbb::blocked_range<uint32_t>& r) {
                    std::vector<uint8_t> padded(e.nx + 2 * R + 8, 0);
                    FilterRowsX<R>(cld, kk, r.begin(), r.end(), state.xs.data(), padded);
                });
                tbb::parallel_for(rows, [&](const tbb::blocked_range<uint32_t>& r) {
                    FilterRowsY<R>(e, state.xs.data(), r.begin(), r.end(), slot(kk));
                });
            }
            tbb::parallel_for(rows, [&](const tbb::blocked_range<uint32_t>& r) {
                std::vector<uint32_t> acc(e.nx);
                SumRowsZ<R>(e, k, r.begin(), r.end(), slot, acc.data(), q);
            });
        }
    });
    state.cld = &cld, state.radius = R, state.next = k1, state.extent = e;
}

}  // namespace

Status Smooth(tbb::task_arena& arena, SmoothCpuState& state, int radius, const Buffer& cldBuffer, Buffer& qBuffer,
              SliceRange slices) {
    if (radius < 0 || radius > 2) return MakeError("cpu: smooth radius must be 0, 1 or 2");
    const BitField& cld = static_cast<const BufferCpu&>(cldBuffer).Bits();
    float* q = static_cast<BufferCpu&>(qBuffer).F32();
    const Extent3 e = cld.Extent();
    // The share: output slices k in [k0, k1). Each reads cld slices k - radius ..
    // k + radius, so a share of s slices filters s + 2 radius slices in x and y.
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) return {};

    if (radius == 0) {
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<uint32_t>(e.ny * k0, e.ny * k1, 64), [&](const tbb::blocked_range<uint32_t>& rows) {
                std::vector<uint8_t> bytes(e.nx + 8);
                for (uint32_t r = rows.begin(); r != rows.end(); ++r) {
                    ExpandRow(cld.Row(r % e.ny, r / e.ny), e.nx, bytes.data());
                    float* out = q + size_t(e.nx) * r;
                    for (uint32_t i = 0; i < e.nx; ++i) out[i] = float(bytes[i]);
                }
            });
        });
        return {};
    }

    if (!slices.IsWhole(e.nz)) {
        if (radius == 1)
            SmoothShare<1>(cld, q, k0, k1, state.share, arena);
        else
            SmoothShare<2>(cld, q, k0, k1, state.share, arena);
        return {};
    }

    // One run of slices per thread: each run recomputes `radius` slices of
    // x/y filtering on either side, so fewer, longer runs waste less.
    const uint32_t runs = std::min<uint32_t>(e.nz, uint32_t(arena.max_concurrency()));
    const uint32_t grain = CeilDiv(e.nz, runs);
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<uint32_t>(0, e.nz, grain),
            [&](const tbb::blocked_range<uint32_t>& slices) {
                if (radius == 1) SmoothSlices<1>(cld, q, slices.begin(), slices.end());
                else SmoothSlices<2>(cld, q, slices.begin(), slices.end());
            },
            tbb::simple_partitioner());
    });
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(Smooth);

uint64_t SmoothCpuState::ScratchBytes(const Scene& scene) const {
    const int r = scene.smooth.radius;
    if (r <= 0) return 0;
    const Extent3 e = scene.grid.size;
    const uint64_t slice = uint64_t(e.nx) * e.ny;
    const uint64_t runs = std::min<uint64_t>(e.nz, uint64_t(threads));
    const uint64_t numeratorBytes = r == 1 ? 1 : 2;  // at r = 1 a byte, at r = 2 two
    const uint64_t perRun = SaturatingAdd(SaturatingMul(slice, (2 * r + 1) * numeratorBytes + 1),
                                          uint64_t(e.nx) + 2 * r + 8 + 4 * uint64_t(e.nx));
    uint64_t bytes = SaturatingMul(runs, perRun);
    if (scene.render.slicesPerFrame > 0)
        bytes = SaturatingAdd(bytes, SaturatingMul(slice, (2 * r + 1) * numeratorBytes + 1));
    return bytes;
}

Status BackendCpu::Smooth(int radius, const Buffer& cldBuffer, Buffer& qBuffer, SliceRange slices) {
    return HWY_DYNAMIC_DISPATCH(Smooth)(mArena, mStages.Get<SmoothCpuState>(), radius, cldBuffer, qBuffer, slices);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
