// Stage `smooth` on the CPU (SPEC 4): the separable binomial filter on integer
// numerators (x, then y per slice, then z), scaled by 1/W once at the end, so
// the float result is exact.
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {

Status BackendCpu::Smooth(int radius, const Buffer& cldBuffer, Buffer& qBuffer) {
    if (radius < 0 || radius > 2) return MakeError("cpu: smooth radius must be 0, 1 or 2");
    const BitField& cld = static_cast<const BufferCpu&>(cldBuffer).Bits();
    float* q = static_cast<BufferCpu&>(qBuffer).F32();
    const Extent3 e = cld.Extent();
    const size_t sliceSize = size_t(e.nx) * e.ny;

    if (radius == 0) {
        mArena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny * e.nz, 64), [&](const tbb::blocked_range<uint32_t>& rows) {
                for (uint32_t r = rows.begin(); r != rows.end(); ++r) {
                    const uint64_t* row = cld.Row(r % e.ny, r / e.ny);
                    float* out = q + size_t(e.nx) * r;
                    for (uint32_t i = 0; i < e.nx; ++i) out[i] = float((row[i >> 6] >> (i & 63)) & 1);
                }
            });
        });
        return {};
    }

    int w[5] = {};
    for (int d = -radius; d <= radius; ++d) w[d + radius] = SmoothWeight(radius, d);
    const float invW = 1.0f / float(SmoothNormaliser(radius));  // a power of two: exact
    mSmoothScratch.resize(e.Count());
    uint16_t* xy = mSmoothScratch.data();  // numerators after the x and y passes (<= 256)

    mArena.execute([&] {
        // x then y, one slice at a time.
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.nz, 1), [&](const tbb::blocked_range<uint32_t>& slices) {
            std::vector<uint8_t> bits(e.nx + 4);
            std::vector<uint8_t> xs(sliceSize);  // x-pass numerators, <= 16
            for (uint32_t k = slices.begin(); k != slices.end(); ++k) {
                for (uint32_t j = 0; j < e.ny; ++j) {
                    const uint64_t* row = cld.Row(j, k);
                    // bits[i + 2] = cld(i); two zero voxels of padding on each side.
                    for (uint32_t i = 0; i < e.nx; ++i) bits[i + 2] = uint8_t((row[i >> 6] >> (i & 63)) & 1);
                    uint8_t* out = xs.data() + size_t(e.nx) * j;
                    for (uint32_t i = 0; i < e.nx; ++i) {
                        int sum = 0;
                        for (int d = -radius; d <= radius; ++d) sum += w[d + radius] * bits[i + 2 + d];
                        out[i] = uint8_t(sum);
                    }
                }
                uint16_t* slice = xy + sliceSize * k;
                for (uint32_t j = 0; j < e.ny; ++j) {
                    uint16_t* out = slice + size_t(e.nx) * j;
                    std::fill(out, out + e.nx, 0);
                    for (int d = -radius; d <= radius; ++d) {
                        int64_t jj = int64_t(j) + d;
                        if (jj < 0 || jj >= e.ny) continue;
                        const uint8_t* in = xs.data() + size_t(e.nx) * jj;
                        const uint16_t weight = uint16_t(w[d + radius]);
                        for (uint32_t i = 0; i < e.nx; ++i) out[i] = uint16_t(out[i] + weight * in[i]);
                    }
                }
            }
        });
        // z, and the scale to float.
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny * e.nz, 16), [&](const tbb::blocked_range<uint32_t>& rows) {
            std::vector<uint32_t> acc(e.nx);
            for (uint32_t r = rows.begin(); r != rows.end(); ++r) {
                const uint32_t j = r % e.ny, k = r / e.ny;
                std::fill(acc.begin(), acc.end(), 0);
                for (int d = -radius; d <= radius; ++d) {
                    int64_t kk = int64_t(k) + d;
                    if (kk < 0 || kk >= e.nz) continue;
                    const uint16_t* in = xy + sliceSize * kk + size_t(e.nx) * j;
                    const uint32_t weight = uint32_t(w[d + radius]);
                    for (uint32_t i = 0; i < e.nx; ++i) acc[i] += weight * in[i];
                }
                float* out = q + size_t(e.nx) * r;
                for (uint32_t i = 0; i < e.nx; ++i) out[i] = float(acc[i]) * invW;
            }
        });
    });
    return {};
}

}  // namespace cb::cpu
