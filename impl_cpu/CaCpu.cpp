// Stage `ca` on the CPU (SPEC 3): Dobashi's bit-field automaton, 64 voxels per
// word, rows spread over the TBB arena.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/math/Automaton.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/CaCpuState.h"
#include "impl_cpu/CaKernels.h"

namespace cb::cpu {
namespace {

// Bits [start, start + 64) of a row as one word; bits outside [0, 64*words) are 0.
inline uint64_t BitsAt(const uint64_t* row, int64_t words, int64_t start) {
    int64_t word = start >> 6;  // floor division (arithmetic shift)
    int shift = int(start & 63);
    auto at = [&](int64_t w) -> uint64_t { return (w >= 0 && w < words) ? row[w] : 0; };
    if (shift == 0) return at(word);
    return (at(word) >> shift) | (at(word + 1) << (64 - shift));
}

// X'(i, j, k) = X(i - sx, j - sy, k), zero-filled (SPEC 3 step 4).
// Rows of slices [k0, k1) only: the shift stays within a slice.
void AdvectField(const BitField& src, BitField& dst, std::span<const int32_t> shiftX,
                 std::span<const int32_t> shiftY, uint32_t k0, uint32_t k1) {
    const Extent3 e = src.Extent();
    const uint32_t words = src.WordsPerRow();
    const uint64_t lastMask = src.LastWordMask();
    const tbb::blocked_range<uint32_t> all(e.ny * k0, e.ny * k1, 64);
    tbb::parallel_for(all, [&](const tbb::blocked_range<uint32_t>& rows) {
        for (uint32_t r = rows.begin(); r != rows.end(); ++r) {
            uint32_t j = r % e.ny, k = r / e.ny;
            uint64_t* out = dst.Row(j, k);
            const uint64_t* in = src.RowOrNull(int64_t(j) - shiftY[k], k);
            if (!in) {
                std::fill(out, out + words, 0);
                continue;
            }
            for (uint32_t w = 0; w < words; ++w) out[w] = BitsAt(in, words, int64_t(w) * 64 - shiftX[k]);
            out[words - 1] &= lastMask;
        }
    });
}

}  // namespace

uint64_t CaCpuState::ScratchBytes(const Scene& scene) const {
    if (!scene.ca.HasWind()) return 0;
    return SaturatingMul(HostBufferBytes(BufferFormat::Bits, scene.grid.size), 3);
}

Status BackendCpu::CaInitialize(const CaInitParams& params, CaFields out) {
    auto& hum = static_cast<BufferCpu&>(*out.hum).Bits();
    auto& act = static_cast<BufferCpu&>(*out.act).Bits();
    auto& cld = static_cast<BufferCpu&>(*out.cld).Bits();
    const Extent3 e = hum.Extent();
    const uint32_t keyHum = StreamKey(params.seed, kInitialStateStep, kStreamHumidity);
    const uint32_t keyAct = StreamKey(params.seed, kInitialStateStep, kStreamActivation);
    const uint32_t qHum0 = params.qHum0, qAct0 = params.qAct0;
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny * e.nz, 64), [&](const tbb::blocked_range<uint32_t>& rows) {
            for (uint32_t r = rows.begin(); r != rows.end(); ++r) {
                uint32_t j = r % e.ny, k = r / e.ny;
                uint64_t* h = hum.Row(j, k);
                uint64_t* a = act.Row(j, k);
                uint64_t* c = cld.Row(j, k);
                uint32_t base = VoxelIndex(e, 0, j, k);
                for (uint32_t w = 0; w < hum.WordsPerRow(); ++w) h[w] = a[w] = c[w] = 0;
                for (uint32_t i = 0; i < e.nx; ++i) {
                    const CaBits<uint32_t> s = CaInitialVoxel(keyHum, keyAct, qHum0, qAct0, base + i);
                    h[i >> 6] |= uint64_t(s.hum) << (i & 63);
                    a[i >> 6] |= uint64_t(s.act) << (i & 63);
                    c[i >> 6] |= uint64_t(s.cld) << (i & 63);
                }
            }
        });
    });
    return {};
}

Status BackendCpu::CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& regionBuffer, CaFields out) {
    const BitField& hum = static_cast<const BufferCpu&>(*in.hum).Bits();
    const BitField& act = static_cast<const BufferCpu&>(*in.act).Bits();
    const BitField& cld = static_cast<const BufferCpu&>(*in.cld).Bits();
    const uint8_t* region = static_cast<const BufferCpu&>(regionBuffer).U8();
    const Extent3 e = hum.Extent();
    // The share: slices k in [k0, k1) of `out`. A bit field packs x into words,
    // so a slice is whole rows of words; the rules read `in` at k - 2 .. k + 1,
    // and the advection stays within a slice, so the scratch of these slices
    // is all a share writes or reads.
    const uint32_t k0 = params.slices.Begin(e.nz), k1 = params.slices.End(e.nz);
    if (k0 >= k1) return {};

    bool wind = false;
    for (size_t k = 0; k < params.shiftX.size(); ++k) wind |= params.shiftX[k] != 0 || params.shiftY[k] != 0;

    // Without wind the rules write straight into `out`; with wind they write
    // into scratch and the advection pass moves the result into `out`.
    BitField* dst[3] = {&static_cast<BufferCpu&>(*out.hum).Bits(), &static_cast<BufferCpu&>(*out.act).Bits(),
                        &static_cast<BufferCpu&>(*out.cld).Bits()};
    if (wind) {
        std::vector<BitField>& advect = mStages.Get<CaCpuState>().advect;
        if (advect.size() != 3 || !(advect[0].Extent() == e)) advect.assign(3, BitField(e));
        for (int f = 0; f < 3; ++f) dst[f] = &advect[f];
    }

    const CaEvents events = MakeCaEvents(params.seed, params.step, params.qExt, params.qHum, params.qAct);

    const CaStepRowsJob job{&hum, &act, &cld, region, dst[0], dst[1], dst[2], events};
    auto rows = [&](const tbb::blocked_range<uint32_t>& range) { CaStepRows(job, range.begin(), range.end()); };

    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(e.ny * k0, e.ny * k1, 16), rows);
        if (wind) {
            for (int f = 0; f < 3; ++f) {
                BitField& target = static_cast<BufferCpu&>(f == 0 ? *out.hum : f == 1 ? *out.act : *out.cld).Bits();
                AdvectField(*dst[f], target, params.shiftX, params.shiftY, k0, k1);
            }
        }
    });
    return {};
}

}  // namespace cb::cpu
