// The scenes shipped in scenes/ load, and have the sizes the docs promise.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/Scene.h"

namespace cb {
namespace {

// Test that every shipped scene passes validation.
TEST(ScenesShipped, AllLoad) {
    size_t count = 0;
    for (const auto& entry : std::filesystem::directory_iterator(CLOUDBENCH_SCENES_DIR)) {
        if (entry.path().extension() != ".json") continue;
        auto scene = LoadScene(entry.path().string());
        EXPECT_TRUE(scene.has_value()) << scene.error().message;
        ++count;
    }
    EXPECT_GE(count, 4u);
}

// Test that the thesis scenes use the thesis's 256x32x256 grid and ci-small stays small.
TEST(ScenesShipped, Sizes) {
    for (const char* name : {"thesis-low", "thesis-medium", "thesis-high"}) {
        auto scene = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/" + name + ".json");
        ASSERT_TRUE(scene.has_value()) << scene.error().message;
        EXPECT_EQ(scene->grid.size, (Extent3{256, 32, 256})) << name;
        EXPECT_EQ(scene->name, name);
    }
    auto small = LoadScene(std::string(CLOUDBENCH_SCENES_DIR) + "/ci-small.json");
    ASSERT_TRUE(small.has_value()) << small.error().message;
    EXPECT_LE(small->grid.size.Count(), 100000u);
}

}  // namespace
}  // namespace cb
