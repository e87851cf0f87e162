// Stage `shade` on the CPU (SPEC 6): inverse shear-warp, one slice after another
// from the sun side. On several threads the slice plane is cut into bands and
// the sweep into blocks of slices, and the tiles run as a pipeline (ShadeGrid).
// How a slice reads the previous one depends on where its rows lie: in place
// when the slices are contiguous planes (w = z), copied per tile and slice
// when rows are a z-slice apart (w = y), copied transposed per tile of 16
// slices when a row is strided (w = x); taps outside the slice read T = 1,
// q = 0. The row kernel runs on whole vectors. At resolution f > 1 the same
// loop runs on the mean of each f^3 block and the result is read back
// trilinearly (ShadeCoarseCpu-inl.h). The ground's shadow is in ShadowCpu.cpp.
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/ShadeCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/parallel_for_each.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "core/pipeline/ShadePlan.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/ShadeCoarseCpu-inl.h"
#include "impl_cpu/ShadeCpuState.h"
#include "impl_cpu/ShadeSchedule.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace {

constexpr uint32_t kMaxStackRow = 512;
// How many grid rows ahead a sweep along x asks for its cache lines.
constexpr uint32_t kPrefetchRows = 8;
// The row kernel runs on whole vectors of this many cells; a shorter rest is
// padded to it (the compiler's scalar epilogue costs ten times a lane).
constexpr uint32_t kRowLanes = 16;

uint32_t WholeVectors(uint32_t n) { return n / kRowLanes * kRowLanes; }
uint32_t PaddedToVectors(uint32_t n) { return (n + kRowLanes - 1) / kRowLanes * kRowLanes; }

// Sixteen floats (a cache line along x, or sixteen cells of a row) in the
// compilers' generic vectors (GCC and Clang): one AVX-512 register here,
// split on narrower CPUs.
// Passed by value only between functions of this file: GCC's note that the
// ABI of such a vector depends on the target does not apply (GCC and Clang).
#pragma GCC diagnostic ignored "-Wpsabi"
typedef float Lanes16 __attribute__((vector_size(64)));

Lanes16 LoadLanes(const float* p) {
    Lanes16 v;
    std::memcpy(&v, p, sizeof v);
    return v;
}
void StoreLanes(float* p, const Lanes16& v) { std::memcpy(p, &v, sizeof v); }

// Lane c of the two-input shuffle that swaps bit B of the row index with bit
// B of the lane: row r (bit B clear) takes lanes with bit B clear from itself
// and the rest from row r + B; row r + B the other halves.
constexpr int SwapBitLane(int B, bool rowWithBit, int c) {
    return (c & B) == 0 ? (rowWithBit ? c + B : c) : (rowWithBit ? 16 + c : 16 + c - B);
}

template <int B, bool kRowWithBit, int... C>
Lanes16 SwapBitShuffle(const Lanes16& a, const Lanes16& b, std::integer_sequence<int, C...>) {
    return __builtin_shufflevector(a, b, SwapBitLane(B, kRowWithBit, C)...);
}

template <int B>
void SwapIndexBit(Lanes16 (&v)[16]) {
    constexpr auto lanes = std::make_integer_sequence<int, 16>();
    for (int r = 0; r < 16; ++r)
        if ((r & B) == 0) {
            const Lanes16 a = v[r], b = v[r + B];
            v[r] = SwapBitShuffle<B, false>(a, b, lanes);
            v[r + B] = SwapBitShuffle<B, true>(a, b, lanes);
        }
}

// v[i][j] becomes v[j][i]: the four bits of the row index swapped with the lane's.
void Transpose16(Lanes16 (&v)[16]) {
    SwapIndexBit<1>(v);
    SwapIndexBit<2>(v);
    SwapIndexBit<4>(v);
    SwapIndexBit<8>(v);
}

// The per-voxel work of one slice, with the options fixed at compile time so
// that the loop over a row vectorises (a switch per voxel stops it).
struct ShadeKernel {
    SliceAttenuation attenuation;
    StorageFormat storage;
};

template <AttenuationKind kAttenuation, StorageFormat kStorage>
void ShadeRowT(const SliceAttenuation& att, const float* __restrict t0, const float* __restrict t1,
               const float* __restrict q0, const float* __restrict q1, float fu, float fv, float* __restrict out,
               uint32_t n) {
    const float depthPerQ = att.opticalDepthPerQ, gain = att.scatterGain, ar = att.thesisAr;
    for (uint32_t a = 0; a < n; ++a) {
        const float t = Bilinear(t0[a], t0[a + 1], t1[a], t1[a + 1], fu, fv);
        const float qs = Bilinear(q0[a], q0[a + 1], q1[a], q1[a + 1], fu, fv);
        const float factor = SliceFactor(kAttenuation == AttenuationKind::Beer, depthPerQ, ar, gain, qs);
        out[a] = StoreTransmittance(kStorage, t, factor);
    }
}

void ShadeRow(const ShadeKernel& k, const float* t0, const float* t1, const float* q0, const float* q1, float fu,
              float fv, float* out, uint32_t n) {
    const SliceAttenuation& a = k.attenuation;
    const bool beer = a.kind == AttenuationKind::Beer;
    switch (k.storage) {
        case StorageFormat::Fp32:
            return beer ? ShadeRowT<AttenuationKind::Beer, StorageFormat::Fp32>(a, t0, t1, q0, q1, fu, fv, out, n)
                        : ShadeRowT<AttenuationKind::Thesis, StorageFormat::Fp32>(a, t0, t1, q0, q1, fu, fv, out, n);
        case StorageFormat::Fp16:
            return beer ? ShadeRowT<AttenuationKind::Beer, StorageFormat::Fp16>(a, t0, t1, q0, q1, fu, fv, out, n)
                        : ShadeRowT<AttenuationKind::Thesis, StorageFormat::Fp16>(a, t0, t1, q0, q1, fu, fv, out, n);
        case StorageFormat::Unorm8:
            return beer ? ShadeRowT<AttenuationKind::Beer, StorageFormat::Unorm8>(a, t0, t1, q0, q1, fu, fv, out, n)
                        : ShadeRowT<AttenuationKind::Thesis, StorageFormat::Unorm8>(a, t0, t1, q0, q1, fu, fv, out, n);
    }
}

// One sweep over slices of the plan's grid (full or coarse): Q in, T out,
// both of plan.cells. Slice m > 0 reads slice m - 1 of T and Q (Row: in place,
// Block: copied, TileAlongX: copied transposed); taps outside the slice read
// T = 1, q = 0 (the constant rows below, or gathered edge cells).
struct ShadeSweep {
    const ShadePlan& plan;
    ShadeKernel kernel;
    const float* Q;
    float* T;
    size_t su, sv, sw;               // strides of u, v, w in the grid
    std::vector<float> ones, zeros;  // nu + 1 each: a row outside the slice

    ShadeSweep(const ShadePlan& p, StorageFormat storage, const float* q, float* t)
        : plan(p), kernel{p.attenuation, storage}, Q(q), T(t) {
        const size_t stride[3] = {1, p.cells[0], size_t(p.cells[0]) * p.cells[1]};
        su = stride[p.geometry.u];
        sv = stride[p.geometry.v];
        sw = stride[p.geometry.w];
        ones.assign(size_t(p.nu) + 1, 1.0f);
        zeros.assign(size_t(p.nu) + 1, 0.0f);
    }

    // Cells [a0, a1) of row b of slice m > 0, gathered: the taps into slice
    // m - 1 copied into padded rows first (a row's edges, or rows too short
    // for a whole vector).
    void Gathered(size_t prev, size_t cur, int64_t r0, uint32_t a0, uint32_t a1) const {
        const ShearWarp& g = plan.geometry;
        const int64_t nu = plan.nu, nv = plan.nv;
        float t0[kMaxStackRow + 1], t1[kMaxStackRow + 1], q0[kMaxStackRow + 1], q1[kMaxStackRow + 1];
        float row[kMaxStackRow];
        for (uint32_t s = a0; s < a1; s += kMaxStackRow) {
            // A few edge cells stay scalar; longer runs are padded to whole vectors.
            const uint32_t count = std::min(kMaxStackRow, a1 - s);
            const uint32_t padded = count < kRowLanes / 2 ? count : PaddedToVectors(count);
            for (uint32_t i = count + 1; i <= padded; ++i) {
                t0[i] = t1[i] = 1.0f;
                q0[i] = q1[i] = 0.0f;
            }
            for (uint32_t i = 0; i <= count; ++i) {
                const int64_t x = int64_t(s) + i + g.u0;
                const bool inU = x >= 0 && x < nu;
                const bool in0 = inU && r0 >= 0 && r0 < nv, in1 = inU && r0 + 1 >= 0 && r0 + 1 < nv;
                const size_t at0 = prev + su * size_t(inU ? x : 0) + sv * size_t(in0 ? r0 : 0);
                const size_t at1 = prev + su * size_t(inU ? x : 0) + sv * size_t(in1 ? r0 + 1 : 0);
                t0[i] = in0 ? T[at0] : 1.0f;
                q0[i] = in0 ? Q[at0] : 0.0f;
                t1[i] = in1 ? T[at1] : 1.0f;
                q1[i] = in1 ? Q[at1] : 0.0f;
            }
            ShadeRow(kernel, t0, t1, q0, q1, g.fu, g.fv, row, padded);
            for (uint32_t i = 0; i < count; ++i) T[cur + su * (s + i)] = row[i];
        }
    }

    // Cells [a0, a1) x [b0, b1) of slice m > 0 from a copy: the taps into
    // slice m - 1 are copied once into a padded block of rows (outside: T = 1,
    // q = 0), then each row is shaded from it. For rows far apart in memory
    // (u not x, or w = y: rows a slice of z apart), where reading them in
    // place costs more than the copy.
    void Block(uint32_t m, uint32_t a0, uint32_t a1, uint32_t b0, uint32_t b1) const {
        const ShearWarp& g = plan.geometry;
        const size_t prev = sw * plan.SliceW(m - 1), cur = sw * plan.SliceW(m);
        const uint32_t na = a1 - a0, padded = PaddedToVectors(na), pitch = padded + 1, rows = b1 - b0 + 1;
        thread_local std::vector<float> scratch;
        scratch.resize(size_t(pitch) * rows * 2 + padded);
        float* t = scratch.data();
        float* q = t + size_t(pitch) * rows;
        float* out = q + size_t(pitch) * rows;
        // Taps x = a0 + u0 + i for i < pitch; inside the slice for i in [i0, i1) (and i <= na).
        const int64_t xa = int64_t(a0) + g.u0;
        const uint32_t i0 = uint32_t(std::clamp<int64_t>(-xa, 0, pitch));
        const uint32_t i1 = uint32_t(std::clamp<int64_t>(int64_t(plan.nu) - xa, i0, na + 1));
        for (uint32_t r = 0; r < rows; ++r) {
            float* tr = t + size_t(pitch) * r;
            float* qr = q + size_t(pitch) * r;
            const int64_t y = int64_t(b0) + r + g.v0;
            const bool inV = y >= 0 && y < int64_t(plan.nv);
            const uint32_t c0 = inV ? i0 : pitch, c1 = inV ? i1 : pitch;
            std::fill(tr, tr + c0, 1.0f);
            std::fill(qr, qr + c0, 0.0f);
            std::fill(tr + c1, tr + pitch, 1.0f);
            std::fill(qr + c1, qr + pitch, 0.0f);
            if (c0 >= c1) continue;
            const size_t at = prev + sv * size_t(y) + su * size_t(xa + c0);
            if (su == 1) {
                std::copy(T + at, T + at + (c1 - c0), tr + c0);
                std::copy(Q + at, Q + at + (c1 - c0), qr + c0);
            } else {
                for (uint32_t i = 0; i < c1 - c0; ++i) {
                    tr[c0 + i] = T[at + su * i];
                    qr[c0 + i] = Q[at + su * i];
                }
            }
        }
        // The next slice copies this slice's q rows: ask for them now (from
        // L3, rows a slice of z apart, which the hardware does not prefetch).
        if (su == 1)
            for (uint32_t r = 0; r < rows; ++r) {
                const int64_t y = int64_t(b0) + r + g.v0;
                if (y < 0 || y >= int64_t(plan.nv) || i0 >= i1) continue;
                const float* at = Q + cur + sv * size_t(y) + size_t(xa + i0);
                for (uint32_t i = 0; i < i1 - i0; i += 16) __builtin_prefetch(at + i);
            }
        for (uint32_t b = b0; b < b1; ++b) {
            const size_t r = size_t(pitch) * (b - b0);
            float* row = T + cur + sv * b + su * a0;
            const bool direct = su == 1 && padded == na;
            ShadeRow(kernel, t + r, t + r + pitch, q + r, q + r + pitch, g.fu, g.fv, direct ? row : out, padded);
            if (direct) continue;
            if (su == 1) std::copy(out, out + na, row);
            else
                for (uint32_t i = 0; i < na; ++i) row[su * i] = out[i];
        }
    }

    // A tile of a sweep along x (u = y, v = z): slices [ma, mb) of cells
    // [a0, a1) of rows [b0, b1). Along x the slices of one (y, z) are
    // consecutive floats, so the tile reads each cache line once: it copies q
    // and T of its slices, transposed, into rows per slice (ma - 1 first; T of
    // the halo, the row and the cell beyond the tile that its taps reach, which
    // other tiles computed, for every slice read), shades there, and writes its
    // slices of T back the same way. A tile of 16 slices moves 16 cells' lines
    // at a time through a 16 x 16 transpose in registers; shorter tiles, the
    // halo and the last cells of a row go one float at a time.
    void TileAlongX(uint32_t ma, uint32_t mb, uint32_t b0, uint32_t b1, uint32_t a0, uint32_t a1) const {
        const ShearWarp& g = plan.geometry;
        if (ma == 0) {
            for (uint32_t b = b0; b < b1; ++b) Row(0, b, a0, a1);
            ma = 1;
        }
        if (ma >= mb) return;
        const uint32_t K = mb - ma, nu = plan.nu, na = a1 - a0;
        const int64_t x0 = plan.SliceW(ma - 1), dx = g.sunAbove ? -1 : 1;  // slice ma - 1 + k at x0 + dx k
        const int64_t yLo = int64_t(b0) + std::min(g.v0, 0), yHi = int64_t(b1) + std::max(g.v0 + 1, 0);
        // The taps' cells: [uLo, uHi) of rows [yLo, yHi).
        const int64_t uLo = int64_t(a0) + std::min(g.u0, 0), uHi = int64_t(a1) + std::max(g.u0 + 1, 0);
        const uint32_t R = uint32_t(yHi - yLo), padded = PaddedToVectors(na), P = padded + 3;
        const size_t plane = size_t(R) * P;  // one slice's rows; cell (r, u) at r P + u - a0 + 1
        thread_local std::vector<float> scratch;
        scratch.resize(plane * (2 * K + 1));
        float* tc = scratch.data();        // K + 1 slices of T: ma - 1 .. mb - 1
        float* qc = tc + plane * (K + 1);  // K slices of q: ma - 1 .. mb - 2
        // With 16 slices, the lines x0 .. x0 + 15 dx (q and T of the slices
        // read, ma - 1 + k for k < 16) lie inside the grid and start at xLine;
        // T of the slices written starts at xOut (slice ma at x0 + dx). Cells
        // [a0, uLines) go by lines.
        const bool lines = K == kLineFloats;
        const uint32_t uLines = a0 + (lines ? na / kLineFloats * kLineFloats : 0);
        const int64_t xLine = dx > 0 ? x0 : x0 - 15, xOut = dx > 0 ? x0 + 1 : x0 - 16;
        auto plane16 = [&](int j) { return uint32_t(dx > 0 ? j : 15 - j); };  // the slice k of lane j
        for (uint32_t r = 0; r < R; ++r) {
            const int64_t y = yLo + r;
            const bool inV = y >= 0 && y < int64_t(plan.nv), inBand = y >= int64_t(b0) && y < int64_t(b1);
            // Cells the copies below do not write: outside T = 1, q = 0.
            for (uint32_t k = 0; k <= K; ++k) {
                float* t = tc + plane * k + size_t(P) * r;
                float* q = k < K ? qc + plane * k + size_t(P) * r : nullptr;
                const uint32_t c0 = inV ? 1 : P;
                std::fill(t, t + c0, 1.0f);
                std::fill(t + std::max(c0, na + 1), t + P, 1.0f);
                if (q) {
                    std::fill(q, q + c0, 0.0f);
                    std::fill(q + std::max(c0, na + 1), q + P, 0.0f);
                }
            }
            if (!inV) continue;
            // In the halo, slices ma - 1 .. mb - 2 are read; in the tile, only ma - 1.
            const uint32_t tSlices = inBand ? 1 : K;
            const size_t rowBase = sv * size_t(y), cell0 = size_t(P) * r + 1;  // cell a0 of row r
            for (uint32_t u = a0; u < uLines; u += kLineFloats) {
                // Lines a grid row apart: the hardware does not fetch them ahead.
                if (u + kLineFloats < uLines)
                    for (uint32_t i = 0; i < kLineFloats; ++i) {
                        const float* next = Q + rowBase + su * (u + kLineFloats + i) + size_t(xLine);
                        __builtin_prefetch(next);
                        __builtin_prefetch(next + 15);
                        if (!inBand) {
                            __builtin_prefetch(T + (next - Q));
                            __builtin_prefetch(T + (next - Q) + 15);
                        }
                    }
                Lanes16 v[16];
                for (uint32_t i = 0; i < kLineFloats; ++i) v[i] = LoadLanes(Q + rowBase + su * (u + i) + size_t(xLine));
                Transpose16(v);
                for (int j = 0; j < 16; ++j) StoreLanes(qc + plane * plane16(j) + cell0 + (u - a0), v[j]);
                if (inBand) {
                    for (uint32_t i = 0; i < kLineFloats; ++i)
                        tc[cell0 + (u - a0) + i] = T[rowBase + su * (u + i) + size_t(x0)];
                    continue;
                }
                for (uint32_t i = 0; i < kLineFloats; ++i) v[i] = LoadLanes(T + rowBase + su * (u + i) + size_t(xLine));
                Transpose16(v);
                for (int j = 0; j < 16; ++j) StoreLanes(tc + plane * plane16(j) + cell0 + (u - a0), v[j]);
            }
            auto copyCell = [&](uint32_t u, uint32_t tCopies) {
                const size_t base = rowBase + su * u, cell = cell0 + u - a0;  // u >= a0 - 1: no wrap
                const size_t ahead = rowBase + su * std::min(u + kPrefetchRows, nu - 1) + size_t(x0);
                __builtin_prefetch(Q + ahead);
                __builtin_prefetch(Q + ahead + size_t(dx * int64_t(K - 1)));
                if (tCopies > 1) __builtin_prefetch(T + ahead);
                for (uint32_t k = 0; k < K; ++k) qc[plane * k + cell] = Q[base + size_t(x0 + dx * k)];
                for (uint32_t k = 0; k < tCopies; ++k) tc[plane * k + cell] = T[base + size_t(x0 + dx * k)];
            };
            for (uint32_t u = uLines; u < a1; ++u) copyCell(u, tSlices);
            // The halo cells of the row beyond the chunk (the previous or the next chunk's, inside the grid).
            for (int64_t u = std::max<int64_t>(uLo, 0); u < std::min<int64_t>(a0, nu); ++u) copyCell(uint32_t(u), K);
            for (int64_t u = a1; u < std::min<int64_t>(uHi, nu); ++u) copyCell(uint32_t(u), K);
        }
        for (uint32_t k = 1; k <= K; ++k)
            for (uint32_t b = b0; b < b1; ++b) {
                const size_t tap = plane * (k - 1) + size_t(P) * size_t(int64_t(b) + g.v0 - yLo) + size_t(g.u0 + 1);
                float* out = tc + plane * k + size_t(P) * size_t(int64_t(b) - yLo);
                // The padding may write past the row's na cells; the cells after
                // them (the halo, or outside: one, or two when u0 = 1) are what
                // the next slice's taps read there, so they are kept.
                const float after[2] = {out[na + 1], out[na + 2]};
                ShadeRow(kernel, tc + tap, tc + tap + P, qc + tap, qc + tap + P, g.fu, g.fv, out + 1, padded);
                out[na + 1] = after[0];
                out[na + 2] = after[1];
            }
        for (uint32_t b = b0; b < b1; ++b) {
            const size_t rowBase = sv * b, cell0 = size_t(P) * size_t(int64_t(b) - yLo) + 1;  // cell a0 of row b
            for (uint32_t u = a0; u < uLines; u += kLineFloats) {
                Lanes16 v[16];
                // Row j: the slice at x = xOut + j; transposed, lane j of cell u + i's line.
                for (int j = 0; j < 16; ++j) v[j] = LoadLanes(tc + plane * (plane16(j) + 1) + cell0 + (u - a0));
                Transpose16(v);
                for (uint32_t i = 0; i < kLineFloats; ++i) StoreLanes(T + rowBase + su * (u + i) + size_t(xOut), v[i]);
            }
            for (uint32_t u = uLines; u < a1; ++u) {
                const size_t base = rowBase + su * u;
                __builtin_prefetch(T + rowBase + su * std::min(u + kPrefetchRows, nu - 1) + size_t(x0 + dx), 1);
                const size_t cell = cell0 + (u - a0);
                for (uint32_t k = 1; k <= K; ++k) T[base + size_t(x0 + dx * k)] = tc[plane * k + cell];
            }
        }
    }

    // Cells [a0, a1) of row b of slice m.
    void Row(uint32_t m, uint32_t b, uint32_t a0, uint32_t a1) const {
        const size_t cur = sw * plan.SliceW(m) + sv * b;
        if (m == 0) {
            for (uint32_t a = a0; a < a1; ++a) T[cur + su * a] = 1.0f;
            return;
        }
        const ShearWarp& g = plan.geometry;
        const size_t prev = sw * plan.SliceW(m - 1);
        const int64_t r0 = int64_t(b) + g.v0;
        // The interior: both taps a + u0 and a + u0 + 1 inside [0, nu).
        const int64_t lo = std::max<int64_t>(a0, -g.u0);
        const int64_t hi = std::min<int64_t>(a1, int64_t(plan.nu) - 1 - g.u0);
        if (su != 1 || hi - lo < int64_t(kRowLanes)) return Gathered(prev, cur, r0, a0, a1);
        auto row = [&](int64_t r, const float* grid, const std::vector<float>& outside) {
            return r >= 0 && r < int64_t(plan.nv) ? grid + prev + sv * size_t(r) + size_t(lo + g.u0) : outside.data();
        };
        // Taps of cell lo (the constant rows need no offset).
        const float *t0 = row(r0, T, ones), *t1 = row(r0 + 1, T, ones), *q0 = row(r0, Q, zeros),
                    *q1 = row(r0 + 1, Q, zeros);
        // Whole vectors from lo, then the last vector again ending at hi (its
        // cells written twice, the same bits), so no cell takes the scalar path.
        const uint32_t whole = WholeVectors(uint32_t(hi - lo));
        ShadeRow(kernel, t0, t1, q0, q1, g.fu, g.fv, T + cur + size_t(lo), whole);
        if (whole < hi - lo) {
            const size_t s = size_t(hi - lo) - kRowLanes;
            ShadeRow(kernel, t0 + s, t1 + s, q0 + s, q1 + s, g.fu, g.fv, T + cur + size_t(lo) + s, kRowLanes);
        }
        if (a0 < lo) Gathered(prev, cur, r0, a0, uint32_t(lo));
        if (hi < a1) Gathered(prev, cur, r0, uint32_t(hi), a1);
    }
};

// Shades the sweep's slices m in [m0, m1) of the plan's grid (full or coarse).
// With m0 > 0, slice m0 - 1 of T must hold what an earlier share wrote there:
// it is read as the previous slice, exactly as the whole sweep would.
//
// In parallel, the slice plane is cut into bands along one axis (and, along
// x, its rows into chunks) and the sweep into blocks of slices; tile (band i,
// chunk j, block M) covers them. Its taps reach one band and one chunk toward
// the sun's side (o0 = u0 or v0 >= 0: the higher one; else the lower), so it
// waits for tiles (i, j, M - 1), (i + dir, j, M) and (i, j + chunkDir, M)
// (the corner tile is done before the last two), and runs as soon as they
// are done: a pipeline, no barriers. Every cell is computed once with the same
// arithmetic, so T does not depend on the schedule.
void ShadeGrid(const ShadePlan& plan, StorageFormat storage, const float* Q, float* T, tbb::task_arena& arena,
               uint32_t m0, uint32_t m1) {
    m1 = std::min(m1, plan.nw);
    if (m0 >= m1) return;
    const ShadeSweep sweep(plan, storage, Q, T);
    const ShadeSchedule s = MakeShadeSchedule(plan, arena.max_concurrency(), m0, m1);
    const uint32_t n = s.axis == 1 ? plan.nv : plan.nu;
    // Rows far apart (u not x; w = y, where v = z) are copied per slice (Block);
    // else each row reads the previous slice in place (Row).
    const bool copied = sweep.su != 1 || sweep.sv > sweep.sw;
    const bool alongX = plan.geometry.w == 0 && s.axis == 1 && sweep.sw == 1;
    auto tile = [&](uint32_t band, uint32_t chunk, uint32_t block) {
        const uint32_t c0 = uint32_t(uint64_t(n) * band / s.bands), c1 = uint32_t(uint64_t(n) * (band + 1) / s.bands);
        const uint32_t ua = s.axis == 1 ? 0 : c0, ub = s.axis == 1 ? plan.nu : c1;
        const uint32_t va = s.axis == 1 ? c0 : 0, vb = s.axis == 1 ? c1 : plan.nv;
        const uint32_t ma = m0 + block * s.blockSlices, mb = std::min(m1, ma + s.blockSlices);
        if (alongX) {
            const uint32_t a0 = chunk * s.chunkCells;
            const uint32_t a1 = s.chunks == 1 ? plan.nu : std::min(plan.nu, a0 + s.chunkCells);
            return sweep.TileAlongX(ma, mb, va, vb, a0, a1);
        }
        for (uint32_t m = ma; m < mb; ++m) {
            if (m > 0 && copied) sweep.Block(m, ua, ub, va, vb);
            else
                for (uint32_t b = va; b < vb; ++b) sweep.Row(m, b, ua, ub);
        }
    };
    const uint32_t B = s.bands, C = s.chunks, blocks = s.blocks;
    if (B == 1 && C == 1) {
        for (uint32_t M = 0; M < blocks; ++M) tile(0, 0, M);
        return;
    }
    // Pending counts the tiles a tile waits for that are not done.
    const int dir = s.towardHigher ? 1 : -1, chunkDir = s.chunkTowardHigher ? 1 : -1;
    const uint32_t lastBand = s.towardHigher ? B - 1 : 0;  // the band that waits for no other
    const uint32_t lastChunk = s.chunkTowardHigher ? C - 1 : 0;
    auto at = [&](uint32_t band, uint32_t chunk, uint32_t block) { return (size_t(block) * C + chunk) * B + band; };
    if (arena.max_concurrency() == 1) {  // one thread: block by block, from the tile that waits for none
        for (uint32_t M = 0; M < blocks; ++M)
            for (uint32_t i = 0; i < B; ++i)
                for (uint32_t j = 0; j < C; ++j)
                    tile(s.towardHigher ? B - 1 - i : i, s.chunkTowardHigher ? C - 1 - j : j, M);
        return;
    }
    std::vector<std::atomic<uint8_t>> pending(size_t(B) * C * blocks);
    for (uint32_t M = 0; M < blocks; ++M)
        for (uint32_t j = 0; j < C; ++j)
            for (uint32_t i = 0; i < B; ++i)
                pending[at(i, j, M)] = uint8_t((M > 0) + (i != lastBand) + (j != lastChunk));
    struct Tile {
        uint32_t band, chunk, block;
    };
    const Tile root{lastBand, lastChunk, 0};
    arena.execute([&] {
        tbb::parallel_for_each(&root, &root + 1, [&](const Tile& t, tbb::feeder<Tile>& feeder) {
            tile(t.band, t.chunk, t.block);
            auto done = [&](uint32_t band, uint32_t chunk, uint32_t block) {
                if (pending[at(band, chunk, block)].fetch_sub(1, std::memory_order_acq_rel) == 1)
                    feeder.add(Tile{band, chunk, block});
            };
            if (t.block + 1 < blocks) done(t.band, t.chunk, t.block + 1);
            if (t.band != (s.towardHigher ? 0u : B - 1)) done(uint32_t(int(t.band) - dir), t.chunk, t.block);
            if (t.chunk != (s.chunkTowardHigher ? 0u : C - 1)) done(t.band, uint32_t(int(t.chunk) - chunkDir), t.block);
        });
    });
}

// Shade's sweep for the sun's T or the sky light's T_sky, each with its own state (its coarse grids).
Status ShadeInto(ShadeCpuState& state, tbb::task_arena& arena, const ShadeParams& params, const Buffer& qBuffer,
                 Buffer& TBuffer) {
    const int f = params.resolution;
    CB_TRY(CheckShadeResolution("cpu", f));
    const float* q = static_cast<const BufferCpu&>(qBuffer).F32();
    float* T = static_cast<BufferCpu&>(TBuffer).F32();
    const Extent3 e = qBuffer.Extent();
    const ShadePlan plan = MakeShadePlan(params, e);
    // The share: the sweep's slices m in [m0, m1), of the shaded (at f > 1 the
    // coarse) grid. At f > 1 the share with m = 0 also forms the coarse q, the
    // coarse grids stay in ShadeCpuState's coarseQ and coarseT until the last share, and the share
    // ending at nw writes all of T from them.
    const uint32_t m0 = params.slices.Begin(plan.nw), m1 = params.slices.End(plan.nw);
    if (m0 >= m1) return {};
    if (f == 1) {
        ShadeGrid(plan, params.storage, q, T, arena, m0, m1);
        return {};
    }

    const uint32_t* c = plan.cells;
    const size_t coarseSlice = size_t(c[0]) * c[1];
    if (m0 > 0 && (state.coarseQ.size() != coarseSlice * c[2] || state.coarseT.size() != coarseSlice * c[2]))
        return MakeError("cpu: shade share [" + std::to_string(m0) + ", " + std::to_string(m1) +
                         ") without the share that starts the sweep");
    if (m0 == 0) {
        state.coarseQ.assign(coarseSlice * c[2], 0.0f);
        state.coarseT.assign(coarseSlice * c[2], 1.0f);
        DownsampleShadeQ(plan, f, q, e, state.coarseQ.data(), arena);
    }
    ShadeGrid(plan, params.storage, state.coarseQ.data(), state.coarseT.data(), arena, m0, m1);
    if (m1 < plan.nw) return {};

    UpsampleShadeT(plan, f, state.coarseT.data(), e, T, arena);
    return {};
}

}  // namespace

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(ShadeInto);

uint64_t ShadeCpuState::ScratchBytes(const Scene& scene) const {
    const uint32_t f = uint32_t(std::max(scene.shade.resolution, 1));
    if (f == 1) return 0;
    const Extent3 e = scene.grid.size;
    const uint64_t cells[3] = {CeilDiv(e.nx, f), CeilDiv(e.ny, f), CeilDiv(e.nz, f)};
    return SaturatingMul(SaturatingMul(cells[0] * cells[1], cells[2]), 2 * 4);
}

Status BackendCpu::Shade(const ShadeParams& params, const Buffer& q, Buffer& T) {
    return HWY_DYNAMIC_DISPATCH(ShadeInto)(mStages.Get<ShadeCpuState>(), mArena, params, q, T);
}

Status BackendCpu::ShadeSky(const ShadeParams& params, const Buffer& q, Buffer& T) {
    return HWY_DYNAMIC_DISPATCH(ShadeInto)(mStages.Get<ShadeSkyCpuState>(), mArena, params, q, T);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
