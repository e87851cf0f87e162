// The OpenGL backend: every stage a fragment-shader pass that renders into
// the slices of 2-D array textures (one layer per slice k), ping-ponging
// between textures as the thesis does (its Figure 4.3). Layouts: bit fields as
// R32UI, 32 voxels per texel along x; byte volumes R8UI; floats R32F.
#pragma once

#include <memory>
#include <optional>
#include <string>

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
    // context: "osmesa" (default) or "egl".
    static Result<std::unique_ptr<BackendGL>> Create(const std::string& context);

    std::string Name() const override { return "gl"; }
    std::string Device() const override { return mContext->Renderer(); }
    bool Supports(Stage stage) const override;
    std::optional<double> LastDeviceMs() const override { return mLastDeviceMs; }

    Result<std::unique_ptr<Buffer>> CreateBuffer(BufferFormat format, Extent3 extent) override;
    Status Upload(Buffer& buffer, std::span<const std::byte> canonical) override;
    Status Download(const Buffer& buffer, std::span<std::byte> canonical) override;

    Status Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region) override;
    Status CaInitialize(const CaInitParams& params, CaFields out) override;
    Status CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) override;
    Status Smooth(int radius, const Buffer& cld, Buffer& q) override;
    Status Density(const DensityParams& params, const Buffer& q, const Buffer& cld, DensityOutputs& out) override;
    Status Shade(const ShadeParams& params, const Buffer& q, Buffer& T) override;
    Status Shadow(const ShadowParams& params, const Buffer& columnSum, Buffer& G) override;
    Status RenderSplat(const SplatParams& params, const SplatInputs& in, Buffer& image, SplatStats* stats) override;

  private:
    explicit BackendGL(std::unique_ptr<GLContext> context) : mContext(std::move(context)) {}
    Status NotYet(const char* stage) const;

    std::unique_ptr<GLContext> mContext;
    std::optional<double> mLastDeviceMs;
};

}  // namespace cb::gl
