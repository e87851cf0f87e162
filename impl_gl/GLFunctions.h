// The OpenGL 4.5 core entry points the backend uses, resolved from the current
// context (OSMesaGetProcAddress or eglGetProcAddress): neither OSMesa nor EGL
// contexts go through libglvnd's GLX dispatch, so the table is filled here.
#pragma once

#include <GL/glcorearb.h>

#define CB_GL_FUNCTIONS(X)                                                     \
    X(PFNGLGETSTRINGPROC, GetString)                                           \
    X(PFNGLGETERRORPROC, GetError)                                             \
    X(PFNGLGETINTEGERVPROC, GetIntegerv)                                       \
    X(PFNGLCREATESHADERPROC, CreateShader)                                     \
    X(PFNGLSHADERSOURCEPROC, ShaderSource)                                     \
    X(PFNGLCOMPILESHADERPROC, CompileShader)                                   \
    X(PFNGLGETSHADERIVPROC, GetShaderiv)                                       \
    X(PFNGLGETSHADERINFOLOGPROC, GetShaderInfoLog)                             \
    X(PFNGLDELETESHADERPROC, DeleteShader)                                     \
    X(PFNGLCREATEPROGRAMPROC, CreateProgram)                                   \
    X(PFNGLATTACHSHADERPROC, AttachShader)                                     \
    X(PFNGLLINKPROGRAMPROC, LinkProgram)                                       \
    X(PFNGLGETPROGRAMIVPROC, GetProgramiv)                                     \
    X(PFNGLGETPROGRAMINFOLOGPROC, GetProgramInfoLog)                           \
    X(PFNGLDELETEPROGRAMPROC, DeleteProgram)                                   \
    X(PFNGLUSEPROGRAMPROC, UseProgram)                                         \
    X(PFNGLGETUNIFORMLOCATIONPROC, GetUniformLocation)                         \
    X(PFNGLUNIFORM1IPROC, Uniform1i)                                           \
    X(PFNGLUNIFORM3IPROC, Uniform3i)                                           \
    X(PFNGLUNIFORM2IPROC, Uniform2i)                                           \
    X(PFNGLUNIFORM1UIPROC, Uniform1ui)                                         \
    X(PFNGLUNIFORM1FPROC, Uniform1f)                                           \
    X(PFNGLUNIFORM1FVPROC, Uniform1fv)                                         \
    X(PFNGLUNIFORM2FPROC, Uniform2f)                                           \
    X(PFNGLCREATETEXTURESPROC, CreateTextures)                                 \
    X(PFNGLDELETETEXTURESPROC, DeleteTextures)                                 \
    X(PFNGLTEXTURESTORAGE2DPROC, TextureStorage2D)                             \
    X(PFNGLTEXTURESTORAGE3DPROC, TextureStorage3D)                             \
    X(PFNGLTEXTURESUBIMAGE3DPROC, TextureSubImage3D)                           \
    X(PFNGLGETTEXTUREIMAGEPROC, GetTextureImage)                               \
    X(PFNGLTEXTUREPARAMETERIPROC, TextureParameteri)                           \
    X(PFNGLBINDTEXTUREUNITPROC, BindTextureUnit)                               \
    X(PFNGLCREATEFRAMEBUFFERSPROC, CreateFramebuffers)                         \
    X(PFNGLDELETEFRAMEBUFFERSPROC, DeleteFramebuffers)                         \
    X(PFNGLNAMEDFRAMEBUFFERTEXTURELAYERPROC, NamedFramebufferTextureLayer)     \
    X(PFNGLCHECKNAMEDFRAMEBUFFERSTATUSPROC, CheckNamedFramebufferStatus)       \
    X(PFNGLBINDFRAMEBUFFERPROC, BindFramebuffer)                               \
    X(PFNGLCREATEVERTEXARRAYSPROC, CreateVertexArrays)                         \
    X(PFNGLDELETEVERTEXARRAYSPROC, DeleteVertexArrays)                         \
    X(PFNGLBINDVERTEXARRAYPROC, BindVertexArray)                               \
    X(PFNGLVIEWPORTPROC, Viewport)                                             \
    X(PFNGLDISABLEPROC, Disable)                                               \
    X(PFNGLENABLEPROC, Enable)                                                 \
    X(PFNGLBLENDFUNCPROC, BlendFunc)                                           \
    X(PFNGLBLENDEQUATIONPROC, BlendEquation)                                   \
    X(PFNGLCLEARTEXIMAGEPROC, ClearTexImage)                                   \
    X(PFNGLCLEARTEXSUBIMAGEPROC, ClearTexSubImage)                             \
    X(PFNGLSCISSORPROC, Scissor)                                               \
    X(PFNGLCREATEBUFFERSPROC, CreateBuffers)                                   \
    X(PFNGLDELETEBUFFERSPROC, DeleteBuffers)                                   \
    X(PFNGLNAMEDBUFFERDATAPROC, NamedBufferData)                               \
    X(PFNGLNAMEDBUFFERSUBDATAPROC, NamedBufferSubData)                         \
    X(PFNGLBINDBUFFERBASEPROC, BindBufferBase)                                 \
    X(PFNGLGETNAMEDBUFFERSUBDATAPROC, GetNamedBufferSubData)                   \
    X(PFNGLMEMORYBARRIERPROC, MemoryBarrier)                                   \
    X(PFNGLDRAWARRAYSPROC, DrawArrays)                                         \
    X(PFNGLPIXELSTOREIPROC, PixelStorei)                                       \
    X(PFNGLFINISHPROC, Finish)                                                 \
    X(PFNGLGENQUERIESPROC, GenQueries)                                         \
    X(PFNGLDELETEQUERIESPROC, DeleteQueries)                                   \
    X(PFNGLQUERYCOUNTERPROC, QueryCounter)                                     \
    X(PFNGLGETQUERYOBJECTUI64VPROC, GetQueryObjectui64v)                       \
    X(PFNGLBEGINQUERYPROC, BeginQuery)                                         \
    X(PFNGLENDQUERYPROC, EndQuery)                                             \
    X(PFNGLDRAWARRAYSINSTANCEDPROC, DrawArraysInstanced)                       \
    X(PFNGLMULTIDRAWARRAYSPROC, MultiDrawArrays)                               \
    X(PFNGLCOPYIMAGESUBDATAPROC, CopyImageSubData)                             \
    X(PFNGLNAMEDFRAMEBUFFERDRAWBUFFERSPROC, NamedFramebufferDrawBuffers)       \
    X(PFNGLNAMEDFRAMEBUFFERTEXTUREPROC, NamedFramebufferTexture)               \
    X(PFNGLCLEARNAMEDFRAMEBUFFERFVPROC, ClearNamedFramebufferfv)               \
    X(PFNGLBINDBUFFERPROC, BindBuffer)                                         \
    X(PFNGLGETFLOATVPROC, GetFloatv)                                           \
    X(PFNGLUNIFORM3FPROC, Uniform3f)                                           \
    X(PFNGLUNIFORM4FPROC, Uniform4f)

namespace cb::gl {

struct Functions {
#define CB_GL_DECLARE(type, name) type name = nullptr;
    CB_GL_FUNCTIONS(CB_GL_DECLARE)
#undef CB_GL_DECLARE
};

}  // namespace cb::gl
