#include "random.glsl"
#include "rules.glsl"
#include "shading.glsl"
#include "automaton.glsl"
#include "phase_table.glsl"
#include "light.glsl"
#include "march.glsl"
#include "layers.glsl"
// Stage `render_layers` (SPEC 15): one mesh, a screen quad (its corners from
// gl_VertexID, a triangle strip), drawn instanced N times; instance n is layer
// layerOrder[n], so the layers arrive back to front (core/pipeline/LayersGpu.h
// LayersDrawOrder). The plane is rasterised exactly: render_layers.frag meets
// each pixel's own ray with the layer's plane, as the CPU does. The quad is cut
// by a clip distance to the pixels whose ray climbs toward the layer (d_z of
// the layer's sign, two pixels of margin): a layer above the eye covers the
// sky above the horizon, one below the ground below it, so the rasteriser
// still skips the side of the eye a layer cannot be seen on. A world-space
// quad as large as the extent lost fragments to the near-plane clip's
// rounding (docs/pipeline.md, "Layered renderer").
layout(std140, binding = 0) uniform LayersBlock { LayersGpu layers; };
layout(std430, binding = 1) readonly buffer LayersOrder { uint layerOrder[]; };
#ifdef LAYERS_BILLBOARDS
layout(std430, binding = 6) readonly buffer LayersBillboards { LayersBillboard layersBillboards[]; };
LayersBillboard LayersBillboardAt(uint i) { return layersBillboards[i]; }
#else
LayersBillboard LayersBillboardAt(uint i) { return LayersBillboard(vec3(0.0), 0.0); }
#endif
flat out uint layerIndex;  // with LAYERS_BILLBOARDS, the billboard's index
out float gl_ClipDistance[1];

// march.glsl's fetches: the vertex stage reads no volume (it never samples one; render_layers.frag does).
vec2 MarchFetchQT(uint paddedIndex) { return vec2(0.0, 1.0); }
float MarchFetchSkyT(uint paddedIndex) { return 1.0; }
bool MarchBrickEmpty(uint brick) { return false; }
float PhaseTableValue(uint i) { return 1.0; }
float LayersMapValue(uint i) { return 0.0; }

#ifdef LAYERS_BILLBOARDS
// Billboard gl_InstanceID (LOD0; the list is in drawing order): its quad in the image plane, halfWidth along right
// and halfHeight along up of its centre at its view depth D, grown by two pixels (2 D / focal) and 1e-5 of the
// coordinates' magnitude on every side (core/math/Layers.h LayersBillboardRect); the
// fragment shader then tests each pixel's ray exactly (BillboardFragment), so the rasteriser's rounding never
// moves an edge. The quad is parallel to the image plane: its projection is a rectangle. A billboard nearer than
// half the near plane (whose fragments all fail t >= tNear) is dropped.
void main() {
    layerIndex = uint(gl_InstanceID);
    gl_ClipDistance[0] = 1.0;
    const LayersBillboard b = layersBillboards[gl_InstanceID];
    const float depth = b.depth;
    if (!(depth >= 0.5 * layers.nearPlane / layers.voxelSize)) {
        gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
        return;
    }
    const vec2 corner = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0);
    const float W = float(layers.width), H = float(layers.height), focal = layers.focalPx;
    const vec3 rel = b.centre - layers.eye;
    const vec3 magnitude = max(abs(b.centre), abs(layers.eye));
    const float margin = 2.0 * depth / focal + 1e-5 * max(1.0, max(magnitude.x, max(magnitude.y, magnitude.z)));
    const float x = dot(rel, layers.right) + corner.x * (layers.halfWidth + margin);
    const float y = dot(rel, layers.up) + corner.y * (layers.halfHeight + margin);
    // Pixel coordinates (rows from the top, as render_layers.frag's gl_FragCoord), then NDC.
    const float px = 0.5 * W + focal * x / depth, py = 0.5 * H - focal * y / depth;
    gl_Position = vec4(2.0 * px / W - 1.0, 2.0 * py / H - 1.0, 0.0, 1.0);
}
#else
void main() {
    const uint i = layerOrder[gl_InstanceID];
    layerIndex = i;
    const vec2 ndc = vec2((gl_VertexID & 1) != 0 ? 1.0 : -1.0, (gl_VertexID & 2) != 0 ? 1.0 : -1.0);
    // Window row y is the image's row y from the top (render_march.frag), so the corner's pixel coordinates are
    // ((ndc + 1) / 2) (W, H), and its ray (MakeLayersRay, unnormalised) forward + u right + v up.
    const float W = float(layers.width), H = float(layers.height), focal = layers.focalPx;
    const float u = ((ndc.x + 1.0) * 0.5 * W - 0.5 * W) / focal;
    const float v = (0.5 * H - (ndc.y + 1.0) * 0.5 * H) / focal;
    const float dz = layers.forward.z + u * layers.right.z + v * layers.up.z;
    const float height = LayerHeight(layers, i) - layers.eye.z;
    const float side = height > 0.0 ? 1.0 : (height < 0.0 ? -1.0 : 0.0);
    const float margin = 2.0 * length(vec2(layers.right.z, layers.up.z)) / focal;
    gl_ClipDistance[0] = side == 0.0 ? -1.0 : side * dz + margin;
    gl_Position = vec4(ndc, 0.0, 1.0);
}
#endif
