#include "impl_vk/BackendVk.h"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <iterator>
#include <vector>

namespace cb::vk {
namespace {

const DeviceBuffer& Dev(const Buffer& b) { return static_cast<const BufferVk&>(b).Device(); }

// The scratch slot that holds field `field` (0 hum, 1 act, 2 cld, as in CaFields) of the rules' output.
VkScratch CaRulesOutputSlot(size_t field) {
    constexpr VkScratch kSlots[] = {VkScratch::CaRulesHum, VkScratch::CaRulesAct, VkScratch::CaRulesCld};
    assert(field < std::size(kSlots));
    return kSlots[field];
}

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

bool BackendVk::Supports(Stage stage) const { return IsSplatPipelineStage(stage); }

template <typename Fn>
Status BackendVk::Record(const char* what, Fn&& fn) {
    auto ms = mContext->Run(what, std::forward<Fn>(fn));
    if (!ms) return std::unexpected(ms.error());
    mLastDeviceMs = *ms;
    return {};
}

Result<DeviceBuffer*> BackendVk::Scratch(VkScratch slot, VkDeviceSize size) {
    DeviceBuffer& b = mScratch.at(size_t(slot));
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
    const std::vector<uint32_t> packed = PackBits32(canonical, buffer.Extent());
    return mContext->Upload(Dev(buffer), std::as_bytes(std::span(packed)));
}

Status BackendVk::Download(const Buffer& buffer, std::span<std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("vk: download size does not match the buffer");
    if (buffer.Format() != BufferFormat::Bits) return mContext->Download(Dev(buffer), canonical);
    const Extent3 e = buffer.Extent();
    std::vector<uint32_t> packed(size_t(CeilDiv(e.nx, 32)) * e.ny * e.nz);
    CB_TRY(mContext->Download(Dev(buffer), std::as_writable_bytes(std::span(packed))));
    UnpackBits32(packed, e, canonical);
    return {};
}

Status BackendVk::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region) {
    const Extent3 e = region.Extent();
    static_assert(sizeof(RasterEllipsoid) == 8 * sizeof(float));
    auto list = Scratch(VkScratch::EllipsoidList, std::max<VkDeviceSize>(32, ellipsoids.size_bytes()));
    if (!list) return std::unexpected(list.error());
    CB_TRY(mContext->Upload(**list, std::as_bytes(ellipsoids)));
    // Per 16x16 tile of each slice, the ellipsoids whose bounding box (the
    // shader's rejection test, widened by a voxel) reaches a voxel centre of it.
    constexpr uint32_t kTile = 16;
    const uint32_t tilesX = CeilDiv(e.nx, kTile), tilesY = CeilDiv(e.ny, kTile);
    std::vector<uint32_t> tileStart(size_t(tilesX) * tilesY * e.nz + 1, 0), tileList;
    for (uint32_t k = 0, tile = 0; k < e.nz; ++k)
        for (uint32_t ty = 0; ty < tilesY; ++ty)
            for (uint32_t tx = 0; tx < tilesX; ++tx, ++tile) {
                const float x0 = float(tx * kTile) + 0.5f, x1 = float(std::min(e.nx, (tx + 1) * kTile) - 1) + 0.5f;
                const float y0 = float(ty * kTile) + 0.5f, y1 = float(std::min(e.ny, (ty + 1) * kTile) - 1) + 0.5f;
                const float z = float(k) + 0.5f;
                for (uint32_t n = 0; n < ellipsoids.size(); ++n) {
                    const RasterEllipsoid& el = ellipsoids[n];
                    const float reach = std::max(el.semiAxes[0], el.semiAxes[1]) + 2.0f;
                    if (std::fabs(z - el.center[2]) > el.semiAxes[2] + 2.0f || el.center[0] + reach < x0 ||
                        el.center[0] - reach > x1 || el.center[1] + reach < y0 || el.center[1] - reach > y1)
                        continue;
                    tileList.push_back(n);
                }
                tileStart[tile + 1] = uint32_t(tileList.size());
            }
    auto starts = Scratch(VkScratch::RegionTileStarts, tileStart.size() * 4);
    if (!starts) return std::unexpected(starts.error());
    CB_TRY(mContext->Upload(**starts, std::as_bytes(std::span(tileStart))));
    auto entries = Scratch(VkScratch::RegionTileEntries, std::max<size_t>(16, tileList.size() * 4));
    if (!entries) return std::unexpected(entries.error());
    if (!tileList.empty()) CB_TRY(mContext->Upload(**entries, std::as_bytes(std::span(tileList))));
    auto pipeline = mContext->GetPipeline("region", 4);
    if (!pipeline) return std::unexpected(pipeline.error());
    struct {
        uint32_t nx, ny, nz, tilesX, tilesY;
    } push{e.nx, e.ny, e.nz, tilesX, tilesY};
    const DeviceBuffer* buffers[] = {*list, &Dev(region), *starts, *entries};
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
            auto s = Scratch(CaRulesOutputSlot(f), VkDeviceSize(count) * 4);
            if (!s) return std::unexpected(s.error());
            targets[f] = *s;
        }
        std::vector<int32_t> packed;
        for (size_t k = 0; k < params.shiftX.size(); ++k) {
            packed.push_back(params.shiftX[k]);
            packed.push_back(params.shiftY[k]);
        }
        auto s = Scratch(VkScratch::CaWindShifts, packed.size() * 4);
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
    auto pipeline = mContext->GetPipeline("smooth", 4);
    if (!pipeline) return std::unexpected(pipeline.error());
    auto sumX = Scratch(VkScratch::SmoothSumX, e.Count() * 4);
    if (!sumX) return std::unexpected(sumX.error());
    auto sumXY = Scratch(VkScratch::SmoothSumXY, e.Count() * 4);
    if (!sumXY) return std::unexpected(sumXY.error());
    struct {
        uint32_t nx, ny, nz, words;
        int32_t radius;
        float invW;
        uint32_t pass;
    } push{e.nx, e.ny, e.nz, (e.nx + 31) / 32, radius, 1.0f / float(SmoothNormaliser(radius)), 0};
    const DeviceBuffer* buffers[] = {&Dev(cld), *sumX, *sumXY, &Dev(q)};
    return Record("smooth", [&](VulkanContext::Recorder& r) {
        for (push.pass = 0; push.pass < 3; ++push.pass) {
            if (push.pass > 0) r.Barrier();
            r.Dispatch(**pipeline, buffers, &push, sizeof push, uint32_t(e.Count()));
        }
    });
}

Status BackendVk::Density(const DensityParams& params, const Buffer& q, const Buffer& cld, DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("vk: density tile and band must be positive");
    const Extent3 e = q.Extent();
    auto columns = mContext->GetPipeline("density", 4);
    if (!columns) return std::unexpected(columns.error());
    auto occupancy = mContext->GetPipeline("occupancy", 4);
    if (!occupancy) return std::unexpected(occupancy.error());
    auto counter = Scratch(VkScratch::CoverCounter, 4);
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

Status BackendVk::Shade(const ShadeParams& params, const Buffer& q, Buffer& T) {
    const int f = params.resolution;
    if (f != 1 && f != 2 && f != 4) return MakeError("vk: shade resolution must be 1, 2 or 4");
    const Extent3 e = q.Extent();
    const uint32_t n[3] = {f == 1 ? e.nx : CeilDiv(e.nx, f), f == 1 ? e.ny : CeilDiv(e.ny, f), f == 1 ? e.nz : CeilDiv(e.nz, f)};
    const VkDeviceSize coarseBytes = VkDeviceSize(n[0]) * n[1] * n[2] * 4;
    const DeviceBuffer* shadeQ = &Dev(q);
    const DeviceBuffer* shadeT = &Dev(T);
    if (f > 1) {
        auto cq = Scratch(VkScratch::ShadeCoarseQ, coarseBytes);
        if (!cq) return std::unexpected(cq.error());
        auto ct = Scratch(VkScratch::ShadeCoarseT, coarseBytes);
        if (!ct) return std::unexpected(ct.error());
        shadeQ = *cq;
        shadeT = *ct;
    }
    auto slice = mContext->GetPipeline("shade_slice", 2);
    if (!slice) return std::unexpected(slice.error());
    Pipeline* down = nullptr;
    Pipeline* up = nullptr;
    if (f > 1) {
        auto d = mContext->GetPipeline("shade_down", 2);
        if (!d) return std::unexpected(d.error());
        auto u = mContext->GetPipeline("shade_up", 2);
        if (!u) return std::unexpected(u.error());
        down = *d;
        up = *u;
    }
    const ShearWarp g = MakeShearWarp(params.sun, params.filter);
    const SliceAttenuation a = MakeSliceAttenuation(params.attenuation, params.sigma, params.voxelSize * float(f), g.absSw,
                                                    params.thesisAr, params.scattering, params.albedo, params.solidAngle,
                                                    params.phase);
    const uint32_t stride[3] = {1, n[0], n[0] * n[1]};
    struct {
        uint32_t nu, nv, strideU, strideV, sliceBase, prevBase;
        int32_t u0, v0;
        float fu, fv;
        uint32_t first, beer;
        float depthPerQ, thesisAr, scatterGain;
        uint32_t storage;
    } push{n[g.u], n[g.v], stride[g.u], stride[g.v], 0, 0, g.u0, g.v0, g.fu, g.fv, 0,
           a.kind == AttenuationKind::Beer ? 1u : 0u, a.opticalDepthPerQ, a.thesisAr, a.scatterGain,
           uint32_t(params.storage)};
    struct {
        uint32_t nx, ny, nz, cx, cy, cz, f;
    } resample{e.nx, e.ny, e.nz, n[0], n[1], n[2], uint32_t(f)};
    const DeviceBuffer* sliceBuffers[] = {shadeQ, shadeT};
    const DeviceBuffer* downBuffers[] = {&Dev(q), shadeQ};
    const DeviceBuffer* upBuffers[] = {shadeT, &Dev(T)};
    const uint32_t nw = n[g.w];
    return Record("shade", [&](VulkanContext::Recorder& r) {
        if (down) {
            r.Dispatch(*down, downBuffers, &resample, sizeof resample, n[0] * n[1] * n[2]);
            r.Barrier();
        }
        uint32_t previous = 0;
        for (uint32_t m = 0; m < nw; ++m) {
            const uint32_t wIndex = g.sunAbove ? nw - 1 - m : m;
            push.first = m == 0 ? 1u : 0u;
            push.sliceBase = wIndex * stride[g.w];
            push.prevBase = previous * stride[g.w];
            r.Dispatch(**slice, sliceBuffers, &push, sizeof push, n[g.u] * n[g.v]);
            r.Barrier();
            previous = wIndex;
        }
        if (up) r.Dispatch(*up, upBuffers, &resample, sizeof resample, uint32_t(e.Count()));
    });
}

Status BackendVk::Shadow(const ShadowParams& params, const Buffer& columnSum, Buffer& G) {
    const Extent3 e = columnSum.Extent();
    auto pipeline = mContext->GetPipeline("shadow", 2);
    if (!pipeline) return std::unexpected(pipeline.error());
    const ShadowLookup l = MakeShadowLookup(params.sun, e.nx, e.ny, params.nz, params.sigma, params.voxelSize);
    struct {
        uint32_t nx, ny;
        int32_t bx, by;
        float fx, fy;
        uint32_t beer;
        float opticalDepthPerD, kappa;
        uint32_t noSun;
    } push{e.nx, e.ny, l.baseX, l.baseY, l.fx, l.fy, params.form == AttenuationKind::Beer ? 1u : 0u,
           l.opticalDepthPerD, params.kappa, l.noSun ? 1u : 0u};
    const DeviceBuffer* buffers[] = {&Dev(columnSum), &Dev(G)};
    return Record("shadow", [&](VulkanContext::Recorder& r) {
        r.Dispatch(**pipeline, buffers, &push, sizeof push, e.nx * e.ny);
    });
}

Status BackendVk::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) {
    if (!p.order || !in.qPrev || !in.qCur || !in.T) return MakeError("vk: render_splat needs q (both steps), T and an order");
    const Extent3 e = in.qCur->Extent();
    if (image.Extent().nx != 3) return MakeError("vk: render_splat image must have extent (3, width, height)");
    const uint32_t W = image.Extent().ny, H = image.Extent().nz;
    const CameraFrame& cam = p.camera;

    // Which tile x band boxes can hold a splat: the frustum (host geometry,
    // shared with the CPU) and, when skipping, the two steps' band occupancy.
    auto visibility = DownloadSplatBoxVisibility(*this, p, in);
    if (!visibility) return std::unexpected(visibility.error());
    const std::vector<uint8_t>& boxes = *visibility;
    // The shared order, outer axis first.
    const SplatOrder& order = *p.order;
    const FlatSplatOrder flat = FlattenSplatOrder(order);
    struct alignas(16) Frame {
        uint32_t grid[4], axes[4], orderBase[4], boxes[4], image[4];
        float eye[4], forward[4], right[4], up[4], sun[4], sunRadiance[4], ambient[4], background[4], origin[4], misc[4];
    } frame{};
    constexpr uint32_t kVoxelsPerChunk = 1024, kSplatsPerChunk = 256, kTileSize = 8;
    const uint32_t voxels = uint32_t(e.Count());
    const uint32_t tilesX = CeilDiv(W, kTileSize), tilesY = CeilDiv(H, kTileSize), screenTiles = tilesX * tilesY;
    frame = {{e.nx, e.ny, e.nz, kVoxelsPerChunk},
             {uint32_t(order.axes[0]), uint32_t(order.axes[1]), uint32_t(order.axes[2]), voxels},
             {flat.base[0], flat.base[1], flat.base[2], 0},
             {p.tile, p.band, CeilDiv(e.nx, p.tile), CeilDiv(e.ny, p.tile)},
             {W, H, tilesX, tilesY},
             {cam.eye[0], cam.eye[1], cam.eye[2], cam.nearPlane},
             {cam.forward[0], cam.forward[1], cam.forward[2], cam.focalPx},
             {cam.right[0], cam.right[1], cam.right[2], 0},
             {cam.upVector[0], cam.upVector[1], cam.upVector[2], 0},
             {p.sun[0], p.sun[1], p.sun[2], p.phase.g},
             {p.sunRadiance[0], p.sunRadiance[1], p.sunRadiance[2], float(p.phase.kind)},
             {p.ambient[0], p.ambient[1], p.ambient[2], p.qMin},
             {p.background[0], p.background[1], p.background[2], p.opacity},
             {p.origin[0], p.origin[1], p.origin[2], p.voxelSize},
             {p.splatDiameter, p.alpha, 0, 0}};
    const uint32_t chunks = CeilDiv(voxels, kVoxelsPerChunk);
    // This stage's scratch buffers, one per VkScratch::Splat* slot (what each holds is said there).
    struct {
        DeviceBuffer *frame, *order, *boxes, *chunkSplats, *chunkVisited, *chunkOffsets;
        DeviceBuffer *splats, *binCounts, *tileTotals, *tileBases, *tileList;
    } scratch{};
    // At least 16 bytes: a binding needs a buffer even when nothing is in it.
    auto need = [&](DeviceBuffer*& buffer, VkScratch slot, VkDeviceSize bytes) -> Status {
        auto b = Scratch(slot, std::max<VkDeviceSize>(bytes, 16));
        if (!b) return std::unexpected(b.error());
        buffer = *b;
        return {};
    };
    CB_TRY(need(scratch.frame, VkScratch::SplatFrame, sizeof frame));
    CB_TRY(need(scratch.order, VkScratch::SplatOrder, flat.indices.size() * 4));
    CB_TRY(need(scratch.boxes, VkScratch::SplatBoxes, boxes.size()));
    CB_TRY(need(scratch.chunkSplats, VkScratch::SplatChunkSplats, VkDeviceSize(chunks) * 4));
    CB_TRY(need(scratch.chunkVisited, VkScratch::SplatChunkVisited, VkDeviceSize(chunks) * 4));
    CB_TRY(need(scratch.chunkOffsets, VkScratch::SplatChunkOffsets, VkDeviceSize(chunks + 1) * 4));
    CB_TRY(mContext->Upload(*scratch.frame, std::as_bytes(std::span(&frame, 1))));
    CB_TRY(mContext->Upload(*scratch.order, std::as_bytes(std::span(flat.indices))));
    CB_TRY(mContext->Upload(*scratch.boxes, std::as_bytes(std::span(boxes))));
    Pipeline* pipes[5] = {};
    const char* names[5] = {"splat_count", "scan", "splat_write", "splat_bin", "splat_composite"};
    const uint32_t bindings[5] = {8, 2, 8, 5, 4};
    for (int n = 0; n < 5; ++n) {
        auto pipe = mContext->GetPipeline(names[n], bindings[n]);
        if (!pipe) return std::unexpected(pipe.error());
        pipes[n] = *pipe;
    }
    const DeviceBuffer* common[6] = {&Dev(*in.qPrev), &Dev(*in.qCur), &Dev(*in.T), scratch.order, scratch.boxes, scratch.frame};
    double deviceMs = 0;
    auto run = [&](const char* what, auto&& record) -> Status {
        CB_TRY(Record(what, record));
        deviceMs += mLastDeviceMs.value_or(0);
        return {};
    };
    // 1. Splats per chunk of ranks, and their offsets.
    const uint32_t chunkPush = chunks;
    const DeviceBuffer* countBuffers[] = {common[0], common[1], common[2], common[3], common[4], common[5], scratch.chunkSplats, scratch.chunkVisited};
    const DeviceBuffer* scanChunks[] = {scratch.chunkSplats, scratch.chunkOffsets};
    CB_TRY(run("render_splat: counting splats", [&](VulkanContext::Recorder& r) {
        r.Dispatch(*pipes[0], countBuffers, &chunkPush, sizeof chunkPush, chunks);
        r.Barrier();
        r.Dispatch(*pipes[1], scanChunks, &chunkPush, sizeof chunkPush, 1);
    }));
    std::vector<uint32_t> chunkOffsets(chunks + 1);
    CB_TRY(mContext->Download(*scratch.chunkOffsets, std::as_writable_bytes(std::span(chunkOffsets))));
    const uint32_t splatCount = chunkOffsets[chunks];

    // 2. Write the splats in order; bin them by screen tile, keeping the order.
    const uint32_t splatChunks = std::max(1u, CeilDiv(splatCount, kSplatsPerChunk));
    CB_TRY(need(scratch.splats, VkScratch::Splats, VkDeviceSize(splatCount) * 48));
    CB_TRY(need(scratch.binCounts, VkScratch::SplatBinCounts, VkDeviceSize(splatChunks) * screenTiles * 4));
    CB_TRY(need(scratch.tileTotals, VkScratch::SplatTileTotals, VkDeviceSize(screenTiles) * 4));
    CB_TRY(need(scratch.tileBases, VkScratch::SplatTileBases, VkDeviceSize(screenTiles + 1) * 4));
    struct {
        uint32_t mode, splatCount, chunkSize, chunks, tilesX, tilesY, tileSize;
    } bin{0, splatCount, kSplatsPerChunk, splatChunks, tilesX, tilesY, kTileSize};
    const DeviceBuffer* writeBuffers[] = {common[0], common[1], common[2], common[3], common[4], common[5], scratch.chunkOffsets, scratch.splats};
    const uint32_t tilesPush = screenTiles;
    const DeviceBuffer* scanTiles[] = {scratch.tileTotals, scratch.tileBases};
    // The list is sized in step 3; splat_bin's binding 4 needs a buffer in the first passes.
    CB_TRY(need(scratch.tileList, VkScratch::SplatTileList, 16));
    const DeviceBuffer* binBuffers[] = {scratch.splats, scratch.binCounts, scratch.tileTotals, scratch.tileBases, scratch.tileList};
    CB_TRY(run("render_splat: binning", [&](VulkanContext::Recorder& r) {
        r.Dispatch(*pipes[2], writeBuffers, &chunkPush, sizeof chunkPush, chunks);
        r.Barrier();
        bin.mode = 0;
        r.Dispatch(*pipes[3], binBuffers, &bin, sizeof bin, splatChunks);
        r.Barrier();
        bin.mode = 1;
        r.Dispatch(*pipes[3], binBuffers, &bin, sizeof bin, screenTiles);
        r.Barrier();
        r.Dispatch(*pipes[1], scanTiles, &tilesPush, sizeof tilesPush, 1);
    }));
    std::vector<uint32_t> bases(screenTiles + 1);
    CB_TRY(mContext->Download(*scratch.tileBases, std::as_writable_bytes(std::span(bases))));

    // 3. Fill the tile lists; composite every pixel.
    CB_TRY(need(scratch.tileList, VkScratch::SplatTileList, VkDeviceSize(bases[screenTiles]) * 4));
    const DeviceBuffer* fillBuffers[] = {scratch.splats, scratch.binCounts, scratch.tileTotals, scratch.tileBases, scratch.tileList};
    struct {
        uint32_t width, height, tilesX, tileSize;
        float background[4];
    } composite{W, H, tilesX, kTileSize, {p.background[0], p.background[1], p.background[2], 0}};
    const DeviceBuffer* compositeBuffers[] = {scratch.splats, scratch.tileBases, scratch.tileList, &Dev(image)};
    CB_TRY(run("render_splat: compositing", [&](VulkanContext::Recorder& r) {
        bin.mode = 2;
        r.Dispatch(*pipes[3], fillBuffers, &bin, sizeof bin, splatChunks);
        r.Barrier();
        r.Dispatch(*pipes[4], compositeBuffers, &composite, sizeof composite, W * H);
    }));
    mLastDeviceMs = deviceMs;
    if (stats) {
        stats->splats = splatCount;
        stats->voxelsVisited = 0;  // not counted on this backend
        stats->fragments = 0;
    }
    return {};
}

}  // namespace cb::vk
