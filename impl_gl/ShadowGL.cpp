#include "impl_gl/BackendGL.h"

namespace cb::gl {

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
    f.Uniform1i(f.GetUniformLocation(*program, "form"), int(params.form));
    f.Uniform1f(f.GetUniformLocation(*program, "opticalDepthPerD"), l.opticalDepthPerD);
    f.Uniform1f(f.GetUniformLocation(*program, "kappa"), params.kappa);
    f.Uniform1f(f.GetUniformLocation(*program, "coverage"), params.coverage);
    f.Uniform1f(f.GetUniformLocation(*program, "densityFactor"), params.densityFactor);
    f.Uniform1i(f.GetUniformLocation(*program, "noSun"), l.noSun ? 1 : 0);
    CB_TRY(BindTargets({{Tex(G).Texture(), 0}}));
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    Timing timer(*this);
    Draw(GL_TRIANGLES, 0, 3);
    timer.Stop();
    return mContext->Check("shadow");
}

}  // namespace cb::gl
