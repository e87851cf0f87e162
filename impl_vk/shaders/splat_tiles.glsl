// Shared by the splat passes that bin splats into screen tiles (SPEC 8): the
// tiles a splat covers, and the linear invocation id of a 2-D dispatch
// (RenderSplatVk.cpp: rows of kRowGroups workgroups of 64).
#ifndef CLOUDBENCH_SPLAT_TILES_GLSL
#define CLOUDBENCH_SPLAT_TILES_GLSL

// The covered tiles' (tx0, ty0, tx1, ty1), inclusive; none (tx0 > tx1) for an
// empty splat. x0..y1 are clipped to the image, so they are >= 0 when not empty.
uvec4 SplatTileRect(Splat s, uint tileSize) {
    if (s.x0 > s.x1 || s.y0 > s.y1) return uvec4(1u, 0u, 0u, 0u);
    return uvec4(uint(s.x0) / tileSize, uint(s.y0) / tileSize, uint(s.x1) / tileSize, uint(s.y1) / tileSize);
}

uint SplatTileCount(Splat s, uint tileSize) {
    const uvec4 r = SplatTileRect(s, tileSize);
    return r.x > r.z ? 0u : (r.z - r.x + 1u) * (r.w - r.y + 1u);
}

uint LinearInvocation() { return gl_GlobalInvocationID.x + gl_NumWorkGroups.x * 64u * gl_GlobalInvocationID.y; }

#endif
