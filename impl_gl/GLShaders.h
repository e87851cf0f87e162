// GLSL sources of impl_gl/shaders, each with "#version 450 core" and the
// shared includes of core/math prepended, embedded at build time after
// glslangValidator checked them (a syntax error fails the build).
#pragma once

#include <string>

namespace cb::gl {

// The source of shaders/<file> (e.g. "smooth.frag"); nullptr if none.
const std::string* FindShader(const std::string& file);

}  // namespace cb::gl
