// Stage `noise` (SPEC 10a) on OpenGL: noise.frag, one full-screen pass per
// slice into the R32F layers of q. The scene's data block (core/math/NoiseGpu.h:
// permutation tables, HD per slice, towers, the detail volume) is made and
// uploaded once per scene into NoiseGLState's `data` storage buffer, kept while
// the settings and the grid stay the same; each call sets only the step's offsets.
#include "core/math/NoiseGpu.h"
#include "impl_gl/BackendGL.h"
#include "impl_gl/NoiseGLState.h"

namespace cb::gl {

uint64_t NoiseGLState::ScratchBytes(const Scene& scene) const {
    return noise::GpuDataBytes(scene.noise, scene.grid.size);
}

Status BackendGL::Noise(const NoiseParams& params, Buffer& q) {
    NoiseGLState& state = mStages.Get<NoiseGLState>();
    if (!params.settings) return MakeError("gl: noise without settings");
    if (q.Format() != BufferFormat::F32 || !(q.Extent() == params.grid))
        return MakeError("gl: noise: q must be an F32 volume of the grid's size");
    const Functions& f = mContext->F();
    auto program = PassProgram("noise");
    if (!program) return std::unexpected(program.error());
    if (!state.form || !(state.form->Settings() == *params.settings) || !(state.form->Grid() == params.grid)) {
        state.form.reset();
        auto form = std::make_unique<noise::NoiseForm>(*params.settings, params.grid);
        const std::vector<uint32_t> words = noise::GpuData(*form);
        const GLuint data = ScratchBuffer(state.data, words.size() * 4);
        f.NamedBufferSubData(data, 0, GLsizeiptr(words.size() * 4), words.data());
        state.form = std::move(form);
    }
    const std::array<float, 8> offsets = noise::GpuOffsets(state.form->Offsets(params.step));
    const Extent3 e = params.grid;
    Timing timer(*this);
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, ScratchBuffer(state.data, 0));
    f.Uniform1fv(f.GetUniformLocation(*program, "offsets"), 8, offsets.data());
    f.Viewport(0, 0, GLsizei(e.nx), GLsizei(e.ny));
    CB_TRY(DrawLayers(*program, e.nz, {Tex(q).Texture()}));
    timer.Stop();
    return mContext->Check("noise");
}

}  // namespace cb::gl
