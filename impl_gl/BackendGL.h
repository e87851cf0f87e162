// The OpenGL backend: every stage a fragment-shader pass that renders into
// the slices of 2-D array textures (one layer per slice k), ping-ponging
// between textures as the thesis does (its Figure 4.3). Layouts: bit fields as
// R32UI, 32 voxels per texel along x; byte volumes R8UI; floats R32F. The
// automaton can also run in the thesis's layout (one RGBA8UI texel per voxel,
// a channel per bit), converted to and from the packed fields it shares with
// the other stages (docs/pipeline.md).
//
// Files: the host side of each stage is in its own <Stage>GL.cpp (RegionGL.cpp,
// CaGL.cpp, ...); BackendGL.cpp holds the context, buffers, transfers and the
// helpers the stages share (scratch slots, BindTargets, DrawLayers). Tex and
// the member templates are defined below the class.
#pragma once

#include <array>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/math/Noise.h"
#include "core/pipeline/Backend.h"
#include "impl_gl/GLContext.h"

namespace cb::gl {

class BufferGL final : public Buffer {
  public:
    BufferGL(BufferFormat format, Extent3 extent, const Functions& f, GLuint texture)
        : Buffer(format, extent), mF(f), mTexture(texture) {}
    ~BufferGL() override { mF.DeleteTextures(1, &mTexture); }
    GLuint Texture() const { return mTexture; }
    // Texels per row: ceil(nx/32) for bit fields, nx otherwise.
    uint32_t Width() const { return Format() == BufferFormat::Bits ? (Extent().nx + 31) / 32 : Extent().nx; }

  private:
    const Functions& mF;
    GLuint mTexture;
};

class BackendGL final : public Backend {
  public:
    // An Error says why the context cannot be made here.
    static Result<std::unique_ptr<BackendGL>> Create(ContextKind context = ContextKind::OSMesa,
                                                     CaLayout caLayout = CaLayout::Packed);
    ~BackendGL() override;

    std::string Name() const override { return "gl"; }
    std::string Device() const override;
    bool Supports(Stage stage) const override;
    std::optional<double> LastDeviceMs() const override { return mLastDeviceMs; }

    // Pipelined timing (core/pipeline/Backend.h). In a batch a stage call records its
    // passes between two GL_TIMESTAMP queries (from a pool) and returns without
    // waiting; EndBatch waits once (glFinish) and reads the queries. Density's
    // cover and render_splat's stats are deferred: each call writes them to a
    // buffer (and a query) of its own, read after EndBatch's wait
    // (TakeDeferredResults). Other host reads in a batch wait, and are counted.
    Status BeginBatch() override;
    void MarkBatch() override;
    Result<std::vector<double>> EndBatch() override;
    std::vector<DeferredHostResult> TakeDeferredResults() override { return std::exchange(mDeferredResults, {}); }
    // Counted where the backend synchronises (Finish, WaitingRead): a submission
    // for each glFinish, or read that must wait, that ends recorded work; a host
    // wait for each glFinish, and each query result or read back into client
    // memory while recorded work may be unfinished.
    SubmissionCounts Submissions() const override { return mCounts; }
    // Draw calls issued since the backend was made (a multi-draw counts once):
    // the per-pass overhead of issue 16.
    uint64_t Draws() const { return mDraws; }
    // Whether full-screen passes over slices are one layered, instanced draw
    // (GLContext::LayeredProgram) where the driver can, or one draw per slice
    // (the thesis's way; for comparison). On by default; both give the same bytes.
    void SetLayered(bool layered) { mLayered = layered; }
    // How render_splat skips the boxes empty in both steps' bands (SPEC 8) in a
    // batch: by draw runs the host derives from the bands read back (a host
    // wait, as outside a batch), or in the vertex shader, which reads the bands
    // on the device (no wait, but every voxel of the frustum's boxes becomes a
    // vertex). Auto: the host's runs on a software rasterizer (llvmpipe, where
    // those vertices cost the CPU far more than the wait; docs/performance.md),
    // the vertex shader on a GPU. The same image and stats either way.
    enum class SplatSkip : uint8_t { Auto, HostRuns, Device };
    void SetSplatSkip(SplatSkip skip) { mSplatSkip = skip; }
    // Whether a batched render_splat skips in the vertex shader (SetSplatSkip).
    bool SplatSkipOnDevice() const {
        return mSplatSkip == SplatSkip::Device || (mSplatSkip == SplatSkip::Auto && !mSoftwareRasterizer);
    }
    bool Layered() const { return mLayered && !mLayeredFailed; }

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    // Texture bytes: bit fields as R32UI, ceil(nx/32) texels per row; bytes R8UI; floats R32F.
    uint64_t BufferBytes(BufferFormat format, const Extent3& extent) const override;
    // The scratch textures whose size the scene fixes (GlScratch): region's R8
    // layers, the automaton's rule outputs with wind (and its RGBA8 state),
    // smooth's R16UI sums, density's cover flags, shade's volumes and slices
    // (counted for the two longest axes), the splat target; the ray marcher's
    // padded volume, bricks and image, each with the storage or pixel buffer it
    // is copied into, and the Mie table. Other buffer objects (lists, counters,
    // blocks) are not counted. GL does not report available memory.
    uint64_t ScratchBytes(const Scene& scene) const override;

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_NOISE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_MARCH_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)

  private:
    // The scratch textures, each used by one stage only (named first), kept
    // between calls and remade when its target, format or size changes.
    enum class GlScratch {
        RegionUnorm,   // Region: the R8 UNORM layers the ellipsoids MAX-blend into
        CaHum,         // CaStep, with wind: the rules' humidity, before advection
        CaAct,         // CaStep, with wind: the rules' activation, before advection
        CaCld,         // CaStep, with wind: the rules' clouds, before advection
        Rgba8StateA,   // CaStep, RGBA8 layout: the state between steps (see mStateOf)
        Rgba8StateB,   // CaStep, RGBA8 layout: the rules' output
        SmoothX,       // Smooth: the R16UI sums along x
        SmoothXY,      // Smooth: the R16UI sums along x and y
        CoverFlags,    // Density: the R8UI flags of the covered columns
        ShadeCoarseQ,  // Shade, resolution > 1: the down-sampled q
        ShadeVolume,   // Shade: the w-major volume of slices
        ShadePing,     // Shade: the slice loop's previous slice
        ShadePong,     // Shade: the slice loop's current slice
        SplatTarget,   // RenderSplat: the RGBA32F image
        MarchVolume,   // RenderMarch: the padded (q_alpha, T) volume, RG32F layers
        MarchBricks,   // RenderMarch, skipping: the R32UI empty flags of the bricks
        MarchTarget,   // RenderMarch: the RGBA32F image
        Count
    };
    // The scratch buffer objects, each used by one stage only, grown as needed.
    enum class GlScratchBuffer {
        EllipsoidList,    // Region: the ellipsoids, read by the vertex shader
        CoverCounter,     // Density: the atomic counter of covered columns
        SplatOrder,       // RenderSplat: the flattened shared order
        SplatFrame,       // RenderSplat: the shared frame block (core/math/Splat.h)
        SplatCounters,    // RenderSplat: the shader's counters (splats drawn)
        ImageCopy,        // RenderSplat: the pixel buffer the image passes through
        NoiseData,        // Noise: the scene's data block (core/math/NoiseGpu.h), kept while mNoiseForm's scene stays
        MarchBlock,       // RenderMarch: the MarchGpu uniform block (core/pipeline/MarchGpu.h)
        MarchVolumeCopy,  // RenderMarch: the padded volume as a storage buffer of (q_alpha, T) pairs
        MarchBricksCopy,  // RenderMarch, skipping: the brick flags as a storage buffer
        MarchPhaseTable,  // RenderMarch, phase mie: kMieCloudTable's values, uploaded once (mMieUploaded)
        MarchCounters,    // RenderMarch: the shader's MarchStats counters
        MarchImageCopy,   // RenderMarch: the pixel buffer the image passes through
        GroundBlock,      // RenderSplat, RenderMarch with the ground: the GroundGpu uniform block (core/math/Ground.h)
        Count
    };
    // An array indexed by one slot enum and nothing else.
    template <typename Slot, typename T>
    class SlotArray {
      public:
        T& operator[](Slot slot) { return mItems[size_t(slot)]; }
        auto begin() { return mItems.begin(); }
        auto end() { return mItems.end(); }

      private:
        std::array<T, size_t(Slot::Count)> mItems{};
    };
    struct ScratchTexture {
        GLuint texture = 0;
        GLenum target = 0, format = 0;
        GLsizei width = 0, height = 0, depth = 0;
    };

    BackendGL(std::unique_ptr<GLContext> context, bool rgba8)
        : mContext(std::move(context)), mRgba8(rgba8), mSoftwareRasterizer(mContext->SoftwareRasterizer()) {}

    // A stage call's device time: a GL_TIMESTAMP query at construction and one
    // at Stop(). Outside a batch Stop() waits (Finish) and sets mLastDeviceMs;
    // in a batch it files the pair under the current interval. Construction
    // also marks work as recorded (mPending) and advances mWriteEpoch.
    class Timing {
      public:
        explicit Timing(BackendGL& backend);
        ~Timing();
        Timing(const Timing&) = delete;
        Timing& operator=(const Timing&) = delete;
        void Stop();

      private:
        BackendGL& mB;
        GLuint mStart = 0;
    };
    // The only places the host synchronises with the device (counted in mCounts).
    void Finish();
    // A read that blocks until the work before it is done: a query result
    // (buffer 0, data a GLuint64), a texture or a buffer into client memory.
    enum class ReadKind { Query, Texture, Buffer };
    void WaitingRead(ReadKind kind, GLuint object, GLenum format, GLenum type, size_t offset, size_t bytes, void* data);
    GLuint64 QueryResult(GLuint query) {
        GLuint64 value = 0;
        WaitingRead(ReadKind::Query, query, 0, 0, 0, sizeof value, &value);
        return value;
    }
    // Work was recorded: the device may be busy and a submission is pending.
    void Recorded() { mPending = true, mIdle = false; }
    GLuint AcquireQuery();
    void ReleaseQuery(GLuint query) { mFreeQueries.push_back(query); }
    // Draw calls, counted in mDraws.
    void Draw(GLenum mode, GLint first, GLsizei count, GLsizei instances = 1);
    void MultiDraw(GLenum mode, const GLint* firsts, const GLsizei* counts, GLsizei draws);
    // A renderer's image whose canonical bytes its pixel buffer `slot` still
    // holds: Download of it reads the buffer instead of the texture while
    // nothing has been written since (mWriteEpoch).
    void KeepImageCopy(const Buffer& image, GlScratchBuffer slot, size_t bytes);
    GLuint Scratch(GlScratch slot, GLenum target, GLenum format, GLsizei width, GLsizei height, GLsizei depth = 1);
    GLuint ScratchBuffer(GlScratchBuffer slot, size_t bytes);
    // In a batch, a zeroed buffer of `bytes` for one call's counters, read and
    // deleted at EndBatch (deferred results); outside one, ScratchBuffer(slot).
    GLuint CounterBuffer(GlScratchBuffer slot, size_t bytes);
    // Copies a renderer's W x H RGB(A) float target into `image` ((3, W, H) F32)
    // on the device, through the pixel buffer in `slot`: the target's rows, top
    // first, in RGB floats are exactly the canonical layout.
    void CopyTargetToImage(GLuint target, uint32_t W, uint32_t H, GlScratchBuffer slot, Buffer& image);
    // Attaches layer `layer` of each texture (layer < 0: a 2-D texture) to the
    // context's framebuffer as colour attachments 0, 1, ... and makes them the
    // draw buffers; the other attachments are detached.
    Status BindTargets(std::span<const std::pair<GLuint, int>> targets);
    Status BindTargets(std::initializer_list<std::pair<GLuint, int>> targets) {
        return BindTargets(std::span(targets.begin(), targets.size()));
    }
    // Draws the full-screen triangle of `program` (in use, its other uniforms
    // set) once per layer k < layers: uniform "layer" = k, the render targets
    // layer k of each of `textures`, and perLayer(k) for whatever else changes
    // with k. The template is defined below the class.
    // DrawLayerRange: the same for the layers begin <= k < end only (a share, SliceRange).
    template <typename PerLayer>
    Status DrawLayerRange(GLuint program, uint32_t begin, uint32_t end, std::initializer_list<GLuint> textures,
                          PerLayer&& perLayer);
    template <typename PerLayer>
    Status DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures, PerLayer&& perLayer) {
        return DrawLayerRange(program, 0, layers, textures, std::forward<PerLayer>(perLayer));
    }
    // Without perLayer, a program from PassProgram may be layered: then one
    // instanced draw into the whole textures covers the layers.
    Status DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures);
    Status DrawLayerRange(GLuint program, uint32_t begin, uint32_t end, std::initializer_list<GLuint> textures);
    // The program of full-screen pass `name`: layered where Layered(), else per slice.
    Result<GLuint> PassProgram(const std::string& name, const std::string& defines = "");
    bool IsLayered(GLuint program) const;
    Status CaStepRgba8(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out);
    Status CaStepRgba8Share(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out);

    std::unique_ptr<GLContext> mContext;
    bool mRgba8 = false;
    std::optional<double> mLastDeviceMs;
    SubmissionCounts mCounts;
    bool mLayered = true, mLayeredFailed = false;
    SplatSkip mSplatSkip = SplatSkip::Auto;
    bool mSoftwareRasterizer = false;  // GLContext::SoftwareRasterizer, read once when made
    std::vector<GLuint> mLayeredPrograms;
    uint64_t mDraws = 0;
    bool mPending = false;  // work recorded since the last submission
    bool mIdle = true;      // no work recorded since the host last waited for the device
    std::vector<GLuint> mFreeQueries, mAllQueries;
    struct BatchState {
        bool active = false;
        uint32_t interval = 0;
        struct Pair {
            GLuint start, end;
            uint32_t interval;
        };
        std::vector<Pair> pairs;
        // A deferred host result (core/pipeline/Backend.h): a buffer of counters this
        // call alone wrote, and for render_splat its fragment query.
        struct Deferred {
            uint32_t mark = 0;
            GLuint counters = 0, fragments = 0;
            bool cover = false;       // density: counters[0] is the cover
            bool deviceSkip = false;  // render_splat: counters[1] is the voxels visited
            uint64_t visited = 0;     // render_splat without deviceSkip: counted on the host
        };
        std::vector<Deferred> deferred;
    };
    BatchState mBatch;
    std::vector<DeferredHostResult> mDeferredResults;
    // Advanced by every call that may write a buffer (CreateBuffer, Upload, each stage call).
    uint64_t mWriteEpoch = 0;
    struct ImageCopy {
        GLuint texture = 0;
        GlScratchBuffer slot{};
        size_t bytes = 0;
        uint64_t epoch = ~uint64_t(0);
    };
    ImageCopy mImageCopy;
    SlotArray<GlScratch, ScratchTexture> mScratch;
    SlotArray<GlScratchBuffer, std::pair<GLuint, size_t>> mBuffers;  // buffer, bytes
    // Noise: the scene whose data block is in the NoiseData buffer (NoiseGL.cpp).
    std::unique_ptr<noise::NoiseForm> mNoiseForm;
    // RenderMarch: whether the MarchPhaseTable buffer holds kMieCloudTable (RenderMarchGL.cpp).
    bool mMieUploaded = false;
    // Which packed fields the thesis-layout state in Rgba8StateA holds: the last
    // step's outputs, valid until a bit field is written some other way.
    std::array<GLuint, 3> mStateOf{};
    uint64_t mBitsWrites = 0, mStateWrites = ~uint64_t(0);
    // Smooth: the slices [begin, end) whose xy sums SmoothXY holds, of which cld
    // at which radius, valid while no bit field is written (mBitsWrites).
    struct SmoothSums {
        GLuint cld = 0;
        int radius = -1;
        Extent3 extent;
        uint64_t bitsWrites = ~uint64_t(0);
        uint32_t begin = 0, end = 0;
    };
    SmoothSums mSmoothSums;
    // CaStep in shares, RGBA8 layout: Rgba8StateA holds `inputs` for slices
    // [packedBegin, packedEnd) and Rgba8StateB this step's rule results for
    // [0, rulesEnd), valid while no bit field is written but by the shares.
    struct Rgba8ShareState {
        std::array<GLuint, 3> inputs{}, outputs{};
        Extent3 extent;
        uint64_t bitsWrites = ~uint64_t(0);
        bool wind = false;
        uint32_t packedBegin = 0, packedEnd = 0, rulesEnd = 0;
    };
    Rgba8ShareState mShareState;
};

// For the stages' host files (<Stage>GL.cpp) and the façade.

// The texture behind a buffer; every buffer this backend sees is one it created.
inline const BufferGL& Tex(const Buffer& b) { return static_cast<const BufferGL&>(b); }

template <typename PerLayer>
Status BackendGL::DrawLayerRange(GLuint program, uint32_t begin, uint32_t end, std::initializer_list<GLuint> textures,
                                 PerLayer&& perLayer) {
    if (IsLayered(program)) return MakeError("gl: a layered pass cannot set uniforms per layer");
    const Functions& f = mContext->F();
    const GLint layerUniform = f.GetUniformLocation(program, "layer");
    std::array<std::pair<GLuint, int>, 4> targets;
    if (textures.size() > targets.size()) return MakeError("gl: a pass has more than 4 render targets");
    for (uint32_t k = begin; k < end; ++k) {
        size_t n = 0;
        for (GLuint texture : textures) targets[n++] = {texture, int(k)};
        CB_TRY(BindTargets(std::span(targets.data(), n)));
        f.Uniform1i(layerUniform, GLint(k));
        perLayer(k);
        Draw(GL_TRIANGLES, 0, 3);
    }
    return {};
}

}  // namespace cb::gl
