#include "core/pipeline/StageDescriptor.h"

#include <cmath>
#include <cstdio>

namespace cb {

std::string_view ResourceName(Resource resource) {
    switch (resource) {
#define CB_RESOURCE_NAME(name, text, format, file) \
    case Resource::name:                           \
        return text;
        CB_RESOURCES(CB_RESOURCE_NAME)
#undef CB_RESOURCE_NAME
    }
    return "?";
}

std::string_view ResourceDumpStem(Resource resource) {
    switch (resource) {
#define CB_RESOURCE_STEM(name, text, format, file) \
    case Resource::name:                           \
        return file;
        CB_RESOURCES(CB_RESOURCE_STEM)
#undef CB_RESOURCE_STEM
    }
    return "";
}

BufferFormat ResourceFormat(Resource resource) {
    switch (resource) {
#define CB_RESOURCE_FORMAT(name, text, format, file) \
    case Resource::name:                             \
        return BufferFormat::format;
        CB_RESOURCES(CB_RESOURCE_FORMAT)
#undef CB_RESOURCE_FORMAT
    }
    return BufferFormat::F32;
}

bool IsPerCamera(Resource resource) { return ResourceDumpStem(resource).empty(); }

Extent3 ResourceExtent(Resource resource, const Scene& scene) {
    if (IsPerCamera(resource)) return {3, scene.render.width, scene.render.height};
    const Extent3 grid = scene.grid.size;
    const uint32_t tile = scene.density.tile, band = scene.density.band;
    switch (resource) {
        case Resource::ColumnSum:
        case Resource::Shadow:
            return {grid.nx, grid.ny, 1};
        case Resource::Tiles:
            return {CeilDiv(grid.nx, tile), CeilDiv(grid.ny, tile), 1};
        case Resource::Bands:
            return {CeilDiv(grid.nx, tile), CeilDiv(grid.ny, tile), CeilDiv(grid.nz, band)};
        default:  // the volumes: region, the automaton's fields, q and T
            return grid;
    }
}

namespace {

// A pixel value as rules state it: "2/255" where it is a whole number of 8-bit steps, "%g" otherwise.
std::string PixelValueText(double value) {
    char text[32];
    if (value * 255 == double(int(value * 255)))
        std::snprintf(text, sizeof text, "%d/255", int(value * 255));
    else
        std::snprintf(text, sizeof text, "%g", value);
    return text;
}

}  // namespace

std::string CompareRule::ToleranceText() const {
    if (kind == Kind::Image) return PixelValueText(tolerance);
    char text[32];
    std::snprintf(text, sizeof text, "%g", tolerance);
    return text;
}

std::string CompareRule::Text(std::string_view symbol) const {
    char text[96];
    std::string d = "|d";
    d.append(symbol).append("|");
    switch (kind) {
        case Kind::BitExact:
            return "bit-exact";
        case Kind::Absolute:
            std::snprintf(text, sizeof text, "%s <= %g", d.c_str(), tolerance);
            break;
        case Kind::Quantised:
            std::snprintf(text, sizeof text, "%s <= %g, <= %g %% differ", d.c_str(), tolerance, share * 100);
            break;
        case Kind::Codes:
            std::snprintf(text, sizeof text, "|d%s| <= %g %s code%s", std::string(symbol).c_str(), tolerance,
                          storage == StorageFormat::Fp16 ? "fp16" : "unorm8", tolerance == 1 ? "" : "s");
            break;
        case Kind::Image:
            std::snprintf(text, sizeof text, "%s on %g %%%s", ToleranceText().c_str(), 100 - share * 100,
                          std::isinf(limit) ? "" : (", " + PixelValueText(limit) + " max").c_str());
            break;
    }
    return text;
}

CompareRule BitExactRule(const Scene&) { return {CompareRule::Kind::BitExact}; }
CompareRule ImageRuleSpec8(const Scene&) { return {CompareRule::Kind::Image, 2.0 / 255.0, 0.001, 8.0 / 255.0}; }

uint32_t SharesOfSlicesK(const Scene& scene, uint32_t) { return scene.grid.size.nz; }

}  // namespace cb
