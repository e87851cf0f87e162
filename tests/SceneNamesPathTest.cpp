// Names that become path components (the scene's out/<name>, the cameras' frame files): the rule, its message,
// and the echoed value kept safe to print, so that nothing escapes its folder.
#include <gtest/gtest.h>

#include <string>

#include "SceneTestUtil.h"
#include "core/plan/SceneLoad.h"
#include "core/scene/Scene.h"

namespace cb {
namespace {

using test::ErrorOf;
using test::HasLine;
using test::Parsed;
using test::SplitLines;

constexpr const char* kRule = "must be 1 to 64 of the characters A-Z a-z 0-9 . _ - and not start with '.'";

// A minimal scene with `name` (JSON text of the value) as its name.
std::string WithName(const std::string& name) { return R"({"grid": {"size": [8, 4, 6]}, "name": )" + name + "}"; }

// A minimal scene with one camera named `name` (JSON text of the value).
std::string WithCamera(const std::string& name) {
    return R"({"grid": {"size": [8, 4, 6]}, "render": {"cameras": [{"name": )" + name +
           R"(, "eye": [0, 0, 0], "target": [1, 0, 0]}]}})";
}

// The one error line expected for a scene name or camera name shown as `shown`.
std::string NameLine(const std::string& field, const std::string& shown) {
    return "test.json: " + field + ": " + kRule + ", got " + shown;
}

// Test that names that would leave out/ or name no file are refused, each with the rule and the value.
TEST(SceneNamesPathTest, SceneNameRefused) {
    const std::string a65(65, 'a');
    const struct {
        const char* json;
        std::string shown;
    } cases[] = {
        {R"("../../x")", R"("../../x")"},
        {R"("a/b")", R"("a/b")"},
        {R"("a\\b")", R"("a\\b")"},
        {R"("")", R"("")"},
        {R"(".")", R"(".")"},
        {R"("..")", R"("..")"},
        {R"(".hidden")", R"(".hidden")"},
        {R"("my scene")", R"("my scene")"},
        {R"("café")", R"("café")"},
    };
    for (const auto& c : cases) {
        const std::string message = ErrorOf(WithName(c.json));
        EXPECT_TRUE(HasLine(message, NameLine("name", c.shown))) << c.json;
        EXPECT_EQ(SplitLines(message).size(), 1u) << message;
    }
    // 65 characters: one too many, shown cut to 57 and "...".
    EXPECT_TRUE(HasLine(ErrorOf(WithName('"' + a65 + '"')), NameLine("name", '"' + a65.substr(0, 57) + "...\"")));
}

// Test that control characters in a refused name are shown escaped, never as raw bytes.
TEST(SceneNamesPathTest, ControlBytesShownEscaped) {
    const std::string esc = ErrorOf(WithName(R"("a\u001b[31mb")"));
    EXPECT_TRUE(HasLine(esc, NameLine("name", R"("a\u001b[31mb")")));
    EXPECT_EQ(esc.find('\x1b'), std::string::npos);
    EXPECT_TRUE(HasLine(ErrorOf(WithName(R"("bell\u0007\n")")), NameLine("name", R"("bell\u0007\u000a")")));
    EXPECT_TRUE(HasLine(ErrorOf(WithName(R"("del\u007f")")), NameLine("name", R"("del\u007f")")));
    // U+009B is the one-character CSI of C1.
    EXPECT_TRUE(HasLine(ErrorOf(WithName(R"("csi\u009b2J")")), NameLine("name", R"("csi\u009b2J")")));
    // Bytes that are not UTF-8 can come from the command line.
    EXPECT_TRUE(HasLine(ErrorOf(WithName(R"("s")"), {{"name", "a\xff\xc3"}}),
                        NameLine("name", R"("a\xff\xc3")") + " (set on the command line)"));
}

// Test that a long refused name is echoed cut short, escapes counting as one character each.
TEST(SceneNamesPathTest, LongValueCutShort) {
    std::string json = "\"";
    for (int i = 0; i < 1000; ++i) json += R"(\u001b)";
    json += '"';
    std::string shown = "\"";
    for (int i = 0; i < 57; ++i) shown += R"(\u001b)";
    shown += "...\"";
    EXPECT_TRUE(HasLine(ErrorOf(WithName(json)), NameLine("name", shown)));
    // Exactly 60 shown characters are not cut.
    const std::string sixty(60, '/');
    EXPECT_TRUE(HasLine(ErrorOf(WithName('"' + sixty + '"')), NameLine("name", '"' + sixty + '"')));
}

// Test that --set name=../../x is refused at load time and said to come from the command line.
TEST(SceneNamesPathTest, OverrideRefused) {
    EXPECT_TRUE(HasLine(ErrorOf(WithName(R"("s")"), {{"name", "../../x"}}),
                        NameLine("name", R"("../../x")") + " (set on the command line)"));
}

// Test that a name of another type is still refused as not a string.
TEST(SceneNamesPathTest, NameNotAString) {
    EXPECT_TRUE(HasLine(ErrorOf(WithName("7")), "test.json: name: expected a string, got 7"));
}

// Test that camera names follow the same rule, each reported on its own entry.
TEST(SceneNamesPathTest, CameraNameRefused) {
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera(R"("a/b")")), NameLine("render.cameras[0].name", R"("a/b")")));
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera(R"("../../x")")), NameLine("render.cameras[0].name", R"("../../x")")));
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera(R"("")")), NameLine("render.cameras[0].name", R"("")")));
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera(R"("..")")), NameLine("render.cameras[0].name", R"("..")")));
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera(R"(".hidden")")), NameLine("render.cameras[0].name", R"(".hidden")")));
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera(R"("a\u001bb")")), NameLine("render.cameras[0].name", R"("a\u001bb")")));
    const std::string a65(65, 'a');
    EXPECT_TRUE(HasLine(ErrorOf(WithCamera('"' + a65 + '"')),
                        NameLine("render.cameras[0].name", '"' + a65.substr(0, 57) + "...\"")));
}

// Test that names inside the rule are accepted as given, up to 64 characters.
TEST(SceneNamesPathTest, ValidNamesAccepted) {
    EXPECT_EQ(Parsed(WithName(R"("thesis-medium_2.v1")")).name, "thesis-medium_2.v1");
    const std::string a64(64, 'a');
    EXPECT_EQ(Parsed(WithName('"' + a64 + '"')).name, a64);
    EXPECT_EQ(Parsed(WithName(R"("x..y")")).name, "x..y");
    EXPECT_EQ(Parsed(WithCamera(R"("thesis-medium_2.v1")")).render.cameras.at(0).name, "thesis-medium_2.v1");
    EXPECT_EQ(Parsed(WithCamera('"' + a64 + '"')).render.cameras.at(0).name, a64);
}

// Test that a default name from a file name outside the rule is refused, naming the file and suggesting "name".
TEST(SceneNamesPathTest, DefaultNameFromFileStem) {
    const std::string text = R"({"grid": {"size": [8, 4, 6]}})";
    Result<Scene> bad = ParseScene(text, "scenes/my scene.json");
    ASSERT_FALSE(bad);
    EXPECT_TRUE(HasLine(bad.error().message, std::string(R"(scenes/my scene.json: name: the default name "my scene")") +
                                                 " (the file name) " + kRule + R"(; set "name" in the file)"));
    EXPECT_EQ(SplitLines(bad.error().message).size(), 1u) << bad.error().message;

    Result<Scene> hidden = ParseScene(text, "scenes/.json");
    ASSERT_FALSE(hidden);
    EXPECT_TRUE(HasLine(hidden.error().message, std::string(R"(scenes/.json: name: the default name ".json")") +
                                                    " (the file name) " + kRule + R"(; set "name" in the file)"));

    // A name in the file (or from --set) replaces the default, and the file name no longer matters.
    Result<Scene> named = ParseScene(R"({"grid": {"size": [8, 4, 6]}, "name": "storm"})", "scenes/my scene.json");
    ASSERT_TRUE(named) << named.error().message;
    EXPECT_EQ(named->name, "storm");
    Result<Scene> set = ParseScene(text, "scenes/my scene.json", {{"name", "storm"}});
    ASSERT_TRUE(set) << set.error().message;
    EXPECT_EQ(set->name, "storm");

    // A valid file name gives the default.
    Result<Scene> good = ParseScene(text, "scenes/thesis-medium_2.v1.json");
    ASSERT_TRUE(good) << good.error().message;
    EXPECT_EQ(good->name, "thesis-medium_2.v1");
}

}  // namespace
}  // namespace cb
