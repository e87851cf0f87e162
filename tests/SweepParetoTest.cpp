// The sweep's Pareto front with ties (harness/accuracy/SweepPareto.h) and which
// varied fields multiply a stage's rows (harness/accuracy/SweepFields.h), on
// cases worked by hand from the rules in docs/accuracy.md ("Sweeps").
#include <gtest/gtest.h>

#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "harness/accuracy/Measurement.h"
#include "harness/accuracy/Evaluator.h"
#include "harness/accuracy/SweepFields.h"
#include "harness/accuracy/SweepPareto.h"

namespace cb {
namespace {

// An ok row: median, q1 and q3 of the time in ms, max |error| (also mean and p99), PSNR for a renderer.
Row TimedRow(Stage stage, double median, double q1, double q3, double error,
             std::optional<double> psnr = std::nullopt) {
    Row r;
    r.stage = stage;
    r.backend = "cpu";
    r.result.timeMs.median = median;
    r.result.timeMs.q1 = q1;
    r.result.timeMs.q3 = q3;
    r.result.all.max = r.result.all.mean = r.result.all.p99 = error;
    r.result.psnrDb = psnr;
    return r;
}

std::string Marks(const std::vector<Row>& rows) {
    std::string out;
    for (const Row& r : rows) out += r.paretoTie ? "=" : r.pareto ? "*" : ".";
    return out;
}

// Test the fastest row within an error bound, per front and backend: shade on cpu, shade on vk and the renderers
// (march and splat together) on cpu, each worked by hand; a bound no shade row on cpu meets leaves it out; with
// psnr the bound is a floor in dB, and an infinite PSNR (an exact image) meets every bound.
TEST(SweepPareto, FastestWithinABound) {
    auto on = [](Row r, const char* backend) {
        r.backend = backend;
        return r;
    };
    const std::vector<Row> rows = {
        TimedRow(Stage::Shade, 1.0, 0.9, 1.1, 0.1), TimedRow(Stage::Shade, 0.5, 0.4, 0.6, 0.3),
        on(TimedRow(Stage::Shade, 2.0, 1.9, 2.1, 0.05), "vk"), TimedRow(Stage::RenderMarch, 3.0, 2.9, 3.1, 0.01, 40.0),
        TimedRow(Stage::RenderSplat, 1.0, 0.9, 1.1, 0.02, 30.0)};
    std::vector<const Row*> picks = FastestWithin(rows, "max", 0.2);
    ASSERT_EQ(picks.size(), 3u);
    EXPECT_EQ(picks[0], &rows[0]);             // shade on cpu: 0.5 ms is faster, but its error 0.3 is over the bound
    EXPECT_EQ(picks[1], &rows[2]);             // shade on vk
    EXPECT_EQ(picks[2], &rows[4]);             // the renderers on cpu: splat, 1 ms against the march's 3
    picks = FastestWithin(rows, "max", 0.06);  // shade on cpu: 0.1 and 0.3 are both over it
    ASSERT_EQ(picks.size(), 2u);
    EXPECT_EQ(picks[0], &rows[2]);
    EXPECT_EQ(picks[1], &rows[4]);
    EXPECT_TRUE(WithinBound(rows[0], "max", 0.1));  // at the bound is within it
    picks = FastestWithin(rows, "psnr", 35.0);      // renderers only; splat's 30 dB is under the floor
    ASSERT_EQ(picks.size(), 1u);
    EXPECT_EQ(picks[0], &rows[3]);
    Row exact = TimedRow(Stage::RenderLayers, 5.0, 4.9, 5.1, 0.0);  // no PSNR: the image equals the reference
    EXPECT_TRUE(WithinBound(exact, "psnr", 1e9));
}

// Two settings that differ only by timing noise (overlapping q1-q3, equal error) are a tie, both on the
// front; a clearly slower row with no better error is off it; a slower, more accurate one is on it.
TEST(SweepPareto, NoiseDuplicatesAreTiesNotAStar) {
    std::vector<Row> rows = {TimedRow(Stage::Shade, 1.00, 0.98, 1.03, 0.5),
                             TimedRow(Stage::Shade, 1.01, 0.99, 1.04, 0.5), TimedRow(Stage::Shade, 3.0, 2.9, 3.1, 0.2),
                             TimedRow(Stage::Shade, 3.5, 3.4, 3.6, 0.6)};
    MarkPareto(rows, "max");
    EXPECT_EQ(Marks(rows), "==*.");
}

// Errors that print alike (3 significant digits) are equal on the front: a clearly faster row beats a slower one
// whose error is smaller only past the printed digits (0.3991 against 0.3992: both "0.399"), and with
// overlapping times the two are a tie; a difference the table shows (0.398) still counts.
TEST(SweepPareto, ErrorsAlikeAsPrintedAreEqual) {
    std::vector<Row> clearly = {TimedRow(Stage::Shade, 0.033, 0.032, 0.034, 0.39919),
                                TimedRow(Stage::Shade, 0.048, 0.047, 0.049, 0.39910)};
    MarkPareto(clearly, "max");
    EXPECT_EQ(Marks(clearly), "*.");
    std::vector<Row> overlapping = {TimedRow(Stage::Shade, 0.033, 0.030, 0.040, 0.39919),
                                    TimedRow(Stage::Shade, 0.035, 0.031, 0.041, 0.39910)};
    MarkPareto(overlapping, "max");
    EXPECT_EQ(Marks(overlapping), "==");
    std::vector<Row> shown = {TimedRow(Stage::Shade, 0.033, 0.032, 0.034, 0.39919),
                              TimedRow(Stage::Shade, 0.048, 0.047, 0.049, 0.398)};
    MarkPareto(shown, "max");
    EXPECT_EQ(Marks(shown), "**");
}

// Overlapping times: the faster median is noise, so the smaller error wins (the old median rule kept both).
TEST(SweepPareto, OverlappingTimesLetTheSmallerErrorWin) {
    std::vector<Row> rows = {TimedRow(Stage::Shade, 1.0, 0.9, 1.2, 0.6), TimedRow(Stage::Shade, 1.1, 1.0, 1.3, 0.5)};
    MarkPareto(rows, "max");
    EXPECT_EQ(Marks(rows), ".*");
}

// The boundary of "clearly faster": q3 equal to the other's q1 overlaps (a tie); just below it does not.
TEST(SweepPareto, ClearlyFasterNeedsTheIntervalsApart) {
    std::vector<Row> touching = {TimedRow(Stage::Shadow, 1.5, 1.0, 2.0, 0.5),
                                 TimedRow(Stage::Shadow, 2.5, 2.0, 3.0, 0.5)};
    MarkPareto(touching, "mean");
    EXPECT_EQ(Marks(touching), "==");
    std::vector<Row> apart = {TimedRow(Stage::Shadow, 1.5, 1.0, 2.0, 0.5),
                              TimedRow(Stage::Shadow, 2.5, 2.0001, 3.0, 0.5)};
    MarkPareto(apart, "mean");
    EXPECT_EQ(Marks(apart), "*.");
    EXPECT_TRUE(ParetoBeats(apart[0], apart[1], "mean"));
    EXPECT_FALSE(ParetoBeats(apart[1], apart[0], "mean"));
    EXPECT_FALSE(ParetoBeats(touching[0], touching[1], "mean"));
}

// PSNR: higher is better; infinite PSNR (no value) beats every finite one, and two infinite ones with
// overlapping times tie.
TEST(SweepPareto, PsnrIsHigherIsBetterAndInfiniteIsBest) {
    std::vector<Row> rows = {
        TimedRow(Stage::RenderMarch, 1.0, 1.0, 1.1, 0.3, 30.0), TimedRow(Stage::RenderMarch, 1.05, 1.0, 1.1, 0.3, 40.0),
        TimedRow(Stage::RenderSplat, 5.5, 5.0, 6.0, 0.0), TimedRow(Stage::RenderLayers, 6.0, 5.5, 6.5, 0.0)};
    MarkPareto(rows, "psnr");
    EXPECT_EQ(Marks(rows), ".*==");
    EXPECT_EQ(MetricLoss(rows[1], "psnr"), -40.0);
    EXPECT_EQ(MetricLoss(rows[2], "psnr"), -std::numeric_limits<double>::infinity());
    // On max error the two fast rows tie (equal error, overlapping times), and so do the two exact ones.
    MarkPareto(rows, "max");
    EXPECT_EQ(Marks(rows), "====");
}

// Each stage has its own front, the renderers one together; rows not ok, and rows whose metric does not
// apply (psnr for shade), are never on it.
TEST(SweepPareto, FrontsPerStageRenderersTogether) {
    std::vector<Row> rows = {TimedRow(Stage::Shade, 2.0, 2.0, 2.0, 0.5), TimedRow(Stage::Shadow, 1.0, 1.0, 1.0, 0.1),
                             TimedRow(Stage::RenderMarch, 2.0, 2.0, 2.0, 0.5, 30.0),
                             TimedRow(Stage::RenderSplat, 1.0, 1.0, 1.0, 0.4, 31.0),
                             TimedRow(Stage::Shade, 0.5, 0.5, 0.5, 0.0)};
    rows[4].result.status = "unsupported";
    MarkPareto(rows, "max");
    EXPECT_EQ(Marks(rows), "**.*.");
    MarkPareto(rows, "psnr");
    EXPECT_EQ(Marks(rows), "...*.");
    EXPECT_FALSE(MetricApplies("psnr", Stage::Shade));
    EXPECT_TRUE(MetricApplies("psnr", Stage::RenderLayers));
    EXPECT_FALSE(IsSweepMetric("rmse"));
}

// Dotted paths overlap when equal or one holds the other, never on a shared prefix of a name.
TEST(SweepFields, FieldsOverlapOnWholeNames) {
    EXPECT_TRUE(FieldsOverlap("shade.sigma", "shade"));
    EXPECT_TRUE(FieldsOverlap("shade", "shade.sigma"));
    EXPECT_TRUE(FieldsOverlap("grid.size", "grid.size"));
    EXPECT_FALSE(FieldsOverlap("shade.sigmax", "shade.sigma"));
    EXPECT_FALSE(FieldsOverlap("shadow.form", "shade"));
}

// What each stage's rows read, from the descriptors and the stages that feed them: shade reads its own
// section, the sun, phase and layers.relight, and through q the automaton and its ellipsoids; shadow reads
// shade.sigma but not shade.resolution; the splat renderer reads shade's T but not march.step, which the
// reference ignores, and the reference's physics (march.powder); nothing reads the description.
TEST(SweepFields, RowsDependOnWhatTheStagesRead) {
    EXPECT_TRUE(RowDependsOn(Stage::Shade, "shade.resolution"));
    EXPECT_TRUE(RowDependsOn(Stage::Shade, "layers.relight"));
    EXPECT_FALSE(RowDependsOn(Stage::Shadow, "layers.relight"));  // shadow reads D, not T
    EXPECT_FALSE(RowDependsOn(Stage::Shade, "layers.count"));
    EXPECT_FALSE(RowDependsOn(Stage::Shade, "march.step"));
    EXPECT_TRUE(RowDependsOn(Stage::Shade, "ca.p_ext"));
    EXPECT_TRUE(RowDependsOn(Stage::Shade, "ellipsoids.target_count"));
    EXPECT_TRUE(RowDependsOn(Stage::Shade, "noise.seed"));
    EXPECT_TRUE(RowDependsOn(Stage::Shadow, "shade.sigma"));
    EXPECT_TRUE(RowDependsOn(Stage::Shadow, "shade"));
    EXPECT_FALSE(RowDependsOn(Stage::Shadow, "shade.resolution"));
    EXPECT_TRUE(RowDependsOn(Stage::RenderMarch, "march.step"));
    EXPECT_FALSE(RowDependsOn(Stage::RenderSplat, "march.step"));
    EXPECT_TRUE(RowDependsOn(Stage::RenderSplat, "march.powder.enabled"));
    EXPECT_TRUE(RowDependsOn(Stage::RenderSplat, "shade.resolution"));
    EXPECT_FALSE(RowDependsOn(Stage::RenderMarch, "layers.count"));
    EXPECT_TRUE(RowDependsOn(Stage::RenderLayers, "grid.tiling"));
    EXPECT_FALSE(RowDependsOn(Stage::Shade, "grid.tiling"));
    for (Stage s : {Stage::Shade, Stage::Shadow, Stage::RenderMarch, Stage::RenderSplat, Stage::RenderLayers}) {
        EXPECT_TRUE(RowDependsOn(s, "grid.size")) << StageName(s);
        EXPECT_TRUE(RowDependsOn(s, "grid")) << StageName(s);
        EXPECT_TRUE(RowDependsOn(s, "steps")) << StageName(s);
        EXPECT_FALSE(RowDependsOn(s, "description")) << StageName(s);
    }
}

std::vector<Stage> StagesOf(std::initializer_list<const char*> paths) {
    std::vector<SweepAxis> axes;
    for (const char* p : paths) axes.push_back({p, {"1", "2"}});
    return SweepStages(axes);
}

// The stages a sweep measures: only those a varied field can change (the layers fields alone measure
// render_layers alone, march.step render_march alone), renderers only when an image section or a light term varies.
TEST(SweepFields, SweepStagesAreThoseTheFieldsReach) {
    using S = std::vector<Stage>;
    EXPECT_EQ(StagesOf({"layers.count"}), (S{Stage::RenderLayers}));
    EXPECT_EQ(StagesOf({"march.step"}), (S{Stage::RenderMarch}));
    EXPECT_EQ(StagesOf({"shade.resolution"}), (S{Stage::Shade}));
    EXPECT_EQ(StagesOf({"shadow.form"}), (S{Stage::Shadow}));
    EXPECT_EQ(StagesOf({"shade.sigma"}), (S{Stage::Shade, Stage::Shadow}));
    EXPECT_EQ(StagesOf({"sun.elevation_deg"}), (S{Stage::Shade, Stage::Shadow}));
    // The renderers in stage order (kAllStages), as their descriptors are walked.
    EXPECT_EQ(StagesOf({"phase.function"}),
              (S{Stage::Shade, Stage::RenderSplat, Stage::RenderMarch, Stage::RenderLayers}));
    EXPECT_EQ(StagesOf({"description"}), S{});
    // A light term reaches every renderer and nothing upstream of them.
    const S renderers = {Stage::RenderSplat, Stage::RenderMarch, Stage::RenderLayers};
    EXPECT_EQ(StagesOf({"lighting.eye_scattering.cone_deg"}), renderers);
    EXPECT_EQ(StagesOf({"lighting.city_glow"}), renderers);
    EXPECT_EQ(StagesOf({"lighting.ambient"}), renderers);
    EXPECT_EQ(StagesOf({"lightning.intensity"}), renderers);
}

// march.step x shade.resolution (the last axis fastest): shade at each resolution once, shadow once,
// render_march (which reads both: T comes from shade) at every point.
TEST(SweepFields, EachStageOncePerDistinctSettingItReads) {
    const std::vector<SweepAxis> axes = {{"march.step", {"0.5", "1"}}, {"shade.resolution", {"1", "2"}}};
    const std::vector<Stage> stages = {Stage::Shade, Stage::Shadow, Stage::RenderMarch};
    const auto measured = DistinctMeasurements(VaryPoints(axes), stages);
    using S = std::vector<Stage>;
    ASSERT_EQ(measured.size(), 4u);
    EXPECT_EQ(measured[0], (S{Stage::Shade, Stage::Shadow, Stage::RenderMarch}));
    EXPECT_EQ(measured[1], (S{Stage::Shade, Stage::RenderMarch}));
    EXPECT_EQ(measured[2], (S{Stage::RenderMarch}));
    EXPECT_EQ(measured[3], (S{Stage::RenderMarch}));
    // A value given twice is one setting.
    const auto twice = DistinctMeasurements(VaryPoints({{"shade.resolution", {"2", "2"}}}), S{Stage::Shade});
    EXPECT_EQ(twice[0], S{Stage::Shade});
    EXPECT_EQ(twice[1], S{});
    // The rows list the fields their stage reads.
    const std::vector<SceneOverride> point = {{"march.step", "0.5"}, {"shade.resolution", "2"}};
    ASSERT_EQ(SettingsRead(Stage::Shade, point).size(), 1u);
    EXPECT_EQ(SettingsRead(Stage::Shade, point)[0].path, "shade.resolution");
    EXPECT_EQ(SettingsRead(Stage::RenderMarch, point).size(), 2u);
}

// Infinite PSNR prints as "inf" in the table and is null in sweep.json's row.
TEST(SweepPareto, InfinitePsnrIsInfAndNull) {
    Row r = TimedRow(Stage::RenderMarch, 1.0, 1.0, 1.0, 0.0);
    const nlohmann::json j = RowJson(r);
    EXPECT_TRUE(j["error"]["psnr_db"].is_null());
    const std::vector<report::Cell> cells = RowCells(r);
    EXPECT_EQ(cells.back().text, "inf");
    r.result.psnrDb = 42.5;
    EXPECT_EQ(RowJson(r)["error"]["psnr_db"].get<double>(), 42.5);
}

}  // namespace
}  // namespace cb

namespace cb {
namespace {

// The lighting inputs (q and D) are simulated once across the fields that only the stages after them read:
// from the descriptors, the sections the evaluator once listed by hand (shade, shadow, sun, phase, render,
// lighting, march, lightning, layers, and description, which nothing reads) and none of those that shape the
// volume.
TEST(SweepFields, LightingOnlyFieldsLeaveTheVolume) {
    for (const char* path : {"shade.sigma", "shadow.form", "sun.elevation_deg", "phase.function", "render.width",
                             "lighting.ambient", "march.step", "lightning.intensity", "layers.count", "description"})
        EXPECT_TRUE(LightingOnly(path)) << path;
    for (const char* path : {"ca.seed", "ca.p_hum", "ellipsoids", "smooth.radius", "noise.seed", "density.tile",
                             "grid.size", "steps", "stages"})
        EXPECT_FALSE(LightingOnly(path)) << path;
}

}  // namespace
}  // namespace cb
