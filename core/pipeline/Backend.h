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
#include "core/scene/MarchSettings.h"
#include "core/scene/Scene.h"
#include "core/scene/Stage.h"

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

// A share of one stage call's work, for time-slicing (SPEC 13): the call
// computes only the slices [begin, end) of the stage's share axis, clamped to
// its share count, and leaves the rest of its outputs as they were. Running
// a step's shares in ascending order, each once, with nothing in between
// that writes the stage's outputs, gives exactly the whole call's outputs.
// The axis of each stage (docs/pipeline.md, "Time-slicing"):
//   region, ca, smooth   slices k; share count nz
//   density              rows of tiles; share count ceil(ny / tile). D, tiles
//                        and bands of those rows; coveredColumns counts the
//                        covered columns of those rows only (the shares' counts add up)
//   shade                the sweep's slices m (ShadePlan::SliceW, nearest the sun
//                        first); share count ShadePlan::nw. At resolution f > 1 the
//                        share holding m = 0 also fills the coarse grid and the share
//                        ending at nw writes T (until then T is left as it was). At
//                        f = 1 a share's slices of T may also wait for that share (a
//                        backend may carry the sweep in scratch); no other slice changes
// The default is the whole call.
struct SliceRange {
    uint32_t begin = 0;
    uint32_t end = UINT32_MAX;

    uint32_t Begin(uint32_t count) const { return begin < count ? begin : count; }
    uint32_t End(uint32_t count) const { return end < count ? end : count; }
    bool IsWhole(uint32_t count) const { return begin == 0 && end >= count; }
    bool operator==(const SliceRange&) const = default;
};

// The automaton's three bit fields at one step.
struct CaFields {
    Buffer* hum = nullptr;
    Buffer* act = nullptr;
    Buffer* cld = nullptr;
};
struct ConstCaFields {
    const Buffer* hum = nullptr;
    const Buffer* act = nullptr;
    const Buffer* cld = nullptr;
};

// Inputs of one automaton step t -> t+1 (SPEC 3). Probabilities are already
// quantised: q* = Q(p*).
struct CaStepParams {
    uint32_t seed = 0;
    uint32_t step = 0;
    uint32_t qExt = 0, qHum = 0, qAct = 0;
    // Empty, or one (sx, sy) per slice k.
    std::span<const int32_t> shiftX, shiftY;
    SliceRange slices;  // the slices k of `out` to write
};

struct CaInitParams {
    uint32_t seed = 0;
    uint32_t qHum0 = 0, qAct0 = 0;
};

// Outputs of the density stage (SPEC 5) for one step. The tile and band
// occupancy are this step's alone; the renderer ORs the two steps it
// interpolates between (docs/pipeline.md).
struct DensityOutputs {
    Buffer* columnSum = nullptr;  // F32, (nx, ny, 1): D
    Buffer* tiles = nullptr;      // U8, (ceil(nx/T), ceil(ny/T), 1): 1 iff D > 0 in the tile
    Buffer* bands = nullptr;      // U8, (ceil(nx/T), ceil(ny/T), ceil(nz/B)): 1 iff q > 0 in tile x band
    uint32_t coveredColumns = 0;  // columns (i, j) with any cld = 1; without cld, with D > 0
};

struct DensityParams {
    uint32_t tile = 32;
    uint32_t band = 4;
    SliceRange slices;  // the rows of tiles to compute
};

// Inputs of the noise producer of q (SPEC 10a): the scene's noise settings,
// the grid q has, and the step, whose index is the time coordinate (the
// noise drifts by settings->drift voxels per step).
struct NoiseParams {
    uint32_t step = 0;
    const NoiseSettings* settings = nullptr;  // not owned; must outlive the call
    Extent3 grid;                             // must equal q's extent
};

// What a shade stage answers for a resolution outside kShadeResolutions: "BACKEND: shade resolution must be ...".
inline Status CheckShadeResolution(std::string_view backend, int64_t f) {
    if (IsShadeResolution(f)) return {};
    return MakeError(std::string(backend) + ": shade resolution must be " + kShadeResolutionsText);
}

// Inputs of the shade stage (SPEC 6) besides q.
struct ShadeParams {
    Vec3 sun{0, 0, 1};  // unit vector toward the sun
    AttenuationKind attenuation = AttenuationKind::Beer;
    float sigma = 0.02f;   // 1/m at q = 1
    float voxelSize = 50;  // h, metres
    float thesisAr = 0.9f;
    SampleFilter filter = SampleFilter::Bilinear;
    int resolution = 1;  // one of kShadeResolutions
    StorageFormat storage = StorageFormat::Fp32;
    bool scattering = false;
    float albedo = 0.9f, solidAngle = 0.05f;
    PhaseParams phase;
    SliceRange slices;  // the sweep's slices m to compute
};

// Inputs of the shadow stage (SPEC 7) besides D.
struct ShadowParams {
    Vec3 sun{0, 0, 1};
    ShadowForm form = ShadowForm::Beer;
    float sigma = 0.02f, voxelSize = 50, kappa = 0.25f;
    float coverage = 1, densityFactor = 1;  // wang form (Wang, Ji and Zhang, eq. 19)
    uint32_t nz = 1;                        // grid height in voxels (the volume's mid-height is nz/2)
};

// Inputs of the splat renderer (SPEC 8). The order is computed on the host
// (MakeSplatOrder) and shared by every backend.
struct SplatParams {
    CameraFrame camera;
    const SplatOrder* order = nullptr;
    Vec3 sun{0, 0, 1};          // toward the sun
    Vec3 sunRadiance{1, 1, 1};  // colour * intensity
    Vec3 ambient{0, 0, 0}, background{0, 0, 0};
    PhaseParams phase;
    float qMin = 0.3f, splatDiameter = 75, opacity = 0.6f, alpha = 0.5f;
    std::array<float, 3> origin{0, 0, 0};
    float voxelSize = 50;
    bool culling = true, skipping = true;
    uint32_t tile = 32, band = 4;  // of the occupancy maps
    GroundParams ground;           // the ground plane under the clouds (core/math/Ground.h); on: SplatInputs::G
};

// Which tile x band boxes may hold a visible splat (SPEC 8): every box, less
// those outside the frustum when culling, less those empty in both steps'
// band occupancy (canonical bytes) when skipping. Index as FrustumVisibleBoxes.
std::vector<uint8_t> SplatBoxVisibility(const SplatParams& params, const Extent3& grid,
                                        std::span<const uint8_t> bandsPrev, std::span<const uint8_t> bandsCur);

struct SplatInputs {
    const Buffer* qPrev = nullptr;  // F32 volume
    const Buffer* qCur = nullptr;   // F32 volume
    const Buffer* T = nullptr;      // F32 volume: full-resolution transmittance
    // Occupancy of both steps (density stage); read only when skipping.
    const Buffer* tilesPrev = nullptr;
    const Buffer* tilesCur = nullptr;
    const Buffer* bandsPrev = nullptr;
    const Buffer* bandsCur = nullptr;
    const Buffer* G = nullptr;  // F32 (nx, ny, 1): the ground shadow; read only with params.ground.on
};

struct SplatStats {
    uint64_t splats = 0;         // splats drawn (q_alpha > q_min, in front of the near plane, not culled)
    uint64_t voxelsVisited = 0;  // voxels the renderer looked at after culling and skipping
    uint64_t fragments = 0;      // pixel blends: covered pixels summed over splats, clipped to the image
};

// Inputs of the ray marcher (SPEC 10) besides its buffers: the kernel's
// constants (core/math/March.h, voxel units) and how the backend feeds it.
struct MarchParams {
    CameraFrame camera;
    MarchSetup setup;
    std::array<float, 3> origin{0, 0, 0};  // world position of voxel corner (0, 0, 0)
    float alpha = 0.5f;                    // q_alpha = (1 - alpha) q_prev + alpha q_cur
    MarchLightSource light = MarchLightSource::Shade;
    uint32_t lightSteps = 8;  // n_l of the light march (sun with `march`, and the point light)
    bool jitter = false;
    uint32_t seed = 1, frame = 0;  // xi = rand24(seed, frame, 3, x + W y) / 2^24 with jitter
    bool skipping = true;
    uint32_t brick = 8;
    GroundParams ground;  // the ground plane under the clouds (core/math/Ground.h); on: MarchInputs::G
};

struct MarchInputs {
    const Buffer* qPrev = nullptr;  // F32 volume
    const Buffer* qCur = nullptr;   // F32 volume
    const Buffer* T = nullptr;      // F32 volume; required with MarchLightSource::Shade, else unread
    const Buffer* G = nullptr;      // F32 (nx, ny, 1): the ground shadow; read only with params.ground.on
};

// The light on the ground of a renderer's call (core/math/Ground.h): the ground's
// albedo, the call's sun, ambient and flat background.
GroundLight MakeGroundLight(const SplatParams& params);
GroundLight MakeGroundLight(const MarchParams& params);
// With the ground on, G must be an F32 buffer of extent (nx, ny, 1) of `grid`;
// an error naming the backend and stage otherwise. Ok with the ground off.
Status CheckGroundInput(const GroundParams& ground, const Buffer* G, const Extent3& grid, std::string_view where);

struct MarchStats {
    uint64_t rays = 0;                     // rays that met the box between the near and far planes
    uint64_t samples = 0;                  // density samples
    uint64_t lightSamples = 0;             // light functor calls (samples with q_alpha > 0)
    uint64_t bricksSkipped = 0;            // empty bricks jumped over, summed over rays
    uint64_t emptyBricks = 0, bricks = 0;  // of the skip structure (0 without skipping)
};

// A renderer's counters as lists: each counter's member, its JSON name and
// where it is shown. The lists drive the read-back from an isolated child and
// a saved state (harness/run/RunTransfer.cpp), results.json and its schema
// (harness/report/ResultsJson.cpp, harness/report/InputFormats.cpp) and the
// text report (harness/report/TimingSection.cpp), so a new counter is its
// member and one line here; the static_asserts fail when a member is missing.
enum class CounterShown {
    ReadBack,          // travels with the record only (a child's result, a saved state)
    Results,           // also per frame in results.json
    ResultsAndReport,  // also the count the text report gives after a camera's frames (one per renderer)
};
template <typename Stats>
struct Counter {
    std::string_view name;  // the JSON key
    uint64_t Stats::*member;
    CounterShown shown;
};
inline constexpr Counter<SplatStats> kSplatCounters[] = {
    {"splats", &SplatStats::splats, CounterShown::ResultsAndReport},
    {"voxels_visited", &SplatStats::voxelsVisited, CounterShown::Results},
    {"fragments", &SplatStats::fragments, CounterShown::ReadBack},
};
inline constexpr Counter<MarchStats> kMarchCounters[] = {
    {"rays", &MarchStats::rays, CounterShown::ReadBack},
    {"samples", &MarchStats::samples, CounterShown::ResultsAndReport},
    {"light_samples", &MarchStats::lightSamples, CounterShown::Results},
    {"bricks_skipped", &MarchStats::bricksSkipped, CounterShown::Results},
    {"empty_bricks", &MarchStats::emptyBricks, CounterShown::ReadBack},
    {"bricks", &MarchStats::bricks, CounterShown::ReadBack},
};
// The one counter of `list` that the text report gives.
template <typename Stats, size_t N>
constexpr const Counter<Stats>& ReportedCounter(const Counter<Stats> (&list)[N]) {
    size_t found = N;
    for (size_t i = 0; i < N; ++i)
        if (list[i].shown == CounterShown::ResultsAndReport) found = found == N ? i : N + 1;
    if (found >= N) throw "a renderer's counters name exactly one ResultsAndReport";  // fails the constant evaluation
    return list[found];
}
static_assert(ReportedCounter(kSplatCounters).name == "splats");
static_assert(ReportedCounter(kMarchCounters).name == "samples");
static_assert(sizeof(SplatStats) == std::size(kSplatCounters) * sizeof(uint64_t), "a SplatStats member is unlisted");
static_assert(sizeof(MarchStats) == std::size(kMarchCounters) * sizeof(uint64_t), "a MarchStats member is unlisted");

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

// Every entry point.
#define CB_BACKEND_ENTRIES(X) CB_SPLAT_PIPELINE_ENTRIES(X) CB_NOISE_ENTRIES(X) CB_MARCH_ENTRIES(X)

// In a backend's class: declares the override of one entry.
#define CB_OVERRIDE_BACKEND_ENTRY(stage, Method, parameters) Status Method parameters override;

// What a backend has asked of its device since it was made (pipelined timing,
// issue 16). A backend without a device (the CPU) counts nothing.
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
    std::optional<SplatStats> splat;         // RenderSplat: *stats
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

    // ---- Memory (core/pipeline/MemoryPlan.h prices a scene's buffer plan with these) ----
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

    // ---- Stages: one virtual per entry of CB_BACKEND_ENTRIES ----
    // Each returns "unsupported" here; a backend overrides the entries of the
    // stages it implements (CB_OVERRIDE_BACKEND_ENTRY) and says so in Supports.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#define CB_DEFAULT_BACKEND_ENTRY(stage, Method, parameters) \
    virtual Status Method parameters { return Unsupported(Stage::stage); }
    CB_BACKEND_ENTRIES(CB_DEFAULT_BACKEND_ENTRY)
#undef CB_DEFAULT_BACKEND_ENTRY
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
