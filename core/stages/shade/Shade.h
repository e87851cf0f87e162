// Stage `shade` (SPEC 6, docs/contract.md): the transmittance T toward the sun by inverse shear-warp
// (Fizimayer's thesis, chapter 5).
// Its home: the types (ShadeTypes.h), the reader of its section, its parameters from a scene, its descriptor and its
// call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/shade/ShadeTypes.h"

namespace cb {

namespace scene_io {
void ReadShade(const Json& root, Validator& check, ShadeSettings& shade);
}  // namespace scene_io

// The sun shade lights toward at `step`: the scene's (SunSettings::DirectionAt; step 0 is the fixed sun's), or
// when a renderer relights (Scene::needs.shadeOnce) the first step's at every step (Wang, Ji and Zhang: shade once).
Vec3 ShadeSunAt(const Scene& scene, uint32_t step);
ShadeParams MakeShadeParams(const Scene& scene, uint32_t step = 0);

// SPEC 6's comparison of T: 1e-5 in fp32, one storage quantum on the stored codes otherwise (T_sky's too).
CompareRule ShadeCompareRule(const Scene& scene);

// Two of its choice settings (its descriptor's `choices`), for the commands that set them.
const ChoiceSetting& ShadeResolutionSetting();
const ChoiceSetting& ShadeScatteringSetting();

const StageDescriptor& DescribeShade();
Status CallShade(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                 StageCallRecord& record);

}  // namespace cb
