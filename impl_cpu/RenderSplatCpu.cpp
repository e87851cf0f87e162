// Stage `render_splat` on the CPU (SPEC 8): a deterministic tile-free splat
// rasteriser.
//   1. Culling and skipping decide, per tile x height-band box, whether any of
//      its voxels can make a visible splat (conservatively: the image is the
//      same with both off).
//   2. Splats are generated in the shared back-to-front order, one outer-axis
//      slice per task, and concatenated in order.
//   3. A counting sort bins them by bands of image rows, keeping their order.
//   4. Each row band composites its splats in order, in parallel.
// Every pixel sees its splats in the same order for any thread count.
#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "core/Splat.h"
#include "impl_cpu/BackendCpu.h"

namespace cb::cpu {
namespace {

constexpr uint32_t kRowsPerBand = 8;

}  // namespace

Status BackendCpu::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& imageBuffer, SplatStats* stats) {
    if (!p.order || !in.qPrev || !in.qCur || !in.T) return MakeError("cpu: render_splat needs q (both steps), T and an order");
    if (p.skipping && (!in.tilesPrev || !in.tilesCur || !in.bandsPrev || !in.bandsCur))
        return MakeError("cpu: render_splat with skipping needs both steps' occupancy");
    const Extent3 e = in.qCur->Extent();
    const Extent3 imageExtent = imageBuffer.Extent();
    if (imageExtent.nx != 3) return MakeError("cpu: render_splat image must have extent (3, width, height)");
    const uint32_t W = imageExtent.ny, H = imageExtent.nz;
    const float* qPrev = static_cast<const BufferCpu&>(*in.qPrev).F32();
    const float* qCur = static_cast<const BufferCpu&>(*in.qCur).F32();
    const float* T = static_cast<const BufferCpu&>(*in.T).F32();
    float* image = static_cast<BufferCpu&>(imageBuffer).F32();
    // The ground (core/Ground.h): each pixel's background where its ray meets the plane.
    CB_TRY(CheckGroundInput(p.ground, in.G, e, "cpu: render_splat"));
    const float* G = p.ground.on ? static_cast<const BufferCpu&>(*in.G).F32() : nullptr;
    const GroundLight groundLight = MakeGroundLight(p);
    const Vec3 eyeVoxel = GroundEyeVoxel(p.camera, p.origin, p.voxelSize);

    // 1. Which tile x band boxes can contribute.
    const uint32_t tilesX = CeilDiv(e.nx, p.tile), tilesY = CeilDiv(e.ny, p.tile), bandCount = CeilDiv(e.nz, p.band);
    const size_t boxCount = size_t(tilesX) * tilesY * bandCount;
    std::span<const uint8_t> bandsPrev, bandsCur;
    if (p.skipping) {
        bandsPrev = {static_cast<const BufferCpu&>(*in.bandsPrev).U8(), boxCount};
        bandsCur = {static_cast<const BufferCpu&>(*in.bandsCur).U8(), boxCount};
    }
    const std::vector<uint8_t> boxVisible = SplatBoxVisibility(p, e, bandsPrev, bandsCur);

    // 2. Splats in the shared order: task `n` makes those of the n-th outer slice.
    const SplatOrder& order = *p.order;
    const int outer = order.axes[0], middle = order.axes[1], inner = order.axes[2];
    const std::vector<uint32_t>& outerIdx = order.indices[outer];
    std::vector<std::vector<Splat>> perSlice(outerIdx.size());
    std::vector<uint64_t> visitedPerSlice(outerIdx.size(), 0);
    const SplatFrame frame = MakeSplatFrame(p, e, FlattenSplatOrder(order), W, H);
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, outerIdx.size()), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t n = range.begin(); n != range.end(); ++n) {
                std::vector<Splat>& out = perSlice[n];
                uint32_t idx[3];
                idx[outer] = outerIdx[n];
                for (uint32_t mIndex : order.indices[middle]) {
                    idx[middle] = mIndex;
                    for (uint32_t iIndex : order.indices[inner]) {
                        idx[inner] = iIndex;
                        const uint32_t i = idx[0], j = idx[1], k = idx[2];
                        if (!boxVisible[i / p.tile + size_t(tilesX) * (j / p.tile + size_t(tilesY) * (k / p.band))])
                            continue;
                        ++visitedPerSlice[n];
                        const uint32_t v = VoxelIndex(e, i, j, k);
                        Splat s;
                        if (MakeSplat(frame, i, j, k, SplatQ(qPrev[v], qCur[v], p.alpha), T[v], s)) out.push_back(s);
                    }
                }
            }
        });
    });
    std::vector<Splat> splats;
    uint64_t visited = 0;
    {
        size_t total = 0;
        for (const auto& slice : perSlice) total += slice.size();
        splats.reserve(total);
        for (size_t n = 0; n < perSlice.size(); ++n) {
            splats.insert(splats.end(), perSlice[n].begin(), perSlice[n].end());
            visited += visitedPerSlice[n];
            std::vector<Splat>().swap(perSlice[n]);
        }
    }
    if (stats) {
        stats->splats = splats.size();
        stats->voxelsVisited = visited;
    }

    // 3. Bin by bands of rows, keeping the order (counting sort).
    const uint32_t bands = CeilDiv(H, kRowsPerBand);
    std::vector<uint32_t> count(bands + 1, 0);
    auto bandRange = [&](const Splat& s, uint32_t& b0, uint32_t& b1) {
        if (s.x0 > s.x1 || s.y0 > s.y1) return false;
        b0 = uint32_t(s.y0) / kRowsPerBand;
        b1 = uint32_t(s.y1) / kRowsPerBand;
        return true;
    };
    for (const Splat& s : splats) {
        uint32_t b0, b1;
        if (bandRange(s, b0, b1))
            for (uint32_t b = b0; b <= b1; ++b) ++count[b + 1];
    }
    for (uint32_t b = 0; b < bands; ++b) count[b + 1] += count[b];
    if (stats) {
        stats->fragments = 0;
        for (const Splat& s : splats)
            if (s.x0 <= s.x1 && s.y0 <= s.y1) stats->fragments += uint64_t(s.x1 - s.x0 + 1) * uint64_t(s.y1 - s.y0 + 1);
    }
    std::vector<uint32_t> binned(count[bands]);
    {
        std::vector<uint32_t> cursor(count.begin(), count.end() - 1);
        for (uint32_t n = 0; n < splats.size(); ++n) {
            uint32_t b0, b1;
            if (bandRange(splats[n], b0, b1))
                for (uint32_t b = b0; b <= b1; ++b) binned[cursor[b]++] = n;
        }
    }

    // 4. Composite each band: C <- alpha c + (1 - alpha) C, from the background.
    // A splat row is blended as one run of floats (RGB interleaved): first the
    // alphas of its pixels, spread to their three channels, and the splat's
    // colour repeated, then one contiguous loop the compiler vectorises. The
    // arithmetic per channel is the scalar formula's, so the image is the same.
    mArena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, bands), [&](const tbb::blocked_range<uint32_t>& range) {
            std::vector<float> alphaRun(3 * size_t(W)), colourRun(3 * size_t(W));
            for (uint32_t b = range.begin(); b != range.end(); ++b) {
                const uint32_t rowLo = b * kRowsPerBand, rowHi = std::min(H, rowLo + kRowsPerBand) - 1;
                for (uint32_t y = rowLo; y <= rowHi; ++y) {
                    float* row = image + size_t(3) * W * y;
                    for (uint32_t x = 0; x < W; ++x) {
                        const Vec3 background =
                            G ? GroundBackground(p.camera, eyeVoxel, p.voxelSize, groundLight, G, e.nx, e.ny, x, y)
                              : p.background;
                        for (int c = 0; c < 3; ++c) row[3 * x + c] = background[c];
                    }
                }
                float* alphas = alphaRun.data();
                float* colours = colourRun.data();
                for (uint32_t n = count[b]; n < count[b + 1]; ++n) {
                    const Splat& s = splats[binned[n]];
                    const int32_t y0 = std::max<int32_t>(s.y0, int32_t(rowLo)), y1 = std::min<int32_t>(s.y1, int32_t(rowHi));
                    if (y0 > y1) continue;
                    const int32_t width = s.x1 - s.x0 + 1;  // <= W: MakeSplat clamps the range to the image
                    const float r = s.colour[0], g = s.colour[1], bl = s.colour[2];
                    for (int32_t i = 0; i < width; ++i) {
                        colours[3 * i] = r;
                        colours[3 * i + 1] = g;
                        colours[3 * i + 2] = bl;
                    }
                    const float px = s.px, size = s.size, alphaScale = s.alphaScale;
                    const int32_t x0 = s.x0;
                    for (int32_t y = y0; y <= y1; ++y) {
                        const float bCoord = SplatCoord(float(y) + 0.5f, s.py, size);
                        for (int32_t i = 0; i < width; ++i) {
                            const float alpha =
                                SplatAlpha(alphaScale, SplatCoord(float(x0 + i) + 0.5f, px, size), bCoord);
                            alphas[3 * i] = alpha;
                            alphas[3 * i + 1] = alpha;
                            alphas[3 * i + 2] = alpha;
                        }
                        float* run = image + size_t(3) * (size_t(W) * uint32_t(y) + uint32_t(x0));
                        for (int32_t j = 0; j < 3 * width; ++j)
                            run[j] = Lerp(run[j], colours[j], alphas[j]);
                    }
                }
            }
        });
    });
    return {};
}

}  // namespace cb::cpu
