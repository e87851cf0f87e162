#include <algorithm>
#include <array>
#include <string>
#include <utility>

#include "core/pipeline/ShadePlan.h"
#include "impl_gl/BackendGL.h"
#include "impl_gl/ShadeGLState.h"

namespace cb::gl {

uint64_t ShadeGLState::ScratchBytes(const Scene& scene) const {
    const Extent3 e = scene.grid.size;
    const uint32_t f = uint32_t(std::max(scene.shade.resolution, 1));
    uint64_t cells[3] = {CeilDiv(e.nx, f), CeilDiv(e.ny, f), CeilDiv(e.nz, f)};
    const uint64_t grid = cells[0] * cells[1] * cells[2] * 4;
    std::sort(cells, cells + 3);
    return (f > 1 ? 2 : 1) * grid + 2 * cells[1] * cells[2] * 4;
}

// shade: optional down-sampling pass, then the slice loop from the sun's side
// (ping-pong between two 2-D textures, each slice also written to layer w of a
// w-major volume), then one pass that writes the z-layered T, reading the
// w-major volume trilinearly (exactly, at f = 1). A share [m0, m1) of the
// sweep: the share with m = 0 down-samples, the slices m0 <= m < m1 run (the
// slice before m0 is in the ping-pong texture of m0's parity, left by the
// preceding share), and the share ending at nw writes T.
Status BackendGL::ShadeSweep(ShadeGLState& state, const char* stage, const ShadeParams& params, const Buffer& q,
                             Buffer& T) {
    const int res = params.resolution;
    CB_TRY(CheckShadeResolution("gl", res));
    const Functions& f = mContext->F();
    auto slice = mContext->Program("shade_slice");
    if (!slice) return std::unexpected(slice.error());
    auto up = PassProgram("shade_up");
    if (!up) return std::unexpected(up.error());
    auto down = PassProgram("shade_down");
    if (!down) return std::unexpected(down.error());
    const Extent3 e = q.Extent();
    const ShadePlan plan = MakeShadePlan(params, e);
    const int n[3] = {int(plan.cells[0]), int(plan.cells[1]), int(plan.cells[2])};
    const ShearWarp& g = plan.geometry;
    const SliceAttenuation& a = plan.attenuation;
    const int nu = int(plan.nu), nv = int(plan.nv), nw = int(plan.nw);
    const uint32_t m0 = params.slices.Begin(plan.nw), m1 = params.slices.End(plan.nw);
    if (m0 >= m1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    Timing timer(*this);
    f.BindVertexArray(mContext->EmptyVao());
    GLuint shadedQ = Tex(q).Texture();
    if (res > 1) shadedQ = Scratch(state.coarseQ, GL_TEXTURE_2D_ARRAY, GL_R32F, n[0], n[1], n[2]);
    if (res > 1 && m0 == 0) {
        f.UseProgram(*down);
        f.BindTextureUnit(0, Tex(q).Texture());
        f.Uniform3i(f.GetUniformLocation(*down, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        f.Uniform1i(f.GetUniformLocation(*down, "f"), res);
        f.Viewport(0, 0, n[0], n[1]);
        CB_TRY(DrawLayers(*down, uint32_t(n[2]), {shadedQ}));
    }
    const GLuint volume = Scratch(state.volume, GL_TEXTURE_2D_ARRAY, GL_R32F, nu, nv, nw);
    GLuint ping = Scratch(state.ping, GL_TEXTURE_2D, GL_R32F, nu, nv);
    GLuint pong = Scratch(state.pong, GL_TEXTURE_2D, GL_R32F, nu, nv);
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
    if (m0 % 2 == 1) std::swap(ping, pong);
    int previous = m0 > 0 ? int(plan.SliceW(m0 - 1)) : 0;
    for (int m = int(m0); m < int(m1); ++m) {
        const int w = int(plan.SliceW(uint32_t(m)));
        CB_TRY(BindTargets({{pong, -1}, {volume, w}}));
        f.BindTextureUnit(0, ping);
        f.Uniform1i(first, m == 0 ? 1 : 0);
        f.Uniform3i(previousW, previous * ew[0], previous * ew[1], previous * ew[2]);
        Draw(GL_TRIANGLES, 0, 3);
        std::swap(ping, pong);
        previous = w;
    }
    if (m1 < plan.nw) {
        timer.Stop();
        return mContext->Check((std::string(stage) + ", a share").c_str());
    }
    f.UseProgram(*up);
    f.BindTextureUnit(0, volume);
    f.Uniform3i(f.GetUniformLocation(*up, "cells"), n[0], n[1], n[2]);
    f.Uniform3i(f.GetUniformLocation(*up, "axes"), g.u, g.v, g.w);
    f.Uniform1i(f.GetUniformLocation(*up, "f"), res);
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    CB_TRY(DrawLayers(*up, e.nz, {Tex(T).Texture()}));
    timer.Stop();
    return mContext->Check(stage);
}

Status BackendGL::Shade(const ShadeParams& params, const Buffer& q, Buffer& T) {
    return ShadeSweep(mStages.Get<ShadeGLState>(), "shade", params, q, T);
}

Status BackendGL::ShadeSky(const ShadeParams& params, const Buffer& q, Buffer& T) {
    return ShadeSweep(mStages.Get<ShadeSkyGLState>(), "shade_sky", params, q, T);
}

}  // namespace cb::gl
