#include "impl_cpu/BackendCpu.h"

#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <cstring>
#include <thread>

#include "core/base/ProcessCpuTime.h"
#include "core/base/ProcessMemory.h"
#include "core/scene/Scene.h"
#include "impl_cpu/CpuIsa.h"

namespace cb::cpu {

BufferCpu::BufferCpu(BufferFormat format, Extent3 extent) : Buffer(format, extent) {
    switch (format) {
        case BufferFormat::Bits: mBits = BitField(extent); break;
        case BufferFormat::U8: mU8.assign(extent.Count() + kPadding, 0); break;
        case BufferFormat::F32: mF32.assign(extent.Count(), 0.0f); break;
    }
}

BackendCpu::BackendCpu(int threads) : mArena(threads > 0 ? threads : tbb::task_arena::automatic) {
    mStages.Get<SmoothCpuState>().threads = std::max(Threads(), 1);
}

void BackendCpu::BusyFor(double wallMs, double cpuMs) {
    // Equal shares, so that the threads finish together as a balanced stage's do.
    const double share = std::min(cpuMs / Threads(), wallMs);
    mArena.execute([&] {
        tbb::parallel_for(
            0, Threads(), 1, [&](int) { SpinCpuFor(share); }, tbb::static_partitioner());
    });
}

std::string BackendCpu::Device() const {
    return std::to_string(mArena.max_concurrency()) + " threads (TBB), SIMD " + ActiveCpuIsaDescription();
}

Result<std::unique_ptr<Buffer>> BackendCpu::CreateBuffer(BufferFormat format, Extent3 extent) {
    if (extent.Count() == 0) return MakeError("cpu: cannot create an empty buffer");
    return std::make_unique<BufferCpu>(format, extent);
}

std::optional<uint64_t> BackendCpu::AvailableBytes() const {
    const std::optional<MemoryFigure> available = ProcessAvailableMemory();
    return available ? std::optional(available->bytes) : std::nullopt;
}

uint64_t BackendCpu::BufferBytes(BufferFormat format, const Extent3& extent) const {
    return HostBufferBytes(format, extent);
}

Status BackendCpu::Upload(Buffer& buffer, std::span<const std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("cpu: upload size does not match the buffer");
    auto& b = static_cast<BufferCpu&>(buffer);
    const Extent3 e = b.Extent();
    switch (b.Format()) {
        case BufferFormat::Bits: {
            const auto* src = reinterpret_cast<const uint8_t*>(canonical.data());
            BitField& bits = b.Bits();
            std::fill(bits.Words().begin(), bits.Words().end(), 0);
            for (uint32_t k = 0; k < e.nz; ++k)
                for (uint32_t j = 0; j < e.ny; ++j) {
                    uint64_t* row = bits.Row(j, k);
                    const uint8_t* in = src + size_t(e.nx) * (j + size_t(e.ny) * k);
                    for (uint32_t i = 0; i < e.nx; ++i) row[i >> 6] |= uint64_t(in[i] != 0) << (i & 63);
                }
            break;
        }
        case BufferFormat::U8: std::memcpy(b.U8(), canonical.data(), canonical.size()); break;
        case BufferFormat::F32: std::memcpy(b.F32(), canonical.data(), canonical.size()); break;
    }
    return {};
}

Status BackendCpu::Download(const Buffer& buffer, std::span<std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("cpu: download size does not match the buffer");
    const auto& b = static_cast<const BufferCpu&>(buffer);
    const Extent3 e = b.Extent();
    switch (b.Format()) {
        case BufferFormat::Bits: {
            auto* dst = reinterpret_cast<uint8_t*>(canonical.data());
            for (uint32_t k = 0; k < e.nz; ++k)
                for (uint32_t j = 0; j < e.ny; ++j) {
                    const uint64_t* row = b.Bits().Row(j, k);
                    uint8_t* out = dst + size_t(e.nx) * (j + size_t(e.ny) * k);
                    for (uint32_t i = 0; i < e.nx; ++i) out[i] = uint8_t((row[i >> 6] >> (i & 63)) & 1);
                }
            break;
        }
        case BufferFormat::U8: std::memcpy(canonical.data(), b.U8(), canonical.size()); break;
        case BufferFormat::F32: std::memcpy(canonical.data(), b.F32(), canonical.size()); break;
    }
    return {};
}

}  // namespace cb::cpu
