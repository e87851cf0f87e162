#include "impl_gl/GLContext.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/osmesa.h>

#include <cstring>
#include <vector>

#include "impl_gl/GLShaders.h"

namespace cb::gl {
namespace {

const char* ErrorName(GLenum e) {
    switch (e) {
        case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
        case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
        case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
        default: return "GL error";
    }
}

void* OsmesaResolve(const char* name) { return reinterpret_cast<void*>(OSMesaGetProcAddress(name)); }
void* EglResolve(const char* name) { return reinterpret_cast<void*>(eglGetProcAddress(name)); }

// The attribute-less vertex shader of every pass: one triangle covering the viewport.
constexpr const char* kFullScreenVertex = R"(#version 450 core
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
)";

// The layered passes' vertex shader (GLContext::LayeredProgram).
constexpr const char* kLayeredVertex = R"(#version 450 core
#extension GL_ARB_shader_viewport_layer_array : require
uniform int layer0;
flat out int layer;
void main() {
    vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
    layer = layer0 + gl_InstanceID;
    gl_Layer = layer;
}
)";

// The info log of a shader or program (getiv/getLog: glGetShaderiv/InfoLog or glGetProgramiv/InfoLog).
template <typename GetIv, typename GetLog>
std::string InfoLog(GLuint object, GetIv getiv, GetLog getLog) {
    GLint length = 0;
    getiv(object, GL_INFO_LOG_LENGTH, &length);
    std::string log(size_t(std::max(length, 1)), '\0');
    getLog(object, length, nullptr, log.data());
    return log;
}

Result<GLuint> Compile(const Functions& f, GLenum type, const std::string& source, const std::string& name) {
    GLuint shader = f.CreateShader(type);
    const char* text = source.c_str();
    f.ShaderSource(shader, 1, &text, nullptr);
    f.CompileShader(shader);
    GLint ok = 0;
    f.GetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        const std::string log = InfoLog(shader, f.GetShaderiv, f.GetShaderInfoLog);
        f.DeleteShader(shader);
        return MakeError("gl: compiling the " + name + " shader failed:\n" + log);
    }
    return shader;
}

}  // namespace

Status GLContext::LoadFunctions(void* (*resolve)(const char*)) {
#define CB_GL_LOAD(type, name)                                                          \
    mF.name = reinterpret_cast<type>(resolve("gl" #name));                              \
    if (!mF.name) return MakeError("gl: the context lacks gl" #name " (OpenGL 4.5 core needed)");
    CB_GL_FUNCTIONS(CB_GL_LOAD)
#undef CB_GL_LOAD
    return {};
}

Result<std::unique_ptr<GLContext>> GLContext::Create(ContextKind kind) {
    std::unique_ptr<GLContext> ctx(new GLContext());
    ctx->mKind = kind;
    if (kind == ContextKind::OSMesa) {
        const int attribs[] = {OSMESA_FORMAT, OSMESA_RGBA, OSMESA_DEPTH_BITS, 0, OSMESA_PROFILE, OSMESA_CORE_PROFILE,
                               OSMESA_CONTEXT_MAJOR_VERSION, 4, OSMESA_CONTEXT_MINOR_VERSION, 5, 0};
        OSMesaContext context = OSMesaCreateContextAttribs(attribs, nullptr);
        if (!context) return MakeError("gl: OSMesa could not create an OpenGL 4.5 core context (libosmesa6)");
        ctx->mOsmesa = context;
        // OSMesa needs a default framebuffer; the passes render to their own.
        ctx->mOsmesaBuffer = std::make_unique<unsigned char[]>(4 * 4 * 4);
        if (!OSMesaMakeCurrent(context, ctx->mOsmesaBuffer.get(), GL_UNSIGNED_BYTE, 4, 4))
            return MakeError("gl: OSMesaMakeCurrent failed");
        CB_TRY(ctx->LoadFunctions(&OsmesaResolve));
    } else {
        // EGL without a window: the surfaceless platform (Mesa), else the default display.
        auto getPlatformDisplay =
            reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
        EGLDisplay display = EGL_NO_DISPLAY;
        if (getPlatformDisplay) display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (display == EGL_NO_DISPLAY) display = eglGetDisplay(EGL_DEFAULT_DISPLAY);
        if (display == EGL_NO_DISPLAY || !eglInitialize(display, nullptr, nullptr))
            return MakeError("gl: no EGL display could be initialised (libegl1, libegl-mesa0 or a GPU driver)");
        ctx->mEglDisplay = display;
        if (!eglBindAPI(EGL_OPENGL_API)) return MakeError("gl: EGL has no desktop OpenGL API");
        // No surface is ever made, so a config is only needed where
        // EGL_KHR_no_config_context is missing.
        const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
        EGLConfig config = EGL_NO_CONFIG_KHR;
        EGLint count = 0;
        const char* extensions = eglQueryString(display, EGL_EXTENSIONS);
        const bool noConfig = extensions && std::strstr(extensions, "EGL_KHR_no_config_context");
        if (!noConfig && (!eglChooseConfig(display, configAttribs, &config, 1, &count) || count == 0))
            return MakeError("gl: EGL has no OpenGL config");
        const EGLint contextAttribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
        EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
        if (context == EGL_NO_CONTEXT) return MakeError("gl: EGL could not create an OpenGL 4.5 core context");
        ctx->mEglContext = context;
        if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
            return MakeError("gl: EGL could not make the context current without a surface");
        CB_TRY(ctx->LoadFunctions(&EglResolve));
    }
    const Functions& f = ctx->mF;
    f.CreateVertexArrays(1, &ctx->mVao);
    f.CreateFramebuffers(1, &ctx->mFramebuffer);
    f.Disable(GL_DEPTH_TEST);
    f.Disable(GL_BLEND);
    CB_TRY(ctx->Check("creating the context objects"));
    return ctx;
}

void GLContext::MakeCurrent() const {
    if (mOsmesa && OSMesaGetCurrentContext() != mOsmesa)
        OSMesaMakeCurrent(static_cast<OSMesaContext>(mOsmesa), mOsmesaBuffer.get(), GL_UNSIGNED_BYTE, 4, 4);
    if (mEglContext && eglGetCurrentContext() != mEglContext)
        eglMakeCurrent(mEglDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, mEglContext);
}

GLContext::~GLContext() {
    // The objects are this context's: delete them with it current, not another's of the same names.
    MakeCurrent();
    if (mF.DeleteProgram) {
        for (auto& [name, program] : mPrograms) mF.DeleteProgram(program);
        if (mVao) mF.DeleteVertexArrays(1, &mVao);
        if (mFramebuffer) mF.DeleteFramebuffers(1, &mFramebuffer);
    }
    if (mOsmesa) OSMesaDestroyContext(static_cast<OSMesaContext>(mOsmesa));
    if (mEglDisplay) {
        eglMakeCurrent(mEglDisplay, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        if (mEglContext) eglDestroyContext(mEglDisplay, mEglContext);
        eglTerminate(mEglDisplay);
    }
}

bool GLContext::SoftwareRasterizer() const {
    const std::string renderer = String(GL_RENDERER);
    return renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos;
}

std::string GLContext::Renderer() const {
    return String(GL_RENDERER) + (mKind == ContextKind::OSMesa ? " (OSMesa)" : " (EGL)");
}

std::string GLContext::String(GLenum name) const {
    const char* text = reinterpret_cast<const char*>(F().GetString(name));
    return text ? text : "?";
}

GLint GLContext::Integer(GLenum name) const {
    GLint value = 0;
    F().GetIntegerv(name, &value);
    return value;
}

Status GLContext::Check(const char* what) const {
    const GLenum e = F().GetError();
    if (e == GL_NO_ERROR) return {};
    return MakeError(std::string("gl: ") + what + ": " + ErrorName(e));
}

Result<GLuint> GLContext::Program(const std::string& name, const std::string& defines) {
    const std::string key = defines.empty() ? name : name + "\n" + defines;
    if (auto it = mPrograms.find(key); it != mPrograms.end()) return it->second;
    const std::string* fragment = FindShader(name + ".frag");
    if (!fragment) return MakeError("gl: no shader named '" + name + "'");
    std::string source = *fragment;
    if (!defines.empty()) source.insert(source.find('\n') + 1, defines);
    const std::string* vertex = FindShader(name + ".vert");
    std::string vertexSource;
    if (vertex && !defines.empty()) {
        vertexSource = *vertex;
        vertexSource.insert(vertexSource.find('\n') + 1, defines);
        vertex = &vertexSource;
    }
    auto program = LinkProgram(name, vertex, source);
    if (program) mPrograms[key] = *program;
    return program;
}

Result<GLuint> GLContext::LayeredProgram(const std::string& name, const std::string& defines) {
    const std::string key = "layered\n" + name + "\n" + defines;
    if (auto it = mPrograms.find(key); it != mPrograms.end()) return it->second;
    const std::string* fragment = FindShader(name + ".frag");
    if (!fragment) return MakeError("gl: no shader named '" + name + "'");
    if (FindShader(name + ".vert")) return MakeError("gl: pass '" + name + "' has its own vertex shader");
    std::string source = *fragment;
    const std::string uniform = "uniform int layer;";
    const size_t at = source.find(uniform);
    if (at == std::string::npos) return MakeError("gl: pass '" + name + "' has no uniform layer");
    source.replace(at, uniform.size(), "flat in int layer;");
    if (!defines.empty()) source.insert(source.find('\n') + 1, defines);
    const std::string vertex = kLayeredVertex;
    auto program = LinkProgram(name + " (layered)", &vertex, source);
    if (program) mPrograms[key] = *program;
    return program;
}

Result<GLuint> GLContext::LinkProgram(const std::string& name, const std::string* vertex, const std::string& fragment) {
    MakeCurrent();
    auto vs = Compile(mF, GL_VERTEX_SHADER, vertex ? *vertex : std::string(kFullScreenVertex), name + " vertex");
    if (!vs) return std::unexpected(vs.error());
    auto fs = Compile(mF, GL_FRAGMENT_SHADER, fragment, name + " fragment");
    if (!fs) {
        mF.DeleteShader(*vs);
        return std::unexpected(fs.error());
    }
    const GLuint program = mF.CreateProgram();
    mF.AttachShader(program, *vs);
    mF.AttachShader(program, *fs);
    mF.LinkProgram(program);
    mF.DeleteShader(*vs);
    mF.DeleteShader(*fs);
    GLint ok = 0;
    mF.GetProgramiv(program, GL_LINK_STATUS, &ok);
    if (!ok) {
        const std::string log = InfoLog(program, mF.GetProgramiv, mF.GetProgramInfoLog);
        mF.DeleteProgram(program);
        return MakeError("gl: linking the " + name + " program failed:\n" + log);
    }
    return program;
}

}  // namespace cb::gl
