#include "impl_cpu/BackendCpu.h"

#include <algorithm>
#include <cstring>
#include <thread>

#include "core/base/ProcessMemory.h"
#include "core/scene/Scene.h"
#include "impl_cpu/CaKernels.h"

namespace cb::cpu {

BufferCpu::BufferCpu(BufferFormat format, Extent3 extent) : Buffer(format, extent) {
    switch (format) {
        case BufferFormat::Bits: mBits = BitField(extent); break;
        case BufferFormat::U8: mU8.assign(extent.Count() + kPadding, 0); break;
        case BufferFormat::F32: mF32.assign(extent.Count(), 0.0f); break;
    }
}

BackendCpu::BackendCpu(int threads)
    : mArena(threads > 0 ? threads : tbb::task_arena::automatic) {}

std::string BackendCpu::Device() const {
    return std::to_string(mArena.max_concurrency()) + " threads (TBB), " + CaKernelName();
}

bool BackendCpu::Supports(Stage stage) const {
    return IsSplatPipelineStage(stage) || stage == Stage::RenderMarch || stage == Stage::Noise;
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

uint64_t BackendCpu::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    const uint64_t slice = uint64_t(e.nx) * e.ny;
    uint64_t bytes = 0;
    // ca with wind: the rules write three fields that advection then moves into the output (CaCpu.cpp).
    if (scene.stages.Has(Stage::Ca) && scene.ca.HasWind())
        bytes = SaturatingAdd(bytes, SaturatingMul(HostBufferBytes(BufferFormat::Bits, e), 3));
    // smooth at radius r > 0: each run of slices (one per thread, at most nz) keeps a ring of 2r + 1 slices of
    // numerators (1 byte each at r = 1, 2 at r = 2), a slice of x sums and two rows (SmoothCpu.cpp).
    if (const int r = scene.smooth.radius; scene.stages.Has(Stage::Smooth) && r > 0) {
        const uint64_t runs = std::min<uint64_t>(e.nz, uint64_t(std::max(Threads(), 1)));
        const uint64_t numeratorBytes = r == 1 ? 1 : 2;
        const uint64_t perRun = SaturatingAdd(SaturatingMul(slice, (2 * r + 1) * numeratorBytes + 1),
                                              uint64_t(e.nx) + 2 * r + 8 + 4 * uint64_t(e.nx));
        bytes = SaturatingAdd(bytes, SaturatingMul(runs, perRun));
        // Time-sliced, the shares of one sweep keep their ring and a slice of x sums between calls
        // (SmoothShareState).
        if (scene.render.slicesPerFrame > 0)
            bytes = SaturatingAdd(bytes, SaturatingMul(slice, (2 * r + 1) * numeratorBytes + 1));
    }
    if (scene.stages.Has(Stage::Shade)) {
        // The shaded grid: ceil(n / f) cells per axis (ShadePlan). Below full resolution the coarse q and T
        // (ShadeCpu.cpp). The sweep reads the previous slice in place: its rows and tile counts are per call.
        const uint64_t f = uint64_t(std::max(scene.shade.resolution, 1));
        const uint64_t cells[3] = {CeilDiv(e.nx, uint32_t(f)), CeilDiv(e.ny, uint32_t(f)), CeilDiv(e.nz, uint32_t(f))};
        if (f > 1) bytes = SaturatingAdd(bytes, SaturatingMul(SaturatingMul(cells[0] * cells[1], cells[2]), 2 * 4));
    }
    if (scene.stages.Has(Stage::RenderMarch)) {
        // The padded (q_alpha, T) volume and one byte per brick (RenderMarchCpu.cpp).
        const uint64_t padded = uint64_t(e.nx + 2ull) * (e.ny + 2ull) * (e.nz + 2ull);
        const uint32_t b = std::max(scene.march.brick, 1u);
        const uint64_t bricks = uint64_t(CeilDiv(e.nx, b)) * CeilDiv(e.ny, b) * CeilDiv(e.nz, b);
        bytes = SaturatingAdd(bytes, SaturatingAdd(SaturatingMul(padded, sizeof(MarchQT)), bricks));
    }
    // noise: the detail volume (size^3 floats) and the weather map (nx * ny floats) (NoiseCpu.cpp).
    if (scene.stages.Has(Stage::Noise)) {
        if (scene.noise.detail.enabled) bytes = SaturatingAdd(bytes, 4 * uint64_t(scene.noise.detail.size) *
                                                                         scene.noise.detail.size * scene.noise.detail.size);
        if (scene.noise.coverage.enabled) bytes = SaturatingAdd(bytes, 4 * slice);
    }
    return bytes;
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
