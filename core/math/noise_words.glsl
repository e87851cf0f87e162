// The header words of stage noise's data block (core/math/NoiseGpu.h lays the
// block out: a header, the permutation tables, HD per slice, the towers, the
// detail volume): each word's name and index, the one list both languages read.
// core/math/NoiseGpu.h makes of it the C++ enum noise::GpuWord (kGpu<Name>),
// core/math/noise.glsl the GLSL constants kNoise<Name>. Plain preprocessor, the
// same in C++ and GLSL; a vector's components take consecutive words from its index.
#ifndef CLOUDBENCH_NOISE_WORDS_GLSL
#define CLOUDBENCH_NOISE_WORDS_GLSL

#define CB_NOISE_WORDS(X)                                                      \
    X(Nx, 0u)             /* the grid */                                       \
    X(Ny, 1u)                                                                  \
    X(Nz, 2u)                                                                  \
    X(Basis, 3u)          /* fBm: NoiseBasis */                                \
    X(Octaves, 4u)                                                             \
    X(Gain, 5u)           /* float */                                          \
    X(Lacunarity, 6u)                                                          \
    X(Turbulence, 7u)     /* 0 or 1 */                                         \
    X(Scale, 8u)          /* 3 floats: frequency / n per axis */               \
    X(Period, 11u)        /* 3 words: the frequency per axis */                \
    X(DetailOn, 14u)                                                           \
    X(DetailSize, 15u)                                                         \
    X(Strength, 16u)      /* float */                                          \
    X(CoverageOn, 17u)                                                         \
    X(Coverage, 18u)      /* float */                                          \
    X(Density, 19u)       /* float */                                          \
    X(Threshold, 20u)     /* float */                                          \
    X(MapOctaves, 21u)                                                         \
    X(MapGain, 22u)       /* float */                                          \
    X(MapPeriod, 23u)     /* 2 words */                                        \
    X(MapScale, 25u)      /* 2 floats */                                       \
    X(TowerCount, 27u)                                                         \
    X(Seed, 28u)                                                               \
    X(BasePerm, 29u)      /* where the base permutation starts (a word index) */ \
    X(MapPerm, 30u)       /* the weather map's permutation */                  \
    X(Heights, 31u)       /* HD per slice */                                   \
    X(Towers, 32u)        /* 7 floats per tower */                             \
    X(Detail, 33u)        /* the detail volume */

#endif
