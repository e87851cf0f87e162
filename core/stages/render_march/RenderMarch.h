// Stage `render_march` (SPEC 10, docs/contract.md): the per-pixel ray march (Olajos, Santos and
// Dehling), lit by the sun and the lightning's point light (Wang, Ji and Zhang, section 6.3).
// Its home: the types (RenderMarchTypes.h), the reader of its section, its parameters from a scene, its descriptor and
// its call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/render_march/RenderMarchTypes.h"

namespace cb {

namespace scene_io {
// `stages` is the scene's list: the default light source "shade" needs the shade stage when render_march runs.
void ReadMarch(const Json& root, Validator& check, const StageSet& stages, MarchSettings& march);
}  // namespace scene_io

// The ray marcher's parameters for one camera at `step` (the jitter's frame, the lightning's flash window and the
// sun), frame `frame` of a step of `frames` frames (its alpha).
MarchParams MakeMarchParams(const Scene& scene, const CameraSettings& camera, uint32_t step, uint32_t frame = 0,
                            uint32_t frames = 0);

const StageDescriptor& DescribeRenderMarch();
Status CallRenderMarch(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                       StageCallRecord& record);

}  // namespace cb
