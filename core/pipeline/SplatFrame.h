// The frame every splat of one image shares (SplatFrame, core/math/Splat.h),
// made from stage render_splat's parameters.
#pragma once

#include <cstdint>

#include "core/math/Splat.h"
#include "core/pipeline/Backend.h"

namespace cb {

// The frame of one image of `grid` in `width` x `height` pixels.
SplatFrame MakeSplatFrame(const SplatParams& params, const Extent3& grid, const FlatSplatOrder& order, uint32_t width,
                          uint32_t height);

}  // namespace cb
