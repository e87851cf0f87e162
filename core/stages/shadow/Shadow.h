// Stage `shadow` (SPEC 7, docs/contract.md): the ground shadow G from the column sums D.
// Its home: the types (ShadowTypes.h), the reader of its section, its parameters from a scene, its descriptor and its
// call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/shadow/ShadowTypes.h"

namespace cb {

namespace scene_io {
void ReadShadow(const Json& root, Validator& check, ShadowSettings& shadow);
}  // namespace scene_io

// The sun is the scene's at `step`.
ShadowParams MakeShadowParams(const Scene& scene, uint32_t step = 0);

const StageDescriptor& DescribeShadow();
Status CallShadow(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record);

}  // namespace cb
