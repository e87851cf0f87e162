#include "impl_gl/BackendGLInternal.h"

namespace cb::gl {

// smooth: three separable passes, x then y then z, through R16UI sums.
Status BackendGL::Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) {
    if (slices != SliceRange{}) return MakeError("gl: smooth in shares (time-slicing) is not implemented yet");
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

}  // namespace cb::gl
