#include <algorithm>

#include "impl_gl/BackendGL.h"
#include "impl_gl/DensityGLState.h"

namespace cb::gl {

uint64_t DensityGLState::ScratchBytes(const Scene& scene) const {
    return uint64_t(scene.grid.size.nx) * scene.grid.size.ny;
}

Status BackendGL::Density(const DensityParams& params, const Buffer& q, const Buffer* cld, DensityOutputs& out) {
    if (params.tile == 0 || params.band == 0) return MakeError("gl: density tile and band must be positive");
    const Functions& f = mContext->F();
    auto sum = PassProgram("density_sum");
    if (!sum) return std::unexpected(sum.error());
    auto cover = mContext->Program("density_cover");
    if (!cover) return std::unexpected(cover.error());
    auto occupancy = PassProgram("occupancy");
    if (!occupancy) return std::unexpected(occupancy.error());
    const Extent3 e = q.Extent();
    const uint32_t tilesX = CeilDiv(e.nx, params.tile), tilesY = CeilDiv(e.ny, params.tile);
    const uint32_t bandCount = CeilDiv(e.nz, params.band);
    // A share: the rows of tiles [t0, t1), columns' rows [y0, y1); each pass's
    // viewport covers those rows only (gl_FragCoord stays the texel's).
    const uint32_t t0 = params.slices.Begin(tilesY), t1 = params.slices.End(tilesY);
    if (t0 >= t1) {
        out.coveredColumns = 0;
        mLastDeviceMs = 0.0;
        return {};
    }
    const GLint y0 = GLint(t0 * params.tile);
    const GLsizei rows = GLsizei(std::min(e.ny, t1 * params.tile)) - y0;
    Timing timer(*this);
    f.BindVertexArray(mContext->EmptyVao());

    // D: additive blending of the slices, k ascending.
    const float zero = 0.0f;
    f.ClearTexSubImage(Tex(*out.columnSum).Texture(), 0, 0, y0, 0, GLsizei(e.nx), rows, 1, GL_RED, GL_FLOAT, &zero);
    CB_TRY(BindTargets({{Tex(*out.columnSum).Texture(), 0}}));
    f.Viewport(0, y0, GLsizei(e.nx), rows);
    f.UseProgram(*sum);
    f.BindTextureUnit(0, Tex(q).Texture());
    f.Enable(GL_BLEND);
    f.BlendEquation(GL_FUNC_ADD);
    f.BlendFunc(GL_ONE, GL_ONE);
    if (IsLayered(*sum)) {
        // One instance per slice into the one target (not layered: gl_Layer is
        // ignored); blending follows the instances' order, k ascending.
        f.Uniform1i(f.GetUniformLocation(*sum, "layer0"), 0);
        Draw(GL_TRIANGLES, 0, 3, GLsizei(e.nz));
    } else {
        const GLint sumLayer = f.GetUniformLocation(*sum, "layer");
        for (uint32_t k = 0; k < e.nz; ++k) {
            f.Uniform1i(sumLayer, GLint(k));
            Draw(GL_TRIANGLES, 0, 3);
        }
    }
    f.Disable(GL_BLEND);

    // Cover: an atomic counter over the columns; the column flags land in a scratch R8UI layer.
    const GLuint counter = CounterBuffer(mStages.Get<DensityGLState>().coverCounter, sizeof(GLuint));
    const GLuint initial = 0;
    f.NamedBufferSubData(counter, 0, sizeof initial, &initial);
    f.BindBufferBase(GL_ATOMIC_COUNTER_BUFFER, 0, counter);
    const GLuint flags = Scratch(mStages.Get<DensityGLState>().coverFlags, GL_TEXTURE_2D_ARRAY, GL_R8UI, GLsizei(e.nx),
                                 GLsizei(e.ny), 1);
    CB_TRY(BindTargets({{flags, 0}}));
    f.UseProgram(*cover);  // in the rows' viewport: only their columns count
    // Without cld the cover counts columns with D > 0 and leaves the cld unit unbound.
    f.BindTextureUnit(0, cld ? Tex(*cld).Texture() : 0);
    f.BindTextureUnit(1, Tex(*out.columnSum).Texture());
    f.Uniform1i(f.GetUniformLocation(*cover, "fromCld"), cld ? 1 : 0);
    f.Uniform3i(f.GetUniformLocation(*cover, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    Draw(GL_TRIANGLES, 0, 3);

    // Occupancy: max-downsampling to tiles (from D) and to tile x band (from q).
    f.UseProgram(*occupancy);
    f.BindTextureUnit(0, Tex(q).Texture());
    f.BindTextureUnit(1, Tex(*out.columnSum).Texture());
    f.Uniform3i(f.GetUniformLocation(*occupancy, "size"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform2i(f.GetUniformLocation(*occupancy, "tileBand"), GLint(params.tile), GLint(params.band));
    const GLint mode = f.GetUniformLocation(*occupancy, "mode");
    f.Viewport(0, GLint(t0), GLsizei(tilesX), GLsizei(t1 - t0));
    f.Uniform1i(mode, 0);
    CB_TRY(DrawLayers(*occupancy, bandCount, {Tex(*out.bands).Texture()}));
    f.Uniform1i(mode, 1);
    CB_TRY(BindTargets({{Tex(*out.tiles).Texture(), 0}}));
    Draw(GL_TRIANGLES, 0, 3);

    f.MemoryBarrier(GL_ATOMIC_COUNTER_BARRIER_BIT | GL_BUFFER_UPDATE_BARRIER_BIT);
    timer.Stop();
    if (mBatch.active) {  // read after EndBatch's wait (TakeDeferredResults)
        mBatch.deferred.push_back({mBatch.interval, counter, 0, true, false, 0});
        return mContext->Check("density");
    }
    GLuint covered = 0;
    WaitingRead(ReadKind::Buffer, counter, 0, 0, 0, sizeof covered, &covered);
    out.coveredColumns = covered;
    return mContext->Check("density");
}

}  // namespace cb::gl
