#include "impl_gl/BackendGL.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace cb::gl {
namespace {

struct TexelFormat {
    GLenum internal, format, type;
};

TexelFormat FormatOf(BufferFormat format) {
    switch (format) {
        case BufferFormat::Bits: return {GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT};
        case BufferFormat::U8: return {GL_R8UI, GL_RED_INTEGER, GL_UNSIGNED_BYTE};
        case BufferFormat::F32: return {GL_R32F, GL_RED, GL_FLOAT};
    }
    return {GL_R32F, GL_RED, GL_FLOAT};
}

const BufferGL& Tex(const Buffer& b) { return static_cast<const BufferGL&>(b); }

// Device time from a GL_TIMESTAMP query at construction to one at StopMs(),
// which waits for the work between them (glFinish).
class GpuTimer {
  public:
    explicit GpuTimer(const Functions& f) : mF(f) {
        mF.GenQueries(2, mQueries);
        mF.QueryCounter(mQueries[0], GL_TIMESTAMP);
    }
    ~GpuTimer() { mF.DeleteQueries(2, mQueries); }
    GpuTimer(const GpuTimer&) = delete;
    GpuTimer& operator=(const GpuTimer&) = delete;

    double StopMs() {
        mF.QueryCounter(mQueries[1], GL_TIMESTAMP);
        mF.Finish();
        GLuint64 t0 = 0, t1 = 0;
        mF.GetQueryObjectui64v(mQueries[0], GL_QUERY_RESULT, &t0);
        mF.GetQueryObjectui64v(mQueries[1], GL_QUERY_RESULT, &t1);
        return double(t1 - t0) * 1e-6;
    }

  private:
    const Functions& mF;
    GLuint mQueries[2] = {};
};

}  // namespace

Result<std::unique_ptr<BackendGL>> BackendGL::Create(const std::string& context) {
    if (!context.empty() && context != "osmesa" && context != "egl")
        return MakeError("gl: unknown context '" + context + "' (osmesa or egl)");
    auto ctx = GLContext::Create(context == "egl" ? ContextKind::Egl : ContextKind::OSMesa);
    if (!ctx) return std::unexpected(ctx.error());
    return std::unique_ptr<BackendGL>(new BackendGL(std::move(*ctx)));
}

bool BackendGL::Supports(Stage stage) const {
    return stage == Stage::Smooth || stage == Stage::Density || stage == Stage::Shadow;
}

Status BackendGL::NotYet(const char* stage) const {
    return MakeError(std::string("gl: stage '") + stage + "' is not implemented yet (issue 5)");
}

Result<std::unique_ptr<Buffer>> BackendGL::CreateBuffer(BufferFormat format, Extent3 extent) {
    if (extent.Count() == 0) return MakeError("gl: cannot create an empty buffer");
    const Functions& f = mContext->F();
    const TexelFormat t = FormatOf(format);
    GLuint texture = 0;
    f.CreateTextures(GL_TEXTURE_2D_ARRAY, 1, &texture);
    const GLsizei width = GLsizei(format == BufferFormat::Bits ? (extent.nx + 31) / 32 : extent.nx);
    f.TextureStorage3D(texture, 1, t.internal, width, GLsizei(extent.ny), GLsizei(extent.nz));
    f.TextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    f.TextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    auto buffer = std::make_unique<BufferGL>(format, extent, f, texture);
    CB_TRY(mContext->Check("creating a texture"));
    return std::unique_ptr<Buffer>(std::move(buffer));
}

Status BackendGL::Upload(Buffer& buffer, std::span<const std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("gl: upload size does not match the buffer");
    const Functions& f = mContext->F();
    const BufferGL& b = Tex(buffer);
    const Extent3 e = b.Extent();
    const TexelFormat t = FormatOf(b.Format());
    f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    std::vector<uint32_t> packed;
    const void* data = canonical.data();
    if (b.Format() == BufferFormat::Bits) {
        packed = PackBits32(canonical, e);
        data = packed.data();
    }
    f.TextureSubImage3D(b.Texture(), 0, 0, 0, 0, GLsizei(b.Width()), GLsizei(e.ny), GLsizei(e.nz), t.format, t.type, data);
    return mContext->Check("uploading a texture");
}

Status BackendGL::Download(const Buffer& buffer, std::span<std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("gl: download size does not match the buffer");
    const Functions& f = mContext->F();
    const BufferGL& b = Tex(buffer);
    const Extent3 e = b.Extent();
    const TexelFormat t = FormatOf(b.Format());
    f.PixelStorei(GL_PACK_ALIGNMENT, 1);
    if (b.Format() != BufferFormat::Bits) {
        f.GetTextureImage(b.Texture(), 0, t.format, t.type, GLsizei(canonical.size()), canonical.data());
        return mContext->Check("downloading a texture");
    }
    std::vector<uint32_t> packed(size_t(b.Width()) * e.ny * e.nz);
    f.GetTextureImage(b.Texture(), 0, t.format, t.type, GLsizei(packed.size() * 4), packed.data());
    CB_TRY(mContext->Check("downloading a texture"));
    UnpackBits32(packed, e, canonical);
    return {};
}

Status BackendGL::Smooth(int radius, const Buffer& cld, Buffer& q) {
    if (radius < 0 || radius > 2) return MakeError("gl: smooth radius must be 0, 1 or 2");
    const Functions& f = mContext->F();
    auto program = mContext->Program("smooth");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = cld.Extent();
    GpuTimer timer(f);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindTextureUnit(0, Tex(cld).Texture());
    f.Uniform1i(f.GetUniformLocation(*program, "radius"), radius);
    f.Uniform1f(f.GetUniformLocation(*program, "invW"), 1.0f / float(SmoothNormaliser(radius)));
    f.Uniform3i(f.GetUniformLocation(*program, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    const GLint layerLocation = f.GetUniformLocation(*program, "layer");
    f.BindFramebuffer(GL_FRAMEBUFFER, mContext->Framebuffer());
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    for (uint32_t k = 0; k < e.nz; ++k) {
        f.NamedFramebufferTextureLayer(mContext->Framebuffer(), GL_COLOR_ATTACHMENT0, Tex(q).Texture(), 0, GLint(k));
        if (k == 0 && f.CheckNamedFramebufferStatus(mContext->Framebuffer(), GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
            return MakeError("gl: smooth: the R32F slice is not a complete framebuffer");
        f.Uniform1i(layerLocation, GLint(k));
        f.DrawArrays(GL_TRIANGLES, 0, 3);
    }
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("smooth");
}

Status BackendGL::Region(std::span<const RasterEllipsoid>, Buffer&) { return NotYet("region"); }
Status BackendGL::CaInitialize(const CaInitParams&, CaFields) { return NotYet("ca"); }
Status BackendGL::CaStep(const CaStepParams&, ConstCaFields, const Buffer&, CaFields) { return NotYet("ca"); }
Status BackendGL::Density(const DensityParams& params, const Buffer& q, const Buffer& cld, DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("gl: density tile and band must be positive");
    const Functions& f = mContext->F();
    auto sum = mContext->Program("density_sum");
    if (!sum) return std::unexpected(sum.error());
    auto cover = mContext->Program("density_cover");
    if (!cover) return std::unexpected(cover.error());
    auto occupancy = mContext->Program("occupancy");
    if (!occupancy) return std::unexpected(occupancy.error());
    const Extent3 e = q.Extent();
    const GLuint fb = mContext->Framebuffer();
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    GpuTimer timer(f);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindFramebuffer(GL_FRAMEBUFFER, fb);

    // D: additive blending of the slices, k ascending.
    const float zero = 0.0f;
    f.ClearTexImage(Tex(*out.columnSum).Texture(), 0, GL_RED, GL_FLOAT, &zero);
    f.NamedFramebufferTextureLayer(fb, GL_COLOR_ATTACHMENT0, Tex(*out.columnSum).Texture(), 0, 0);
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    f.UseProgram(*sum);
    f.BindTextureUnit(0, Tex(q).Texture());
    f.Enable(GL_BLEND);
    f.BlendEquation(GL_FUNC_ADD);
    f.BlendFunc(GL_ONE, GL_ONE);
    const GLint sumLayer = f.GetUniformLocation(*sum, "layer");
    for (uint32_t k = 0; k < e.nz; ++k) {
        f.Uniform1i(sumLayer, GLint(k));
        f.DrawArrays(GL_TRIANGLES, 0, 3);
    }
    f.Disable(GL_BLEND);

    // Cover: an atomic counter over the columns; the column flags land in a scratch R8UI layer.
    GLuint counter = 0;
    f.CreateBuffers(1, &counter);
    const GLuint initial = 0;
    f.NamedBufferData(counter, sizeof initial, &initial, GL_DYNAMIC_READ);
    f.BindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, counter);
    auto flags = CreateBuffer(BufferFormat::U8, {e.nx, e.ny, 1});
    if (!flags) return std::unexpected(flags.error());
    f.NamedFramebufferTextureLayer(fb, GL_COLOR_ATTACHMENT0, Tex(**flags).Texture(), 0, 0);
    f.UseProgram(*cover);
    f.BindTextureUnit(0, Tex(cld).Texture());
    f.Uniform3i(f.GetUniformLocation(*cover, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.DrawArrays(GL_TRIANGLES, 0, 3);

    // Occupancy: max-downsampling to tiles (from D) and to tile x band (from q).
    f.UseProgram(*occupancy);
    f.BindTextureUnit(0, Tex(q).Texture());
    f.BindTextureUnit(1, Tex(*out.columnSum).Texture());
    f.Uniform3i(f.GetUniformLocation(*occupancy, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform2i(f.GetUniformLocation(*occupancy, "tileBand"), GLint(params.tile), GLint(params.band));
    const GLint mode = f.GetUniformLocation(*occupancy, "mode"), layer = f.GetUniformLocation(*occupancy, "layer");
    f.Viewport(0, 0, GLsizei(tilesX), GLsizei(tilesY));
    f.Uniform1i(mode, 0);
    for (uint32_t b = 0; b < bandCount; ++b) {
        f.NamedFramebufferTextureLayer(fb, GL_COLOR_ATTACHMENT0, Tex(*out.bands).Texture(), 0, GLint(b));
        f.Uniform1i(layer, GLint(b));
        f.DrawArrays(GL_TRIANGLES, 0, 3);
    }
    f.Uniform1i(mode, 1);
    f.NamedFramebufferTextureLayer(fb, GL_COLOR_ATTACHMENT0, Tex(*out.tiles).Texture(), 0, 0);
    f.DrawArrays(GL_TRIANGLES, 0, 3);

    f.MemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    mLastDeviceMs = timer.StopMs();
    GLuint covered = 0;
    f.GetNamedBufferSubData(counter, 0, sizeof covered, &covered);
    f.DeleteBuffers(1, &counter);
    out.coveredColumns = covered;
    return mContext->Check("density");
}
Status BackendGL::Shade(const ShadeParams&, const Buffer&, Buffer&) { return NotYet("shade"); }
Status BackendGL::Shadow(const ShadowParams& params, const Buffer& columnSum, Buffer& G) {
    const Functions& f = mContext->F();
    auto program = mContext->Program("shadow");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = columnSum.Extent();
    const ShadowLookup l = MakeShadowLookup(params.sun, e.nx, e.ny, params.nz, params.sigma, params.voxelSize);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindTextureUnit(0, Tex(columnSum).Texture());
    f.Uniform2i(f.GetUniformLocation(*program, "size"), GLint(e.nx), GLint(e.ny));
    f.Uniform2i(f.GetUniformLocation(*program, "base"), l.baseX, l.baseY);
    f.Uniform2f(f.GetUniformLocation(*program, "fraction"), l.fx, l.fy);
    f.Uniform1i(f.GetUniformLocation(*program, "beer"), params.form == AttenuationKind::Beer ? 1 : 0);
    f.Uniform1f(f.GetUniformLocation(*program, "opticalDepthPerD"), l.opticalDepthPerD);
    f.Uniform1f(f.GetUniformLocation(*program, "kappa"), params.kappa);
    f.Uniform1i(f.GetUniformLocation(*program, "noSun"), l.noSun ? 1 : 0);
    const GLuint fb = mContext->Framebuffer();
    f.BindFramebuffer(GL_FRAMEBUFFER, fb);
    f.NamedFramebufferTextureLayer(fb, GL_COLOR_ATTACHMENT0, Tex(G).Texture(), 0, 0);
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    GpuTimer timer(f);
    f.DrawArrays(GL_TRIANGLES, 0, 3);
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("shadow");
}
Status BackendGL::RenderSplat(const SplatParams&, const SplatInputs&, Buffer&, SplatStats*) { return NotYet("render_splat"); }

}  // namespace cb::gl
