// What the host files of the GL stages share besides BackendGL's private
// members: included by BackendGL.cpp and each <Stage>GL.cpp, not by users of the backend.
#pragma once

#include <array>
#include <span>
#include <utility>

#include "impl_gl/BackendGL.h"

namespace cb::gl {

// The texture behind a buffer; every buffer this backend sees is one it created.
inline const BufferGL& Tex(const Buffer& b) { return static_cast<const BufferGL&>(b); }

template <typename PerLayer>
Status BackendGL::DrawLayerRange(GLuint program, uint32_t begin, uint32_t end, std::initializer_list<GLuint> textures,
                                 PerLayer&& perLayer) {
    if (IsLayered(program)) return MakeError("gl: a layered pass cannot set uniforms per layer");
    const Functions& f = mContext->F();
    const GLint layerUniform = f.GetUniformLocation(program, "layer");
    std::array<std::pair<GLuint, int>, 4> targets;
    if (textures.size() > targets.size()) return MakeError("gl: a pass has more than 4 render targets");
    for (uint32_t k = begin; k < end; ++k) {
        size_t n = 0;
        for (GLuint texture : textures) targets[n++] = {texture, int(k)};
        CB_TRY(BindTargets(std::span(targets.data(), n)));
        f.Uniform1i(layerUniform, GLint(k));
        perLayer(k);
        Draw(GL_TRIANGLES, 0, 3);
    }
    return {};
}

}  // namespace cb::gl
