// Shafts of light (SPEC 18) on OpenGL: shafts.frag writes the frame plus the
// shells' light into an RGBA32F target, which then replaces the image (as a
// renderer's target does, CopyTargetToImage).
#include "core/pipeline/ShaftsPass.h"
#include "impl_gl/BackendGL.h"

namespace cb::gl {

Status BackendGL::AddShafts(const ShaftsFrame& frame, const Buffer& columnSum, Buffer& image) {
    CB_TRY(CheckShaftsBuffers(frame, columnSum, image, "gl"));
    const uint32_t W = frame.width, H = frame.height;
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
