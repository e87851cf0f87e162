// GLSL sources of impl_gl/shaders, each with "#version 450 core" and the
// shared includes of core/glsl prepended, embedded at build time after
// glslangValidator checked them (a syntax error fails the build).
#pragma once

#include <string>

namespace cb::gl {

// The fragment shader of pass `name` (shaders/<name>.frag); nullptr if none.
const std::string* FindFragmentShader(const std::string& name);

}  // namespace cb::gl
