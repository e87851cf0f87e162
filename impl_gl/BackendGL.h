// The OpenGL backend: every stage a fragment-shader pass that renders into
// the slices of 2-D array textures (one layer per slice k), ping-ponging
// between textures as the thesis does (its Figure 4.3). Layouts: bit fields as
// R32UI, 32 voxels per texel along x; byte volumes R8UI; floats R32F. The
// automaton can also run in the thesis's layout (one RGBA8UI texel per voxel,
// a channel per bit), converted to and from the packed fields it shares with
// the other stages (docs/pipeline.md).
//
// Files: each stage has its object in <Stage>GLState.h (what it keeps between calls
// and its scratch bytes) and its entry in <Stage>GL.cpp (RegionGL.cpp,
// CaGL.cpp, ...); BackendGL.cpp holds the context, buffers, transfers and the
// helpers the stages share (Scratch, BindTargets, DrawLayers). Tex and the
// member templates are defined below the class.
#pragma once

#include <array>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/pipeline/Backend.h"
#include "core/pipeline/MarchGpu.h"
#include "core/pipeline/StageObjects.h"
#include "impl_gl/CaGLState.h"
#include "impl_gl/DensityGLState.h"
#include "impl_gl/GLContext.h"
#include "impl_gl/NoiseGLState.h"
#include "impl_gl/RegionGLState.h"
#include "impl_gl/RenderLayersGLState.h"
#include "impl_gl/RenderMarchGLState.h"
#include "impl_gl/RenderSplatGLState.h"
#include "impl_gl/ScratchGL.h"
#include "impl_gl/ShadeGLState.h"
#include "impl_gl/SmoothGLState.h"

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

// The limits of a context that bound what gl can run, as glGetIntegerv reports them.
struct GLLimits {
    GLint textureSize = 0;     // GL_MAX_TEXTURE_SIZE: every texture's width and height
    GLint arrayLayers = 0;     // GL_MAX_ARRAY_TEXTURE_LAYERS: a texture array's layers
    GLint viewportWidth = 0;   // GL_MAX_VIEWPORT_DIMS[0]: a pass's drawn width (a wider viewport is clamped)
    GLint viewportHeight = 0;  // GL_MAX_VIEWPORT_DIMS[1]
};
GLLimits ReadGLLimits(const GLContext& context);
// The limits as Backend::Limits lists them, each with what it bounds in a scene.
std::vector<DeviceLimit> DescribeGLLimits(const GLLimits& limits);
// The first setting of `scene` past `limits` on gl (Backend::ExceededLimit).
std::optional<LimitExceeded> FindExceededGLLimit(const GLLimits& limits, const Scene& scene);

class BackendGL final : public Backend {
  public:
    // An Error says why the context cannot be made here.
    static Result<std::unique_ptr<BackendGL>> Create(ContextKind context = ContextKind::OSMesa,
                                                     CaLayout caLayout = CaLayout::Packed);
    ~BackendGL() override;

    std::string Name() const override { return "gl"; }
    std::string Device() const override;
    bool Supports(Stage stage) const override { return StagesGL::Implements(stage); }
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
    // the per-pass overhead.
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
    // The sum of the stage objects' textures whose size the scene fixes (each
    // says which in its <Stage>GLState.h) and the ray marcher's storage and pixel
    // copies; other buffer objects (lists, counters, blocks) are not counted.
    // GL does not report available memory.
    // The stage objects' and, with shafts of light, the shafts pass's target, image copy and block.
    uint64_t ScratchBytes(const Scene& scene) const override {
        const uint64_t shafts =
            scene.lighting.shafts.on
                ? uint64_t(scene.render.width) * scene.render.height * (16 + 12) + sizeof(ShaftsFrame)
                : 0;
        return mStages.ScratchBytes(scene) + shafts;
    }

    // The context's texture and viewport limits, read when the backend is made.
    std::vector<DeviceLimit> Limits() const override { return DescribeGLLimits(mLimits); }
    std::optional<LimitExceeded> ExceededLimit(const Scene& scene) const override {
        if (auto unbuilt = MarchReprojectionNotBuilt(scene, "gl")) return unbuilt;
        return FindExceededGLLimit(mLimits, scene);
    }

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_SKY_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_NOISE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_MARCH_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    CB_LAYERS_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)
    Status AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) override;

  private:
    // The stage objects (core/pipeline/StageObjects.h): each stage's textures,
    // buffer objects and what it keeps between calls, in its <Stage>GLState.h.
    using StagesGL = StageObjects<RegionGLState, CaGLState, SmoothGLState, DensityGLState, ShadeGLState,
                                  ShadeSkyGLState, NothingKept<Stage::Shadow>, RenderSplatGLState, NoiseGLState,
                                  RenderMarchGLState, RenderLayersGLState>;

    BackendGL(std::unique_ptr<GLContext> context, bool rgba8)
        : mContext(std::move(context)),
          mSoftwareRasterizer(mContext->SoftwareRasterizer()),
          mLimits(ReadGLLimits(*mContext)) {
        mStages.Get<CaGLState>().rgba8 = rgba8;
    }

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
    // A renderer's image whose canonical bytes its pixel buffer `copy` still
    // holds: Download of it reads the buffer instead of the texture while
    // nothing has been written since (mWriteEpoch).
    void KeepImageCopy(const Buffer& image, const BufferSlot& copy, size_t bytes);
    // The slot's texture, remade when its target, format or size differ.
    GLuint Scratch(TextureSlot& slot, GLenum target, GLenum format, GLsizei width, GLsizei height, GLsizei depth = 1);
    // The slot's buffer object, grown to at least `bytes` (16 at least); its contents are undefined.
    GLuint ScratchBuffer(BufferSlot& slot, size_t bytes);
    // In a batch, a zeroed buffer of `bytes` for one call's counters, read and
    // deleted at EndBatch (deferred results); outside one, ScratchBuffer(slot).
    GLuint CounterBuffer(BufferSlot& slot, size_t bytes);
    // Copies a renderer's W x H RGB(A) float target into `image` ((3, W, H) F32)
    // on the device, through the pixel buffer in `copy`: the target's rows, top
    // first, in RGB floats are exactly the canonical layout.
    void CopyTargetToImage(GLuint target, uint32_t W, uint32_t H, BufferSlot& copy, Buffer& image);
    // render_march's and render_layers' padded (q_alpha, T) volume (PaddedVolumeGL.cpp): whether its storage
    // buffer fits this driver's storage blocks (an error names `stage`; T_sky's, half its size, then fits too),
    // and the pass that forms it.
    Status CheckPaddedVolumeFits(const Extent3& grid, const char* stage);
    // march_volume.frag into `volume`'s RG32F layers: q_alpha = Lerp(qPrev, qCur, alpha) and T (null: 1), the
    // border (0, 1) or with `wrap` the opposite edge's voxels in x and y; copied into `copy`, which it returns,
    // a storage buffer of (q_alpha, T) pairs in the padded index order.
    Result<GLuint> FormPaddedVolume(TextureSlot& volume, BufferSlot& copy, const Buffer& qPrev, const Buffer& qCur,
                                    const Buffer* T, float alpha, bool wrap);
    // The same pass for the sky light's T_sky into `volume`'s R32F layers: the border 1, or with `wrap` the opposite
    // edge's voxels in x and y; copied into `copy`, which it returns, a storage buffer of floats in the padded
    // index order (march.glsl's MarchFetchSkyT).
    Result<GLuint> FormPaddedSkyVolume(TextureSlot& volume, BufferSlot& copy, const Buffer& TSky, bool wrap);
    // What both passes share: `program` (in use, its inputs bound) draws the padded volume of grid e, its
    // `grid` and `wrap` uniforms set here, into `volume`'s layers of `internalFormat`, copied as `format` floats
    // per cell (cellBytes) into `copy`, which it returns.
    Result<GLuint> DrawPaddedVolume(GLuint program, const Extent3& e, bool wrap, GLenum internalFormat, GLenum format,
                                    size_t cellBytes, TextureSlot& volume, BufferSlot& copy);
    // Shade's sweep (ShadeGL.cpp) writing T from q, on `state`'s textures: shade's with the sun, shade_sky's
    // with the sky light; errors name `stage`.
    Status ShadeSweep(ShadeGLState& state, const char* stage, const ShadeParams& params, const Buffer& q, Buffer& T);
    // kMieCloudTable's values in `table`, uploaded on the first call (`uploaded`).
    GLuint MiePhaseTable(BufferSlot& table, bool& uploaded);
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
    StagesGL mStages;  // after mContext: their names are deleted while it is current
    // The shafts pass's block, its RGBA32F target and the image's pixel buffer (ShaftsGL.cpp); after mContext likewise.
    struct {
        BufferSlot block, imageCopy;
        TextureSlot target;
    } mShafts;
    std::optional<double> mLastDeviceMs;
    SubmissionCounts mCounts;
    bool mLayered = true, mLayeredFailed = false;
    SplatSkip mSplatSkip = SplatSkip::Auto;
    bool mSoftwareRasterizer = false;  // GLContext::SoftwareRasterizer, read once when made
    GLLimits mLimits;                  // ReadGLLimits, read once when made
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
        GLuint texture = 0, buffer = 0;
        size_t bytes = 0;
        uint64_t epoch = ~uint64_t(0);
    };
    ImageCopy mImageCopy;
    // Counts the writes of bit fields (Upload, the automaton), so that what a
    // stage keeps from one call to the next is known to be current.
    uint64_t mBitsWrites = 0;
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
