// Stage `density` (SPEC 5, docs/contract.md): the density map: column sums D, tile and band
// occupancy, and the cover.
// Its home: the types (DensityTypes.h), the reader of its section, its parameters from a scene, its descriptor and its
// call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/density/DensityTypes.h"

namespace cb {

namespace scene_io {
// `grid` is the grid's size when it was valid (the tile and band bounds follow from it).
void ReadDensity(const Json& root, Validator& check, DensitySettings& density, const Extent3* grid);
}  // namespace scene_io

DensityParams MakeDensityParams(const Scene& scene);

const StageDescriptor& DescribeDensity();
Status CallDensity(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                   StageCallRecord& record);

}  // namespace cb
