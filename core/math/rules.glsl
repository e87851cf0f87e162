// GLSL twin of core/math/Rules.h (SPEC 2-4): region weight, quantisation, smoothing weights.
#ifndef CLOUDBENCH_RULES_GLSL
#define CLOUDBENCH_RULES_GLSL

// An ellipsoid as 8 floats: centre xyz, semi-axes abc, cos yaw, sin yaw.
// `precise` keeps the compiler from fusing a*b + c, as the CPU reference does not.
float EllipsoidWeight(vec3 c, vec3 axes, float cosYaw, float sinYaw, vec3 p) {
    precise float ox = p.x - c.x;
    precise float oy = p.y - c.y;
    precise float dz = p.z - c.z;
    precise float dx = cosYaw * ox + sinYaw * oy;
    precise float dy = -sinYaw * ox + cosYaw * oy;
    precise float nx = dx / axes.x;
    precise float ny = dy / axes.y;
    precise float nz = dz / axes.z;
    precise float rho = sqrt(nx * nx + ny * ny + nz * nz);
    return max(0.0, 1.0 - rho);
}

uint QuantizeRegion(float w) {
    precise float r = floor(255.0 * w + 0.5);
    return uint(min(255.0, r));
}

int SmoothWeight(int radius, int d) {
    if (radius == 0) return d == 0 ? 1 : 0;
    if (radius == 1) return (d >= -1 && d <= 1) ? (d == 0 ? 2 : 1) : 0;
    if (d < -2 || d > 2) return 0;
    return d == 0 ? 6 : ((d == 1 || d == -1) ? 4 : 1);
}

#endif
