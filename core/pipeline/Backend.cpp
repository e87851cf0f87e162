#include "core/pipeline/Backend.h"

#include <algorithm>

#include "core/base/ProcessCpuTime.h"
#include "core/base/ProcessMemory.h"

namespace cb {

void Backend::BusyFor(double wallMs, double cpuMs) { SpinCpuFor(std::min(wallMs, cpuMs)); }

size_t CanonicalElementBytes(BufferFormat format) { return format == BufferFormat::F32 ? 4 : 1; }

uint64_t CanonicalBufferBytes(BufferFormat format, const Extent3& extent) {
    uint64_t count, bytes;
    if (__builtin_mul_overflow(uint64_t(extent.nx) * extent.ny, uint64_t(extent.nz), &count) ||
        __builtin_mul_overflow(count, uint64_t(CanonicalElementBytes(format)), &bytes))
        return UINT64_MAX;
    return bytes;
}

std::vector<uint32_t> PackBits32(std::span<const std::byte> canonical, const Extent3& e) {
    const uint32_t words = CeilDiv(e.nx, 32);
    std::vector<uint32_t> packed(size_t(words) * e.ny * e.nz, 0);
    const auto* src = reinterpret_cast<const uint8_t*>(canonical.data());
    for (size_t row = 0; row < size_t(e.ny) * e.nz; ++row)
        for (uint32_t i = 0; i < e.nx; ++i)
            packed[row * words + i / 32] |= uint32_t(src[row * e.nx + i] != 0) << (i % 32);
    return packed;
}

void UnpackBits32(std::span<const uint32_t> packed, const Extent3& e, std::span<std::byte> canonical) {
    const uint32_t words = CeilDiv(e.nx, 32);
    auto* dst = reinterpret_cast<uint8_t*>(canonical.data());
    for (size_t row = 0; row < size_t(e.ny) * e.nz; ++row)
        for (uint32_t i = 0; i < e.nx; ++i)
            dst[row * e.nx + i] = uint8_t((packed[row * words + i / 32] >> (i % 32)) & 1);
}

std::vector<uint8_t> SplatBoxVisibility(const SplatParams& p, const Extent3& e, std::span<const uint8_t> bandsPrev,
                                        std::span<const uint8_t> bandsCur) {
    std::vector<uint8_t> boxes(size_t(CeilDiv(e.nx, p.tile)) * CeilDiv(e.ny, p.tile) * CeilDiv(e.nz, p.band), 1);
    if (p.culling) boxes = FrustumVisibleBoxes(p.camera, e, p.origin, p.voxelSize, p.tile, p.band, p.splatDiameter);
    if (p.skipping)
        for (size_t n = 0; n < boxes.size(); ++n) boxes[n] &= uint8_t(bandsPrev[n] | bandsCur[n]);
    return boxes;
}

Result<std::vector<uint8_t>> DownloadSplatBoxVisibility(Backend& backend, const SplatParams& p, const SplatInputs& in) {
    std::vector<uint8_t> bandsPrev, bandsCur;
    if (p.skipping) {
        if (!in.bandsPrev || !in.bandsCur)
            return MakeError(backend.Name() + ": render_splat with skipping needs both steps' occupancy");
        bandsPrev.resize(in.bandsPrev->CanonicalBytes());
        bandsCur.resize(in.bandsCur->CanonicalBytes());
        CB_TRY(backend.Download(*in.bandsPrev, std::as_writable_bytes(std::span(bandsPrev))));
        CB_TRY(backend.Download(*in.bandsCur, std::as_writable_bytes(std::span(bandsCur))));
    }
    return SplatBoxVisibility(p, in.qCur->Extent(), bandsPrev, bandsCur);
}

GroundLight MakeGroundLight(const SplatParams& p) {
    return {p.ground.albedo, p.light.sunRadiance, p.light.ambient, p.background, p.sun[2]};
}

GroundLight MakeGroundLight(const MarchParams& p) {
    return {p.ground.albedo, p.setup.light.sunRadiance, p.setup.light.ambient, p.setup.background, p.setup.sun[2]};
}

Status CheckGroundInput(const GroundParams& ground, const Buffer* G, const Extent3& grid, std::string_view where) {
    if (!ground.on) return {};
    if (!G) return MakeError(std::string(where) + ": the ground needs G (enable the stage \"shadow\")");
    if (G->Format() != BufferFormat::F32 || G->Extent() != Extent3{grid.nx, grid.ny, 1})
        return MakeError(std::string(where) + ": G must be F32 of extent (nx, ny, 1) of the grid");
    return {};
}

uint64_t HostBufferBytes(BufferFormat format, const Extent3& e) {
    switch (format) {
        case BufferFormat::Bits:
            return SaturatingMul(SaturatingMul(uint64_t(CeilDiv(e.nx, 64)) * e.ny, e.nz), 8);
        case BufferFormat::U8:
            return SaturatingAdd(CanonicalBufferBytes(format, e), kHostU8Padding);
        case BufferFormat::F32:
            return CanonicalBufferBytes(format, e);
    }
    return CanonicalBufferBytes(format, e);
}

GroundParams MakeGroundParams(const Scene& sc) {
    const auto& a = sc.render.ground.albedo;
    return {sc.render.ground.on, {float(a[0]), float(a[1]), float(a[2])}};
}

}  // namespace cb
