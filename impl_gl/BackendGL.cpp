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

Result<std::unique_ptr<BackendGL>> BackendGL::Create(const std::string& context, const std::string& caLayout) {
    if (!context.empty() && context != "osmesa" && context != "egl")
        return MakeError("gl: unknown context '" + context + "' (osmesa or egl)");
    if (!caLayout.empty() && caLayout != "packed" && caLayout != "rgba8")
        return MakeError("gl: unknown automaton layout '" + caLayout + "' (packed or rgba8)");
    auto ctx = GLContext::Create(context == "egl" ? ContextKind::Egl : ContextKind::OSMesa);
    if (!ctx) return std::unexpected(ctx.error());
    return std::unique_ptr<BackendGL>(new BackendGL(std::move(*ctx), caLayout == "rgba8"));
}

BackendGL::~BackendGL() {
    const Functions& f = mContext->F();
    for (ScratchTexture& t : mScratch)
        if (t.texture) f.DeleteTextures(1, &t.texture);
    for (auto& [buffer, bytes] : mBuffers)
        if (buffer) f.DeleteBuffers(1, &buffer);
}

std::string BackendGL::Device() const { return mContext->Renderer() + (mRgba8 ? ", automaton in RGBA8" : ""); }

bool BackendGL::Supports(Stage stage) const { return IsSplatPipelineStage(stage); }

GLuint BackendGL::Scratch(GlScratch slot, GLenum target, GLenum format, GLsizei width, GLsizei height, GLsizei depth) {
    const Functions& f = mContext->F();
    ScratchTexture& t = mScratch[slot];
    if (t.texture && t.target == target && t.format == format && t.width == width && t.height == height && t.depth == depth)
        return t.texture;
    if (t.texture) f.DeleteTextures(1, &t.texture);
    t = {0, target, format, width, height, depth};
    f.CreateTextures(target, 1, &t.texture);
    if (target == GL_TEXTURE_2D) f.TextureStorage2D(t.texture, 1, format, width, height);
    else f.TextureStorage3D(t.texture, 1, format, width, height, depth);
    f.TextureParameteri(t.texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    f.TextureParameteri(t.texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return t.texture;
}

GLuint BackendGL::ScratchBuffer(GlScratchBuffer slot, size_t bytes) {
    const Functions& f = mContext->F();
    auto& [buffer, size] = mBuffers[slot];
    bytes = std::max<size_t>(bytes, 16);
    if (buffer && size >= bytes) return buffer;
    if (buffer) f.DeleteBuffers(1, &buffer);
    f.CreateBuffers(1, &buffer);
    f.NamedBufferData(buffer, GLsizeiptr(bytes), nullptr, GL_DYNAMIC_DRAW);
    size = bytes;
    return buffer;
}

Status BackendGL::BindTargets(std::span<const std::pair<GLuint, int>> targets) {
    const Functions& f = mContext->F();
    const GLuint framebuffer = mContext->Framebuffer();
    GLenum drawBuffers[4] = {};
    GLsizei n = 0;
    for (const auto& [texture, layer] : targets) {
        const GLenum attachment = GL_COLOR_ATTACHMENT0 + GLenum(n);
        if (layer < 0) f.NamedFramebufferTexture(framebuffer, attachment, texture, 0);
        else f.NamedFramebufferTextureLayer(framebuffer, attachment, texture, 0, layer);
        drawBuffers[n++] = attachment;
    }
    // Detach the rest: attachments of other sizes would clip the render area.
    for (GLsizei unused = n; unused < 4; ++unused)
        f.NamedFramebufferTexture(framebuffer, GL_COLOR_ATTACHMENT0 + GLenum(unused), 0, 0);
    f.NamedFramebufferDrawBuffers(framebuffer, n, drawBuffers);
    f.BindFramebuffer(GL_FRAMEBUFFER, framebuffer);
    if (f.CheckNamedFramebufferStatus(framebuffer, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        return MakeError("gl: a pass's render targets do not make a complete framebuffer");
    return {};
}

template <typename PerLayer>
Status BackendGL::DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures,
                             PerLayer&& perLayer) {
    const Functions& f = mContext->F();
    const GLint layerUniform = f.GetUniformLocation(program, "layer");
    std::array<std::pair<GLuint, int>, 4> targets;
    if (textures.size() > targets.size()) return MakeError("gl: a pass has more than 4 render targets");
    for (uint32_t k = 0; k < layers; ++k) {
        size_t n = 0;
        for (GLuint texture : textures) targets[n++] = {texture, int(k)};
        CB_TRY(BindTargets(std::span(targets.data(), n)));
        f.Uniform1i(layerUniform, GLint(k));
        perLayer(k);
        f.DrawArrays(GL_TRIANGLES, 0, 3);
    }
    return {};
}

Status BackendGL::DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures) {
    return DrawLayers(program, layers, textures, [](uint32_t) {});
}

Result<std::unique_ptr<Buffer>> BackendGL::CreateBuffer(BufferFormat format, Extent3 extent) {
    if (extent.Count() == 0) return MakeError("gl: cannot create an empty buffer");
    const Functions& f = mContext->F();
    const TexelFormat t = FormatOf(format);
    const GLsizei width = GLsizei(format == BufferFormat::Bits ? (extent.nx + 31) / 32 : extent.nx);
    GLint maxSize = 0, maxLayers = 0;
    f.GetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
    f.GetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
    if (width > maxSize || extent.ny > uint32_t(maxSize) || extent.nz > uint32_t(maxLayers))
        return MakeError("gl: a buffer of extent (" + std::to_string(extent.nx) + ", " + std::to_string(extent.ny) + ", " +
                         std::to_string(extent.nz) + ") needs a " + std::to_string(width) + " x " +
                         std::to_string(extent.ny) + " texture with " + std::to_string(extent.nz) +
                         " layers; this driver allows " + std::to_string(maxSize) + " x " + std::to_string(maxSize) +
                         " with " + std::to_string(maxLayers) + " layers (an image's height is its layer count)");
    GLuint texture = 0;
    f.CreateTextures(GL_TEXTURE_2D_ARRAY, 1, &texture);
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
        ++mBitsWrites;
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

// smooth: three separable passes, x then y then z, through R16UI sums.
Status BackendGL::Smooth(int radius, const Buffer& cld, Buffer& q) {
    if (radius < 0 || radius > 2) return MakeError("gl: smooth radius must be 0, 1 or 2");
    const Functions& f = mContext->F();
    GLuint passes[3];
    const char* names[3] = {"smooth_x", "smooth_y", "smooth_z"};
    for (int n = 0; n < 3; ++n) {
        auto program = mContext->Program(names[n]);
        if (!program) return std::unexpected(program.error());
        passes[n] = *program;
    }
    const Extent3 e = cld.Extent();
    const GLsizei nx = GLsizei(e.nx), ny = GLsizei(e.ny), nz = GLsizei(e.nz);
    const GLuint sumX = Scratch(GlScratch::SmoothX, GL_TEXTURE_2D_ARRAY, GL_R16UI, nx, ny, nz);
    const GLuint sumXY = Scratch(GlScratch::SmoothXY, GL_TEXTURE_2D_ARRAY, GL_R16UI, nx, ny, nz);
    const GLuint input[3] = {Tex(cld).Texture(), sumX, sumXY};
    const GLuint output[3] = {sumX, sumXY, Tex(q).Texture()};
    GpuTimer timer(f);
    f.BindVertexArray(mContext->EmptyVao());
    f.Viewport(0, 0, nx, ny);
    for (int n = 0; n < 3; ++n) {
        const GLuint program = passes[n];
        f.UseProgram(program);
        f.BindTextureUnit(0, input[n]);
        f.Uniform1i(f.GetUniformLocation(program, "radius"), radius);
        f.Uniform3i(f.GetUniformLocation(program, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        if (n == 2) f.Uniform1f(f.GetUniformLocation(program, "invW"), 1.0f / float(SmoothNormaliser(radius)));
        CB_TRY(DrawLayers(program, e.nz, {output[n]}));
    }
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("smooth");
}

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
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    GpuTimer timer(f);
    f.BindVertexArray(mContext->EmptyVao());

    // D: additive blending of the slices, k ascending.
    const float zero = 0.0f;
    f.ClearTexImage(Tex(*out.columnSum).Texture(), 0, GL_RED, GL_FLOAT, &zero);
    CB_TRY(BindTargets({{Tex(*out.columnSum).Texture(), 0}}));
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
    const GLuint counter = ScratchBuffer(GlScratchBuffer::CoverCounter, sizeof(GLuint));
    const GLuint initial = 0;
    f.NamedBufferSubData(counter, 0, sizeof initial, &initial);
    f.BindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, counter);
    const GLuint flags = Scratch(GlScratch::CoverFlags, GL_TEXTURE_2D_ARRAY, GL_R8UI, GLsizei(e.nx), GLsizei(e.ny), 1);
    CB_TRY(BindTargets({{flags, 0}}));
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
    const GLint mode = f.GetUniformLocation(*occupancy, "mode");
    f.Viewport(0, 0, GLsizei(tilesX), GLsizei(tilesY));
    f.Uniform1i(mode, 0);
    CB_TRY(DrawLayers(*occupancy, bandCount, {Tex(*out.bands).Texture()}));
    f.Uniform1i(mode, 1);
    CB_TRY(BindTargets({{Tex(*out.tiles).Texture(), 0}}));
    f.DrawArrays(GL_TRIANGLES, 0, 3);

    f.MemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    mLastDeviceMs = timer.StopMs();
    GLuint covered = 0;
    f.GetNamedBufferSubData(counter, 0, sizeof covered, &covered);
    out.coveredColumns = covered;
    return mContext->Check("density");
}
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
    CB_TRY(BindTargets({{Tex(G).Texture(), 0}}));
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    GpuTimer timer(f);
    f.DrawArrays(GL_TRIANGLES, 0, 3);
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("shadow");
}


// region: per slice, one instanced quad per ellipsoid into an R8 UNORM layer
// with MAX blending (integer targets cannot blend), then one copy into the
// R8UI volume (the same 8-bit texel class, so the bits carry over).
Status BackendGL::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region) {
    const Functions& f = mContext->F();
    auto program = mContext->Program("region");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = region.Extent();
    static_assert(sizeof(RasterEllipsoid) == 8 * sizeof(float));
    GpuTimer timer(f);
    const GLuint list = ScratchBuffer(GlScratchBuffer::EllipsoidList, ellipsoids.size_bytes());
    if (!ellipsoids.empty()) f.NamedBufferSubData(list, 0, GLsizeiptr(ellipsoids.size_bytes()), ellipsoids.data());
    const GLuint unorm =
        Scratch(GlScratch::RegionUnorm, GL_TEXTURE_2D_ARRAY, GL_R8, GLsizei(e.nx), GLsizei(e.ny), GLsizei(e.nz));
    const float zero = 0.0f;
    f.ClearTexImage(unorm, 0, GL_RED, GL_FLOAT, &zero);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, list);
    f.Uniform2i(f.GetUniformLocation(*program, "size"), GLint(e.nx), GLint(e.ny));
    const GLint layer = f.GetUniformLocation(*program, "layer");
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    f.Enable(GL_BLEND);
    f.BlendEquation(GL_MAX);
    for (uint32_t k = 0; k < e.nz && !ellipsoids.empty(); ++k) {
        CB_TRY(BindTargets({{unorm, int(k)}}));
        f.Uniform1i(layer, GLint(k));
        f.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, GLsizei(ellipsoids.size()));
    }
    f.Disable(GL_BLEND);
    f.BlendEquation(GL_FUNC_ADD);
    f.CopyImageSubData(unorm, GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0, Tex(region).Texture(), GL_TEXTURE_2D_ARRAY, 0, 0, 0, 0,
                       GLsizei(e.nx), GLsizei(e.ny), GLsizei(e.nz));
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("region");
}

Status BackendGL::CaInitialize(const CaInitParams& params, CaFields out) {
    const Functions& f = mContext->F();
    auto program = mContext->Program("ca_init");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = out.hum->Extent();
    GpuTimer timer(f);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.Uniform3i(f.GetUniformLocation(*program, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform1ui(f.GetUniformLocation(*program, "seed"), params.seed);
    f.Uniform1ui(f.GetUniformLocation(*program, "qHum0"), params.qHum0);
    f.Uniform1ui(f.GetUniformLocation(*program, "qAct0"), params.qAct0);
    f.Viewport(0, 0, GLsizei(CeilDiv(e.nx, 32)), GLsizei(e.ny));
    CB_TRY(DrawLayers(*program, e.nz, {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()}));
    ++mBitsWrites;
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("ca initial state");
}

Status BackendGL::CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    if (mRgba8) return CaStepRgba8(params, in, region, out);
    const Functions& f = mContext->F();
    auto rules = mContext->Program("ca");
    if (!rules) return std::unexpected(rules.error());
    auto advect = mContext->Program("advect");
    if (!advect) return std::unexpected(advect.error());
    const Extent3 e = in.hum->Extent();
    const GLsizei words = GLsizei(CeilDiv(e.nx, 32));
    const bool wind = !params.shiftX.empty();
    // With wind the rules write scratch fields that the advection pass shifts into `out`.
    GLuint next[3] = {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()};
    if (wind) {
        next[0] = Scratch(GlScratch::CaHum, GL_TEXTURE_2D_ARRAY, GL_R32UI, words, GLsizei(e.ny), GLsizei(e.nz));
        next[1] = Scratch(GlScratch::CaAct, GL_TEXTURE_2D_ARRAY, GL_R32UI, words, GLsizei(e.ny), GLsizei(e.nz));
        next[2] = Scratch(GlScratch::CaCld, GL_TEXTURE_2D_ARRAY, GL_R32UI, words, GLsizei(e.ny), GLsizei(e.nz));
    }
    GpuTimer timer(f);
    f.BindVertexArray(mContext->EmptyVao());
    f.Viewport(0, 0, words, GLsizei(e.ny));
    f.UseProgram(*rules);
    f.BindTextureUnit(0, Tex(*in.hum).Texture());
    f.BindTextureUnit(1, Tex(*in.act).Texture());
    f.BindTextureUnit(2, Tex(*in.cld).Texture());
    f.BindTextureUnit(3, Tex(region).Texture());
    f.Uniform3i(f.GetUniformLocation(*rules, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform1i(f.GetUniformLocation(*rules, "words"), words);
    f.Uniform1ui(f.GetUniformLocation(*rules, "seed"), params.seed);
    f.Uniform1ui(f.GetUniformLocation(*rules, "step"), params.step);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qExt"), params.qExt);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qHum"), params.qHum);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qAct"), params.qAct);
    CB_TRY(DrawLayers(*rules, e.nz, {next[0], next[1], next[2]}));
    if (wind) {
        f.UseProgram(*advect);
        for (int n = 0; n < 3; ++n) f.BindTextureUnit(GLuint(n), next[n]);
        f.Uniform3i(f.GetUniformLocation(*advect, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        f.Uniform1i(f.GetUniformLocation(*advect, "words"), words);
        const GLint shift = f.GetUniformLocation(*advect, "shift");
        CB_TRY(DrawLayers(*advect, e.nz, {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()},
                          [&](uint32_t k) { f.Uniform2i(shift, params.shiftX[k], params.shiftY[k]); }));
    }
    ++mBitsWrites;
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("ca");
}

// The thesis's layout: the step runs on RGBA8UI voxels (Rgba8StateA -> Rgba8StateB,
// and back to Rgba8StateA through the advection pass when there is wind), then the
// packed fields the other stages read are written from it. The packing of
// `in` is skipped when Rgba8StateA already holds it (the previous step's result).
Status BackendGL::CaStepRgba8(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    const Functions& f = mContext->F();
    auto pack = mContext->Program("ca_pack_rgba8");
    if (!pack) return std::unexpected(pack.error());
    auto rules = mContext->Program("ca_rgba8");
    if (!rules) return std::unexpected(rules.error());
    auto advect = mContext->Program("advect_rgba8");
    if (!advect) return std::unexpected(advect.error());
    auto unpack = mContext->Program("ca_unpack_rgba8");
    if (!unpack) return std::unexpected(unpack.error());
    const Extent3 e = in.hum->Extent();
    const GLsizei nx = GLsizei(e.nx), ny = GLsizei(e.ny), nz = GLsizei(e.nz);
    const GLuint stateA = Scratch(GlScratch::Rgba8StateA, GL_TEXTURE_2D_ARRAY, GL_RGBA8UI, nx, ny, nz);
    const GLuint stateB = Scratch(GlScratch::Rgba8StateB, GL_TEXTURE_2D_ARRAY, GL_RGBA8UI, nx, ny, nz);
    const std::array<GLuint, 3> inputs = {Tex(*in.hum).Texture(), Tex(*in.act).Texture(), Tex(*in.cld).Texture()};
    const bool packed = mStateOf == inputs && mStateWrites == mBitsWrites;
    const bool wind = !params.shiftX.empty();
    GpuTimer timer(f);
    f.BindVertexArray(mContext->EmptyVao());
    f.Viewport(0, 0, nx, ny);
    auto perSlice = [&](GLuint program, GLuint target, auto&& setLayer) -> Status {
        f.UseProgram(program);
        f.Uniform3i(f.GetUniformLocation(program, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        return DrawLayers(program, e.nz, {target}, setLayer);
    };
    if (!packed) {
        for (int n = 0; n < 3; ++n) f.BindTextureUnit(GLuint(n), inputs[n]);
        CB_TRY(perSlice(*pack, stateA, [](uint32_t) {}));
    }
    f.BindTextureUnit(0, stateA);
    f.BindTextureUnit(1, Tex(region).Texture());
    f.UseProgram(*rules);
    f.Uniform1ui(f.GetUniformLocation(*rules, "seed"), params.seed);
    f.Uniform1ui(f.GetUniformLocation(*rules, "step"), params.step);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qExt"), params.qExt);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qHum"), params.qHum);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qAct"), params.qAct);
    CB_TRY(perSlice(*rules, stateB, [](uint32_t) {}));
    GLuint result = stateB;
    if (wind) {
        f.BindTextureUnit(0, stateB);
        const GLint shift = f.GetUniformLocation(*advect, "shift");
        CB_TRY(perSlice(*advect, stateA, [&](uint32_t k) { f.Uniform2i(shift, params.shiftX[k], params.shiftY[k]); }));
        result = stateA;
    }
    f.BindTextureUnit(0, result);
    f.Viewport(0, 0, GLsizei(CeilDiv(e.nx, 32)), ny);
    f.UseProgram(*unpack);
    f.Uniform3i(f.GetUniformLocation(*unpack, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    CB_TRY(DrawLayers(*unpack, e.nz, {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()}));
    ++mBitsWrites;
    // Without wind the result is in Rgba8StateB: swap the slots so Rgba8StateA holds it.
    if (result == stateB) std::swap(mScratch[GlScratch::Rgba8StateA], mScratch[GlScratch::Rgba8StateB]);
    mStateOf = {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()};
    mStateWrites = mBitsWrites;
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("ca (RGBA8 layout)");
}

// shade: optional down-sampling pass, then the slice loop from the sun's side
// (ping-pong between two 2-D textures, each slice also written to layer w of a
// w-major volume), then one pass that writes the z-layered T, reading the
// w-major volume trilinearly (exactly, at f = 1).
Status BackendGL::Shade(const ShadeParams& params, const Buffer& q, Buffer& T) {
    const int res = params.resolution;
    if (res != 1 && res != 2 && res != 4) return MakeError("gl: shade resolution must be 1, 2 or 4");
    const Functions& f = mContext->F();
    auto slice = mContext->Program("shade_slice");
    if (!slice) return std::unexpected(slice.error());
    auto up = mContext->Program("shade_up");
    if (!up) return std::unexpected(up.error());
    auto down = mContext->Program("shade_down");
    if (!down) return std::unexpected(down.error());
    const Extent3 e = q.Extent();
    const int n[3] = {int(CeilDiv(e.nx, uint32_t(res))), int(CeilDiv(e.ny, uint32_t(res))), int(CeilDiv(e.nz, uint32_t(res)))};
    const ShearWarp g = MakeShearWarp(params.sun, params.filter);
    const SliceAttenuation a = MakeSliceAttenuation(params.attenuation, params.sigma, params.voxelSize * float(res), g.absSw,
                                                    params.thesisAr, params.scattering, params.albedo, params.solidAngle,
                                                    params.phase);
    const int nu = n[g.u], nv = n[g.v], nw = n[g.w];
    GpuTimer timer(f);
    f.BindVertexArray(mContext->EmptyVao());
    GLuint shadedQ = Tex(q).Texture();
    if (res > 1) {
        shadedQ = Scratch(GlScratch::ShadeCoarseQ, GL_TEXTURE_2D_ARRAY, GL_R32F, n[0], n[1], n[2]);
        f.UseProgram(*down);
        f.BindTextureUnit(0, Tex(q).Texture());
        f.Uniform3i(f.GetUniformLocation(*down, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        f.Uniform1i(f.GetUniformLocation(*down, "f"), res);
        f.Viewport(0, 0, n[0], n[1]);
        CB_TRY(DrawLayers(*down, uint32_t(n[2]), {shadedQ}));
    }
    const GLuint volume = Scratch(GlScratch::ShadeVolume, GL_TEXTURE_2D_ARRAY, GL_R32F, nu, nv, nw);
    GLuint ping = Scratch(GlScratch::ShadePing, GL_TEXTURE_2D, GL_R32F, nu, nv);
    GLuint pong = Scratch(GlScratch::ShadePong, GL_TEXTURE_2D, GL_R32F, nu, nv);
    auto unit = [](int axis) {
        GLint v[3] = {0, 0, 0};
        v[axis] = 1;
        return std::array<GLint, 3>{v[0], v[1], v[2]};
    };
    const auto eu = unit(g.u), ev = unit(g.v), ew = unit(g.w);
    f.UseProgram(*slice);
    f.BindTextureUnit(1, shadedQ);
    f.Uniform3i(f.GetUniformLocation(*slice, "axisU"), eu[0], eu[1], eu[2]);
    f.Uniform3i(f.GetUniformLocation(*slice, "axisV"), ev[0], ev[1], ev[2]);
    f.Uniform2i(f.GetUniformLocation(*slice, "sliceSize"), nu, nv);
    f.Uniform2i(f.GetUniformLocation(*slice, "tapOffset"), g.u0, g.v0);
    f.Uniform2f(f.GetUniformLocation(*slice, "tapFraction"), g.fu, g.fv);
    f.Uniform1i(f.GetUniformLocation(*slice, "beer"), a.kind == AttenuationKind::Beer ? 1 : 0);
    f.Uniform1f(f.GetUniformLocation(*slice, "depthPerQ"), a.opticalDepthPerQ);
    f.Uniform1f(f.GetUniformLocation(*slice, "thesisAr"), a.thesisAr);
    f.Uniform1f(f.GetUniformLocation(*slice, "scatterGain"), a.scatterGain);
    f.Uniform1ui(f.GetUniformLocation(*slice, "storage"), uint32_t(params.storage));
    const GLint first = f.GetUniformLocation(*slice, "first"), previousW = f.GetUniformLocation(*slice, "previousW");
    f.Viewport(0, 0, nu, nv);
    int previous = 0;
    for (int m = 0; m < nw; ++m) {
        const int w = g.sunAbove ? nw - 1 - m : m;
        CB_TRY(BindTargets({{pong, -1}, {volume, w}}));
        f.BindTextureUnit(0, ping);
        f.Uniform1i(first, m == 0 ? 1 : 0);
        f.Uniform3i(previousW, previous * ew[0], previous * ew[1], previous * ew[2]);
        f.DrawArrays(GL_TRIANGLES, 0, 3);
        std::swap(ping, pong);
        previous = w;
    }
    f.UseProgram(*up);
    f.BindTextureUnit(0, volume);
    f.Uniform3i(f.GetUniformLocation(*up, "cells"), n[0], n[1], n[2]);
    f.Uniform3i(f.GetUniformLocation(*up, "axes"), g.u, g.v, g.w);
    f.Uniform1i(f.GetUniformLocation(*up, "f"), res);
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    CB_TRY(DrawLayers(*up, e.nz, {Tex(T).Texture()}));
    mLastDeviceMs = timer.StopMs();
    return mContext->Check("shade");
}

// render_splat: GL_POINTS in the shared order, one vertex per voxel; culling
// and skipping become a multi-draw over the runs of ranks whose tile x band
// box is visible. The RGBA32F target is drawn with row 0 at the top, so one
// read into a pixel buffer and one upload from it give the canonical (3, W, H) image.
Status BackendGL::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) {
    if (!p.order || !in.qPrev || !in.qCur || !in.T) return MakeError("gl: render_splat needs q (both steps), T and an order");
    if (image.Extent().nx != 3) return MakeError("gl: render_splat image must have extent (3, width, height)");
    const Functions& f = mContext->F();
    auto program = mContext->Program("splat");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = in.qCur->Extent();
    const uint32_t W = image.Extent().ny, H = image.Extent().nz;
    const CameraFrame& cam = p.camera;

    auto visibility = DownloadSplatBoxVisibility(*this, p, in);
    if (!visibility) return std::unexpected(visibility.error());
    const std::vector<uint8_t>& boxes = *visibility;

    // Runs of consecutive ranks whose box is visible: one draw each.
    const SplatOrder& order = *p.order;
    const int outer = order.axes[0], middle = order.axes[1], inner = order.axes[2];
    const uint32_t tilesX = CeilDiv(e.nx, p.tile), tilesY = CeilDiv(e.ny, p.tile);
    const uint32_t boxSize[3] = {p.tile, p.tile, p.band};
    const uint32_t boxStride[3] = {1, tilesX, tilesX * tilesY};
    std::vector<GLint> firsts;
    std::vector<GLsizei> counts;
    uint64_t visited = 0;
    {
        const auto& innerIdx = order.indices[inner];
        std::vector<uint32_t> innerBox(innerIdx.size());
        for (size_t n = 0; n < innerIdx.size(); ++n) innerBox[n] = (innerIdx[n] / boxSize[inner]) * boxStride[inner];
        GLint rank = 0;
        GLint runStart = -1;
        for (uint32_t o : order.indices[outer])
            for (uint32_t m : order.indices[middle]) {
                const uint32_t base = (o / boxSize[outer]) * boxStride[outer] + (m / boxSize[middle]) * boxStride[middle];
                for (size_t n = 0; n < innerIdx.size(); ++n, ++rank) {
                    const bool visible = boxes[base + innerBox[n]] != 0;
                    if (visible && runStart < 0) runStart = rank;
                    if (!visible && runStart >= 0) {
                        firsts.push_back(runStart);
                        counts.push_back(rank - runStart);
                        runStart = -1;
                    }
                }
            }
        if (runStart >= 0) {
            firsts.push_back(runStart);
            counts.push_back(rank - runStart);
        }
        for (GLsizei c : counts) visited += uint64_t(c);
    }

    const FlatSplatOrder flat = FlattenSplatOrder(order);
    GLfloat pointRange[2] = {1, 1};
    f.GetFloatv(GL_POINT_SIZE_RANGE, pointRange);
    constexpr float kGuard = 130;  // > the largest half splat plus the 2-pixel margin

    GpuTimer timer(f);
    const GLuint orderBuffer = ScratchBuffer(GlScratchBuffer::SplatOrder, flat.indices.size() * 4);
    f.NamedBufferSubData(orderBuffer, 0, GLsizeiptr(flat.indices.size() * 4), flat.indices.data());
    const GLuint counters = ScratchBuffer(GlScratchBuffer::SplatCounters, 16);
    const uint32_t zero[4] = {};
    f.NamedBufferSubData(counters, 0, sizeof zero, zero);
    const GLuint target = Scratch(GlScratch::SplatTarget, GL_TEXTURE_2D, GL_RGBA32F, GLsizei(W), GLsizei(H));
    CB_TRY(BindTargets({{target, -1}}));
    const float background[4] = {p.background[0], p.background[1], p.background[2], 1};
    f.ClearNamedFramebufferfv(mContext->Framebuffer(), GL_COLOR, 0, background);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, orderBuffer);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, counters);
    f.BindTextureUnit(0, Tex(*in.qPrev).Texture());
    f.BindTextureUnit(1, Tex(*in.qCur).Texture());
    f.BindTextureUnit(2, Tex(*in.T).Texture());
    auto uniform = [&](const char* name) { return f.GetUniformLocation(*program, name); };
    f.Uniform3i(uniform("grid"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform3i(uniform("axes"), outer, middle, inner);
    f.Uniform3i(uniform("orderBase"), GLint(flat.base[0]), GLint(flat.base[1]), GLint(flat.base[2]));
    f.Uniform2f(uniform("image"), float(W), float(H));
    f.Uniform1f(uniform("guard"), kGuard);
    f.Uniform4f(uniform("eye"), cam.eye[0], cam.eye[1], cam.eye[2], cam.nearPlane);
    f.Uniform4f(uniform("forward"), cam.forward[0], cam.forward[1], cam.forward[2], cam.focalPx);
    f.Uniform3f(uniform("right"), cam.right[0], cam.right[1], cam.right[2]);
    f.Uniform3f(uniform("up"), cam.upVector[0], cam.upVector[1], cam.upVector[2]);
    f.Uniform4f(uniform("sun"), p.sun[0], p.sun[1], p.sun[2], p.phase.g);
    f.Uniform4f(uniform("sunRadiance"), p.sunRadiance[0], p.sunRadiance[1], p.sunRadiance[2], float(p.phase.kind));
    f.Uniform4f(uniform("ambient"), p.ambient[0], p.ambient[1], p.ambient[2], p.qMin);
    f.Uniform4f(uniform("origin"), p.origin[0], p.origin[1], p.origin[2], p.voxelSize);
    f.Uniform4f(uniform("misc"), p.splatDiameter, p.alpha, p.opacity, pointRange[1]);
    f.Enable(GL_PROGRAM_POINT_SIZE);
    f.Enable(GL_BLEND);
    f.BlendEquation(GL_FUNC_ADD);
    f.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    f.Viewport(-GLint(kGuard), -GLint(kGuard), GLsizei(W + 2 * kGuard), GLsizei(H + 2 * kGuard));
    GLuint fragments = 0;
    if (stats) {
        f.GenQueries(1, &fragments);
        f.BeginQuery(GL_SAMPLES_PASSED, fragments);
    }
    if (!firsts.empty()) f.MultiDrawArrays(GL_POINTS, firsts.data(), counts.data(), GLsizei(firsts.size()));
    if (stats) f.EndQuery(GL_SAMPLES_PASSED);
    f.Disable(GL_BLEND);
    f.Disable(GL_PROGRAM_POINT_SIZE);
    // The image: RGB floats of rows top first are exactly the canonical layout.
    const size_t imageBytes = size_t(W) * H * 3 * sizeof(float);
    const GLuint copy = ScratchBuffer(GlScratchBuffer::ImageCopy, imageBytes);
    f.MemoryBarrier(GL_PIXEL_BUFFER_BARRIER_BIT);
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, copy);
    f.PixelStorei(GL_PACK_ALIGNMENT, 1);
    f.GetTextureImage(target, 0, GL_RGB, GL_FLOAT, GLsizei(imageBytes), nullptr);
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    f.BindBuffer(GL_PIXEL_UNPACK_BUFFER, copy);
    f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    f.TextureSubImage3D(Tex(image).Texture(), 0, 0, 0, 0, 3, GLsizei(W), GLsizei(H), GL_RED, GL_FLOAT, nullptr);
    f.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    mLastDeviceMs = timer.StopMs();
    if (stats) {
        GLuint64 passed = 0;
        f.GetQueryObjectui64v(fragments, GL_QUERY_RESULT, &passed);
        f.DeleteQueries(1, &fragments);
        uint32_t drawn = 0;
        f.GetNamedBufferSubData(counters, 0, sizeof drawn, &drawn);
        stats->splats = drawn;
        stats->voxelsVisited = visited;
        stats->fragments = passed;
    }
    return mContext->Check("render_splat");
}

}  // namespace cb::gl
