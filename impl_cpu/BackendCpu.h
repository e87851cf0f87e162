// The CPU backend: bit-field automaton (64 voxels per word) and plain float
// volumes, parallelised with TBB inside a task arena of a chosen size.
#pragma once

#include <tbb/task_arena.h>

#include <memory>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/pipeline/StageObjects.h"
#include "impl_cpu/BitField.h"
#include "impl_cpu/CaCpuState.h"
#include "impl_cpu/NoiseCpuState.h"
#include "impl_cpu/RenderLayersCpuState.h"
#include "impl_cpu/RenderMarchCpuState.h"
#include "impl_cpu/RenderSplatCpuState.h"
#include "impl_cpu/ShadeCpuState.h"
#include "impl_cpu/SmoothCpuState.h"

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

// Not final: tests derive test-only stages from it (a producer of q other than smooth).
class BackendCpu : public Backend {
  public:
    // threads = 0: all hardware threads.
    explicit BackendCpu(int threads = 0);

    std::string Name() const override { return "cpu"; }
    std::string Device() const override;
    bool Supports(Stage stage) const override { return StagesCpu::Implements(stage); }

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    // The host layout (HostBufferBytes).
    uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const override;
    // The sum of the stage objects' (each says what it counts in its <Stage>CpuState.h).
    uint64_t ScratchBytes(const Scene& scene) const override { return mStages.ScratchBytes(scene); }
    // What this process may still allocate: available memory, cgroup and RLIMIT_AS (core/base/ProcessMemory.h).
    std::optional<uint64_t> AvailableBytes() const override;

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_SKY_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_MARCH_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_NOISE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_LAYERS_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    Status AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) override;

    int Threads() const { return mArena.max_concurrency(); }
    // Every thread of the arena spins for an equal share of `cpuMs` of CPU time, at most `wallMs` each.
    void BusyFor(double wallMs, double cpuMs) override;

  private:
    // The stage objects (core/pipeline/StageObjects.h): what each stage keeps
    // between calls so that steady-state steps do not allocate, in its <Stage>CpuState.h.
    using StagesCpu = StageObjects<NothingKept<Stage::Region>, CaCpuState, SmoothCpuState, NothingKept<Stage::Density>,
                                   ShadeCpuState, ShadeSkyCpuState, NothingKept<Stage::Shadow>, RenderSplatCpuState,
                                   NoiseCpuState, RenderMarchCpuState, RenderLayersCpuState>;

    tbb::task_arena mArena;
    StagesCpu mStages;
};

}  // namespace cb::cpu
