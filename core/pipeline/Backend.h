// The backend-neutral interface: one entry per SPEC stage. impl_cpu, impl_gl and
// impl_vk each implement it in their own library; the registry (registry/) links
// whichever were built and makes them by name (CreateBackend).
//
// Data lives in backend-owned Buffers whose internal layout is the backend's
// business (the CPU packs bit fields 64 voxels to a word). Upload and Download
// convert to and from the canonical layout of SPEC 0 (docs/contract.md), so the harness
// can feed any stage another backend's output (stage-isolated conformance) and
// time transfers apart from stages. Every stage call returns when its outputs
// are complete. No exceptions cross this interface: failures come back as Status.
#pragma once

#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/base/Error.h"
#include "core/math/Camera.h"
#include "core/math/Grid.h"
#include "core/math/Ground.h"
#include "core/math/March.h"
#include "core/math/NoiseSettings.h"
#include "core/math/Rules.h"
#include "core/math/Shading.h"
#include "core/math/Shafts.h"
#include "core/scene/Scene.h"
#include "core/scene/Stage.h"
#include "core/stages/ca/CaTypes.h"
#include "core/stages/density/DensityTypes.h"
#include "core/stages/noise/NoiseTypes.h"
#include "core/stages/region/RegionTypes.h"
#include "core/stages/render_layers/RenderLayersTypes.h"
#include "core/stages/render_march/RenderMarchTypes.h"
#include "core/stages/render_splat/RenderSplatTypes.h"
#include "core/stages/shade/ShadeTypes.h"
#include "core/stages/shadow/ShadowTypes.h"
#include "core/stages/smooth/SmoothTypes.h"

namespace cb {

struct Scene;  // core/scene/Scene.h

// Canonical element types (SPEC 0): bit fields are one byte per voxel (0 or 1).
enum class BufferFormat : uint8_t {
    Bits,  // canonical uint8 0/1
    U8,    // canonical uint8
    F32,   // canonical float32
};

size_t CanonicalElementBytes(BufferFormat format);
// Bytes of a buffer in the canonical layout: one element per voxel (saturates at UINT64_MAX).
uint64_t CanonicalBufferBytes(BufferFormat format, const Extent3& extent);

// Spare zero bytes after a host U8 buffer, so that kernels may read a full
// 64-voxel word past a row's end.
inline constexpr uint64_t kHostU8Padding = 64;

// Bytes of one buffer in the host layout, the CPU backend's: bit fields as
// rows of ceil(nx/64) 64-bit words, U8 one byte per voxel plus
// kHostU8Padding, F32 four bytes per voxel. Saturates at UINT64_MAX.
uint64_t HostBufferBytes(BufferFormat format, const Extent3& extent);

// Canonical bit fields (one byte, 0 or 1, per voxel) to 32 voxels per uint32
// along x, rows of ceil(nx/32) words, and back: the GPU backends' layout.
std::vector<uint32_t> PackBits32(std::span<const std::byte> canonical, const Extent3& extent);
void UnpackBits32(std::span<const uint32_t> packed, const Extent3& extent, std::span<std::byte> canonical);

class Buffer {
  public:
    Buffer(BufferFormat format, Extent3 extent) : mFormat(format), mExtent(extent) {}
    virtual ~Buffer() = default;
    Buffer(const Buffer&) = delete;
    Buffer& operator=(const Buffer&) = delete;

    BufferFormat Format() const { return mFormat; }
    const Extent3& Extent() const { return mExtent; }
    size_t CanonicalBytes() const { return mExtent.Count() * CanonicalElementBytes(mFormat); }

  private:
    BufferFormat mFormat;
    Extent3 mExtent;
};

// Which tile x band boxes may hold a visible splat (SPEC 8): every box, less
// those outside the frustum when culling, less those empty in both steps'
// band occupancy (canonical bytes) when skipping. Index as FrustumVisibleBoxes.
std::vector<uint8_t> SplatBoxVisibility(const SplatParams& params, const Extent3& grid,
                                        std::span<const uint8_t> bandsPrev, std::span<const uint8_t> bandsCur);

// The scene's ground (render.ground) as both renderers take it.
GroundParams MakeGroundParams(const Scene& scene);

// The light on the ground of a renderer's call (core/math/Ground.h): the ground's
// albedo, the call's sun, ambient and flat background.
GroundLight MakeGroundLight(const SplatParams& params);
GroundLight MakeGroundLight(const MarchParams& params);
// With the ground on, G must be an F32 buffer of extent (nx, ny, 1) of `grid`;
// an error naming the backend and stage otherwise. Ok with the ground off.
Status CheckGroundInput(const GroundParams& ground, const Buffer* G, const Extent3& grid, std::string_view where);

// The backends' entry points, X(stage, Method, (parameters)): one or more per
// stage (the automaton has two). Contracts:
// Region, CaStep, Smooth, Density and Shade compute the share `slices` (SliceRange).
//   Region        R = max-blend of the ellipsoids; region is U8 of the grid size.
//   CaInitialize  the automaton's state at t = 0.
//   CaStep        one step t -> t+1; `in` and `out` must be distinct buffers.
//   Smooth        q (F32) from cld (Bits); radius 0, 1 or 2.
//   Density       D, this step's tile and band occupancy from q, and the cover:
//                 columns with any cld = 1, or without an automaton (cld null)
//                 columns with D > 0.
//   Shade         T (F32, grid size) from q.
//   Shadow        G (F32, (nx, ny, 1)) from D.
//   RenderSplat   a linear RGB image, F32 with extent (3, width, height):
//                 channel fastest, then x, then y, row 0 at the top.
//   RenderMarch   the same image layout, linear HDR, one MarchRay per pixel
//                 (core/math/March.h); the brick structure is built inside the call.
#define CB_SPLAT_PIPELINE_ENTRIES(X)                                                                            \
    X(Region, Region, (std::span<const RasterEllipsoid> ellipsoids, Buffer & region, SliceRange slices = {}))   \
    X(Ca, CaInitialize, (const CaInitParams& params, CaFields out))                                             \
    X(Ca, CaStep, (const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out))           \
    X(Smooth, Smooth, (int radius, const Buffer& cld, Buffer& q, SliceRange slices = {}))                       \
    X(Density, Density, (const DensityParams& params, const Buffer& q, const Buffer* cld, DensityOutputs& out)) \
    X(Shade, Shade, (const ShadeParams& params, const Buffer& q, Buffer& T))                                    \
    X(Shadow, Shadow, (const ShadowParams& params, const Buffer& columnSum, Buffer& G))                         \
    X(RenderSplat, RenderSplat, (const SplatParams& params, const SplatInputs& in, Buffer& image, SplatStats* stats))

// The producers of q other than the automaton and smoothing. Noise  q (F32,
// grid size) formed from noise (SPEC 10a); every backend implements it.
#define CB_NOISE_ENTRIES(X) X(Noise, Noise, (const NoiseParams& params, Buffer& q))

// The ray marcher (SPEC 10); every backend implements it (GPU: core/math/march.glsl).
#define CB_MARCH_ENTRIES(X) \
    X(RenderMarch, RenderMarch, (const MarchParams& params, const MarchInputs& in, Buffer& image, MarchStats* stats))

// The layered renderer (SPEC 15): the same image layout, the layers of
// core/math/Layers.h composited back to front (GPU: core/math/layers.glsl).
#define CB_LAYERS_ENTRIES(X)      \
    X(RenderLayers, RenderLayers, \
      (const LayersParams& params, const LayersInputs& in, Buffer& image, LayersStats* stats))

// The sky light's attenuation (SPEC 16): shade's sweep toward the sky light, T_sky (F32, grid size) from q, with
// stage objects of its own (a sky shade between two shares of the sun's sweep leaves them as they were).
#define CB_SKY_ENTRIES(X) X(ShadeSky, ShadeSky, (const ShadeParams& params, const Buffer& q, Buffer& T))

// Every entry point.
#define CB_BACKEND_ENTRIES(X) \
    CB_SPLAT_PIPELINE_ENTRIES(X) CB_SKY_ENTRIES(X) CB_NOISE_ENTRIES(X) CB_MARCH_ENTRIES(X) CB_LAYERS_ENTRIES(X)

// In a backend's class: declares the override of one entry.
#define CB_OVERRIDE_BACKEND_ENTRY(stage, Method, parameters) Status Method parameters override;

// What a backend has asked of its device since it was made (pipelined timing).
// A backend without a device (the CPU) counts nothing.
struct SubmissionCounts {
    // Batches of commands handed to the device: vkQueueSubmit; on GL a flush or
    // finish that ends a batch of draws.
    uint64_t submissions = 0;
    // Times the host blocked until the device had finished work: a fence wait,
    // glFinish, a query result or a read back that must wait.
    uint64_t hostWaits = 0;
};

// A host result a call in a batch delivered after EndBatch instead of on
// return (Backend::TakeDeferredResults).
struct DeferredHostResult {
    // The MarkBatch() calls made in the batch before the call: 1 for a call
    // after the first mark.
    uint32_t mark = 0;
    std::optional<uint32_t> coveredColumns;  // Density: DensityOutputs::coveredColumns
    std::optional<FrameCounters> frameCounters;  // a renderer: its *stats, as ToFrameCounters lists them
};

// One limit of a backend's device that bounds the scenes it can run, as the
// device reports it (glGetIntegerv, VkPhysicalDeviceLimits).
struct DeviceLimit {
    std::string name;    // the API's own name: "GL_MAX_TEXTURE_SIZE", "maxStorageBufferRange"
    uint64_t value = 0;  // as the device reports it
    std::string bounds;  // what it bounds in a scene: "grid nz and render.height"
};

// A scene setting past one of a backend's DeviceLimits: the scene field
// ("grid.size", "render.height") and why, naming the backend and the limit.
struct LimitExceeded {
    std::string field;
    std::string reason;
};

class Backend {
  public:
    virtual ~Backend() = default;

    // "cpu", "gl" or "vk".
    virtual std::string Name() const = 0;
    // A one-line description of the device (e.g. "2 threads, TBB").
    virtual std::string Device() const = 0;
    virtual bool Supports(Stage stage) const = 0;
    // Device time of the last stage call in ms, for backends that measure it
    // (GPU timestamp queries); nullopt where wall time is all there is.
    virtual std::optional<double> LastDeviceMs() const { return std::nullopt; }
    // Does the work of a call that took `wallMs` of wall time and `cpuMs` of
    // the process's CPU time, the way the backend's stages do theirs, for the
    // test-only slowdown switch (harness/run/StageCall.cpp): its threads spin
    // until together they have used `cpuMs` of CPU time, in equal shares of
    // at most `wallMs` each, so that both clocks grow as for a balanced stage
    // doing more work. By default the calling thread spins; the CPU backend
    // spins on the threads of its task arena, so that its workers stay awake
    // and in the arena.
    virtual void BusyFor(double wallMs, double cpuMs);

    // ---- Pipelined timing (docs/performance.md, "Two ways to time a step") ----
    // Between BeginBatch and EndBatch a backend may record stage calls and
    // return before their outputs are complete, submitting as few times as it
    // can (ideally once, at EndBatch) and waiting once at EndBatch. Outside a
    // batch every call completes before it returns, as the interface says.
    // In a batch:
    //  - Buffers named in a call must stay alive until EndBatch (host data its
    //    parameters point to, like spans, only until the call returns). Upload and
    //    Download keep their order with the recorded calls; a Download waits (a host wait).
    //  - Host results of a call (DensityOutputs::coveredColumns, SplatStats,
    //    MarchStats) are complete when it returns, as outside a batch, except
    //    that a backend may defer the cover and SplatStats: it leaves them as
    //    the caller set them and, after EndBatch, TakeDeferredResults() gives
    //    their values, each with the mark of its call. A backend that must wait
    //    for a host result counts the wait in Submissions().
    //  - MarkBatch() starts the batch's next interval. EndBatch returns, for each
    //    interval in order, the device time of the work recorded in it (ms, the
    //    sum over its commands' timestamp pairs, so host gaps between submissions
    //    are not counted), or an empty vector where the backend has no device clock:
    //    one per MarkBatch (harness: a leading one, before the first mark, is dropped).
    // Batches do not nest. A failed call inside a batch still needs EndBatch. LastDeviceMs() is meaningless in a batch.
    virtual Status BeginBatch() { return {}; }
    virtual void MarkBatch() {}
    virtual Result<std::vector<double>> EndBatch() { return std::vector<double>{}; }
    // The host results the last batch's calls deferred, in call order; each
    // call once (a second call returns nothing).
    virtual std::vector<DeferredHostResult> TakeDeferredResults() { return {}; }
    // Cumulative; the harness reports the difference over a step.
    virtual SubmissionCounts Submissions() const { return {}; }

    // ---- Buffers and transfers (timed apart from stages) ----
    virtual Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) = 0;
    // `canonical` must hold exactly buffer.CanonicalBytes().
    virtual Status Upload(Buffer& buffer, std::span<const std::byte> canonical) = 0;
    virtual Status Download(const Buffer& buffer, std::span<std::byte> canonical) = 0;

    // ---- Memory (core/plan/MemoryPlan.h prices a scene's buffer plan with these) ----
    // Bytes one buffer takes in this backend's own layout; here the canonical bytes.
    virtual uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const {
        return CanonicalBufferBytes(format, extent);
    }
    // Bytes of the stage scratch this backend keeps while it runs `scene`, besides
    // the planned buffers; here none.
    virtual uint64_t ScratchBytes(const Scene& /*scene*/) const { return 0; }
    // The memory its buffers and scratch can take (physical memory, a device
    // heap); nullopt when the backend cannot tell.
    virtual std::optional<uint64_t> AvailableBytes() const { return std::nullopt; }

    // ---- Device limits (a scene past one is refused before any stage runs) ----
    // The limits of this backend's device that bound what it can run; none here.
    virtual std::vector<DeviceLimit> Limits() const { return {}; }
    // The first setting of `scene` past one of Limits(), or nullopt when every pass of the scene fits them.
    virtual std::optional<LimitExceeded> ExceededLimit(const Scene& /*scene*/) const { return std::nullopt; }

    // ---- Stages: one virtual per entry of CB_BACKEND_ENTRIES ----
    // Each returns "unsupported" here; a backend overrides the entries of the
    // stages it implements (CB_OVERRIDE_BACKEND_ENTRY) and says so in Supports.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#define CB_DEFAULT_BACKEND_ENTRY(stage, Method, parameters) \
    virtual Status Method parameters { return Unsupported(Stage::stage); }
    CB_BACKEND_ENTRIES(CB_DEFAULT_BACKEND_ENTRY)
#undef CB_DEFAULT_BACKEND_ENTRY

    // Shafts of light (SPEC 18, core/math/Shafts.h ShaftsPixel): adds the shells' light to every pixel of a
    // renderer's (3, width, height) image; columnSum is the density stage's D, (nx, ny, 1). Not a stage of its own:
    // the renderers' stage calls run it after drawing (core/pipeline/ShaftsPass.h).
    virtual Status AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) {
        return MakeError(Name() + " does not implement shafts of light");
    }
#pragma GCC diagnostic pop

  protected:
    // The error of an entry point whose stage this backend does not implement.
    Status Unsupported(Stage stage) const {
        return MakeError(Name() + " does not implement stage '" + std::string(StageName(stage)) + "'");
    }
};

// SplatBoxVisibility for a backend whose occupancy lives on a device: reads
// both steps' bands back through backend.Download when skipping.
Result<std::vector<uint8_t>> DownloadSplatBoxVisibility(Backend& backend, const SplatParams& params,
                                                        const SplatInputs& in);

}  // namespace cb
