#include <vector>

#include "core/math/Splat.h"
#include "core/pipeline/SplatFrame.h"
#include "impl_gl/BackendGL.h"
#include "impl_gl/RenderSplatGLState.h"

namespace cb::gl {

uint64_t RenderSplatGLState::ScratchBytes(const Scene& scene) const {
    uint64_t bytes = uint64_t(scene.render.width) * scene.render.height * 16;
    if (scene.phase.kind == PhaseKind::Mie) bytes += uint64_t(kMieCloudTable.count) * 4;
    return bytes;
}

// render_splat: GL_POINTS in the shared order, one vertex per voxel; culling
// and skipping become a multi-draw over the runs of ranks whose tile x band
// box is visible. The RGBA32F target is drawn with row 0 at the top, so one
// read into a pixel buffer and one upload from it give the canonical (3, W, H) image.
Status BackendGL::RenderSplat(const SplatParams& p, const SplatInputs& in, Buffer& image, SplatStats* stats) {
    RenderSplatGLState& state = mStages.Get<RenderSplatGLState>();
    if (!p.order || !in.qPrev || !in.qCur || !in.T)
        return MakeError("gl: render_splat needs q (both steps), T and an order");
    if (image.Extent().nx != 3) return MakeError("gl: render_splat image must have extent (3, width, height)");
    const Functions& f = mContext->F();
    auto program = mContext->Program("splat");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = in.qCur->Extent();
    const uint32_t W = image.Extent().ny, H = image.Extent().nz;
    const bool skyLight = p.light.skyOn;
    if (skyLight && (!in.TSky || in.TSky->Extent() != e))
        return MakeError("gl: render_splat: the sky light needs T_sky of q's size");
    CB_TRY(CheckGroundInput(p.ground, in.G, e, "gl: render_splat"));
    Result<GLuint> groundProgram = GLuint(0);
    if (p.ground.on) {
        groundProgram = mContext->Program("ground");
        if (!groundProgram) return std::unexpected(groundProgram.error());
    }

    // In a batch, empty boxes may be skipped in the vertex shader, which reads
    // the bands on the device, instead of by runs the host derives from the
    // bands read back: no host wait (SetSplatSkip). The frustum's boxes stay
    // host runs (camera data).
    const bool deviceSkip = mBatch.active && p.skipping && SplatSkipOnDevice();
    Result<std::vector<uint8_t>> visibility = std::vector<uint8_t>{};
    if (deviceSkip) {
        if (!in.bandsPrev || !in.bandsCur)
            return MakeError("gl: render_splat with skipping needs both steps' occupancy");
        SplatParams culled = p;
        culled.skipping = false;
        visibility = SplatBoxVisibility(culled, e, {}, {});
    } else {
        visibility = DownloadSplatBoxVisibility(*this, p, in);
    }
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
                const uint32_t base =
                    (o / boxSize[outer]) * boxStride[outer] + (m / boxSize[middle]) * boxStride[middle];
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
    constexpr float kGuard = kSplatGuardPixels;

    Timing timer(*this);
    const GLuint orderBuffer = ScratchBuffer(state.order, flat.indices.size() * 4);
    f.NamedBufferSubData(orderBuffer, 0, GLsizeiptr(flat.indices.size() * 4), flat.indices.data());
    // The shared frame; this backend's lane: the largest point size.
    SplatFrame frame = MakeSplatFrame(p, e, flat, W, H);
    frame.maxPointSize = pointRange[1];
    const GLuint frameBuffer = ScratchBuffer(state.frame, sizeof frame);
    f.NamedBufferSubData(frameBuffer, 0, sizeof frame, &frame);
    const GLuint counters = CounterBuffer(state.counters, 16);
    const uint32_t zero[4] = {};
    f.NamedBufferSubData(counters, 0, sizeof zero, zero);
    const GLuint target = Scratch(state.target, GL_TEXTURE_2D, GL_RGBA32F, GLsizei(W), GLsizei(H));
    CB_TRY(BindTargets({{target, -1}}));
    f.BindVertexArray(mContext->EmptyVao());
    if (p.ground.on) {
        // The ground pass (ground.frag): each pixel's background, which the splats then blend over.
        const GroundGpu block = MakeGroundGpu(p.camera, p.origin, p.voxelSize, MakeGroundLight(p), e.nx, e.ny);
        const GLuint groundBuffer = ScratchBuffer(state.ground, sizeof block);
        f.NamedBufferSubData(groundBuffer, 0, sizeof block, &block);
        f.UseProgram(*groundProgram);
        f.BindBufferBase(GL_UNIFORM_BUFFER, 1, groundBuffer);
        f.BindTextureUnit(3, Tex(*in.G).Texture());
        f.Viewport(0, 0, GLsizei(W), GLsizei(H));
        Draw(GL_TRIANGLES, 0, 3);
    } else {
        const float background[4] = {p.background[0], p.background[1], p.background[2], 1};
        f.ClearNamedFramebufferfv(mContext->Framebuffer(), GL_COLOR, 0, background);
    }
    f.UseProgram(*program);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, orderBuffer);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, counters);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, frameBuffer);
    // splat.vert's phase table: kMieCloudTable with phase Mie; else the frame stands in, unread.
    const GLuint phaseTable =
        p.light.phase.kind == PhaseKind::Mie ? MiePhaseTable(state.phaseTable, state.mieUploaded) : frameBuffer;
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, phaseTable);
    f.BindTextureUnit(0, Tex(*in.qPrev).Texture());
    f.BindTextureUnit(1, Tex(*in.qCur).Texture());
    f.BindTextureUnit(2, Tex(*in.T).Texture());
    f.BindTextureUnit(6, Tex(skyLight ? *in.TSky : *in.T).Texture());  // T stands in, unread, without the sky light
    f.Uniform1f(f.GetUniformLocation(*program, "guard"), kGuard);
    f.Uniform1i(f.GetUniformLocation(*program, "deviceSkip"), deviceSkip ? 1 : 0);
    f.Uniform2i(f.GetUniformLocation(*program, "tileBand"), GLint(p.tile), GLint(p.band));
    f.BindTextureUnit(4, deviceSkip ? Tex(*in.bandsPrev).Texture() : 0);
    f.BindTextureUnit(5, deviceSkip ? Tex(*in.bandsCur).Texture() : 0);
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
    if (!firsts.empty()) MultiDraw(GL_POINTS, firsts.data(), counts.data(), GLsizei(firsts.size()));
    if (stats) f.EndQuery(GL_SAMPLES_PASSED);
    f.Disable(GL_BLEND);
    f.Disable(GL_PROGRAM_POINT_SIZE);
    f.BindTextureUnit(4, 0);
    f.BindTextureUnit(5, 0);
    CopyTargetToImage(target, W, H, state.imageCopy, image);
    timer.Stop();
    if (mBatch.active) {  // read after EndBatch's wait (TakeDeferredResults); the buffer is this call's own
        if (stats)
            mBatch.deferred.push_back({mBatch.interval, counters, fragments, false, deviceSkip, visited});
        else
            mContext->F().DeleteBuffers(1, &counters);
        return mContext->Check("render_splat");
    }
    if (stats) {
        const GLuint64 passed = QueryResult(fragments);
        f.DeleteQueries(1, &fragments);
        uint32_t counted[2] = {};  // splats drawn, voxels visited (deviceSkip)
        WaitingRead(ReadKind::Buffer, counters, 0, 0, 0, sizeof counted, counted);
        stats->splats = counted[0];
        stats->voxelsVisited = deviceSkip ? counted[1] : visited;
        stats->fragments = passed;
    }
    return mContext->Check("render_splat");
}

void BackendGL::CopyTargetToImage(GLuint target, uint32_t W, uint32_t H, BufferSlot& copySlot, Buffer& image) {
    const Functions& f = mContext->F();
    const size_t imageBytes = size_t(W) * H * 3 * sizeof(float);
    const GLuint copy = ScratchBuffer(copySlot, imageBytes);
    f.MemoryBarrier(GL_PIXEL_BUFFER_BARRIER_BIT);
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, copy);
    f.PixelStorei(GL_PACK_ALIGNMENT, 1);
    f.GetTextureImage(target, 0, GL_RGB, GL_FLOAT, GLsizei(imageBytes), nullptr);
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    f.BindBuffer(GL_PIXEL_UNPACK_BUFFER, copy);
    f.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
    f.TextureSubImage3D(Tex(image).Texture(), 0, 0, 0, 0, 3, GLsizei(W), GLsizei(H), GL_RED, GL_FLOAT, nullptr);
    f.BindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    // The pixel buffer keeps the canonical image: a Download reads it without a texture read back.
    KeepImageCopy(image, copySlot, imageBytes);
}

}  // namespace cb::gl
