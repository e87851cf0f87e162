// The OpenGL backend: every stage a fragment-shader pass that renders into
// the slices of 2-D array textures (one layer per slice k), ping-ponging
// between textures as the thesis does (its Figure 4.3). Layouts: bit fields as
// R32UI, 32 voxels per texel along x; byte volumes R8UI; floats R32F. The
// automaton can also run in the thesis's layout (one RGBA8UI texel per voxel,
// a channel per bit), converted to and from the packed fields it shares with
// the other stages (docs/pipeline.md).
#pragma once

#include <array>
#include <initializer_list>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>

#include "core/Backend.h"
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
    // context: "osmesa" (default) or "egl"; caLayout: "packed" (default) or "rgba8".
    static Result<std::unique_ptr<BackendGL>> Create(const std::string& context, const std::string& caLayout = "");
    ~BackendGL() override;

    std::string Name() const override { return "gl"; }
    std::string Device() const override;
    bool Supports(Stage stage) const override;
    std::optional<double> LastDeviceMs() const override { return mLastDeviceMs; }

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    CB_SPLAT_PIPELINE_ENTRIES(CB_OVERRIDE_BACKEND_ENTRY)

  private:
    // Scratch textures and buffers, kept between calls and remade when their shape changes.
    enum ScratchSlot : size_t {
        kRegionUnorm, kSmoothX, kSmoothXY, kCaHum, kCaAct, kCaCld, kStateA, kStateB, kShadeCoarseQ, kShadeVolume, kShadePing,
        kShadePong, kSplatTarget, kCoverFlags, kScratchSlots
    };
    enum BufferSlot : size_t { kCoverCounter, kEllipsoidList, kSplatOrder, kSplatCounters, kImageCopy, kBufferSlots };
    struct ScratchTexture {
        GLuint texture = 0;
        GLenum target = 0, format = 0;
        GLsizei width = 0, height = 0, depth = 0;
    };

    BackendGL(std::unique_ptr<GLContext> context, bool rgba8) : mContext(std::move(context)), mRgba8(rgba8) {}
    GLuint Scratch(ScratchSlot slot, GLenum target, GLenum format, GLsizei width, GLsizei height, GLsizei depth = 1);
    GLuint ScratchBuffer(BufferSlot slot, size_t bytes);
    // Attaches layer `layer` of each texture (layer < 0: a 2-D texture) to the
    // context's framebuffer as colour attachments 0, 1, ... and makes them the
    // draw buffers; the other attachments are detached.
    Status BindTargets(std::span<const std::pair<GLuint, int>> targets);
    Status BindTargets(std::initializer_list<std::pair<GLuint, int>> targets) {
        return BindTargets(std::span(targets.begin(), targets.size()));
    }
    // Draws the full-screen triangle of `program` (in use, its other uniforms
    // set) once per layer k < layers: uniform "layer" = k, the render targets
    // layer k of each of `textures`, and perLayer(k) for whatever else changes with k.
    template <typename PerLayer>
    Status DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures, PerLayer&& perLayer);
    Status DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures);
    Status CaStepRgba8(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out);

    std::unique_ptr<GLContext> mContext;
    bool mRgba8 = false;
    std::optional<double> mLastDeviceMs;
    std::array<ScratchTexture, kScratchSlots> mScratch{};
    std::array<std::pair<GLuint, size_t>, kBufferSlots> mBuffers{};
    // Which packed fields the thesis-layout state in kStateA holds: the last
    // step's outputs, valid until a bit field is written some other way.
    std::array<GLuint, 3> mStateOf{};
    uint64_t mBitsWrites = 0, mStateWrites = ~uint64_t(0);
};

}  // namespace cb::gl
