// The images a run writes and compares (harness/report/Report.h): frame file names,
// the top view of the density map, frames as EXR and PNG, image comparisons
// and difference images, every file written atomically through the image
// module (harness/report/images/ImageModule.h).
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/math/March.h"
#include "harness/report/Report.h"
#include "harness/report/images/ImageModule.h"
#include "harness/run/Session.h"

namespace cb {

std::string_view RendererFileName(Stage renderer) {
    const RendererDescriptor* d = Describe(renderer).renderer;
    return d ? d->fileStem : StageName(renderer);
}

std::string FrameFileStem(Stage renderer, const std::string& camera, const std::string& backend) {
    return "frame-" + std::string(RendererFileName(renderer)) + "-" + camera + (backend.empty() ? "" : "-" + backend);
}

namespace {

// Writes `image` to `path` atomically, through the image module. OpenImageIO
// opens files by name, so it is handed the temporary file's "/proc/self/fd/N"
// (Session::TemporaryFile): opening that name opens the file WriteAtomically
// created exclusively in the output folder's descriptor, whatever link is
// planted in the folder since (measured on Debian 12's OIIO 2.4: PNG and EXR
// write and read back through it, and the file renamed into place holds the
// image). An OIIO IOProxy would do the same for the writers that take one; the
// path works for every format and for the read-back. The format is named from
// `path`'s extension, since the /proc name has none. Errors read
// "PATH: cannot write: <reason>"; Session::WriteAtomically adds the errno.
// The image module, or "PATH: cannot write: <why it cannot be loaded>".
Result<const images::Module*> ModuleToWrite(const std::string& path) {
    auto module = images::Load();
    if (!module) return MakeError(path + ": cannot write: " + module.error().message);
    return module;
}

Status WriteImage(const std::string& path, images::ImageView image, bool eightBit) {
    auto module = ModuleToWrite(path);
    if (!module) return std::unexpected(module.error());
    const std::string extension = std::filesystem::path(path).extension().string();
    const std::string format = extension.empty() ? "" : extension.substr(1);  // "png", "exr"
    return Session::WriteAtomically(path, [&](const Session::TemporaryFile& temp) -> Status {
        const std::string why = (*module)->write(temp.path, format, image, eightBit);
        if (!why.empty()) return MakeError(path + ": cannot write: " + why);
        return {};
    });
}

images::ImageView Rgb(const std::vector<float>& pixels, uint32_t width, uint32_t height) {
    return {int(width), int(height), 3, pixels.data()};
}

}  // namespace

Status WriteTopView(const std::string& path, const std::vector<float>& columnSum, uint32_t nx, uint32_t ny,
                    uint32_t nz) {
    // Optical-depth look: brightness 1 - exp(-D / 4); a column of 4 full voxels is ~63 % white.
    (void)nz;
    std::vector<float> grey(size_t(nx) * ny);
    for (uint32_t y = 0; y < ny; ++y) {
        const uint32_t j = ny - 1 - y;  // top row first, y up
        for (uint32_t i = 0; i < nx; ++i)
            grey[size_t(i) + size_t(nx) * y] = 1.0f - std::exp(-columnSum[size_t(i) + size_t(nx) * j] / 4.0f);
    }
    return WriteImage(path, {int(nx), int(ny), 1, grey.data()}, /*eightBit=*/true);
}

Result<ImageComparison> CompareImages(const std::vector<float>& reference, const std::vector<float>& candidate,
                                      uint32_t width, uint32_t height, const CompareRule& rule) {
    auto module = images::Load();
    if (!module) return MakeError("cannot compare images: " + module.error().message);
    // failthresh: the limit; warnthresh: the tolerance. A pixel counts once, as a failure or a warning.
    const float limit = std::isinf(rule.limit) ? std::numeric_limits<float>::max() : float(rule.limit);
    const images::Comparison result =
        (*module)->compare(Rgb(reference, width, height), Rgb(candidate, width, height), limit, float(rule.tolerance));
    ImageComparison c;
    c.rule = rule;
    c.maxError = result.maxError;
    c.meanError = result.meanError;
    c.psnr = result.psnr;
    c.pixelsOverTolerance = result.pixelsOverTolerance;
    c.pixels = size_t(width) * height;
    c.worstX = result.worstX;
    c.worstY = result.worstY;
    return c;
}

Status WriteDifferenceImage(const std::string& path, const std::vector<float>& reference,
                            const std::vector<float>& candidate, uint32_t width, uint32_t height) {
    auto module = ModuleToWrite(path);
    if (!module) return std::unexpected(module.error());
    images::FloatImage difference;
    const std::string why = (*module)->difference(Rgb(reference, width, height), Rgb(candidate, width, height), 1.0f,
                                                  /*clamp=*/false, difference);
    if (!why.empty()) return MakeError(path + ": cannot write: " + why);
    return WriteImage(path, difference.View(), /*eightBit=*/false);
}

Status WriteVdbVolume(const std::string& path, const std::string& name, const std::vector<float>& values,
                      const Extent3& e, const std::array<double, 3>& origin, double voxelSize) {
    auto module = ModuleToWrite(path);
    if (!module) return std::unexpected(module.error());
    images::VolumeView volume{e.nx,      e.ny,        e.nz, values.data(), {origin[0], origin[1], origin[2]},
                              voxelSize, name.c_str()};
    return Session::WriteAtomically(path, [&](const Session::TemporaryFile& temp) -> Status {
        const std::string why = (*module)->writeVdb(temp.path, volume);
        if (!why.empty()) return MakeError(path + ": cannot write: " + why);
        return {};
    });
}

Result<std::vector<std::string>> WriteFrame(const std::string& stem, const std::vector<float>& rgb, uint32_t width,
                                            uint32_t height, bool png, const std::optional<FrameToneMap>& toneMap) {
    std::vector<std::string> written;
    const std::string exr = stem + ".exr";
    CB_TRY(WriteImage(exr, Rgb(rgb, width, height), /*eightBit=*/false));
    written.push_back(exr);
    if (png) {
        const std::string path = stem + ".png";
        auto module = ModuleToWrite(path);
        if (!module) return std::unexpected(module.error());
        std::vector<float> mapped;
        if (toneMap) {
            mapped.resize(rgb.size());
            for (size_t i = 0; i < rgb.size(); ++i)
                mapped[i] = toneMap->reinhard ? ReinhardToneMap(rgb[i], toneMap->exposure)
                                              : std::clamp(rgb[i] * toneMap->exposure, 0.0f, 1.0f);
        }
        images::FloatImage srgb;
        const std::string why = (*module)->linearToSrgb(Rgb(toneMap ? mapped : rgb, width, height), srgb);
        if (!why.empty()) return MakeError(path + ": colour conversion failed: " + why);
        CB_TRY(WriteImage(path, srgb.View(), /*eightBit=*/true));
        written.push_back(path);
    }
    return written;
}

}  // namespace cb
