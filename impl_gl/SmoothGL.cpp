#include <algorithm>

#include "impl_gl/BackendGL.h"
#include "impl_gl/SmoothGLState.h"

namespace cb::gl {

uint64_t SmoothGLState::ScratchBytes(const Scene& scene) const { return 2 * scene.grid.size.Count() * 2; }

// smooth: three separable passes, x then y then z, through R16UI sums. A share
// [b, e) needs the xy sums of slices [b - r, e + r); those a preceding share
// left in sumXY (SmoothGLState::held: same cld, radius and bit-field writes) are not
// summed again, so shares in ascending order sum each slice once.
Status BackendGL::Smooth(int radius, const Buffer& cld, Buffer& q, SliceRange slices) {
    SmoothGLState& state = mStages.Get<SmoothGLState>();
    if (radius < 0 || radius > 2) return MakeError("gl: smooth radius must be 0, 1 or 2");
    const Functions& f = mContext->F();
    GLuint passes[3];
    const char* names[3] = {"smooth_x", "smooth_y", "smooth_z"};
    for (int n = 0; n < 3; ++n) {
        auto program = PassProgram(names[n]);
        if (!program) return std::unexpected(program.error());
        passes[n] = *program;
    }
    const Extent3 e = cld.Extent();
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    // The slices of the x and y sums to compute, [s0, s1), and of q, [k0, k1).
    const uint32_t r = uint32_t(radius);
    uint32_t s0 = k0 > r ? k0 - r : 0, s1 = std::min(e.nz, k1 + r);
    const GLuint cldTexture = Tex(cld).Texture();
    SmoothGLState::Sums held{cldTexture, radius, e, mBitsWrites, s0, s1};
    if (slices.IsWhole(e.nz)) {
        held = {};  // shares reuse only what shares summed
    } else {
        const SmoothGLState::Sums& c = state.held;
        if (c.cld == cldTexture && c.radius == radius && c.extent == e && c.bitsWrites == mBitsWrites &&
            c.begin <= s0 && c.end >= s0) {
            held.begin = c.begin;
            s0 = std::min(c.end, s1);
            held.end = std::max(c.end, s1);
        }
    }
    const GLsizei nx = GLsizei(e.nx), ny = GLsizei(e.ny), nz = GLsizei(e.nz);
    const GLuint sumX = Scratch(state.sumX, GL_TEXTURE_2D_ARRAY, GL_R16UI, nx, ny, nz);
    const GLuint sumXY = Scratch(state.sumXY, GL_TEXTURE_2D_ARRAY, GL_R16UI, nx, ny, nz);
    const GLuint input[3] = {cldTexture, sumX, sumXY};
    const GLuint output[3] = {sumX, sumXY, Tex(q).Texture()};
    Timing timer(*this);
    f.BindVertexArray(mContext->EmptyVao());
    f.Viewport(0, 0, nx, ny);
    for (int n = 0; n < 3; ++n) {
        const GLuint program = passes[n];
        f.UseProgram(program);
        f.BindTextureUnit(0, input[n]);
        f.Uniform1i(f.GetUniformLocation(program, "radius"), radius);
        f.Uniform3i(f.GetUniformLocation(program, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
        if (n == 2) f.Uniform1f(f.GetUniformLocation(program, "invW"), 1.0f / float(SmoothNormaliser(radius)));
        CB_TRY(n == 2 ? DrawLayerRange(program, k0, k1, {output[n]}) : DrawLayerRange(program, s0, s1, {output[n]}));
    }
    state.held = held;
    timer.Stop();
    return mContext->Check("smooth");
}

}  // namespace cb::gl
