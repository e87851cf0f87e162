// Stage `region` (SPEC 2, docs/contract.md): the region volume R from the ellipsoids (Fizimayer's
// thesis, chapter 4).
// Its home: the types (RegionTypes.h), the reader of its section, its descriptor and its call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/region/RegionTypes.h"

namespace cb {

namespace scene_io {
void ReadEllipsoids(const Json& root, Validator& check, EllipsoidSettings& ellipsoids);
}  // namespace scene_io

const StageDescriptor& DescribeRegion();
Status CallRegion(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                  StageCallRecord& record);

}  // namespace cb
