// Stage `render_splat` (SPEC 8), the thesis's way (its chapter 6): one
// GL_POINTS vertex per voxel, drawn in the shared back-to-front order (the
// vertex id is the voxel's rank), so blending composites in that order. The
// vertex shader reads the volumes and throws away voxels that make no splat
// (section 6.2) by placing them outside the clip volume.
layout(std430, binding = 0) readonly buffer Order { uint orderIndex[]; };  // outer, middle, inner axis orders
layout(std430, binding = 1) buffer Counters { uint splatCount; };
layout(binding = 0) uniform sampler2DArray qPrev;
layout(binding = 1) uniform sampler2DArray qCur;
layout(binding = 2) uniform sampler2DArray transmittance;
uniform ivec3 grid;        // nx, ny, nz
uniform ivec3 axes;        // outer, middle, inner axis
uniform ivec3 orderBase;   // where each axis's order starts in orderIndex
uniform vec2 image;        // width, height in pixels
uniform float guard;       // pixels of viewport beyond each image edge
uniform vec4 eye;          // xyz, near
uniform vec4 forward;      // xyz, focal length in pixels
uniform vec3 right, up;
uniform vec4 sun;          // xyz toward the sun, phase g
uniform vec4 sunRadiance;  // rgb, phase kind
uniform vec4 ambient;      // rgb, q_min
uniform vec4 origin;       // xyz, voxel size
uniform vec4 misc;         // splat diameter, alpha, opacity, largest point size
flat out vec4 colour;      // rgb, q_alpha * opacity
flat out vec3 splat;       // px, py, size (pixels; row 0 at the top)

void Reject() {
    gl_Position = vec4(2.0, 2.0, 2.0, 1.0);
    gl_PointSize = 1.0;
}

void main() {
    const int rank = gl_VertexID;
    const int nMid = grid[axes.y], nIn = grid[axes.z];
    ivec3 idx;
    idx[axes.x] = int(orderIndex[orderBase.x + rank / (nMid * nIn)]);
    idx[axes.y] = int(orderIndex[orderBase.y + (rank % (nMid * nIn)) / nIn]);
    idx[axes.z] = int(orderIndex[orderBase.z + rank % nIn]);
    precise float qa = texelFetch(qPrev, idx, 0).r + misc.y * (texelFetch(qCur, idx, 0).r - texelFetch(qPrev, idx, 0).r);
    if (!(qa > ambient.w)) {
        Reject();
        return;
    }
    const float h = origin.w;
    precise vec3 centre = vec3(origin.x + (float(idx.x) + 0.5) * h, origin.y + (float(idx.y) + 0.5) * h,
                               origin.z + (float(idx.z) + 0.5) * h);
    precise float dx = centre.x - eye.x, dy = centre.y - eye.y, dz = centre.z - eye.z;
    precise float x = dx * right.x + dy * right.y + dz * right.z;
    precise float y = dx * up.x + dy * up.y + dz * up.z;
    precise float depth = dx * forward.x + dy * forward.y + dz * forward.z;
    if (!(depth > eye.w)) {
        Reject();
        return;
    }
    const float focal = forward.w;
    precise float px = 0.5 * image.x + x * focal / depth;
    precise float py = 0.5 * image.y - y * focal / depth;
    precise float size = clamp(misc.x * focal / depth, 1.0, 255.0);
    precise float len = sqrt(dx * dx + dy * dy + dz * dz);
    precise float cosTheta = (sun.x * dx + sun.y * dy + sun.z * dz) / len;
    precise float light = texelFetch(transmittance, idx, 0).r * PhaseValue(uint(sunRadiance.w), sun.w, cosTheta);
    colour = vec4(sunRadiance.rgb * light + ambient.rgb, qa * misc.z);
    splat = vec3(px, py, size);
    atomicAdd(splatCount, 1u);
    // Window y = py, so framebuffer row 0 is the image's top row. The point is
    // drawn two pixels wider than the splat and the fragment shader keeps
    // exactly SPEC 8's coverage; the viewport's guard band keeps points whose
    // centre is just off the image from being clipped whole.
    const vec2 viewport = image + 2.0 * guard;
    gl_Position = vec4((vec2(px, py) + guard) / viewport * 2.0 - 1.0, 0.0, 1.0);
    gl_PointSize = min(size + 2.0, misc.w);
}
