// Stage `render_splat` (SPEC 8, docs/contract.md): point-sprite splatting of the density volume
// (Fizimayer's thesis, chapter 6).
// Its home: the types (RenderSplatTypes.h), the reader of its section, its parameters from a scene, its descriptor and
// its call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/render_splat/RenderSplatTypes.h"

namespace cb {

namespace scene_io {
// The splat renderer's fields of the `render` section (its keys are checked by ReadRender).
void ReadSplat(const Json& root, Validator& check, SplatSettings& splat);
}  // namespace scene_io

// Everything but the order, which the caller makes (MakeSplatOrder) and keeps alive; the sun at `step`, alpha of
// frame `frame` of a step of `frames` frames (RenderSettings::FrameAlpha; 0: render.frames_per_step).
SplatParams MakeSplatParams(const Scene& scene, const CameraSettings& camera, uint32_t step = 0, uint32_t frame = 0,
                            uint32_t frames = 0);

const StageDescriptor& DescribeRenderSplat();
Status CallRenderSplat(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record);

}  // namespace cb
