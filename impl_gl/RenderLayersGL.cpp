// Stage `render_layers` (SPEC 15) on OpenGL, Wang, Ji and Zhang's way:
//   1. march_volume: the padded (q_alpha, T) volume (render_march's step 1 with
//      `wrap` under tiling), copied on the device into a storage buffer; with the
//      sky light march_sky_volume likewise forms T_sky's into a storage buffer of its own;
//   2. one screen quad drawn instanced N times (render_layers.vert: instance n
//      is the n-th layer back to front, cut by a clip distance to the side of
//      the horizon the layer lies on), blended SRC_ALPHA, ONE_MINUS_SRC_ALPHA over
//      the background; each fragment is LayerFragment of core/math/layers.glsl on
//      its pixel's ray (render_layers.frag), the counters by storage-buffer atomics;
//   3. with LOD0, the same program built with LAYERS_BILLBOARDS: one quad instanced per
//      billboard, back to front, each fragment BillboardFragment on its pixel's ray.
// The RGBA32F target's rows come back top row first and pass through a pixel
// buffer into the (3, width, height) image, as render_march's.
#include <vector>

#include "core/pipeline/LayersGpu.h"
#include "impl_gl/BackendGL.h"
#include "impl_gl/RenderLayersGLState.h"

namespace cb::gl {

uint64_t RenderLayersGLState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    const uint64_t padded = uint64_t(e.nx + 2) * (e.ny + 2) * (e.nz + 2);
    uint64_t bytes = 2 * padded * 8;
    if (scene.lighting.sky.on) bytes += 2 * padded * 4;
    bytes += uint64_t(scene.render.width) * scene.render.height * (16 + 12);
    if (scene.phase.kind == PhaseKind::Mie) bytes += uint64_t(kMieCloudTable.count) * 4;
    if (scene.layers.wang.enabled) bytes += uint64_t(scene.grid.size.nx) * scene.grid.size.ny * 4;
    bytes += uint64_t(LayersBillboardBound(scene.layers, scene.grid.voxelSize, scene.grid.size.nz)) *
             sizeof(LayersBillboard);
    return bytes;
}

Status BackendGL::RenderLayers(const LayersParams& params, const LayersInputs& in, Buffer& image, LayersStats* stats) {
    RenderLayersGLState& state = mStages.Get<RenderLayersGLState>();
    if (!in.qPrev || !in.qCur || !in.T) return MakeError("gl: render_layers needs q and T");
    const Extent3 e = in.qCur->Extent();
    if (in.qPrev->Extent() != e || in.T->Extent() != e)
        return MakeError("gl: render_layers: q_prev, q_cur and T differ in size");
    const uint32_t W = params.camera.width, H = params.camera.height;
    if (image.Extent() != Extent3{3, W, H}) return MakeError("gl: render_layers: the image is not (3, width, height)");
    if (params.setup.wang && !params.setup.map) return MakeError("gl: render_layers: wang opacity needs its map");
    const bool skyLight = params.setup.light.skyOn;
    if (skyLight && (!in.TSky || in.TSky->Extent() != e))
        return MakeError("gl: render_layers: the sky light needs T_sky of q's size");
    const Functions& f = mContext->F();
    auto layersProgram = mContext->Program("render_layers");
    if (!layersProgram) return std::unexpected(layersProgram.error());
    CB_TRY(CheckPaddedVolumeFits(e, "render_layers"));
    const std::vector<LayersBillboard> billboards = MakeLayersBillboards(params.setup, params.camera.forward);
    Result<GLuint> billboardProgram = GLuint(0);
    if (!billboards.empty()) billboardProgram = mContext->Program("render_layers", "#define LAYERS_BILLBOARDS 1\n");
    if (!billboardProgram) return std::unexpected(billboardProgram.error());
    const LayersGpu block = MakeLayersGpu(params, uint32_t(billboards.size()));
    const std::vector<uint32_t> order = LayersDrawOrder(params.setup);

    Timing timer(*this);
    f.BindVertexArray(mContext->EmptyVao());
    const GLuint counters = ScratchBuffer(state.counters, 4 * 4);
    const uint32_t zero[4] = {};
    f.NamedBufferSubData(counters, 0, sizeof zero, zero);

    // 1. The padded (q_alpha, T) volume.
    auto volumeCopy =
        FormPaddedVolume(state.volume, state.volumeCopy, *in.qPrev, *in.qCur, in.T, params.alpha, params.setup.tiling);
    if (!volumeCopy) return std::unexpected(volumeCopy.error());
    GLuint skyVolumeCopy = *volumeCopy;  // bound to the unused binding without the sky light
    if (skyLight) {
        auto skyFormed = FormPaddedSkyVolume(state.skyVolume, state.skyVolumeCopy, *in.TSky, params.setup.tiling);
        if (!skyFormed) return std::unexpected(skyFormed.error());
        skyVolumeCopy = *skyFormed;
    }
    f.MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);

    // 2. The layers, instanced, back to front over the background.
    GLuint phaseTable = *volumeCopy;  // bound to the unused binding unless the phase is Mie
    if (params.setup.light.phase.kind == PhaseKind::Mie)
        phaseTable = MiePhaseTable(state.phaseTable, state.mieUploaded);
    const GLuint blockBuffer = ScratchBuffer(state.block, sizeof block);
    f.NamedBufferSubData(blockBuffer, 0, sizeof block, &block);
    const GLuint orderBuffer = ScratchBuffer(state.order, order.size() * 4);
    f.NamedBufferSubData(orderBuffer, 0, GLsizeiptr(order.size() * 4), order.data());
    const GLuint target = Scratch(state.target, GL_TEXTURE_2D, GL_RGBA32F, GLsizei(W), GLsizei(H));
    CB_TRY(BindTargets({{target, -1}}));
    const LayersSetup& s = params.setup;
    const float background[4] = {s.background[0], s.background[1], s.background[2], 1};
    f.ClearNamedFramebufferfv(mContext->Framebuffer(), GL_COLOR, 0, background);
    f.UseProgram(*layersProgram);
    f.BindBufferBase(GL_UNIFORM_BUFFER, 0, blockBuffer);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, orderBuffer);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, *volumeCopy);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, phaseTable);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, counters);
    GLuint map = *volumeCopy;  // likewise unless the opacity is wang
    if (s.wang) {
        const size_t bytes = size_t(e.nx) * e.ny * 4;
        map = ScratchBuffer(state.map, bytes);
        f.NamedBufferSubData(map, 0, GLsizeiptr(bytes), s.map);
    }
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, map);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 7, skyVolumeCopy);
    f.Enable(GL_BLEND);
    f.BlendEquation(GL_FUNC_ADD);
    f.BlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    f.Viewport(0, 0, GLsizei(W), GLsizei(H));
    f.Enable(GL_CLIP_DISTANCE0);
    Draw(GL_TRIANGLE_STRIP, 0, 4, GLsizei(s.count));
    f.Disable(GL_CLIP_DISTANCE0);
    // 3. LOD0's billboards over the layers, back to front: one quad instanced per billboard.
    if (!billboards.empty()) {
        const size_t bytes = billboards.size() * sizeof(LayersBillboard);
        const GLuint list = ScratchBuffer(state.billboards, bytes);
        f.NamedBufferSubData(list, 0, GLsizeiptr(bytes), billboards.data());
        f.UseProgram(*billboardProgram);
        f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 6, list);
        Draw(GL_TRIANGLE_STRIP, 0, 4, GLsizei(billboards.size()));
    }
    f.Disable(GL_BLEND);

    CopyTargetToImage(target, W, H, state.imageCopy, image);
    timer.Stop();
    if (stats) {
        f.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        uint32_t words[4] = {};
        WaitingRead(ReadKind::Buffer, counters, 0, 0, 0, sizeof words, words);
        const auto wide = [&words](int n) { return uint64_t(words[2 * n]) | uint64_t(words[2 * n + 1]) << 32; };
        *stats = {wide(0), wide(1)};
    }
    return mContext->Check("render_layers");
}

}  // namespace cb::gl
