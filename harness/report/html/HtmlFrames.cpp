// The frames section of `cloudbench report` (FrameBlocks in ReportSections.h):
// images read and compared through the image module (OpenImageIO),
// differences encoded as PNG in memory.
#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>

#include "core/base/PathPolicy.h"
#include "harness/report/Report.h"
#include "harness/report/html/ReportSections.h"
#include "harness/report/images/ImageModule.h"

namespace cb::html {
namespace {

using nlohmann::json;

// "DIR/NAME", as messages show a file of the results folder.
std::string ShownIn(const std::string& dir, const std::string& name) {
    return (std::filesystem::path(dir) / name).string();
}

// The frame `name` that results.json lists, read beneath the results folder `dir`: a link out of it is refused
// (core/base/PathPolicy.h), so a folder from elsewhere cannot embed this machine's files in the page.
Result<std::string> ReadBytes(const std::string& dir, const std::string& name) {
    return ReadInputBeneath(dir, name, kArrayInput);
}

// A frame to embed as it is: its bytes, which must be a PNG file (the page says "data:image/png").
Result<std::string> ReadPng(const std::string& dir, const std::string& name) {
    Result<std::string> bytes = ReadBytes(dir, name);
    if (!bytes) return bytes;
    static constexpr std::string_view kSignature{"\x89PNG\r\n\x1a\n", 8};
    if (!bytes->starts_with(kSignature))
        return MakeError(ShownIn(dir, name) + ": not a PNG file" + (bytes->empty() ? " (empty)" : ""));
    return bytes;
}

// The first three channels of the image file `name` in `dir` as linear floats, row 0 at the top.
Result<images::FloatImage> ReadRgb(const images::Module& module, const std::string& dir, const std::string& name) {
    auto bytes = ReadBytes(dir, name);
    if (!bytes) return std::unexpected(bytes.error());
    images::FloatImage image;
    const std::string why = module.decode(name, *bytes, 3, image);
    if (!why.empty()) return MakeError(ShownIn(dir, name) + ": cannot read: " + why);
    return image;
}

struct Difference {
    std::string png;
    ImageComparison comparison;
    double gain = 1;
};

// |candidate - reference| scaled so that the image rule's limit is white; both files are in `dir`.
Result<Difference> DifferenceOf(const std::string& dir, const std::string& referenceName,
                                const std::string& candidateName) {
    const std::string referencePath = ShownIn(dir, referenceName), candidatePath = ShownIn(dir, candidateName);
    auto module = images::Load();
    if (!module) return MakeError(candidatePath + ": cannot compare: " + module.error().message);
    auto reference = ReadRgb(**module, dir, referenceName);
    if (!reference) return std::unexpected(reference.error());
    auto candidate = ReadRgb(**module, dir, candidateName);
    if (!candidate) return std::unexpected(candidate.error());
    const int w0 = reference->width, h0 = reference->height, w1 = candidate->width, h1 = candidate->height;
    if (w0 != w1 || h0 != h1)
        return MakeError(candidatePath + ": " + std::to_string(w1) + "x" + std::to_string(h1) + ", but " +
                         referencePath + " is " + std::to_string(w0) + "x" + std::to_string(h0));
    Difference d;
    auto comparison = CompareImages(reference->pixels, candidate->pixels, uint32_t(w0), uint32_t(h0));
    if (!comparison) return std::unexpected(comparison.error());
    d.comparison = *comparison;
    d.gain = d.comparison.rule.limit > 0 && std::isfinite(d.comparison.rule.limit) ? 1 / d.comparison.rule.limit : 1;
    images::FloatImage scaled;
    std::string why =
        (*module)->difference(reference->View(), candidate->View(), float(d.gain), /*clamp=*/true, scaled);
    if (!why.empty()) return MakeError(candidatePath + ": difference: " + why);
    why = (*module)->encodePng(scaled.View(), d.png);
    if (!why.empty()) return MakeError("difference.png: " + why);
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

    // "frame-<renderer>-<camera>-<backend>.png" -> the view "<renderer>-<camera>", by backend in backends' order.
    std::map<std::string, std::vector<std::string>> views;
    for (const std::string& file : files)
        for (const std::string& backend : backends) {
            const std::string tail = "-" + backend + ".png";
            if (file.starts_with("frame-") && file.ends_with(tail) && file.size() > 6 + tail.size())
                views[file.substr(6, file.size() - 6 - tail.size())].push_back(backend);
        }
    for (auto& [view, frameBackends] : views)
        std::ranges::sort(frameBackends, {},
                          [&](const std::string& b) { return std::ranges::find(backends, b) - backends.begin(); });
    if (views.empty()) blocks.emplace_back(report::Paragraph{"No rendered frames are listed in " + results.path + "."});
    for (const auto& [view, frameBackends] : views) {
        blocks.emplace_back(report::Paragraph{"View " + view + ":"});
        for (const std::string& backend : frameBackends) {
            const std::string name = "frame-" + view + "-" + backend + ".png";
            auto bytes = ReadPng(dir.string(), name);
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
            std::string ext =
                listed("frame-" + view + "-" + reference + ".exr") && listed("frame-" + view + "-" + backend + ".exr")
                    ? ".exr"
                    : ".png";
            const std::string a = "frame-" + view + "-" + reference + ext, b = "frame-" + view + "-" + backend + ext;
            auto d = DifferenceOf(dir.string(), a, b);
            if (!d) {
                blocks.emplace_back(report::Paragraph{"No difference image: " + d.error().message});
                continue;
            }
            const ImageComparison& c = d->comparison;
            blocks.emplace_back(report::Image{
                "|" + b + " - " + a + "|",
                "|" + backend + " - " + reference + "| of " + view + " (" + ext.substr(1) + ") x " +
                    Format("%.4g", d->gain) + " (white = SPEC 8's limit " + Format("%.4g", c.rule.limit) + "): max " +
                    Format("%.4g", c.maxError) + ", mean " + Format("%.3g", c.meanError) + ", " +
                    std::to_string(c.pixelsOverTolerance) + " of " + std::to_string(c.pixels) +
                    " pixels over the tolerance; " + (c.Passes() ? "within" : "outside") + " SPEC 8's rule",
                std::move(d->png)});
        }
    }
    for (const std::string& backend : backends) {
        const std::string name = "topview-" + backend + ".png";
        if (!listed(name)) continue;
        auto bytes = ReadPng(dir.string(), name);
        if (bytes)
            blocks.emplace_back(report::Image{name, "density map from above, " + backend, std::move(*bytes)});
        else
            blocks.emplace_back(report::Paragraph{bytes.error().message});
    }
    return blocks;
}

}  // namespace cb::html
