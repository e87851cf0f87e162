#include "core/stages/density/Density.h"

#include <algorithm>

#include "core/scene/SceneReaders.h"

namespace cb::scene_io {
namespace {

constexpr std::string_view kDensityKeys[] = {"tile", "band"};

}  // namespace

// `grid` is the grid's size when it was valid. Tile and band counts are CeilDiv(edge, tile), computed in 32 bits as
// (edge + tile - 1) / tile: tile + edge - 1 must fit, so tile is at most 2^32 - the edge it divides.
void ReadDensity(const Json& root, Validator& check, DensitySettings& density, const Extent3* grid) {
    const Json* section = check.Section(root, "", "density", kDensityKeys);
    if (!section) return;
    auto read = [&](std::string_view key, uint32_t edge, std::string_view edgeText, uint32_t& target) {
        const Json* v = Validator::Find(*section, key);
        if (!v) return;
        const std::string field = JoinField("density", key);
        auto n = check.Integer(*v, field, 1, kU32Max);
        if (!n) return;
        const int64_t most = kU32Max + 1 - int64_t(edge);
        if (*n > most) {
            check.Fail(field, "must be at most " + std::to_string(most) + " (2^32 - " + std::string(edgeText) + " " +
                                  std::to_string(edge) + ", so the count fits 32 bits), got " + Describe(*v));
            return;
        }
        target = uint32_t(*n);
    };
    read("tile", grid ? std::max(grid->nx, grid->ny) : 1, "the grid's longer horizontal edge", density.tile);
    read("band", grid ? grid->nz : 1, "the grid's height", density.band);
}

}  // namespace cb::scene_io

namespace cb {
namespace {

// Time-slicing's shares (SliceRange): the rows of tiles.
uint32_t RowsOfTiles(const Scene& scene, uint32_t) { return CeilDiv(scene.grid.size.ny, scene.density.tile); }

}  // namespace

DensityParams MakeDensityParams(const Scene& sc) {
    DensityParams p;
    p.tile = sc.density.tile;
    p.band = sc.density.band;
    return p;
}

// What its parameters read from the scene (StageDescriptor::sceneFields).
constexpr std::string_view kDensitySceneFields[] = {"density"};

constexpr std::string_view kDensitySceneKeys[] = {"density"};

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
const StageDescriptor& DescribeDensity() {
    static const StageDescriptor descriptor{
        .stage = Stage::Density,
        .section = "density",
        .sceneKeys = kDensitySceneKeys,
        .readSettings = [](const scene_io::Json& root, scene_io::Validator& check, const Extent3* grid,
                           Scene& scene) { scene_io::ReadDensity(root, check, scene.density, grid); },
        .reads = {Resource::Q},
        .optionalReads = {Resource::Cld},
        .writes = {Resource::ColumnSum, Resource::Tiles, Resource::Bands},
        .skipsUnchangedInputs = true,
        .shareCount = RowsOfTiles,
        .symbol = "D",
        .rule = BitExactRule,
        .sceneFields = kDensitySceneFields,
    };
    return descriptor;
}
#pragma GCC diagnostic pop

Status CallDensity(Backend& backend, const Scene& sc, const StageHostInputs& host, const StageBuffers& io,
                   StageCallRecord& record) {
    DensityOutputs out{io.Current(Resource::ColumnSum), io.Current(Resource::Tiles), io.Current(Resource::Bands), 0};
    DensityParams params = MakeDensityParams(sc);
    params.slices = host.slices;
    CB_TRY(TimedStage(Stage::Density, backend, host, record, [&] {
        return backend.Density(params, *io.Current(Resource::Q), io.Current(Resource::Cld), out);
    }));
    record.coveredColumns = out.coveredColumns;
    return {};
}

}  // namespace cb
