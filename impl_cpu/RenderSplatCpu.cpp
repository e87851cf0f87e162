// Stage `render_splat` on the CPU (SPEC 8): a deterministic tile-free splat
// rasteriser.
//   1. Culling and skipping decide, per tile x height-band box, whether any of
//      its voxels can make a visible splat (conservatively: the image is the
//      same with both off).
//   2. Splats are generated in the shared back-to-front order, one outer-axis
//      slice per task; each slice keeps its own list (no concatenation). When
//      the order's inner axis is not x, the candidates are first marked in
//      one pass over memory, and each slice walks only its marks.
//   3. A counting sort bins pointers to them by bands of image rows, keeping
//      their order.
//   4. Each row band composites its splats in order, in parallel, into planar
//      R, G, B rows (then interleaved into the image once).
// Every pixel sees its splats in the same order for any thread count, and
// every pixel's arithmetic is the scalar formula's (SplatCoord, SplatKernel,
// SplatAlpha, Lerp) operation for operation, so the image is the same bit for
// bit as one pixel at a time (docs/performance.md, "render_splat on 2 cores").
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "impl_cpu/RenderSplatCpu.cpp"
#include <hwy/foreach_target.h>  // includes this file again, once per SIMD target (impl_cpu/CpuIsa.h)
#include <hwy/highway.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/math/Splat.h"
#include "core/pipeline/SplatFrame.h"
#include "impl_cpu/BackendCpu.h"
#include "impl_cpu/RenderSplatCpuState.h"

HWY_BEFORE_NAMESPACE();
namespace cb::cpu::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;
namespace {

constexpr uint32_t kSplatCpuRowsPerBand = 8;

// The squared kernel coordinate (2 a - 1)^2 of a splat's pixel whose centre is
// at `pixelCentre`, as SplatCoord and SplatKernel compute it: a depends only on
// the pixel's column (or row), so it is worked out once per column (row) of a
// splat, not once per pixel.
inline float SplatCpuKernelSquare(float pixelCentre, float centre, float size) {
    const float x = 2.0f * SplatCoord(pixelCentre, centre, size) - 1.0f;
    return x * x;
}

// std::max(0, u), which is (0 < u) ? u : 0. The x86 max instructions give
// their second operand unless the first is greater, the same; Highway's
// one-lane Max differs for NaN, so the scalar target compares.
template <class V>
HWY_INLINE V MaxOfZeroAnd(V zero, V u) {
#if HWY_TARGET == HWY_SCALAR || HWY_TARGET == HWY_EMU128
    return hn::IfThenElse(hn::Lt(zero, u), u, zero);
#else
    return hn::Max(u, zero);
#endif
}

// std::clamp(v, 0, 1), which is v < 0 ? 0 : (1 < v ? 1 : v): on x86
// min(1, max(0, v)) in that operand order (see MaxOfZeroAnd).
template <class V>
HWY_INLINE V ClampToUnit(V zero, V one, V v) {
#if HWY_TARGET == HWY_SCALAR || HWY_TARGET == HWY_EMU128
    return hn::IfThenElse(hn::Lt(v, zero), zero, hn::IfThenElse(hn::Lt(one, v), one, v));
#else
    return hn::Min(one, hn::Max(zero, v));
#endif
}

// Blends the rows y0 .. y1 of splat `s` into the band's planar channel rows
// (R, G, B: rows of `stride` floats, row 0 = image row `rowLo`). Per pixel:
// alpha = clamp(alphaScale t^2, 0, 1) with t = max(0, 1 - (xx + yy)), xx and
// yy the squared kernel coordinates of its column and row, then
// C <- C (1 - alpha) + colour alpha: SplatAlpha's and Lerp's operations, in
// their order, on every target (one lane at a time on the scalar one).
inline void SplatCpuBlend(const Splat& s, int32_t y0, int32_t y1, uint32_t rowLo, size_t stride, float* R, float* G,
                          float* B) {
    // Aligned blocks of N columns (N lanes of the target), each block's xx kept
    // in a register for all rows. Loads and stores are whole aligned vectors
    // (the rows are 64-byte aligned and a multiple of 16 floats long), lanes
    // outside the splat storing back what they loaded, so that every load
    // meets an earlier store of exactly the same vector and can be forwarded
    // from it (a load that overlaps a store only in part waits until the store
    // reaches the cache; the splats of a band overlap their neighbours'
    // columns). max(0, u) and the clamp give <algorithm>'s results on every
    // target, NaN and signed zeros included.
    const hn::ScalableTag<float> d;
    const hn::RebindToSigned<decltype(d)> di;
    const int32_t N = int32_t(hn::Lanes(d));
    const auto half = hn::Set(d, 0.5f), two = hn::Set(d, 2.0f), one = hn::Set(d, 1.0f), zero = hn::Zero(d);
    const auto vpx = hn::Set(d, s.px), vsize = hn::Set(d, s.size), scale = hn::Set(d, s.alphaScale);
    const auto cr = hn::Set(d, s.colour[0]), cg = hn::Set(d, s.colour[1]), cb = hn::Set(d, s.colour[2]);
    const auto first = hn::Set(di, s.x0), last = hn::Set(di, s.x1);
    const auto iota = hn::Iota(di, 0);
    float yy[kSplatCpuRowsPerBand];  // y1 - y0 < kSplatCpuRowsPerBand: the rows lie in one band
    for (int32_t y = y0; y <= y1; ++y) yy[y - y0] = SplatCpuKernelSquare(float(y) + 0.5f, s.py, s.size);
    for (int32_t xb = s.x0 & ~(N - 1); xb <= s.x1; xb += N) {
        const auto column = hn::Add(hn::Set(di, xb), iota);
        const auto inside = hn::RebindMask(d, hn::And(hn::Not(hn::Lt(column, first)), hn::Not(hn::Gt(column, last))));
        // SplatCoord and SplatKernel's x: exact int -> float (|x| < 2^24), then the same operations.
        const auto a = hn::Add(hn::Div(hn::Sub(hn::Add(hn::ConvertTo(d, column), half), vpx), vsize), half);
        const auto c = hn::Sub(hn::Mul(two, a), one);
        const auto xx = hn::Mul(c, c);
        // A block wholly inside the splat stores its blend as it is; an edge block keeps its outside lanes.
        const bool whole = hn::AllTrue(d, inside);
        for (int32_t y = y0; y <= y1; ++y) {
            const auto u = hn::Sub(one, hn::Add(xx, hn::Set(d, yy[y - y0])));
            const auto t = MaxOfZeroAnd(zero, u);
            const auto v = hn::Mul(scale, hn::Mul(t, t));
            const auto alpha = ClampToUnit(zero, one, v);
            const auto keep = hn::Sub(one, alpha);
            const size_t o = stride * uint32_t(y - int32_t(rowLo)) + uint32_t(xb);
            const auto r = hn::Load(d, R + o), g = hn::Load(d, G + o), b = hn::Load(d, B + o);
            const auto nr = hn::Add(hn::Mul(r, keep), hn::Mul(cr, alpha));
            const auto ng = hn::Add(hn::Mul(g, keep), hn::Mul(cg, alpha));
            const auto nb = hn::Add(hn::Mul(b, keep), hn::Mul(cb, alpha));
            hn::Store(whole ? nr : hn::IfThenElse(inside, nr, r), d, R + o);
            hn::Store(whole ? ng : hn::IfThenElse(inside, ng, g), d, G + o);
            hn::Store(whole ? nb : hn::IfThenElse(inside, nb, b), d, B + o);
        }
    }
}

}  // namespace

Status RenderSplat(tbb::task_arena& arena, RenderSplatCpuState& state, const SplatParams& p, const SplatInputs& in,
                   Buffer& imageBuffer, SplatStats* stats) {
    std::vector<std::vector<Splat>>& slicesKept = state.slices;
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
    const bool skyLight = p.light.skyOn;
    if (skyLight && (!in.TSky || in.TSky->Extent() != e))
        return MakeError("cpu: render_splat: the sky light needs T_sky of q's size");
    const float* skyT = skyLight ? static_cast<const BufferCpu&>(*in.TSky).F32() : nullptr;
    float* image = static_cast<BufferCpu&>(imageBuffer).F32();
    // The ground (core/math/Ground.h): each pixel's background where its ray meets the plane.
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
    // Per axis: a voxel index's part of its box index and of its voxel index,
    // so that the walk below adds three numbers instead of dividing per voxel.
    const uint32_t extent[3] = {e.nx, e.ny, e.nz};
    const size_t voxelStride[3] = {1, size_t(e.nx), size_t(e.nx) * e.ny};
    std::vector<uint32_t> boxPart[3];
    for (int a = 0; a < 3; ++a) {
        boxPart[a].resize(extent[a]);
        for (uint32_t n = 0; n < extent[a]; ++n)
            boxPart[a][n] = a == 0 ? n / p.tile : a == 1 ? tilesX * (n / p.tile) : tilesX * tilesY * (n / p.band);
    }

    // 2. Splats in the shared order: task `n` makes those of the n-th outer slice.
    // When the inner axis is not x, walking it steps through memory by whole
    // rows or slices (the view from above: inner z, 256 KiB a step). Then one
    // pass over the grid in memory order first marks the candidates (a visible
    // box and q_alpha > q_min) in a bit mask per outer slice, at bit
    // rankMiddle * nInner + rankInner, and the walk visits the marked voxels
    // in that bit order, which is the order's; it counts the visited voxels
    // (all of the visible boxes') box by box.
    const SplatOrder& order = *p.order;
    const int outer = order.axes[0], middle = order.axes[1], inner = order.axes[2];
    const std::vector<uint32_t>& outerIdx = order.indices[outer];
    const std::vector<uint32_t>& middleIdx = order.indices[middle];
    const std::vector<uint32_t>& innerIdx = order.indices[inner];
    const uint32_t nMiddle = uint32_t(middleIdx.size()), nInner = uint32_t(innerIdx.size());
    const bool marked = voxelStride[inner] != 1;
    std::vector<uint32_t> rank[3];
    for (int a = 0; a < 3; ++a) {
        rank[a].resize(order.indices[a].size());
        for (uint32_t r = 0; r < rank[a].size(); ++r) rank[a][order.indices[a][r]] = r;
    }
    if (slicesKept.size() < outerIdx.size()) slicesKept.resize(outerIdx.size());
    std::vector<uint64_t> visitedPerSlice(outerIdx.size(), 0);
    const SplatFrame frame = MakeSplatFrame(p, e, FlattenSplatOrder(order), W, H);
    const float qMin = frame.qMin, alpha = p.alpha;
    const uint8_t* const visible = boxVisible.data();
    const uint32_t *const boxMiddle = boxPart[middle].data(), *const boxInner = boxPart[inner].data();
    const size_t strideMiddle = voxelStride[middle], strideInner = voxelStride[inner];
    const size_t sliceWords = marked ? (size_t(nMiddle) * nInner + 63) / 64 : 0;
    std::vector<uint64_t> marks(sliceWords * outerIdx.size(), 0);
    if (marked) {
        arena.execute([&] {
            tbb::parallel_for(tbb::blocked_range<uint32_t>(0, e.ny * e.nz), [&](const tbb::blocked_range<uint32_t>& rows) {
                std::vector<uint8_t> candidate(size_t(e.nx) + 8, 0);
                uint32_t idx[3];
                for (uint32_t row = rows.begin(); row != rows.end(); ++row) {
                    idx[1] = row % e.ny;
                    idx[2] = row / e.ny;
                    const float *a = qPrev + size_t(e.nx) * row, *b = qCur + size_t(e.nx) * row;
                    for (uint32_t x = 0; x < e.nx; ++x) candidate[x] = SplatQ(a[x], b[x], alpha) > qMin;
                    const uint32_t rowBox = boxPart[1][idx[1]] + boxPart[2][idx[2]];
                    for (uint32_t x0 = 0; x0 < e.nx; x0 += 8) {
                        uint64_t eight;
                        std::memcpy(&eight, candidate.data() + x0, 8);
                        if (eight == 0) continue;
                        for (uint32_t x = x0; x < std::min(e.nx, x0 + 8); ++x) {
                            if (!candidate[x] || !visible[rowBox + boxPart[0][x]]) continue;
                            idx[0] = x;
                            const size_t bit = size_t(rank[middle][idx[middle]]) * nInner + rank[inner][idx[inner]];
                            std::atomic_ref<uint64_t>(marks[sliceWords * rank[outer][idx[outer]] + bit / 64])
                                .fetch_or(uint64_t(1) << (bit % 64), std::memory_order_relaxed);
                        }
                    }
                }
            });
        });
    }
    // Voxels of an outer slice in visible boxes, box by box: the middle and
    // inner indices cut into runs of consecutive indices with one box part.
    struct PartRun {
        uint32_t part, voxels;
    };
    auto partRuns = [&](int axis) {
        std::vector<PartRun> runs;
        for (uint32_t n = 0; n < extent[axis]; ++n)
            if (runs.empty() || runs.back().part != boxPart[axis][n]) runs.push_back({boxPart[axis][n], 1});
            else ++runs.back().voxels;
        return runs;
    };
    const std::vector<PartRun> middleRuns = partRuns(middle), innerRuns = partRuns(inner);
    // flatten: MakeSplat and what it calls (core/math, compiled for the
    // baseline where they are not inlined) become this target's code.
    arena.execute([&] {
        tbb::parallel_for(
            tbb::blocked_range<size_t>(0, outerIdx.size()), [&](const tbb::blocked_range<size_t>& range) __attribute__((
                                                                flatten)) {
                for (size_t n = range.begin(); n != range.end(); ++n) {
                    std::vector<Splat>& out = slicesKept[n];
                    out.clear();
                    uint64_t visited = 0;
                    uint32_t idx[3];
                    idx[outer] = outerIdx[n];
                    const size_t vOuter = voxelStride[outer] * idx[outer];
                    const uint32_t bOuter = boxPart[outer][idx[outer]];
                    if (marked) {
                        for (const PartRun& m : middleRuns)
                            for (const PartRun& i : innerRuns)
                                if (visible[bOuter + m.part + i.part]) visited += uint64_t(m.voxels) * i.voxels;
                        const uint64_t* sliceMarks = marks.data() + sliceWords * n;
                        for (size_t w = 0; w < sliceWords; ++w)
                            for (uint64_t bits = sliceMarks[w]; bits != 0; bits &= bits - 1) {
                                const size_t bit = 64 * w + size_t(std::countr_zero(bits));
                                idx[middle] = middleIdx[bit / nInner];
                                idx[inner] = innerIdx[bit % nInner];
                                const size_t v = vOuter + strideMiddle * idx[middle] + strideInner * idx[inner];
                                Splat s;
                                if (MakeSplat(frame, idx[0], idx[1], idx[2], SplatQ(qPrev[v], qCur[v], alpha), T[v],
                                              skyT ? skyT[v] : 1.0f, s))
                                    out.push_back(s);
                            }
                        visitedPerSlice[n] = visited;
                        continue;
                    }
                    for (uint32_t mr = 0; mr < nMiddle; ++mr) {
                        const uint32_t mIndex = middleIdx[mr];
                        idx[middle] = mIndex;
                        const size_t vMiddle = vOuter + strideMiddle * mIndex;
                        const uint32_t bMiddle = bOuter + boxMiddle[mIndex];
                        for (uint32_t ir = 0; ir < nInner; ++ir) {
                            const uint32_t iIndex = innerIdx[ir];
                            if (!visible[bMiddle + boxInner[iIndex]]) continue;
                            ++visited;
                            const size_t v = vMiddle + strideInner * iIndex;
                            const float qa = SplatQ(qPrev[v], qCur[v], alpha);
                            if (!(qa > qMin)) continue;  // MakeSplat's first test
                            idx[inner] = iIndex;
                            Splat s;
                            if (MakeSplat(frame, idx[0], idx[1], idx[2], qa, T[v], skyT ? skyT[v] : 1.0f, s))
                                out.push_back(s);
                        }
                    }
                    visitedPerSlice[n] = visited;
                }
            });
    });

    // 3. Bin by bands of rows, keeping the order: a counting sort in parallel
    // over runs of consecutive slices (each run counts, then writes from its
    // own offsets, which follow the earlier runs'), so every band's list is in
    // slice order; the fragments are counted on the way.
    const std::span<const std::vector<Splat>> slices(slicesKept.data(), outerIdx.size());
    const uint32_t bands = CeilDiv(H, kSplatCpuRowsPerBand);
    const size_t runs = std::clamp<size_t>(slices.size(), 1, 64), perRun = (slices.size() + runs - 1) / runs;
    std::vector<uint32_t> runCount(runs * bands, 0);  // runCount[run * bands + band]
    std::vector<uint64_t> runFragments(runs, 0);
    arena.execute([&] {
        tbb::parallel_for(size_t(0), runs, [&](size_t r) {
            uint32_t* c = runCount.data() + r * bands;
            uint64_t f = 0;
            for (size_t n = r * perRun; n < std::min(slices.size(), (r + 1) * perRun); ++n)
                for (const Splat& s : slices[n]) {
                    if (s.x0 > s.x1 || s.y0 > s.y1) continue;
                    f += uint64_t(s.x1 - s.x0 + 1) * uint64_t(s.y1 - s.y0 + 1);
                    for (uint32_t b = uint32_t(s.y0) / kSplatCpuRowsPerBand; b <= uint32_t(s.y1) / kSplatCpuRowsPerBand; ++b)
                        ++c[b];
                }
            runFragments[r] = f;
        });
    });
    uint64_t splatCount = 0, visited = 0, fragments = 0;
    for (size_t n = 0; n < slices.size(); ++n) {
        visited += visitedPerSlice[n];
        splatCount += slices[n].size();
    }
    for (uint64_t f : runFragments) fragments += f;
    if (stats) {
        stats->splats = splatCount;
        stats->voxelsVisited = visited;
        stats->fragments = fragments;
    }
    // count[b]: where band b's list starts; runCount becomes each run's cursor.
    std::vector<uint32_t> count(bands + 1, 0);
    for (uint32_t b = 0; b < bands; ++b) {
        uint32_t at = count[b];
        for (size_t r = 0; r < runs; ++r) {
            const uint32_t c = runCount[r * bands + b];
            runCount[r * bands + b] = at;
            at += c;
        }
        count[b + 1] = at;
    }
    std::vector<const Splat*> binned(count[bands]);
    arena.execute([&] {
        tbb::parallel_for(size_t(0), runs, [&](size_t r) {
            uint32_t* cursor = runCount.data() + r * bands;
            for (size_t n = r * perRun; n < std::min(slices.size(), (r + 1) * perRun); ++n)
                for (const Splat& s : slices[n]) {
                    if (s.x0 > s.x1 || s.y0 > s.y1) continue;
                    for (uint32_t b = uint32_t(s.y0) / kSplatCpuRowsPerBand; b <= uint32_t(s.y1) / kSplatCpuRowsPerBand; ++b)
                        binned[cursor[b]++] = &s;
                }
        });
    });

    // 4. Composite each band: C <- alpha c + (1 - alpha) C, from the background,
    // into planar rows of the band (one per channel), then interleave them into
    // the image. Per splat the squared kernel coordinate of each of its columns
    // is worked out once (the division), per row once more; each pixel then
    // adds, clamps and blends (SplatCpuBlendRow).
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range<uint32_t>(0, bands), [&](const tbb::blocked_range<uint32_t>& range) {
            // Rows of `stride` floats, 64-byte aligned (SplatCpuBlend's aligned blocks).
            const size_t stride = (size_t(W) + 15) & ~size_t(15), plane = kSplatCpuRowsPerBand * stride;
            std::vector<float> planes(3 * plane + 16);
            float* const pr = planes.data() + (16 - (reinterpret_cast<uintptr_t>(planes.data()) / sizeof(float)) % 16) % 16;
            float* const pg = pr + plane;
            float* const pb = pg + plane;
            for (uint32_t b = range.begin(); b != range.end(); ++b) {
                const uint32_t rowLo = b * kSplatCpuRowsPerBand, rowHi = std::min(H, rowLo + kSplatCpuRowsPerBand) - 1;
                for (uint32_t y = rowLo; y <= rowHi; ++y) {
                    const size_t o = stride * (y - rowLo);
                    if (!G) {
                        std::fill_n(pr + o, W, p.background[0]);
                        std::fill_n(pg + o, W, p.background[1]);
                        std::fill_n(pb + o, W, p.background[2]);
                        continue;
                    }
                    for (uint32_t x = 0; x < W; ++x) {
                        const Vec3 background =
                            GroundBackground(p.camera, eyeVoxel, p.voxelSize, groundLight, G, e.nx, e.ny, x, y);
                        pr[o + x] = background[0];
                        pg[o + x] = background[1];
                        pb[o + x] = background[2];
                    }
                }
                const uint32_t end = count[b + 1];
                for (uint32_t n = count[b]; n < end; ++n) {
                    if (n + 8 < end) __builtin_prefetch(binned[n + 8]);  // the splats of a band lie apart in memory
                    const Splat& s = *binned[n];
                    const int32_t y0 = std::max<int32_t>(s.y0, int32_t(rowLo)), y1 = std::min<int32_t>(s.y1, int32_t(rowHi));
                    if (y0 <= y1) SplatCpuBlend(s, y0, y1, rowLo, stride, pr, pg, pb);
                }
                for (uint32_t y = rowLo; y <= rowHi; ++y) {
                    const size_t o = stride * (y - rowLo);
                    float* row = image + size_t(3) * W * y;
                    for (uint32_t x = 0; x < W; ++x) {
                        row[3 * x] = pr[o + x];
                        row[3 * x + 1] = pg[o + x];
                        row[3 * x + 2] = pb[o + x];
                    }
                }
            }
        });
    });
    return {};
}

}  // namespace cb::cpu::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace cb::cpu {

HWY_EXPORT(RenderSplat);

Status BackendCpu::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& imageBuffer, SplatStats* stats) {
    return HWY_DYNAMIC_DISPATCH(RenderSplat)(mArena, mStages.Get<RenderSplatCpuState>(), p, in, imageBuffer, stats);
}

}  // namespace cb::cpu
#endif  // HWY_ONCE
