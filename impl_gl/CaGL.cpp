#include <algorithm>
#include <array>
#include <utility>

#include "impl_gl/BackendGL.h"
#include "impl_gl/CaGLState.h"

namespace cb::gl {

uint64_t CaGLState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    uint64_t bytes = 0;
    if (scene.ca.HasWind()) bytes += 3 * Extent3{CeilDiv(e.nx, 32), e.ny, e.nz}.Count() * 4;  // R32UI words
    if (rgba8) bytes += 2 * e.Count() * 4;
    return bytes;
}

Status BackendGL::CaInitialize(const CaInitParams& params, CaFields out) {
    const Functions& f = mContext->F();
    auto program = PassProgram("ca_init");
    if (!program) return std::unexpected(program.error());
    const Extent3 e = out.hum->Extent();
    Timing timer(*this);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.Uniform3i(f.GetUniformLocation(*program, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform1ui(f.GetUniformLocation(*program, "seed"), params.seed);
    f.Uniform1ui(f.GetUniformLocation(*program, "qHum0"), params.qHum0);
    f.Uniform1ui(f.GetUniformLocation(*program, "qAct0"), params.qAct0);
    f.Viewport(0, 0, GLsizei(CeilDiv(e.nx, 32)), GLsizei(e.ny));
    CB_TRY(DrawLayers(*program, e.nz, {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()}));
    ++mBitsWrites;
    timer.Stop();
    return mContext->Check("ca initial state");
}

Status BackendGL::CaStep(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    CaGLState& ca = mStages.Get<CaGLState>();
    if (ca.rgba8)
        return params.slices.IsWhole(in.hum->Extent().nz) ? CaStepRgba8(params, in, region, out)
                                                          : CaStepRgba8Share(params, in, region, out);
    const Functions& f = mContext->F();
    auto rules = PassProgram("ca");
    if (!rules) return std::unexpected(rules.error());
    auto advect = mContext->Program("advect");
    if (!advect) return std::unexpected(advect.error());
    const Extent3 e = in.hum->Extent();
    const uint32_t k0 = params.slices.Begin(e.nz), k1 = params.slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const GLsizei words = GLsizei(CeilDiv(e.nx, 32));
    const bool wind = !params.shiftX.empty();
    // With wind the rules write scratch fields that the advection pass shifts into `out`.
    GLuint next[3] = {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()};
    if (wind) {
        next[0] = Scratch(ca.rulesHum, GL_TEXTURE_2D_ARRAY, GL_R32UI, words, GLsizei(e.ny), GLsizei(e.nz));
        next[1] = Scratch(ca.rulesAct, GL_TEXTURE_2D_ARRAY, GL_R32UI, words, GLsizei(e.ny), GLsizei(e.nz));
        next[2] = Scratch(ca.rulesCld, GL_TEXTURE_2D_ARRAY, GL_R32UI, words, GLsizei(e.ny), GLsizei(e.nz));
    }
    Timing timer(*this);
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
    CB_TRY(DrawLayerRange(*rules, k0, k1, {next[0], next[1], next[2]}));
    if (wind) {
        f.UseProgram(*advect);
        for (int n = 0; n < 3; ++n) f.BindTextureUnit(GLuint(n), next[n]);
        f.Uniform3i(f.GetUniformLocation(*advect, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        f.Uniform1i(f.GetUniformLocation(*advect, "words"), words);
        const GLint shift = f.GetUniformLocation(*advect, "shift");
        CB_TRY(DrawLayerRange(*advect, k0, k1,
                              {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()},
                              [&](uint32_t k) { f.Uniform2i(shift, params.shiftX[k], params.shiftY[k]); }));
    }
    ++mBitsWrites;
    timer.Stop();
    return mContext->Check("ca");
}

// The thesis's layout: the step runs on RGBA8UI voxels (stateA -> stateB,
// and back to stateA through the advection pass when there is wind), then the
// packed fields the other stages read are written from it. The packing of
// `in` is skipped when stateA already holds it (the previous step's result).
Status BackendGL::CaStepRgba8(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    CaGLState& ca = mStages.Get<CaGLState>();
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
    const GLuint stateA = Scratch(ca.stateA, GL_TEXTURE_2D_ARRAY, GL_RGBA8UI, nx, ny, nz);
    const GLuint stateB = Scratch(ca.stateB, GL_TEXTURE_2D_ARRAY, GL_RGBA8UI, nx, ny, nz);
    const std::array<GLuint, 3> inputs = {Tex(*in.hum).Texture(), Tex(*in.act).Texture(), Tex(*in.cld).Texture()};
    const bool packed = ca.stateOf == inputs && ca.stateWrites == mBitsWrites;
    const bool wind = !params.shiftX.empty();
    ca.share = {};  // this call rewrites stateA
    Timing timer(*this);
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
    // Without wind the result is in stateB: swap the slots so stateA holds it.
    if (result == stateB) ca.stateA.Swap(ca.stateB);
    ca.stateOf = {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()};
    ca.stateWrites = mBitsWrites;
    timer.Stop();
    return mContext->Check("ca (RGBA8 layout)");
}

// A share [k0, k1) of a step in the thesis's layout. The rules read act at
// k - 2 .. k + 1, so the share needs `in` in stateA for slices
// [k0 - 2, k1 + 1); it packs only those a preceding share (ca.share) or the
// previous step (ca.stateOf) did not leave there. stateA is not written: the
// rules go to stateB and are unpacked from there, with wind through a
// shifted unpacking that folds in the advection. Without wind, the share that
// ends a complete ascending sequence leaves the step's state in stateA as
// the whole call does; with wind the next step packs its input again.
Status BackendGL::CaStepRgba8Share(const CaStepParams& params, ConstCaFields in, const Buffer& region, CaFields out) {
    CaGLState& ca = mStages.Get<CaGLState>();
    const Functions& f = mContext->F();
    const bool wind = !params.shiftX.empty();
    auto pack = mContext->Program("ca_pack_rgba8");
    if (!pack) return std::unexpected(pack.error());
    auto rules = mContext->Program("ca_rgba8");
    if (!rules) return std::unexpected(rules.error());
    auto unpack =
        wind ? mContext->Program("ca_unpack_rgba8", "#define SHIFTED 1\n") : mContext->Program("ca_unpack_rgba8");
    if (!unpack) return std::unexpected(unpack.error());
    const Extent3 e = in.hum->Extent();
    const uint32_t k0 = params.slices.Begin(e.nz), k1 = params.slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const GLsizei nx = GLsizei(e.nx), ny = GLsizei(e.ny), nz = GLsizei(e.nz);
    const GLuint stateA = Scratch(ca.stateA, GL_TEXTURE_2D_ARRAY, GL_RGBA8UI, nx, ny, nz);
    const GLuint stateB = Scratch(ca.stateB, GL_TEXTURE_2D_ARRAY, GL_RGBA8UI, nx, ny, nz);
    const std::array<GLuint, 3> inputs = {Tex(*in.hum).Texture(), Tex(*in.act).Texture(), Tex(*in.cld).Texture()};
    const std::array<GLuint, 3> outputs = {Tex(*out.hum).Texture(), Tex(*out.act).Texture(), Tex(*out.cld).Texture()};
    // What stateA holds of `in`, and what stateB holds of this step's rules.
    CaGLState::ShareState& held = ca.share;
    const bool continues = held.inputs == inputs && held.outputs == outputs && held.extent == e &&
                           held.bitsWrites == mBitsWrites && held.wind == wind;
    if (!continues) {
        // The previous step's whole state, or nothing.
        const bool whole = ca.stateOf == inputs && ca.stateWrites == mBitsWrites;
        held = {inputs, outputs, e, mBitsWrites, wind, 0, whole ? e.nz : 0, 0};
    }
    ca.stateOf = {};  // stateB is about to change; stateA's claim lives on in `held`
    const uint32_t lo = k0 >= 2 ? k0 - 2 : 0, hi = std::min(e.nz, k1 + 1);
    uint32_t pack0 = lo;
    if (held.packedBegin <= lo && held.packedEnd >= lo) {
        pack0 = std::min(held.packedEnd, hi);
    } else {
        held.packedBegin = lo, held.packedEnd = 0;
    }
    Timing timer(*this);
    f.BindVertexArray(mContext->EmptyVao());
    f.Viewport(0, 0, nx, ny);
    if (pack0 < hi) {
        f.UseProgram(*pack);
        for (int n = 0; n < 3; ++n) f.BindTextureUnit(GLuint(n), inputs[n]);
        f.Uniform3i(f.GetUniformLocation(*pack, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        CB_TRY(DrawLayerRange(*pack, pack0, hi, {stateA}));
    }
    held.packedEnd = std::max(held.packedEnd, hi);
    f.BindTextureUnit(0, stateA);
    f.BindTextureUnit(1, Tex(region).Texture());
    f.UseProgram(*rules);
    f.Uniform3i(f.GetUniformLocation(*rules, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform1ui(f.GetUniformLocation(*rules, "seed"), params.seed);
    f.Uniform1ui(f.GetUniformLocation(*rules, "step"), params.step);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qExt"), params.qExt);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qHum"), params.qHum);
    f.Uniform1ui(f.GetUniformLocation(*rules, "qAct"), params.qAct);
    CB_TRY(DrawLayerRange(*rules, k0, k1, {stateB}));
    // stateB's rule results: a run from slice 0 grown by ascending shares.
    held.rulesEnd = held.rulesEnd == k0 ? k1 : 0;
    f.BindTextureUnit(0, stateB);
    f.Viewport(0, 0, GLsizei(CeilDiv(e.nx, 32)), ny);
    f.UseProgram(*unpack);
    f.Uniform3i(f.GetUniformLocation(*unpack, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    const GLint shift = wind ? f.GetUniformLocation(*unpack, "shift") : -1;
    CB_TRY(DrawLayerRange(*unpack, k0, k1, {outputs[0], outputs[1], outputs[2]}, [&](uint32_t k) {
        if (wind) f.Uniform2i(shift, params.shiftX[k], params.shiftY[k]);
    }));
    ++mBitsWrites;
    held.bitsWrites = mBitsWrites;
    if (!wind && held.rulesEnd == e.nz) {
        // The step is complete in stateB: it becomes the state the next step starts from.
        ca.stateA.Swap(ca.stateB);
        ca.stateOf = outputs;
        ca.stateWrites = mBitsWrites;
        held = {};
    }
    timer.Stop();
    return mContext->Check("ca (RGBA8 layout, a share)");
}

}  // namespace cb::gl
