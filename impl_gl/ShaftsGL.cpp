// Shafts of light (SPEC 18) on OpenGL: shafts.frag writes the frame plus the
// shells' light into an RGBA32F target, which then replaces the image (as a
// renderer's target does, CopyTargetToImage).
#include "impl_gl/BackendGL.h"

namespace cb::gl {

Status BackendGL::AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) {
    const Extent3 e = columnSum.Extent();
    if (e.nx != frame.gridX || e.ny != frame.gridY || e.nz != 1)
        return MakeError("gl: shafts: D is not (nx, ny, 1) of the frame's grid");
    const uint32_t W = frame.width, H = frame.height;
    if (image.Extent() != Extent3{3, W, H}) return MakeError("gl: shafts: the image is not (3, width, height)");
    auto program = mContext->Program("shafts");
    if (!program) return std::unexpected(program.error());
    const Functions& f = mContext->F();
    Timing timer(*this);
    const GLuint block = ScratchBuffer(mShafts.block, sizeof frame);
    f.NamedBufferSubData(block, 0, sizeof frame, &frame);
    const GLuint target = Scratch(mShafts.target, GL_TEXTURE_2D, GL_RGBA32F, GLsizei(W), GLsizei(H));
    CB_TRY(BindTargets({{target, -1}}));
    f.UseProgram(*program);
    f.BindVertexArray(mContext->EmptyVao());
    f.BindBufferBase(GL_UNIFORM_BUFFER, 0, block);
    f.BindTextureUnit(3, Tex(columnSum).Texture());
    f.BindTextureUnit(4, Tex(image).Texture());
    f.Viewport(0, 0, GLsizei(W), GLsizei(H));
    Draw(GL_TRIANGLES, 0, 3);
    CopyTargetToImage(target, W, H, mShafts.imageCopy, image);
    timer.Stop();
    return mContext->Check("shafts");
}

}  // namespace cb::gl
