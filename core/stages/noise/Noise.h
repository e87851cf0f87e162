// Stage `noise` (SPEC 10a, docs/contract.md): a producer of q formed from noise (Olajos, Santos and
// Dehling), instead of the automaton and smoothing.
// Its home: the types (NoiseTypes.h), the reader of its section, its parameters from a scene, its descriptor and its
// call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/noise/NoiseTypes.h"

namespace cb {

namespace scene_io {
void ReadNoise(const Json& root, Validator& check, NoiseSettings& noise);
// Section `key` of `parent` (at `parentField`) as Wang, Ji and Zhang's eq. 15-16 settings: coverage, density and
// the 2-D map's frequency, octaves and gain (noise.coverage, and render_layers' layers.wang); enabled when present.
void ReadCoverage(const Json& parent, std::string_view parentField, std::string_view key, Validator& check,
                  NoiseCoverage& coverage);
}  // namespace scene_io

// Points into scene.noise: the scene must outlive the parameters.
NoiseParams MakeNoiseParams(const Scene& scene, uint32_t step);

const StageDescriptor& DescribeNoise();
Status CallNoise(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                 StageCallRecord& record);

}  // namespace cb
