// The padded (q_alpha, T) volume that render_march and render_layers read by
// index (march.glsl's MarchFetchQT), the sky light's padded T_sky volume (MarchFetchSkyT), and the Mie table
// both look up.
#include <string>

#include "core/math/Shading.h"
#include "impl_gl/BackendGL.h"

namespace cb::gl {
namespace {

constexpr size_t kPairBytes = 8;  // a (q_alpha, T) cell
constexpr size_t kSkyBytes = 4;   // a T_sky cell
size_t PaddedCells(const Extent3& e) { return size_t(e.nx + 2) * size_t(e.ny + 2) * size_t(e.nz + 2); }
size_t PaddedVolumeBytes(const Extent3& e) { return PaddedCells(e) * kPairBytes; }

}  // namespace

Status BackendGL::CheckPaddedVolumeFits(const Extent3& grid, const char* stage) {
    GLint maxStorage = 0;
    mContext->F().GetIntegerv(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxStorage);
    const size_t bytes = PaddedVolumeBytes(grid);
    if (bytes > size_t(uint32_t(maxStorage)))
        return MakeError(std::string("gl: ") + stage + ": the padded volume takes " + std::to_string(bytes) +
                         " bytes; this driver's storage blocks hold " + std::to_string(maxStorage));
    return {};
}

Result<GLuint> BackendGL::DrawPaddedVolume(GLuint program, const Extent3& e, bool wrap, GLenum internalFormat,
                                           GLenum format, size_t cellBytes, TextureSlot& volume, BufferSlot& copy) {
    const Functions& f = mContext->F();
    const GLsizei px = GLsizei(e.nx + 2), py = GLsizei(e.ny + 2), pz = GLsizei(e.nz + 2);
    const GLuint texture = Scratch(volume, GL_TEXTURE_2D_ARRAY, internalFormat, px, py, pz);
    f.Uniform3i(f.GetUniformLocation(program, "grid"), GLint(e.nx), GLint(e.ny), GLint(e.nz));
    f.Uniform1i(f.GetUniformLocation(program, "wrap"), wrap ? 1 : 0);
    f.Viewport(0, 0, px, py);
    CB_TRY(DrawLayers(program, uint32_t(pz), {texture}));
    const size_t bytes = PaddedCells(e) * cellBytes;
    const GLuint buffer = ScratchBuffer(copy, bytes);
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, buffer);
    f.PixelStorei(GL_PACK_ALIGNMENT, 1);
    f.GetTextureImage(texture, 0, format, GL_FLOAT, GLsizei(bytes), nullptr);
    f.BindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    return buffer;
}

Result<GLuint> BackendGL::FormPaddedVolume(TextureSlot& volume, BufferSlot& copy, const Buffer& qPrev,
                                           const Buffer& qCur, const Buffer* T, float alpha, bool wrap) {
    const Functions& f = mContext->F();
    auto program = PassProgram("march_volume");
    if (!program) return std::unexpected(program.error());
    f.UseProgram(*program);
    f.BindTextureUnit(0, Tex(qPrev).Texture());
    f.BindTextureUnit(1, Tex(qCur).Texture());
    f.BindTextureUnit(2, Tex(T ? *T : qCur).Texture());
    f.Uniform1f(f.GetUniformLocation(*program, "alpha"), alpha);
    f.Uniform1i(f.GetUniformLocation(*program, "hasT"), T ? 1 : 0);
    return DrawPaddedVolume(*program, qCur.Extent(), wrap, GL_RG32F, GL_RG, kPairBytes, volume, copy);
}

Result<GLuint> BackendGL::FormPaddedSkyVolume(TextureSlot& volume, BufferSlot& copy, const Buffer& TSky, bool wrap) {
    const Functions& f = mContext->F();
    auto program = PassProgram("march_sky_volume");
    if (!program) return std::unexpected(program.error());
    f.UseProgram(*program);
    f.BindTextureUnit(0, Tex(TSky).Texture());
    return DrawPaddedVolume(*program, TSky.Extent(), wrap, GL_R32F, GL_RED, kSkyBytes, volume, copy);
}

GLuint BackendGL::MiePhaseTable(BufferSlot& table, bool& uploaded) {
    const size_t bytes = size_t(kMieCloudTable.count) * 4;
    const GLuint buffer = ScratchBuffer(table, bytes);
    if (!uploaded) {
        mContext->F().NamedBufferSubData(buffer, 0, GLsizeiptr(bytes), kMieCloudTable.values);
        uploaded = true;
    }
    return buffer;
}

}  // namespace cb::gl
