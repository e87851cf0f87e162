// An OpenGL 4.5 core context without a window: OSMesa (llvmpipe, the default)
// or EGL (surfaceless or device platform, for real GPUs). Programs come from
// the shader sources embedded at build time (impl_gl/shaders), each with the
// shared GLSL includes of core/math prepended.
#pragma once

#include <map>
#include <memory>
#include <string>

#include "core/base/Error.h"
#include "impl_gl/GLFunctions.h"
#include "impl_gl/GLOptions.h"

namespace cb::gl {

class GLContext {
  public:
    static Result<std::unique_ptr<GLContext>> Create(ContextKind kind);
    ~GLContext();
    GLContext(const GLContext&) = delete;
    GLContext& operator=(const GLContext&) = delete;

    // The GL functions, with this context made current on the calling thread
    // first: a process may hold several contexts (backends, tests), and GL
    // calls go to whichever is current.
    const Functions& F() const {
        MakeCurrent();
        return mF;
    }
    // Makes this context current where another one, or none, is (cheap when it
    // already is).
    void MakeCurrent() const;
    // GL_RENDERER, then the context kind: "llvmpipe (...) (OSMesa)".
    std::string Renderer() const;
    // Whether the renderer is a software rasterizer (llvmpipe, softpipe), where
    // vertices and fragments cost the host's CPU.
    bool SoftwareRasterizer() const;
    // glGetString(name) as the driver spells it; "?" when it returns null.
    std::string String(GLenum name) const;
    // glGetIntegerv(name): one of this context's limits (GL_MAX_TEXTURE_SIZE, GL_MAX_ARRAY_TEXTURE_LAYERS, ...).
    GLint Integer(GLenum name) const;
    // "doing X: GL_INVALID_OPERATION" for a pending GL error; ok otherwise.
    Status Check(const char* what) const;
    // The linked program of pass `name`: shaders/<name>.frag with
    // shaders/<name>.vert, or the full-screen triangle where there is none; a
    // compile or link failure carries its log and the pass's name. `defines`
    // (whole "#define ..." lines) go after the #version line of the fragment
    // shader, and of the pass's own vertex shader where it has one: a
    // specialised variant, linked on first use and cached apart.
    Result<GLuint> Program(const std::string& name, const std::string& defines = "");
    // The layered variant of full-screen pass `name` (one without a .vert): one
    // instance per layer, the vertex stage writing gl_Layer = layer0 +
    // gl_InstanceID (ARB_shader_viewport_layer_array) and passing that layer to
    // the fragment stage, whose `uniform int layer;` becomes `flat in int
    // layer;`. Set uniform "layer0" and draw the triangle with end - begin
    // instances into layered targets (one draw, not one per slice).
    // An Error where the driver cannot (the caller draws per slice).
    Result<GLuint> LayeredProgram(const std::string& name, const std::string& defines = "");
    // Compiles and links a program from full sources (vertex: nullptr for the
    // full-screen triangle); errors name `name` and carry the GL log.
    Result<GLuint> LinkProgram(const std::string& name, const std::string* vertex, const std::string& fragment);
    // An empty vertex array for attribute-less draws.
    GLuint EmptyVao() const { return mVao; }
    // The framebuffer every pass renders through (BackendGL::BindTargets attaches its targets).
    GLuint Framebuffer() const { return mFramebuffer; }

  private:
    GLContext() = default;
    Status LoadFunctions(void* (*resolve)(const char*));

    ContextKind mKind = ContextKind::OSMesa;
    void* mOsmesa = nullptr;            // OSMesaContext
    std::unique_ptr<unsigned char[]> mOsmesaBuffer;
    void* mEglDisplay = nullptr;        // EGLDisplay
    void* mEglContext = nullptr;        // EGLContext
    Functions mF;
    GLuint mVao = 0, mFramebuffer = 0;
    std::map<std::string, GLuint> mPrograms;
};

}  // namespace cb::gl
