// The renderers' padded volumes (march_volume.comp, sky_volume.comp): (nx+2) x (ny+2) x (nz+2) with voxel
// (i, j, k) at padded (i+1, j+1, k+1), the border outside the grid or, wrapped (tiling), the opposite edge's voxel
// (core/math/March.h PaddedSourceVoxel).
#ifndef CLOUDBENCH_PADDED_VOLUME_GLSL
#define CLOUDBENCH_PADDED_VOLUME_GLSL

// The voxel padded index i stands for along an axis of n voxels; -1 for the border.
int PaddedSource(uint i, uint n, bool wrap) {
    if (i >= 1u && i <= n) return int(i) - 1;
    if (!wrap) return -1;
    return i == 0u ? int(n) - 1 : 0;
}

#endif
