// Stage `render_layers` (SPEC 15, docs/contract.md): Wang, Ji and Zhang's layered renderer,
// N horizontal layers around the eye composited back to front, lit by shade's T.
// Its home: the types (RenderLayersTypes.h), the reader of its section, its parameters from a scene,
// its descriptor and its call adapter.
#pragma once

#include <cstdint>

#include "core/pipeline/StageAdapter.h"
#include "core/pipeline/StageDescriptor.h"
#include "core/scene/SectionReader.h"
#include "core/stages/render_layers/RenderLayersTypes.h"

namespace cb {

namespace scene_io {
// `nz` is the grid's, when its size was read: the layer count is checked against it.
void ReadLayers(const Json& root, Validator& check, std::optional<uint32_t> nz, LayersSettings& layers);
// LOD0's radius against the layers' extent (layers.extent, or each camera's far plane) and the billboards' count
// (LayersBillboardBound, with `grid` read), once the scene's other sections are read.
void CheckLayersLod0(const Scene& scene, const Extent3* grid, Validator& check);
}  // namespace scene_io

// The layered renderer's parameters for one camera at `step` (the sun), frame `frame` of a step of `frames`
// frames (its alpha). With layers.wang the caller points setup.map at MakeLayersMap's values.
LayersParams MakeLayersParams(const Scene& scene, const CameraSettings& camera, uint32_t step, uint32_t frame = 0,
                              uint32_t frames = 0);
// With layers.wang, the modulation map m at `step`: the noise stage's weather map (core/math/Noise.h
// NoiseForm::Map) with layers.wang's frequency, octaves and gain, the scene's noise seed and drift, at each column
// centre (nx * ny values, x fastest); empty without.
std::vector<float> MakeLayersMap(const Scene& scene, uint32_t step);

// LOD0's grid spacing p_s in metres: layers.billboard_spacing, or the voxel size when it is 0.
double LayersBillboardSpacing(const Scene& scene);

const StageDescriptor& DescribeRenderLayers();
Status CallRenderLayers(Backend& backend, const Scene& scene, const StageHostInputs& host, const StageBuffers& io,
                        StageCallRecord& record);

}  // namespace cb
