// The images a run writes and compares (harness/Report.h): frame file names,
// the top view of the density map, frames as EXR and PNG, image comparisons
// and difference images, every file written atomically through OpenImageIO.
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/March.h"
#include "harness/Report.h"
#include "harness/Session.h"

namespace cb {

std::string_view RendererFileName(Stage renderer) {
    switch (renderer) {
        case Stage::RenderSplat:
            return "splat";
        case Stage::RenderMarch:
            return "march";
        default:
            return StageName(renderer);
    }
}

std::string FrameFileStem(Stage renderer, const std::string& camera, const std::string& backend) {
    return "frame-" + std::string(RendererFileName(renderer)) + "-" + camera + (backend.empty() ? "" : "-" + backend);
}

namespace {

// Writes `image` to `path` atomically. OpenImageIO opens files by name, so it
// is handed the temporary file's "/proc/self/fd/N" (Session::TemporaryFile):
// opening that name opens the file WriteAtomically created exclusively in the
// output folder's descriptor, whatever link is planted in the folder since
// (measured on Debian 12's OIIO 2.4: PNG and EXR write and read back through
// it, and the file renamed into place holds the image). An OIIO IOProxy would
// do the same for the writers that take one; the path works for every format
// and for the read-back. The format is named from `path`'s extension, since
// the /proc name has none. OIIO's PNG writer can report success on a full
// disk, so the temporary file is read back whole before it is renamed.
// Errors read "PATH: cannot write: <reason>"; Session::WriteAtomically adds the errno.
Status WriteImage(const std::string& path, const OIIO::ImageBuf& image) {
    const std::string extension = std::filesystem::path(path).extension().string();
    const std::string format = extension.empty() ? "" : extension.substr(1);  // "png", "exr"
    return Session::WriteAtomically(path, [&](const Session::TemporaryFile& temp) -> Status {
        if (!image.write(temp.path, OIIO::TypeUnknown, format))
            return MakeError(path + ": cannot write: " + image.geterror());
        // ImageInput, not ImageBuf: the shared image cache could answer with an earlier file of the same name.
        auto in = OIIO::ImageInput::create(format);
        OIIO::ImageSpec got;
        const OIIO::ImageSpec& want = image.spec();
        std::vector<float> pixels(size_t(want.width) * size_t(want.height) * size_t(want.nchannels));
        const bool whole = in && in->open(temp.path, got) && got.width == want.width && got.height == want.height &&
                           got.nchannels == want.nchannels &&
                           in->read_image(0, 0, 0, want.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
        const std::string why = in ? in->geterror() : OIIO::geterror();
        if (!whole) return MakeError(path + ": cannot write: it does not read back whole (" + why + ")");
        return {};
    });
}

}  // namespace

Status WriteTopView(const std::string& path, const std::vector<float>& columnSum, uint32_t nx, uint32_t ny,
                    uint32_t nz) {
    OIIO::ImageSpec spec(int(nx), int(ny), 1, OIIO::TypeDesc::UINT8);
    OIIO::ImageBuf image(spec);
    // Optical-depth look: brightness 1 - exp(-D / 4); a column of 4 full voxels is ~63 % white.
    (void)nz;
    for (uint32_t y = 0; y < ny; ++y) {
        const uint32_t j = ny - 1 - y;  // top row first, y up
        for (uint32_t i = 0; i < nx; ++i) {
            float v = 1.0f - std::exp(-columnSum[size_t(i) + size_t(nx) * j] / 4.0f);
            image.setpixel(int(i), int(y), &v, 1);
        }
    }
    return WriteImage(path, image);
}

ImageComparison CompareImages(const std::vector<float>& reference, const std::vector<float>& candidate, uint32_t width,
                              uint32_t height, const CompareRule& rule) {
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf a(spec, const_cast<float*>(reference.data())), b(spec, const_cast<float*>(candidate.data()));
    // failthresh: the limit; warnthresh: the tolerance. A pixel counts once, as a failure or a warning.
    const float limit = std::isinf(rule.limit) ? std::numeric_limits<float>::max() : float(rule.limit);
    const auto result = OIIO::ImageBufAlgo::compare(a, b, limit, float(rule.tolerance));
    ImageComparison c;
    c.rule = rule;
    c.maxError = result.maxerror;
    c.meanError = result.meanerror;
    c.psnr = result.PSNR;
    c.pixelsOverTolerance = size_t(result.nfail + result.nwarn);
    c.pixels = size_t(width) * height;
    c.worstX = result.maxx;
    c.worstY = result.maxy;
    return c;
}

Status WriteDifferenceImage(const std::string& path, const std::vector<float>& reference,
                            const std::vector<float>& candidate, uint32_t width, uint32_t height) {
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf a(spec, const_cast<float*>(reference.data())), b(spec, const_cast<float*>(candidate.data()));
    OIIO::ImageBuf diff = OIIO::ImageBufAlgo::absdiff(a, b);
    return WriteImage(path, diff);
}

Result<std::vector<std::string>> WriteFrame(const std::string& stem, const std::vector<float>& rgb, uint32_t width,
                                            uint32_t height, bool png, const std::optional<FrameToneMap>& toneMap) {
    OIIO::ImageSpec spec(int(width), int(height), 3, OIIO::TypeDesc::FLOAT);
    OIIO::ImageBuf linear(spec, const_cast<float*>(rgb.data()));  // wraps, does not copy
    std::vector<std::string> written;
    const std::string exr = stem + ".exr";
    CB_TRY(WriteImage(exr, linear));
    written.push_back(exr);
    if (png) {
        std::vector<float> mapped;
        OIIO::ImageBuf display;
        if (toneMap) {
            mapped.resize(rgb.size());
            for (size_t i = 0; i < rgb.size(); ++i)
                mapped[i] = toneMap->reinhard ? ReinhardToneMap(rgb[i], toneMap->exposure)
                                              : std::clamp(rgb[i] * toneMap->exposure, 0.0f, 1.0f);
            display = OIIO::ImageBuf(spec, mapped.data());
        }
        OIIO::ImageBuf srgb;
        if (!OIIO::ImageBufAlgo::colorconvert(srgb, toneMap ? display : linear, "linear", "sRGB"))
            return MakeError(stem + ".png: colour conversion failed: " + srgb.geterror());
        const std::string path = stem + ".png";
        srgb.set_write_format(OIIO::TypeDesc::UINT8);
        CB_TRY(WriteImage(path, srgb));
        written.push_back(path);
    }
    return written;
}

}  // namespace cb
