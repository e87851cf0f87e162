#include "impl_gl/BackendGL.h"

#include <algorithm>
#include <vector>

#include "core/scene/Scene.h"

namespace cb::gl {
namespace {

struct TexelFormat {
    GLenum internal, format, type;
};

TexelFormat FormatOf(BufferFormat format) {
    switch (format) {
        case BufferFormat::Bits:
            return {GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT};
        case BufferFormat::U8:
            return {GL_R8UI, GL_RED_INTEGER, GL_UNSIGNED_BYTE};
        case BufferFormat::F32:
            return {GL_R32F, GL_RED, GL_FLOAT};
    }
    return {GL_R32F, GL_RED, GL_FLOAT};
}

}  // namespace

GLLimits ReadGLLimits(const GLContext& context) {
    GLint viewport[2] = {0, 0};
    context.F().GetIntegerv(GL_MAX_VIEWPORT_DIMS, viewport);
    return {context.Integer(GL_MAX_TEXTURE_SIZE), context.Integer(GL_MAX_ARRAY_TEXTURE_LAYERS), viewport[0],
            viewport[1]};
}

std::vector<DeviceLimit> DescribeGLLimits(const GLLimits& limits) {
    // Every buffer is a 2-D texture array, a layer per z slice (an image's rows are its layers), and every pass
    // draws one slice in one viewport; shade's volume has a layer per slice along the sun's principal axis.
    return {
        {"GL_MAX_TEXTURE_SIZE", uint64_t(limits.textureSize),
         "grid nx and ny (nx + 2 and ny + 2 with render_march or render_layers) and render.width"},
        {"GL_MAX_ARRAY_TEXTURE_LAYERS", uint64_t(limits.arrayLayers),
         "grid nz (nz + 2 with render_march or render_layers), render.height, and with shade the grid's cells along "
         "the sun's principal axis"},
        {"GL_MAX_VIEWPORT_DIMS[0]", uint64_t(limits.viewportWidth),
         "grid nx and render.width (render.width + " + std::to_string(2 * kSplatGuardPixels) +
             " with render_splat)"},
        {"GL_MAX_VIEWPORT_DIMS[1]", uint64_t(limits.viewportHeight),
         "grid ny and render.height (render.height + " + std::to_string(2 * kSplatGuardPixels) +
             " with render_splat)"},
    };
}

namespace {

// The sun's principal axes (0 x, 1 y, 2 z) at the steps shade runs, as ShadeSunAt picks the sun
// (core/stages/shade/Shade.cpp): the first step's only when the sun stands still or a renderer relights.
std::array<bool, 3> ShadeAxes(const Scene& scene) {
    std::array<bool, 3> axes{};
    const bool fixed = !scene.sun.Moves() || scene.needs.shadeOnce;
    const uint32_t steps = fixed ? 1 : std::max<uint32_t>(scene.steps, 1);
    for (uint32_t step = 0; step < steps; ++step) axes[size_t(PrincipalAxis(scene.sun.DirectionAt(step)))] = true;
    return axes;
}

}  // namespace

std::optional<LimitExceeded> FindExceededGLLimit(const GLLimits& limits, const Scene& scene) {
    const Extent3 e = scene.grid.size;
    // `what` (`value`) past the limit `name` (`max`), because `why`.
    auto past = [](const char* field, const std::string& what, uint64_t value, const char* name, GLint max,
                   const std::string& why) -> std::optional<LimitExceeded> {
        if (value <= uint64_t(std::max(max, 0))) return std::nullopt;
        return LimitExceeded{field, "gl: " + what + " " + std::to_string(value) + " is more than this device's " +
                                        name + " " + std::to_string(max) + " (" + why + ")"};
    };
    const char* kGrid = "grid.size";
    std::optional<LimitExceeded> found;
    auto check = [&](std::optional<LimitExceeded> result) {
        if (!found) found = std::move(result);
    };
    const std::string buffer = "every grid buffer is a texture array";
    check(past(kGrid, "nx", e.nx, "GL_MAX_TEXTURE_SIZE", limits.textureSize, buffer + " nx texels wide"));
    check(past(kGrid, "ny", e.ny, "GL_MAX_TEXTURE_SIZE", limits.textureSize, buffer + " ny texels high"));
    check(past(kGrid, "nz", e.nz, "GL_MAX_ARRAY_TEXTURE_LAYERS", limits.arrayLayers,
               buffer + " with a layer per z slice"));
    const std::string slice = "a pass draws a z slice in one viewport";
    check(past(kGrid, "nx", e.nx, "GL_MAX_VIEWPORT_DIMS[0]", limits.viewportWidth, slice));
    check(past(kGrid, "ny", e.ny, "GL_MAX_VIEWPORT_DIMS[1]", limits.viewportHeight, slice));
    if (scene.stages.Has(Stage::Shade)) {
        const uint32_t f = uint32_t(std::max(scene.shade.resolution, 1));
        const std::array<bool, 3> axes = ShadeAxes(scene);
        const uint32_t n[3] = {e.nx, e.ny, e.nz};
        const char* names[3] = {"nx", "ny", "nz"};
        for (int axis = 0; axis < 3; ++axis)
            if (axes[size_t(axis)])
                check(past(kGrid, std::string(names[axis]) + (f > 1 ? " / shade.resolution" : ""),
                           CeilDiv(n[axis], f), "GL_MAX_ARRAY_TEXTURE_LAYERS", limits.arrayLayers,
                           std::string("shade keeps a texture array with a layer per slice along the sun's "
                                       "principal axis, ") +
                               "xyz"[axis] + " here"));
    }
    if (scene.stages.Has(Stage::RenderMarch) || scene.stages.Has(Stage::RenderLayers)) {
        const std::string padded = "render_march and render_layers read a volume padded by one voxel each side";
        check(past(kGrid, "nx + 2", uint64_t(e.nx) + 2, "GL_MAX_TEXTURE_SIZE", limits.textureSize, padded));
        check(past(kGrid, "ny + 2", uint64_t(e.ny) + 2, "GL_MAX_TEXTURE_SIZE", limits.textureSize, padded));
        check(past(kGrid, "nz + 2", uint64_t(e.nz) + 2, "GL_MAX_ARRAY_TEXTURE_LAYERS", limits.arrayLayers, padded));
    }
    if (scene.stages.Has(Stage::RenderSplat) || scene.stages.Has(Stage::RenderMarch) ||
        scene.stages.Has(Stage::RenderLayers)) {
        const uint32_t W = scene.render.width, H = scene.render.height;
        const std::string image = "an image is a texture array with a layer per row";
        check(past("render.width", "width", W, "GL_MAX_TEXTURE_SIZE", limits.textureSize, image));
        check(past("render.height", "height", H, "GL_MAX_ARRAY_TEXTURE_LAYERS", limits.arrayLayers, image));
        check(past("render.width", "width", W, "GL_MAX_VIEWPORT_DIMS[0]", limits.viewportWidth,
                   "a renderer draws the image in one viewport"));
        check(past("render.height", "height", H, "GL_MAX_VIEWPORT_DIMS[1]", limits.viewportHeight,
                   "a renderer draws the image in one viewport"));
        if (scene.stages.Has(Stage::RenderSplat)) {
            const uint32_t guard = 2 * uint32_t(kSplatGuardPixels);
            const std::string why =
                "render_splat's viewport reaches " + std::to_string(kSplatGuardPixels) + " pixels past each side";
            check(past("render.width", "width + " + std::to_string(guard), uint64_t(W) + guard,
                       "GL_MAX_VIEWPORT_DIMS[0]", limits.viewportWidth, why));
            check(past("render.height", "height + " + std::to_string(guard), uint64_t(H) + guard,
                       "GL_MAX_VIEWPORT_DIMS[1]", limits.viewportHeight, why));
        }
    }
    return found;
}

Result<std::unique_ptr<BackendGL>> BackendGL::Create(ContextKind context, CaLayout caLayout) {
    auto ctx = GLContext::Create(context);
    if (!ctx) return std::unexpected(ctx.error());
    return std::unique_ptr<BackendGL>(new BackendGL(std::move(*ctx), caLayout == CaLayout::Rgba8));
}

BackendGL::~BackendGL() {
    const Functions& f = mContext->F();
    if (!mAllQueries.empty()) f.DeleteQueries(GLsizei(mAllQueries.size()), mAllQueries.data());
    // The stage objects delete their textures and buffers after this, while the context is current.
}

// ---- Synchronisation, counted (Submissions) ----

void BackendGL::Finish() {
    if (mPending) ++mCounts.submissions;
    ++mCounts.hostWaits;
    mContext->F().Finish();
    mPending = false, mIdle = true;
}

void BackendGL::WaitingRead(ReadKind kind, GLuint object, GLenum format, GLenum type, size_t offset, size_t bytes,
                            void* data) {
    // GL runs commands in order: once the read returns, the work before it is
    // done (taken as idle, so reads right after a wait count no second wait).
    if (!mIdle) {
        if (mPending) ++mCounts.submissions;
        ++mCounts.hostWaits;
    }
    const Functions& f = mContext->F();
    switch (kind) {
        case ReadKind::Query:
            f.GetQueryObjectui64v(object, GL_QUERY_RESULT, static_cast<GLuint64*>(data));
            break;
        case ReadKind::Texture:
            f.PixelStorei(GL_PACK_ALIGNMENT, 1);
            f.GetTextureImage(object, 0, format, type, GLsizei(bytes), data);
            break;
        case ReadKind::Buffer:
            f.GetNamedBufferSubData(object, GLintptr(offset), GLsizeiptr(bytes), data);
            break;
    }
    mPending = false, mIdle = true;
}

GLuint BackendGL::AcquireQuery() {
    if (mFreeQueries.empty()) {
        GLuint queries[16] = {};
        mContext->F().GenQueries(16, queries);
        mFreeQueries.insert(mFreeQueries.end(), queries, queries + 16);
        mAllQueries.insert(mAllQueries.end(), queries, queries + 16);
    }
    const GLuint query = mFreeQueries.back();
    mFreeQueries.pop_back();
    return query;
}

BackendGL::Timing::Timing(BackendGL& backend) : mB(backend) {
    mB.Recorded();
    ++mB.mWriteEpoch;
    mStart = mB.AcquireQuery();
    mB.mContext->F().QueryCounter(mStart, GL_TIMESTAMP);
}

BackendGL::Timing::~Timing() {
    if (mStart) mB.ReleaseQuery(mStart);
}

void BackendGL::Timing::Stop() {
    if (!mStart) return;
    const GLuint end = mB.AcquireQuery();
    mB.mContext->F().QueryCounter(end, GL_TIMESTAMP);
    if (mB.mBatch.active) {
        mB.mBatch.pairs.push_back({mStart, end, mB.mBatch.interval});
        mB.mLastDeviceMs.reset();
    } else {
        mB.Finish();
        const GLuint64 t0 = mB.QueryResult(mStart), t1 = mB.QueryResult(end);
        mB.mLastDeviceMs = double(t1 - t0) * 1e-6;
        mB.ReleaseQuery(mStart);
        mB.ReleaseQuery(end);
    }
    mStart = 0;
}

Status BackendGL::BeginBatch() {
    if (mBatch.active) return MakeError("gl: BeginBatch inside a batch (batches do not nest)");
    mBatch = {};
    mBatch.active = true;
    mDeferredResults.clear();
    return {};
}

void BackendGL::MarkBatch() {
    if (mBatch.active) ++mBatch.interval;
}

Result<std::vector<double>> BackendGL::EndBatch() {
    if (!mBatch.active) return MakeError("gl: EndBatch without BeginBatch");
    Finish();
    std::vector<double> ms(size_t(mBatch.interval) + 1, 0.0);
    for (const BatchState::Pair& p : mBatch.pairs) {
        const GLuint64 t0 = QueryResult(p.start), t1 = QueryResult(p.end);
        ms[p.interval] += double(t1 - t0) * 1e-6;
        ReleaseQuery(p.start);
        ReleaseQuery(p.end);
    }
    // The deferred results: read after the wait above, so no read waits again.
    const Functions& f = mContext->F();
    for (const BatchState::Deferred& d : mBatch.deferred) {
        uint32_t counted[2] = {};
        WaitingRead(ReadKind::Buffer, d.counters, 0, 0, 0, sizeof counted, counted);
        DeferredHostResult result;
        result.mark = d.mark;
        if (d.cover) {
            result.coveredColumns = counted[0];
        } else {
            SplatStats stats;
            stats.splats = counted[0];
            stats.voxelsVisited = d.deviceSkip ? counted[1] : d.visited;
            if (d.fragments) {
                stats.fragments = QueryResult(d.fragments);
                f.DeleteQueries(1, &d.fragments);
            }
            result.frameCounters = ToFrameCounters(stats, kSplatCounters);
        }
        f.DeleteBuffers(1, &d.counters);
        mDeferredResults.push_back(result);
    }
    mBatch = {};
    CB_TRY(mContext->Check("ending a batch"));
    return ms;
}

void BackendGL::Draw(GLenum mode, GLint first, GLsizei count, GLsizei instances) {
    const Functions& f = mContext->F();
    if (instances == 1)
        f.DrawArrays(mode, first, count);
    else
        f.DrawArraysInstanced(mode, first, count, instances);
    ++mDraws;
}

void BackendGL::MultiDraw(GLenum mode, const GLint* firsts, const GLsizei* counts, GLsizei draws) {
    mContext->F().MultiDrawArrays(mode, firsts, counts, draws);
    ++mDraws;
}

void BackendGL::KeepImageCopy(const Buffer& image, const BufferSlot& copy, size_t bytes) {
    mImageCopy = {Tex(image).Texture(), copy.name.Get(), bytes, mWriteEpoch};
}

std::string BackendGL::Device() const {
    return mContext->Renderer() + (mStages.Get<CaGLState>().rgba8 ? ", automaton in RGBA8" : "");
}

GLuint BackendGL::Scratch(TextureSlot& t, GLenum target, GLenum format, GLsizei width, GLsizei height, GLsizei depth) {
    if (t.name.Get() && t.target == target && t.format == format && t.width == width && t.height == height &&
        t.depth == depth)
        return t.name.Get();
    const Functions& f = mContext->F();
    GLuint texture = 0;
    f.CreateTextures(target, 1, &texture);
    t.name.Reset(&f, texture);
    t.target = target, t.format = format, t.width = width, t.height = height, t.depth = depth;
    if (target == GL_TEXTURE_2D)
        f.TextureStorage2D(texture, 1, format, width, height);
    else
        f.TextureStorage3D(texture, 1, format, width, height, depth);
    f.TextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    f.TextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    return texture;
}

GLuint BackendGL::ScratchBuffer(BufferSlot& slot, size_t bytes) {
    bytes = std::max<size_t>(bytes, 16);
    if (slot.name.Get() && slot.bytes >= bytes) return slot.name.Get();
    const Functions& f = mContext->F();
    GLuint buffer = 0;
    f.CreateBuffers(1, &buffer);
    slot.name.Reset(&f, buffer);
    f.NamedBufferData(buffer, GLsizeiptr(bytes), nullptr, GL_DYNAMIC_DRAW);
    slot.bytes = bytes;
    return buffer;
}

GLuint BackendGL::CounterBuffer(BufferSlot& slot, size_t bytes) {
    if (!mBatch.active) return ScratchBuffer(slot, bytes);
    const Functions& f = mContext->F();
    GLuint buffer = 0;
    f.CreateBuffers(1, &buffer);
    const std::vector<uint8_t> zeros(std::max<size_t>(bytes, 16), 0);
    f.NamedBufferData(buffer, GLsizeiptr(zeros.size()), zeros.data(), GL_DYNAMIC_DRAW);
    return buffer;
}

Status BackendGL::BindTargets(std::span<const std::pair<GLuint, int>> targets) {
    const Functions& f = mContext->F();
    const GLuint framebuffer = mContext->Framebuffer();
    GLenum drawBuffers[4] = {};
    GLsizei n = 0;
    for (const auto& [texture, layer] : targets) {
        const GLenum attachment = GL_COLOR_ATTACHMENT0 + GLenum(n);
        if (layer < 0)
            f.NamedFramebufferTexture(framebuffer, attachment, texture, 0);
        else
            f.NamedFramebufferTextureLayer(framebuffer, attachment, texture, 0, layer);
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

Status BackendGL::DrawLayers(GLuint program, uint32_t layers, std::initializer_list<GLuint> textures) {
    return DrawLayerRange(program, 0, layers, textures);
}

Status BackendGL::DrawLayerRange(GLuint program, uint32_t begin, uint32_t end, std::initializer_list<GLuint> textures) {
    if (!IsLayered(program)) return DrawLayerRange(program, begin, end, textures, [](uint32_t) {});
    if (begin >= end) return {};
    std::array<std::pair<GLuint, int>, 4> targets;
    if (textures.size() > targets.size()) return MakeError("gl: a pass has more than 4 render targets");
    size_t n = 0;
    for (GLuint texture : textures) targets[n++] = {texture, -1};  // the whole array: a layered target
    CB_TRY(BindTargets(std::span(targets.data(), n)));
    const Functions& f = mContext->F();
    f.Uniform1i(f.GetUniformLocation(program, "layer0"), GLint(begin));
    Draw(GL_TRIANGLES, 0, 3, GLsizei(end - begin));
    return {};
}

Result<GLuint> BackendGL::PassProgram(const std::string& name, const std::string& defines) {
    if (Layered()) {
        if (auto layered = mContext->LayeredProgram(name, defines)) {
            if (!IsLayered(*layered)) mLayeredPrograms.push_back(*layered);
            return layered;
        }
        mLayeredFailed = true;  // this driver cannot: every pass draws per slice from now on
    }
    return mContext->Program(name, defines);
}

bool BackendGL::IsLayered(GLuint program) const {
    return std::find(mLayeredPrograms.begin(), mLayeredPrograms.end(), program) != mLayeredPrograms.end();
}

Result<std::unique_ptr<Buffer>> BackendGL::CreateBuffer(BufferFormat format, Extent3 extent) {
    if (extent.Count() == 0) return MakeError("gl: cannot create an empty buffer");
    const Functions& f = mContext->F();
    const TexelFormat t = FormatOf(format);
    const GLsizei width = GLsizei(format == BufferFormat::Bits ? (extent.nx + 31) / 32 : extent.nx);
    const GLint maxSize = mContext->Integer(GL_MAX_TEXTURE_SIZE),
                maxLayers = mContext->Integer(GL_MAX_ARRAY_TEXTURE_LAYERS);
    if (width > maxSize || extent.ny > uint32_t(maxSize) || extent.nz > uint32_t(maxLayers))
        return MakeError("gl: a buffer of extent (" + std::to_string(extent.nx) + ", " + std::to_string(extent.ny) +
                         ", " + std::to_string(extent.nz) + ") needs a " + std::to_string(width) + " x " +
                         std::to_string(extent.ny) + " texture with " + std::to_string(extent.nz) +
                         " layers; this driver allows " + std::to_string(maxSize) + " x " + std::to_string(maxSize) +
                         " with " + std::to_string(maxLayers) + " layers (an image's height is its layer count)");
    GLuint texture = 0;
    f.CreateTextures(GL_TEXTURE_2D_ARRAY, 1, &texture);
    f.TextureStorage3D(texture, 1, t.internal, width, GLsizei(extent.ny), GLsizei(extent.nz));
    f.TextureParameteri(texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    f.TextureParameteri(texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    ++mWriteEpoch;
    auto buffer = std::make_unique<BufferGL>(format, extent, f, texture);
    CB_TRY(mContext->Check("creating a texture"));
    return std::unique_ptr<Buffer>(std::move(buffer));
}

uint64_t BackendGL::BufferBytes(BufferFormat format, const Extent3& extent) const {
    if (format == BufferFormat::Bits) return Extent3{CeilDiv(extent.nx, 32), extent.ny, extent.nz}.Count() * 4;
    return CanonicalBufferBytes(format, extent);
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
    ++mWriteEpoch;
    Recorded();
    f.TextureSubImage3D(b.Texture(), 0, 0, 0, 0, GLsizei(b.Width()), GLsizei(e.ny), GLsizei(e.nz), t.format, t.type,
                        data);
    return mContext->Check("uploading a texture");
}

Status BackendGL::Download(const Buffer& buffer, std::span<std::byte> canonical) {
    if (canonical.size() != buffer.CanonicalBytes()) return MakeError("gl: download size does not match the buffer");
    const BufferGL& b = Tex(buffer);
    const Extent3 e = b.Extent();
    const TexelFormat t = FormatOf(b.Format());
    // A renderer's image still in its pixel buffer: only the copy out of it.
    const ImageCopy& kept = mImageCopy;
    if (kept.texture == b.Texture() && kept.epoch == mWriteEpoch && kept.bytes == canonical.size()) {
        WaitingRead(ReadKind::Buffer, kept.buffer, 0, 0, 0, canonical.size(), canonical.data());
        return mContext->Check("downloading an image from its pixel buffer");
    }
    if (b.Format() != BufferFormat::Bits) {
        WaitingRead(ReadKind::Texture, b.Texture(), t.format, t.type, 0, canonical.size(), canonical.data());
        return mContext->Check("downloading a texture");
    }
    std::vector<uint32_t> packed(size_t(b.Width()) * e.ny * e.nz);
    WaitingRead(ReadKind::Texture, b.Texture(), t.format, t.type, 0, packed.size() * 4, packed.data());
    CB_TRY(mContext->Check("downloading a texture"));
    UnpackBits32(packed, e, canonical);
    return {};
}

}  // namespace cb::gl
