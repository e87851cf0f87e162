// The OpenGL backend's options and their names. Header-only and free of GL
// types, so that the registry and the command line can name them in a build
// without the OpenGL backend; each table is the one spelling used for parsing,
// messages and help.
#pragma once

#include <array>

#include "core/base/NamedValues.h"

namespace cb::gl {

// The context the backend runs in: OSMesa (llvmpipe) or EGL without a window
// (the surfaceless platform, or a GPU's driver).
enum class ContextKind { OSMesa, Egl };

// How the automaton's state is stored: Packed, one R32UI texel per 32 voxels
// of a row; Rgba8, the thesis's one RGBA8 texel per voxel, a channel per bit.
// Both are bit-exact; only the ca stage differs.
enum class CaLayout { Packed, Rgba8 };

// The first entry of each table is the default.
inline constexpr std::array<NamedValue<ContextKind>, 2> kContextKindNames{{
    {"osmesa", ContextKind::OSMesa},
    {"egl", ContextKind::Egl},
}};
inline constexpr std::array<NamedValue<CaLayout>, 2> kCaLayoutNames{{
    {"packed", CaLayout::Packed},
    {"rgba8", CaLayout::Rgba8},
}};

constexpr std::string_view ContextKindName(ContextKind kind) { return NameOf(kContextKindNames, kind); }
constexpr std::string_view CaLayoutName(CaLayout layout) { return NameOf(kCaLayoutNames, layout); }

}  // namespace cb::gl
