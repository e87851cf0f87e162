// The frames section of `cloudbench report` (FrameBlocks in HtmlReport.h):
// images read and compared through OpenImageIO, differences encoded as PNG
// in memory.
#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>

#include "core/InputFile.h"
#include "harness/Report.h"
#include "harness/html/HtmlReport.h"

namespace cb::html {
namespace {

using nlohmann::json;

Result<std::string> ReadBytes(const std::string& path) { return ReadInputFile(path, kArrayInput); }

// The first three channels of an image file as linear floats, row 0 at the top.
Result<std::vector<float>> ReadRgb(const std::string& path, int& width, int& height) {
    CB_TRY(CheckInputFile(path, kArrayInput));  // OpenImageIO would block on a FIFO
    OIIO::ImageBuf image(path);
    if (!image.read(0, 0, true, OIIO::TypeDesc::FLOAT))
        return MakeError(path + ": cannot read: " + image.geterror());
    const OIIO::ImageSpec& spec = image.spec();
    if (spec.nchannels < 3) return MakeError(path + ": has " + std::to_string(spec.nchannels) + " channels, not RGB");
    width = spec.width;
    height = spec.height;
    std::vector<float> rgb(size_t(width) * size_t(height) * 3);
    OIIO::ROI roi = image.roi();
    roi.chbegin = 0;
    roi.chend = 3;
    if (!image.get_pixels(roi, OIIO::TypeDesc::FLOAT, rgb.data()))
        return MakeError(path + ": cannot read: " + image.geterror());
    return rgb;
}

// `image` (floats in [0, 1] after clamping) as an 8-bit PNG file in memory.
Result<std::string> EncodePng(const OIIO::ImageBuf& image) {
    std::vector<unsigned char> file;
    OIIO::Filesystem::IOVecOutput proxy(file);
    auto out = OIIO::ImageOutput::create("difference.png", &proxy);
    if (!out) return MakeError("difference.png: no PNG writer: " + OIIO::geterror());
    OIIO::ImageSpec spec(image.spec().width, image.spec().height, image.spec().nchannels, OIIO::TypeDesc::UINT8);
    std::vector<unsigned char> pixels(spec.image_bytes());
    if (!image.get_pixels(image.roi(), OIIO::TypeDesc::UINT8, pixels.data()) || !out->open("difference.png", spec) ||
        !out->write_image(OIIO::TypeDesc::UINT8, pixels.data()) || !out->close())
        return MakeError("difference.png: cannot encode: " + out->geterror());
    return std::string(file.begin(), file.end());
}

struct Difference {
    std::string png;
    ImageComparison comparison;
    double gain = 1;
};

// |candidate - reference| scaled so that the image rule's limit is white.
Result<Difference> DifferenceOf(const std::string& referencePath, const std::string& candidatePath) {
    int w0 = 0, h0 = 0, w1 = 0, h1 = 0;
    auto reference = ReadRgb(referencePath, w0, h0);
    if (!reference) return std::unexpected(reference.error());
    auto candidate = ReadRgb(candidatePath, w1, h1);
    if (!candidate) return std::unexpected(candidate.error());
    if (w0 != w1 || h0 != h1)
        return MakeError(candidatePath + ": " + std::to_string(w1) + "x" + std::to_string(h1) + ", but " +
                         referencePath + " is " + std::to_string(w0) + "x" + std::to_string(h0));
    Difference d;
    d.comparison = CompareImages(*reference, *candidate, uint32_t(w0), uint32_t(h0));
    d.gain = d.comparison.rule.limit > 0 && std::isfinite(d.comparison.rule.limit) ? 1 / d.comparison.rule.limit : 1;
    const OIIO::ImageSpec spec(w0, h0, 3, OIIO::TypeDesc::FLOAT);
    const OIIO::ImageBuf a(spec, reference->data()), b(spec, candidate->data());  // wrap, do not copy
    OIIO::ImageBuf scaled = OIIO::ImageBufAlgo::clamp(
        OIIO::ImageBufAlgo::mul(OIIO::ImageBufAlgo::absdiff(a, b), float(d.gain)), 0.0f, 1.0f);
    if (scaled.has_error()) return MakeError(candidatePath + ": difference: " + scaled.geterror());
    auto png = EncodePng(scaled);
    if (!png) return std::unexpected(png.error());
    d.png = std::move(*png);
    return d;
}

std::string Format(const char* format, double value) {
    char text[64];
    std::snprintf(text, sizeof text, format, value);
    return text;
}

}  // namespace

std::vector<report::Block> FrameBlocks(const ReportInput& results) {
    std::vector<report::Block> blocks;
    const std::filesystem::path dir = std::filesystem::path(results.path).parent_path();
    std::vector<std::string> files, backends;
    if (auto it = results.doc.find("files"); it != results.doc.end() && it->is_array())
        for (const json& f : *it)
            if (f.is_string()) files.push_back(f.get<std::string>());
    if (auto it = results.doc.find("backends"); it != results.doc.end() && it->is_object())
        for (const auto& [name, b] : it->items()) backends.push_back(name);
    auto listed = [&](const std::string& name) { return std::ranges::find(files, name) != files.end(); };
    auto at = [&](const std::string& name) { return (dir / name).string(); };

    // "frame-<renderer>-<camera>-<backend>.png" -> the view "<renderer>-<camera>", by backend in backends' order.
    std::map<std::string, std::vector<std::string>> views;
    for (const std::string& file : files)
        for (const std::string& backend : backends) {
            const std::string tail = "-" + backend + ".png";
            if (file.starts_with("frame-") && file.ends_with(tail) && file.size() > 6 + tail.size())
                views[file.substr(6, file.size() - 6 - tail.size())].push_back(backend);
        }
    for (auto& [view, frameBackends] : views)
        std::ranges::sort(frameBackends, {}, [&](const std::string& b) { return std::ranges::find(backends, b) - backends.begin(); });
    if (views.empty()) blocks.emplace_back(report::Paragraph{"No rendered frames are listed in " + results.path + "."});
    for (const auto& [view, frameBackends] : views) {
        blocks.emplace_back(report::Paragraph{"View " + view + ":"});
        for (const std::string& backend : frameBackends) {
            const std::string name = "frame-" + view + "-" + backend + ".png";
            auto bytes = ReadBytes(at(name));
            if (!bytes) {
                blocks.emplace_back(report::Paragraph{bytes.error().message});
                continue;
            }
            blocks.emplace_back(report::Image{name, view + " on " + backend, std::move(*bytes)});
        }
        const std::string& reference = frameBackends.front();
        for (size_t i = 1; i < frameBackends.size(); ++i) {
            const std::string& backend = frameBackends[i];
            // The linear float frames when both are there, else the 8-bit sRGB PNGs.
            std::string ext = listed("frame-" + view + "-" + reference + ".exr") &&
                                      listed("frame-" + view + "-" + backend + ".exr")
                                  ? ".exr"
                                  : ".png";
            const std::string a = "frame-" + view + "-" + reference + ext, b = "frame-" + view + "-" + backend + ext;
            auto d = DifferenceOf(at(a), at(b));
            if (!d) {
                blocks.emplace_back(report::Paragraph{"No difference image: " + d.error().message});
                continue;
            }
            const ImageComparison& c = d->comparison;
            blocks.emplace_back(report::Image{
                "|" + b + " - " + a + "|",
                "|" + backend + " - " + reference + "| of " + view + " (" + ext.substr(1) + ") x " +
                    Format("%.4g", d->gain) + " (white = SPEC 8's limit " + Format("%.4g", c.rule.limit) +
                    "): max " + Format("%.4g", c.maxError) + ", mean " + Format("%.3g", c.meanError) + ", " +
                    std::to_string(c.pixelsOverTolerance) + " of " + std::to_string(c.pixels) +
                    " pixels over the tolerance; " + (c.Passes() ? "within" : "outside") + " SPEC 8's rule",
                std::move(d->png)});
        }
    }
    for (const std::string& backend : backends) {
        const std::string name = "topview-" + backend + ".png";
        if (!listed(name)) continue;
        auto bytes = ReadBytes(at(name));
        if (bytes)
            blocks.emplace_back(report::Image{name, "density map from above, " + backend, std::move(*bytes)});
        else
            blocks.emplace_back(report::Paragraph{bytes.error().message});
    }
    return blocks;
}

}  // namespace cb::html
