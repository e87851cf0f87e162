// Stage `ca` (SPEC 3, docs/contract.md): Dobashi's cellular automaton on the humidity, activation
// and cloud bit fields (Dobashi et al. 2000; Fizimayer's thesis, chapter 3).
// Its home: the types (CaTypes.h), the reader of its section, its parameters from a scene, its descriptor and its call
// adapter.
#pragma once

#include <cstdint>
#include <optional>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/ca/CaTypes.h"

namespace cb {

namespace scene_io {
// `nz` is the grid's when known; the wind shift stays as written (one pair or nz pairs).
void ReadCa(const Json& root, Validator& check, std::optional<uint32_t> nz, CaSettings& ca);
}  // namespace scene_io

CaInitParams MakeCaInitParams(const Scene& scene);
// Without the wind shifts, which the caller keeps alive and sets.
CaStepParams MakeCaStepParams(const Scene& scene, uint32_t step);

const StageDescriptor& DescribeCa();
Status CallCa(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
              StageCallRecord& record);

}  // namespace cb
