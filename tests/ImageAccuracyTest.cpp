// Image error statistics (harness/accuracy/ImageAccuracy.h): per-pixel max over the
// channels, and PSNR against closed forms worked out by hand here.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "harness/accuracy/ImageAccuracy.h"

namespace cb {
namespace {

TEST(ImageAccuracy, PerPixelErrorIsTheLargestChannel) {
    // Two pixels: errors (0.1, -0.3, 0.2) and (0, 0, 0.05).
    const std::vector<float> ref = {1.0f, 2.0f, 4.0f, 0.5f, 0.5f, 0.5f};
    const std::vector<float> img = {1.1f, 1.7f, 4.2f, 0.5f, 0.5f, 0.55f};
    const ImageErrorStats e = ImageErrors(img, ref);
    EXPECT_EQ(e.pixel.count, 2u);
    EXPECT_NEAR(e.pixel.max, 0.3, 1e-6);
    EXPECT_EQ(e.pixel.worst, 0u);
    EXPECT_NEAR(e.pixel.mean, (0.3 + 0.05) / 2, 1e-6);
    // MSE over all six channel values; the peak is the reference's largest value, 4.
    const double mse = (0.01 + 0.09 + 0.04 + 0.0025) / 6;
    EXPECT_NEAR(e.mse, mse, 1e-7);
    EXPECT_EQ(e.peak, 4.0);
    ASSERT_TRUE(e.psnr.has_value());
    EXPECT_NEAR(*e.psnr, 10 * std::log10(16 / mse), 1e-4);
}

TEST(ImageAccuracy, IdenticalImagesHaveInfinitePsnr) {
    const std::vector<float> ref = {0.2f, 0.4f, 0.6f, 0.0f, 1.0f, 0.3f};
    const ImageErrorStats e = ImageErrors(ref, ref);
    EXPECT_EQ(e.pixel.max, 0.0);
    EXPECT_EQ(e.mse, 0.0);
    EXPECT_FALSE(e.psnr.has_value());
}

TEST(ImageAccuracy, UniformErrorGivesTheTextbookPsnr) {
    // Every channel off by 0.01 with peak 1: PSNR = 10 log10(1 / 1e-4) = 40 dB.
    std::vector<float> ref(3 * 100, 0.5f), img(3 * 100, 0.51f);
    ref[7] = 1.0f;
    img[7] = 1.01f;
    const ImageErrorStats e = ImageErrors(img, ref);
    ASSERT_TRUE(e.psnr.has_value());
    EXPECT_NEAR(*e.psnr, 40.0, 1e-3);
    EXPECT_NEAR(e.pixel.p99, 0.01, 1e-6);
}

// PSNR against the formula evaluated here independently, in long double from the decimal values: two
// pixels whose channel differences are 0.1, 0, -0.2 | 0, 0.1, -0.3 (sum of squares 0.15, MSE 0.025) and
// whose reference peaks at 3: 10 log10(9 / 0.025) = 10 log10(360) = 25.5630250 dB.
TEST(ImageAccuracy, PsnrMatchesAnIndependentFormula) {
    const std::vector<float> ref = {0.5f, 1.5f, 2.0f, 0.25f, 0.0f, 3.0f};
    const std::vector<float> img = {0.6f, 1.5f, 1.8f, 0.25f, 0.1f, 2.7f};
    long double squares = 0, peak = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
        squares += (static_cast<long double>(img[i]) - ref[i]) * (static_cast<long double>(img[i]) - ref[i]);
        peak = std::max(peak, static_cast<long double>(ref[i]));
    }
    const long double independent = 10 * std::log10(peak * peak / (squares / ref.size()));
    const ImageErrorStats e = ImageErrors(img, ref);
    ASSERT_TRUE(e.psnr.has_value());
    EXPECT_NEAR(*e.psnr, double(independent), 1e-9);
    EXPECT_NEAR(*e.psnr, 25.5630250, 1e-5);  // the decimal inputs' value, within their float rounding
}

// A black reference has no peak of its own: the display's white (1) stands in, so 0.1 everywhere is 20 dB;
// two black images are equal (infinite PSNR, no value).
TEST(ImageAccuracy, BlackReferenceUsesPeakOne) {
    const std::vector<float> black(3 * 4, 0.0f), grey(3 * 4, 0.1f);
    const ImageErrorStats e = ImageErrors(grey, black);
    EXPECT_EQ(e.peak, 1.0);
    ASSERT_TRUE(e.psnr.has_value());
    EXPECT_NEAR(*e.psnr, 20.0, 1e-5);
    EXPECT_FALSE(ImageErrors(black, black).psnr.has_value());
}

}  // namespace
}  // namespace cb
