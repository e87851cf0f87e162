// The image operations that need OpenImageIO, and the OpenVDB volume writer, in
// a module of their own (libcloudbench_images.so) that the harness loads on
// first use.
//
// OpenImageIO brings about 260 shared libraries with it; loading them and
// running their initialisers takes about 0.2 s of every process (measured on
// Debian 12: 0.21 s for an empty program linked with OpenImageIO, 0.02 s for
// one linked with everything else cloudbench uses). Most commands never touch
// an image (a refused input, `perf`, `merge`, `devices`), so the module is
// opened only by the first call that writes, reads or compares one.
//
// The interface is plain values (sizes and float pixels), so that nothing of
// OpenImageIO leaks into the harness. The module is built with the harness, by
// the same compiler, and is found beside the executable or in the build tree.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/base/Error.h"

namespace cb::images {

// Bumped whenever Module changes, so that a stale module is refused by name.
inline constexpr int kModuleVersion = 3;

// The file name of the module, beside the executable.
inline constexpr const char* kModuleFileName = "libcloudbench_images.so";

// An image to read: `channels` interleaved floats a pixel, row 0 at the top;
// `colorSpace` is OpenImageIO's name for its encoding ("sRGB"), written into
// the file's metadata (a PNG's sRGB, gAMA and cHRM chunks), or empty.
struct ImageView {
    int width = 0, height = 0, channels = 0;
    const float* pixels = nullptr;
    const char* colorSpace = "";
};

// An image made by the module, laid out as ImageView.
struct FloatImage {
    int width = 0, height = 0, channels = 0;
    std::vector<float> pixels;
    std::string colorSpace;
    ImageView View() const { return {width, height, channels, pixels.data(), colorSpace.c_str()}; }
};

// A float volume to write: nx * ny * nz values, x fastest, voxel (i, j, k) centred at world
// origin + (i + 1/2, j + 1/2, k + 1/2) voxelSize.
struct VolumeView {
    unsigned nx = 0, ny = 0, nz = 0;
    const float* values = nullptr;
    double origin[3] = {0, 0, 0};
    double voxelSize = 1;
    const char* name = "";  // the grid's name
};

// OpenImageIO's ImageBufAlgo::compare of two images of one size.
struct Comparison {
    double maxError = 0, meanError = 0, psnr = 0;
    size_t pixelsOverTolerance = 0;  // failures and warnings: a pixel counts once
    int worstX = 0, worstY = 0;
};

// Each function that can fail returns "" or the reason, without the path.
struct Module {
    int version = 0;
    // Writes `image` to `path` as `format` ("png", "exr"; the path may have
    // no extension), 8-bit when `eightBit`, float otherwise, then reads the
    // file back and checks that it holds the whole image.
    std::string (*write)(const std::string& path, const std::string& format, ImageView image, bool eightBit);
    // The first `channels` channels, as floats, of the image file whose bytes are `bytes` (read by the path
    // policy, core/base/PathPolicy.h); `name` is the file's name, whose extension says its format.
    std::string (*decode)(const std::string& name, const std::string& bytes, int channels, FloatImage& image);
    // failthresh `limit`, warnthresh `tolerance`.
    Comparison (*compare)(ImageView a, ImageView b, float limit, float tolerance);
    // |a - b| per channel, times `gain` when it is not 1, clamped to [0, 1] when `clamp`.
    std::string (*difference)(ImageView a, ImageView b, float gain, bool clamp, FloatImage& out);
    // OpenImageIO's colour conversion from "linear" to "sRGB" (colorSpace "sRGB").
    std::string (*linearToSrgb)(ImageView linear, FloatImage& srgb);
    // `image` as an 8-bit PNG file in memory.
    std::string (*encodePng)(ImageView image, std::string& bytes);
    // `volume` as an OpenVDB file of one fog-volume float grid: background 0, every voxel whose value is not
    // +0 (its bits) active with that value, so that reading every voxel back gives the values bit for bit;
    // the index-to-world transform scales by voxelSize and translates by origin + voxelSize / 2. The file is
    // read back and its active voxels counted.
    std::string (*writeVdb)(const std::string& path, VolumeView volume);
};

// The module, opened on the first call and kept; an error names the file
// tried and the loader's reason.
Result<const Module*> Load();

}  // namespace cb::images

// The module's one exported symbol.
extern "C" const cb::images::Module* cloudbench_image_module();
