// Stage `smooth` (SPEC 4, docs/contract.md): binomial smoothing of the cloud field cld into the density q.
// Its home: the types (SmoothTypes.h), the reader of its section, its descriptor and its call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/smooth/SmoothTypes.h"

namespace cb {

namespace scene_io {
void ReadSmooth(const Json& root, Validator& check, SmoothSettings& smooth);
}  // namespace scene_io

const StageDescriptor& DescribeSmooth();
Status CallSmooth(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record);

}  // namespace cb
