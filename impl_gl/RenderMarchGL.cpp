// Stage `render_march` (SPEC 10) on OpenGL, the thesis's way: fragment passes.
//   1. march_volume: the padded (q_alpha, T) volume, one pass per padded layer
//      into the RG32F layers of `volume` (border (0, 1); T only with light
//      "shade", else 1), copied on the device into a storage buffer; with the
//      sky light march_sky_volume likewise forms T_sky's (border 1) into
//      `skyVolume`'s R32F layers and its own storage buffer.
//   2. march_bricks (skipping only): the bricks' empty flags, one pass per
//      brick layer into R32UI layers, copied likewise; counts the empty ones.
//   3. render_march: the full-screen triangle over the image, one fragment per
//      pixel, MarchPixel of core/math/march.glsl with the MarchGpu block
//      (core/pipeline/MarchGpu.h) as a std140 uniform block, in a program specialised
//      for the call's option bits and phase kind (linked on first use of each
//      combination, then cached), and the Mie table (uploaded
//      once, only for phase mie) as a storage buffer; the counters of
//      MarchStats by storage-buffer atomics.
// The RGBA32F target's rows come back top row first (see render_march.frag)
// and pass through a pixel buffer into the (3, width, height) image.
#include <algorithm>
#include <string>

#include "core/math/Shading.h"
#include "core/pipeline/MarchGpu.h"
#include "impl_gl/BackendGL.h"
#include "impl_gl/RenderMarchGLState.h"

namespace cb::gl {

uint64_t RenderMarchGLState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    const uint64_t padded = uint64_t(e.nx + 2) * (e.ny + 2) * (e.nz + 2);
    uint64_t bytes = 2 * padded * 8;
    if (scene.lighting.sky.on) bytes += 2 * padded * 4;
    if (scene.march.skipping) {
        const uint32_t b = std::max(scene.march.brick, 1u);
        bytes += 2 * uint64_t(CeilDiv(e.nx, b)) * CeilDiv(e.ny, b) * CeilDiv(e.nz, b) * 4;
    }
    bytes += uint64_t(scene.render.width) * scene.render.height * (16 + 12);
    if (scene.phase.kind == PhaseKind::Mie) bytes += uint64_t(kMieCloudTable.count) * 4;
    return bytes;
}

Status BackendGL::RenderMarch(const MarchParams& params, const MarchInputs& in, Buffer& image, MarchStats* stats) {
    RenderMarchGLState& state = mStages.Get<RenderMarchGLState>();
    if (!in.qPrev || !in.qCur) return MakeError("gl: render_march needs q");
    if (!params.reprojection.full)
        return MakeError(
            "gl: render_march: temporal reprojection (march.reprojection.block > 1) is implemented on "
            "the cpu backend only so far");
    const Extent3 e = in.qCur->Extent();
    if (in.qPrev->Extent() != e) return MakeError("gl: render_march: q_prev and q_cur differ in size");
    const bool shadeLight = params.light == MarchLightSource::Shade;
    if (shadeLight && !in.T) return MakeError("gl: render_march: light source \"shade\" needs T");
    if (shadeLight && in.T->Extent() != e) return MakeError("gl: render_march: T and q differ in size");
    const bool skyLight = params.setup.light.skyOn;
    if (skyLight && (!in.TSky || in.TSky->Extent() != e))
        return MakeError("gl: render_march: the sky light needs T_sky of q's size");
    const uint32_t W = params.camera.width, H = params.camera.height;
    if (image.Extent() != Extent3{3, W, H}) return MakeError("gl: render_march: the image is not (3, width, height)");
    const Functions& f = mContext->F();
    CB_TRY(CheckGroundInput(params.ground, in.G, e, "gl: render_march"));
    const MarchGpu block = MakeMarchGpu(params, e);
    // The program specialised for this call's option bits, phase kind, point light and sky light
    // (render_march.frag).
    auto marchProgram =
        mContext->Program("render_march", "#define MARCH_FLAGS " + std::to_string(block.flags) +
                                              "u\n#define MARCH_PHASE " + std::to_string(block.light.phaseKind) +
                                              "u\n#define MARCH_POINT " + std::to_string(block.light.pointOn) +
                                              "u\n#define MARCH_SKY " + std::to_string(block.light.skyOn) + "u\n");
    if (!marchProgram) return std::unexpected(marchProgram.error());
    Result<GLuint> bricksProgram = GLuint(0);
    if (params.skipping) {
        bricksProgram = PassProgram("march_bricks");
        if (!bricksProgram) return std::unexpected(bricksProgram.error());
    }

    const GLsizei px = GLsizei(e.nx + 2), py = GLsizei(e.ny + 2), pz = GLsizei(e.nz + 2);
    CB_TRY(CheckPaddedVolumeFits(e, "render_march"));
    const uint32_t B = block.brick;
    const auto brickCounts = MarchBrickCounts(e, B);

    Timing timer(*this);
    f.BindVertexArray(mContext->EmptyVao());
    const GLuint counters = ScratchBuffer(state.counters, 9 * 4);
    const uint32_t zero[9] = {};
    f.NamedBufferSubData(counters, 0, sizeof zero, zero);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, counters);

    // 1. The padded (q_alpha, T) volume.
    auto formed = FormPaddedVolume(state.volume, state.volumeCopy, *in.qPrev, *in.qCur, shadeLight ? in.T : nullptr,
                                   params.alpha, params.setup.tiling);
    if (!formed) return std::unexpected(formed.error());
    const GLuint volume = state.volume.name.Get(), volumeCopy = *formed;
    GLuint skyVolumeCopy = volumeCopy;  // bound to the unused binding without the sky light
    if (skyLight) {
        auto skyFormed = FormPaddedSkyVolume(state.skyVolume, state.skyVolumeCopy, *in.TSky, params.setup.tiling);
        if (!skyFormed) return std::unexpected(skyFormed.error());
        skyVolumeCopy = *skyFormed;
    }

    // 2. The bricks: empty iff q_alpha = 0 over the brick grown by one voxel.
    GLuint bricksCopy = volumeCopy;  // bound to the unused binding without skipping
    if (params.skipping) {
        const GLsizei bx = GLsizei(brickCounts[0]), by = GLsizei(brickCounts[1]), bz = GLsizei(brickCounts[2]);
        const size_t brickBytes = size_t(bx) * size_t(by) * size_t(bz) * 4;
        const GLuint bricks = Scratch(state.bricks, GL_TEXTURE_2D_ARRAY, GL_R32UI, bx, by, bz);
        f.UseProgram(*bricksProgram);
        f.BindTextureUnit(0, volume);
        f.Uniform1i(f.GetUniformLocation(*bricksProgram, "brick"), GLint(B));
        f.Uniform3i(f.GetUniformLocation(*bricksProgram, "padded"), px, py, pz);
        f.Viewport(0, 0, bx, by);
        CB_TRY(DrawLayers(*bricksProgram, uint32_t(bz), {bricks}));
        bricksCopy = ScratchBuffer(state.bricksCopy, brickBytes);
        f.BindBuffer(GL_PIXEL_PACK_BUFFER, bricksCopy);
        f.GetTextureImage(bricks, 0, GL_RED_INTEGER, GL_UNSIGNED_INT, GLsizei(brickBytes), nullptr);
        f.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        f.MemoryBarrier(GL_SHADER_STORAGE_BARRIER_BIT);
    }

    // 3. The rays.
    GLuint phaseTable = volumeCopy;  // bound to the unused binding unless the phase is Mie
    if (params.setup.light.phase.kind == PhaseKind::Mie)
        phaseTable = MiePhaseTable(state.phaseTable, state.mieUploaded);
    const GLuint blockBuffer = ScratchBuffer(state.block, sizeof block);
    f.NamedBufferSubData(blockBuffer, 0, sizeof block, &block);
    const GLuint target = Scratch(state.target, GL_TEXTURE_2D, GL_RGBA32F, GLsizei(W), GLsizei(H));
    CB_TRY(BindTargets({{target, -1}}));
    f.UseProgram(*marchProgram);
    f.BindBufferBase(GL_UNIFORM_BUFFER, 0, blockBuffer);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, volumeCopy);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bricksCopy);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, phaseTable);
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, skyVolumeCopy);
    // The ground's block and G (flag kMarchGpuGround); without the ground, stand-ins the program never reads.
    GLuint groundBuffer = blockBuffer;
    if (params.ground.on) {
        const GroundGpu ground = MakeGroundGpu(params.camera, params.origin, params.setup.voxelSize,
                                               MakeGroundLight(params), e.nx, e.ny);
        groundBuffer = ScratchBuffer(state.ground, sizeof ground);
        f.NamedBufferSubData(groundBuffer, 0, sizeof ground, &ground);
    }
    f.BindBufferBase(GL_UNIFORM_BUFFER, 1, groundBuffer);
    f.BindTextureUnit(3, Tex(params.ground.on ? *in.G : *in.qCur).Texture());
    f.Viewport(0, 0, GLsizei(W), GLsizei(H));
    Draw(GL_TRIANGLES, 0, 3);

    CopyTargetToImage(target, W, H, state.imageCopy, image);
    timer.Stop();
    if (stats) {
        f.MemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
        uint32_t words[9] = {};
        WaitingRead(ReadKind::Buffer, counters, 0, 0, 0, sizeof words, words);
        const auto wide = [&words](int n) { return uint64_t(words[2 * n]) | uint64_t(words[2 * n + 1]) << 32; };
        *stats = {};
        stats->rays = wide(0);
        stats->samples = wide(1);
        stats->lightSamples = wide(2);
        stats->bricksSkipped = wide(3);
        if (params.skipping) {
            stats->bricks = uint64_t(brickCounts[0]) * brickCounts[1] * brickCounts[2];
            stats->emptyBricks = words[8];
        }
    }
    return mContext->Check("render_march");
}

}  // namespace cb::gl
