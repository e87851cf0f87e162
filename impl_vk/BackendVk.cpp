#include "impl_vk/BackendVk.h"

#include <cstring>
#include <vector>

namespace cb::vk {
namespace {

const DeviceBuffer& Dev(const Buffer& b) { return static_cast<const BufferVk&>(b).Device(); }

// Bytes a buffer takes on the device.
VkDeviceSize DeviceBytes(BufferFormat format, const Extent3& e) {
    switch (format) {
        case BufferFormat::Bits: return VkDeviceSize((e.nx + 31) / 32) * e.ny * e.nz * 4;
        case BufferFormat::U8: return VkDeviceSize(e.Count());
        case BufferFormat::F32: return VkDeviceSize(e.Count()) * 4;
    }
    return 0;
}

}  // namespace

Result<std::unique_ptr<BackendVk>> BackendVk::Create(const std::string& device, bool validation) {
    auto context = VulkanContext::Create(device, validation);
    if (!context) return std::unexpected(Error{"vk: " + context.error().message});
    return std::unique_ptr<BackendVk>(new BackendVk(std::move(*context)));
}

BackendVk::~BackendVk() {
    for (DeviceBuffer& b : mScratch) mContext->DestroyBuffer(b);
}

bool BackendVk::Supports(Stage stage) const {
    switch (stage) {
        case Stage::Region:
        case Stage::Ca:
        case Stage::Smooth:
        case Stage::Density: return true;
        default: return false;
    }
}

template <typename Fn>
Status BackendVk::Record(const char* what, Fn&& fn) {
    auto ms = mContext->Run(what, std::forward<Fn>(fn));
    if (!ms) return std::unexpected(ms.error());
    mLastDeviceMs = *ms;
    return {};
}

Result<DeviceBuffer*> BackendVk::Scratch(size_t slot, VkDeviceSize size) {
    DeviceBuffer& b = mScratch.at(slot);
    if (b.size < size) {
        mContext->DestroyBuffer(b);
        auto created = mContext->CreateBuffer(size);
        if (!created) return std::unexpected(created.error());
        b = *created;
    }
    return &b;
}

Result<std::unique_ptr<Buffer>> BackendVk::CreateBuffer(BufferFormat format, Extent3 extent) {
    if (extent.Count() == 0) return MakeError("vk: cannot create an empty buffer");
    auto device = mContext->CreateBuffer(DeviceBytes(format, extent));
    if (!device) return std::unexpected(Error{"vk: " + device.error().message});
    return std::make_unique<BufferVk>(format, extent, *mContext, *device);
}

Status BackendVk::Upload(Buffer& buffer, std::span<const std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("vk: upload size does not match the buffer");
    if (buffer.Format() != BufferFormat::Bits) return mContext->Upload(Dev(buffer), canonical);
    // Pack canonical bytes (0/1) into 32-voxel words.
    const Extent3 e = buffer.Extent();
    const uint32_t words = (e.nx + 31) / 32;
    std::vector<uint32_t> packed(size_t(words) * e.ny * e.nz, 0);
    const auto* src = reinterpret_cast<const uint8_t*>(canonical.data());
    for (size_t row = 0; row < size_t(e.ny) * e.nz; ++row)
        for (uint32_t i = 0; i < e.nx; ++i)
            packed[row * words + i / 32] |= uint32_t(src[row * e.nx + i] != 0) << (i % 32);
    return mContext->Upload(Dev(buffer), std::as_bytes(std::span(packed)));
}

Status BackendVk::Download(const Buffer& buffer, std::span<std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("vk: download size does not match the buffer");
    if (buffer.Format() != BufferFormat::Bits) return mContext->Download(Dev(buffer), canonical);
    const Extent3 e = buffer.Extent();
    const uint32_t words = (e.nx + 31) / 32;
    std::vector<uint32_t> packed(size_t(words) * e.ny * e.nz);
    CB_TRY(mContext->Download(Dev(buffer), std::as_writable_bytes(std::span(packed))));
    auto* dst = reinterpret_cast<uint8_t*>(canonical.data());
    for (size_t row = 0; row < size_t(e.ny) * e.nz; ++row)
        for (uint32_t i = 0; i < e.nx; ++i) dst[row * e.nx + i] = uint8_t((packed[row * words + i / 32] >> (i % 32)) & 1);
    return {};
}

Status BackendVk::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region) {
    const Extent3 e = region.Extent();
    static_assert(sizeof(RasterEllipsoid) == 8 * sizeof(float));
    auto list = Scratch(0, std::max<VkDeviceSize>(32, ellipsoids.size_bytes()));
    if (!list) return std::unexpected(list.error());
    CB_TRY(mContext->Upload(**list, std::as_bytes(ellipsoids)));
    auto pipeline = mContext->GetPipeline("region", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    struct {
        uint32_t nx, ny, nz, count;
    } push{e.nx, e.ny, e.nz, uint32_t(ellipsoids.size())};
    const DeviceBuffer* buffers[] = {*list, &Dev(region)};
    return Record("region", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, uint32_t(e.Count()));
    });
}

Status BackendVk::CaInitialize(const CaInitParams& params, CaFields out) {
    const Extent3 e = out.hum->Extent();
    auto pipeline = mContext->GetPipeline("ca_init", 3);
    if (!pipeline) return std::unexpected(pipeline.error());
    const uint32_t words = (e.nx + 31) / 32;
    struct {
        uint32_t nx, ny, nz, words, seed, qHum0, qAct0;
    } push{e.nx, e.ny, e.nz, words, params.seed, params.qHum0, params.qAct0};
    const DeviceBuffer* buffers[] = {&Dev(*out.hum), &Dev(*out.act), &Dev(*out.cld)};
    return Record("ca initial state", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, words * e.ny * e.nz);
    });
}

Status BackendVk::CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    const Extent3 e = in.hum->Extent();
    const uint32_t words = (e.nx + 31) / 32;
    const uint32_t count = words * e.ny * e.nz;
    auto rules = mContext->GetPipeline("ca", 7);
    if (!rules) return std::unexpected(rules.error());
    bool wind = false;
    for (size_t k = 0; k < params.shiftX.size(); ++k) wind |= params.shiftX[k] != 0 || params.shiftY[k] != 0;

    struct {
        uint32_t nx, ny, nz, words, seed, step, qExt, qHum, qAct;
    } push{e.nx, e.ny, e.nz, words, params.seed, params.step, params.qExt, params.qHum, params.qAct};
    const DeviceBuffer* targets[3] = {&Dev(*out.hum), &Dev(*out.act), &Dev(*out.cld)};
    Pipeline* advect = nullptr;
    DeviceBuffer* shifts = nullptr;
    if (wind) {
        // The rules write into scratch; advection moves the result into `out`.
        for (size_t f = 0; f < 3; ++f) {
            auto s = Scratch(1 + f, VkDeviceSize(count) * 4);
            if (!s) return std::unexpected(s.error());
            targets[f] = *s;
        }
        std::vector<int32_t> packed;
        for (size_t k = 0; k < params.shiftX.size(); ++k) {
            packed.push_back(params.shiftX[k]);
            packed.push_back(params.shiftY[k]);
        }
        auto s = Scratch(4, packed.size() * 4);
        if (!s) return std::unexpected(s.error());
        shifts = *s;
        CB_TRY(mContext->Upload(*shifts, std::as_bytes(std::span(packed))));
        auto p = mContext->GetPipeline("advect", 7);
        if (!p) return std::unexpected(p.error());
        advect = *p;
    }
    const DeviceBuffer* buffers[] = {&Dev(*in.hum), &Dev(*in.act), &Dev(*in.cld), &Dev(region),
                                     targets[0],    targets[1],    targets[2]};
    return Record("ca step", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**rules, buffers, &push, sizeof push, count);
        if (advect) {
            r.Barrier();
            struct {
                uint32_t nx, ny, nz, words;
            } advectPush{e.nx, e.ny, e.nz, words};
            const DeviceBuffer* advectBuffers[] = {targets[0],       targets[1],       targets[2], &Dev(*out.hum),
                                                   &Dev(*out.act), &Dev(*out.cld), shifts};
            r.Dispatch(*advect, advectBuffers, &advectPush, sizeof advectPush, count);
        }
    });
}

Status BackendVk::Smooth(int radius, const Buffer& cld, Buffer& q) {
    if (radius < 0 || radius > 2) return MakeError("vk: smooth radius must be 0, 1 or 2");
    const Extent3 e = cld.Extent();
    auto pipeline = mContext->GetPipeline("smooth", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    struct {
        uint32_t nx, ny, nz, words;
        int32_t radius;
        float invW;
    } push{e.nx, e.ny, e.nz, (e.nx + 31) / 32, radius, 1.0f / float(SmoothNormaliser(radius))};
    const DeviceBuffer* buffers[] = {&Dev(cld), &Dev(q)};
    return Record("smooth", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, uint32_t(e.Count()));
    });
}

Status BackendVk::Density(const DensityParams& params, const Buffer& q, const Buffer& cld, DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("vk: density tile and band must be positive");
    const Extent3 e = q.Extent();
    auto columns = mContext->GetPipeline("density", 4);
    if (!columns) return std::unexpected(columns.error());
    auto occupancy = mContext->GetPipeline("occupancy", 4);
    if (!occupancy) return std::unexpected(occupancy.error());
    auto counter = Scratch(5, 4);
    if (!counter) return std::unexpected(counter.error());
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    struct {
        uint32_t nx, ny, nz, words;
    } columnPush{e.nx, e.ny, e.nz, (e.nx + 31) / 32};
    struct {
        uint32_t nx, ny, nz, tile, band, tilesX, tilesY, bandCount;
    } occupancyPush{e.nx, e.ny, e.nz, params.tile, params.band, tilesX, tilesY, bandCount};
    const DeviceBuffer* columnBuffers[] = {&Dev(q), &Dev(cld), &Dev(*out.columnSum), *counter};
    const DeviceBuffer* occupancyBuffers[] = {&Dev(q), &Dev(*out.columnSum), &Dev(*out.tiles), &Dev(*out.bands)};
    CB_TRY(Record("density", [&](VulkanContext::Recorder& r) {
        r.Fill(**counter, 0);
        r.Barrier();
        r.Dispatch(**columns, columnBuffers, &columnPush, sizeof columnPush, e.nx * e.ny);
        r.Barrier();
        r.Dispatch(**occupancy, occupancyBuffers, &occupancyPush, sizeof occupancyPush, tilesX * tilesY * (bandCount + 1));
    }));
    const double deviceMs = mLastDeviceMs.value_or(0);
    uint32_t covered = 0;
    CB_TRY(mContext->Download(**counter, std::as_writable_bytes(std::span(&covered, 1))));
    mLastDeviceMs = deviceMs;
    out.coveredColumns = covered;
    return {};
}

Status BackendVk::Shade(const ShadeParams&, const Buffer&, Buffer&) {
    return MakeError("vk: stage 'shade' is not implemented yet (issue 4)");
}

Status BackendVk::Shadow(const ShadowParams&, const Buffer&, Buffer&) {
    return MakeError("vk: stage 'shadow' is not implemented yet (issue 4)");
}

Status BackendVk::RenderSplat(const SplatParams&, const SplatInputs&, Buffer&, SplatStats*) {
    return MakeError("vk: stage 'render_splat' is not implemented yet (issue 4)");
}

}  // namespace cb::vk
