// Stage `render_splat` (SPEC 8) on Vulkan: count, write, bin and composite the
// splats in the shared order (splat_*.comp, scan.comp).
#include <algorithm>
#include <vector>

#include "impl_vk/StageVk.h"

namespace cb::vk {

Status BackendVk::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) {
    if (!p.order || !in.qPrev || !in.qCur || !in.T)
        return MakeError("vk: render_splat needs q (both steps), T and an order");
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
        float eye[4], forward[4], right[4], up[4], sun[4], sunRadiance[4], ambient[4], background[4], origin[4],
            misc[4];
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
    const DeviceBuffer* common[6] = {&Dev(*in.qPrev), &Dev(*in.qCur), &Dev(*in.T),
                                     scratch.order,   scratch.boxes,  scratch.frame};
    double deviceMs = 0;
    auto run = [&](const char* what, auto&& record) -> Status {
        CB_TRY(Record(what, record));
        deviceMs += mLastDeviceMs.value_or(0);
        return {};
    };
    // 1. Splats per chunk of ranks, and their offsets.
    const uint32_t chunkPush = chunks;
    const DeviceBuffer* countBuffers[] = {common[0], common[1], common[2],           common[3],
                                          common[4], common[5], scratch.chunkSplats, scratch.chunkVisited};
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
    const DeviceBuffer* writeBuffers[] = {
        common[0], common[1], common[2], common[3], common[4], common[5], scratch.chunkOffsets, scratch.splats};
    const uint32_t tilesPush = screenTiles;
    const DeviceBuffer* scanTiles[] = {scratch.tileTotals, scratch.tileBases};
    // The list is sized in step 3; splat_bin's binding 4 needs a buffer in the first passes.
    CB_TRY(need(scratch.tileList, VkScratch::SplatTileList, 16));
    const DeviceBuffer* binBuffers[] = {scratch.splats, scratch.binCounts, scratch.tileTotals, scratch.tileBases,
                                        scratch.tileList};
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
    const DeviceBuffer* fillBuffers[] = {scratch.splats, scratch.binCounts, scratch.tileTotals, scratch.tileBases,
                                         scratch.tileList};
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
