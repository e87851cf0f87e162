#include "impl_gl/BackendGL.h"
#include "impl_gl/RegionGLState.h"

namespace cb::gl {

uint64_t RegionGLState::ScratchBytes(const Scene& scene) const { return scene.grid.size.Count(); }

// region: per slice, one instanced quad per ellipsoid into an R8 UNORM layer
// with MAX blending (integer targets cannot blend), then one copy into the
// R8UI volume (the same 8-bit texel class, so the bits carry over). A share
// clears, draws and copies its own slices only. Where the driver can, the
// slices are one layered draw of slices x ellipsoids instances (region.vert).
Status BackendGL::Region(std::span<const RasterEllipsoid> ellipsoids, Buffer& region, SliceRange slices) {
    const Functions& f = mContext->F();
    // Layered where the driver can (one draw for the share's slices), else one draw per slice.
    Result<GLuint> program = MakeError("");
    if (Layered()) {
        program = mContext->Program("region", "#extension GL_ARB_shader_viewport_layer_array : require\n#define LAYERED 1\n");
        if (!program) mLayeredFailed = true;
    }
    if (!program) program = mContext->Program("region");
    if (!program) return std::unexpected(program.error());
    const bool layered = Layered();
    const Extent3 e = region.Extent();
    static_assert(sizeof(RasterEllipsoid) == 8 * sizeof(float));
    Timing timer(*this);
    const GLuint list = ScratchBuffer(mStages.Get<RegionGLState>().ellipsoids, ellipsoids.size_bytes());
    if (!ellipsoids.empty()) f.NamedBufferSubData(list, 0, GLsizeiptr(ellipsoids.size_bytes()), ellipsoids.data());
    const GLuint unorm = Scratch(mStages.Get<RegionGLState>().unorm, GL_TEXTURE_2D_ARRAY, GL_R8, GLsizei(e.nx),
                                 GLsizei(e.ny), GLsizei(e.nz));
    const uint32_t k0 = slices.Begin(e.nz), k1 = slices.End(e.nz);
    if (k0 >= k1) {
        mLastDeviceMs = 0.0;
        return {};
    }
    const float zero = 0.0f;
    f.ClearTexSubImage(unorm, 0, 0, 0, GLint(k0), GLsizei(e.nx), GLsizei(e.ny), GLsizei(k1 - k0), GL_RED, GL_FLOAT,
                       &zero);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, list);
    f.Uniform2i(f.GetUniformLocation(*program, "size"), GLint(e.nx), GLint(e.ny));
    const GLint layer = f.GetUniformLocation(*program, "layer");
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    f.Enable(GL_BLEND);
    f.BlendEquation(GL_MAX);
    if (layered && !ellipsoids.empty()) {
        CB_TRY(BindTargets({{unorm, -1}}));
        f.Uniform1i(f.GetUniformLocation(*program, "layer0"), GLint(k0));
        f.Uniform1i(f.GetUniformLocation(*program, "count"), GLint(ellipsoids.size()));
        Draw(GL_TRIANGLE_STRIP, 0, 4, GLsizei(size_t(k1 - k0) * ellipsoids.size()));
    }
    for (uint32_t k = k0; k < k1 && !ellipsoids.empty() && !layered; ++k) {
        CB_TRY(BindTargets({{unorm, int(k)}}));
        f.Uniform1i(layer, GLint(k));
        Draw(GL_TRIANGLE_STRIP, 0, 4, GLsizei(ellipsoids.size()));
    }
    f.Disable(GL_BLEND);
    f.BlendEquation(GL_FUNC_ADD);
    f.CopyImageSubData(unorm, GL_TEXTURE_2D_ARRAY, 0, 0, 0, GLint(k0), Tex(region).Texture(), GL_TEXTURE_2D_ARRAY, 0, 0,
                       0, GLint(k0), GLsizei(e.nx), GLsizei(e.ny), GLsizei(k1 - k0));
    timer.Stop();
    return mContext->Check("region");
}

}  // namespace cb::gl
