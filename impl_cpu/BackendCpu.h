// The CPU backend: bit-field automaton (64 voxels per word) and plain float
// volumes, parallelised with TBB inside a task arena of a chosen size.
#pragma once

#include <tbb/task_arena.h>

#include <memory>
#include <vector>

#include "core/math/Noise.h"
#include "core/math/Splat.h"
#include "core/pipeline/Backend.h"
#include "impl_cpu/BitField.h"

namespace cb::cpu {

// Buffer storage on the CPU, in the host layout (HostBufferBytes, core/pipeline/Backend.h). U8 volumes
// carry kPadding spare zero bytes at the end so that kernels may read a full
// 64-voxel word past a row's end.
class BufferCpu final : public Buffer {
  public:
    static constexpr size_t kPadding = kHostU8Padding;

    BufferCpu(BufferFormat format, Extent3 extent);

    BitField& Bits() { return mBits; }
    const BitField& Bits() const { return mBits; }
    uint8_t* U8() { return mU8.data(); }
    const uint8_t* U8() const { return mU8.data(); }
    float* F32() { return mF32.data(); }
    const float* F32() const { return mF32.data(); }

  private:
    BitField mBits;
    std::vector<uint8_t> mU8;
    std::vector<float> mF32;
};

// One voxel of the ray marcher's formed volume: q_alpha and T side by side,
// so a trilinear sample of both touches one set of cache lines.
struct MarchQT {
    float q, t;
};

// What smooth keeps between the shares of one sweep (SmoothCpu.cpp): the ring
// of slices filtered in x and y, valid for a share that starts at `next` on the
// same cld field and radius.
struct SmoothShareState {
    const BitField* cld = nullptr;  // not owned; nullptr: nothing to resume
    int radius = 0;
    Extent3 extent;
    uint32_t next = 0;      // the first output slice of the share that may resume
    uint32_t filtered = 0;  // slices below this one have been filtered into the ring
    std::vector<uint8_t> ring;  // 2 radius + 1 slices of numerators (1 or 2 bytes each)
    std::vector<uint8_t> xs;    // one slice of x sums
};

// Not final: tests derive test-only stages from it (a producer of q other than smooth).
class BackendCpu : public Backend {
  public:
    // threads = 0: all hardware threads.
    explicit BackendCpu(int threads = 0);

    std::string Name() const override { return "cpu"; }
    std::string Device() const override;
    bool Supports(Stage stage) const override;

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    // The host layout (HostBufferBytes).
    uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const override;
    // The automaton's advection fields with wind, each thread's smoothing ring,
    // shade's coarse grids; per-call rows and the renderer's
    // splat lists (which depend on the clouds) are not counted.
    uint64_t ScratchBytes(const Scene& scene) const override;
    // What this process may still allocate: available memory, cgroup and RLIMIT_AS (core/base/ProcessMemory.h).
    std::optional<uint64_t> AvailableBytes() const override;

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_MARCH_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_NOISE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)

    int Threads() const { return mArena.max_concurrency(); }

  private:
    tbb::task_arena mArena;
    // Scratch kept between calls so that steady-state steps do not allocate.
    std::vector<BitField> mAdvectScratch;
    SmoothShareState mSmoothShare;                    // smooth in shares (time-slicing)
    std::vector<float> mShadeCoarseQ, mShadeCoarseT;  // shade at resolution f > 1
    std::vector<MarchQT> mMarchVolume;                // render_march: padded (q_alpha, T)
    std::vector<uint8_t> mMarchBricks;                // render_march: empty bricks
    std::vector<std::vector<Splat>> mSplatSlices;     // render_splat: each outer slice's splats
    // Noise: what does not change per step (permutations, the detail volume),
    // made on the first call and again only when the settings or grid change;
    // and the weather map of one call (coverage only).
    std::unique_ptr<noise::NoiseForm> mNoiseForm;
    std::vector<float> mNoiseMap;
};

}  // namespace cb::cpu
