// The one reader of input files (core/base/PathPolicy.h) and the schemas of the JSON
// files cloudbench reads back (harness/platform/JsonInput.h, harness/report/InputFormats.h).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>

#include "core/base/PathPolicy.h"
#include "core/base/Npy.h"
#include "harness/platform/JsonInput.h"
#include "harness/report/InputFormats.h"

namespace cb {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

class InputFileTest : public ::testing::Test {
  protected:
    void SetUp() override {
        mDir = fs::temp_directory_path() / ("cloudbench-input-" + std::to_string(getpid()));
        fs::create_directories(mDir);
    }
    void TearDown() override { fs::remove_all(mDir); }
    std::string Write(const std::string& name, const std::string& text) {
        const std::string path = (mDir / name).string();
        std::ofstream(path, std::ios::binary) << text;
        return path;
    }
    fs::path mDir;
};

std::string ErrorOf(const Status& s) { return s ? "" : s.error().message; }
template <typename T>
std::string ErrorOf(const Result<T>& r) {
    return r ? "" : r.error().message;
}

// Test that a FIFO nobody writes is refused at once instead of blocking the reader.
TEST_F(InputFileTest, FifoRefusedWithoutBlocking) {
    const std::string path = (mDir / "pipe").string();
    ASSERT_EQ(mkfifo(path.c_str(), 0600), 0);
    const auto start = std::chrono::steady_clock::now();
    const auto read = ReadInputFile(path, kDocumentInput);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(2));
    EXPECT_EQ(ErrorOf(read), path + ": not a regular file (a FIFO)");
}

// Test that a device and a folder are refused by kind, and a missing file with the system's reason.
TEST_F(InputFileTest, DevicesFoldersAndMissingFiles) {
    EXPECT_EQ(ErrorOf(ReadInputFile("/dev/zero", kHistoryInput)), "/dev/zero: not a regular file (a device)");
    EXPECT_EQ(ErrorOf(ReadInputFile(mDir.string(), kSceneInput)), mDir.string() + ": not a regular file (a folder)");
    const std::string missing = (mDir / "missing.json").string();
    EXPECT_EQ(ErrorOf(ReadInputFile(missing, kSceneInput)),
              missing + ": cannot read the file: No such file or directory");
    EXPECT_EQ(ErrorOf(ReadNpy("/dev/zero")), "/dev/zero: not a regular file (a device)");
}

// Test that a file over its kind's size is refused with both numbers, and one at the size is read whole.
TEST_F(InputFileTest, SizeLimit) {
    constexpr InputKind kTiny{"a tiny file", 8, 1};
    const std::string at = Write("eight", "12345678"), over = Write("nine", "123456789");
    ASSERT_TRUE(ReadInputFile(at, kTiny));
    EXPECT_EQ(*ReadInputFile(at, kTiny), "12345678");
    EXPECT_EQ(ErrorOf(ReadInputFile(over, kTiny)), over + ": 9 bytes, more than the 8 bytes a tiny file may have");
    EXPECT_EQ(ErrorOf(OpenInputFile(over, kTiny)), over + ": 9 bytes, more than the 8 bytes a tiny file may have");
}

// Test that a .npy whose shape claims more elements than its data holds is refused before any allocation
// (a shape of 2^40 x 2^40 would ask for more memory than exists).
TEST_F(InputFileTest, NpyShapeBeyondItsData) {
    std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (1099511627776, 1099511627776), }";
    header.append((64 - (10 + header.size() + 1) % 64) % 64, ' ');
    header.push_back('\n');
    std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
    bytes.push_back(char(header.size() & 0xff));
    bytes.push_back(char(header.size() >> 8));
    bytes += header + std::string(16, '\0');
    const std::string path = Write("huge.npy", bytes);
    EXPECT_EQ(ErrorOf(ReadNpy(path)), path + ": truncated .npy data");
}

using namespace schema;

// Test that each kind of schema error names the field as a JSON pointer and gives the reason.
TEST(JsonSchema, ErrorsNameTheFieldAndTheReason) {
    const Node s = Object({{"format", TextOf({"a/1"}), true},
                           {"backends", MapOf(KeyRule::Backend, Object({{"ms", ArrayOf(Number(0, 10))}}))},
                           {"grid", ArrayOf(Integer(1, 100), 3, 3)},
                           {"name", Name()}});
    auto error = [&](const char* text) { return ErrorOf(Validate(json::parse(text), s, "f.json")); };
    EXPECT_EQ(error(R"({"format": "a/1"})"), "");
    EXPECT_EQ(error(R"({})"), "f.json: /format: missing");
    EXPECT_EQ(error(R"({"format": "a/2"})"), "f.json: /format: must be one of \"a/1\", not \"a/2\"");
    EXPECT_EQ(error(R"({"format": "a/1", "formt": 1})"), "f.json: /formt: unknown field (did you mean \"format\"?)");
    EXPECT_EQ(error(R"({"format": "a/1", "backends": {"cpuu": {}}})"),
              "f.json: /backends/cpuu: unknown backend \"cpuu\" (did you mean \"cpu\"?); known: cpu, gl, vk");
    EXPECT_EQ(error(R"({"format": "a/1", "backends": {"cpu": {"ms": [1, "2"]}}})"),
              "f.json: /backends/cpu/ms/1: must be a number in [0, 10], not \"2\"");
    EXPECT_EQ(error(R"({"format": "a/1", "backends": {"cpu": {"ms": [1, -1]}}})"),
              "f.json: /backends/cpu/ms/1: must be a number in [0, 10], got -1");
    EXPECT_EQ(error(R"({"format": "a/1", "backends": {"cpu": {"ms": [1e308]}}})"),
              "f.json: /backends/cpu/ms/0: must be a number in [0, 10], got 1e+308");
    EXPECT_EQ(error(R"({"format": "a/1", "grid": [1, 2]})"), "f.json: /grid: must have 3 elements, has 2");
    EXPECT_EQ(error(R"({"format": "a/1", "grid": [1, 2.5, 3]})"),
              "f.json: /grid/1: must be a whole number in [1, 100], got 2.5");
    EXPECT_EQ(error(R"({"format": "a/1", "name": "../x"})"),
              "f.json: /name: \"../x\" is not a name: must be 1 to 64 of the characters A-Z a-z 0-9 . _ - and not "
              "start with '.'");
    EXPECT_EQ(error(R"([])"), "f.json: /: must be an object, not an array");
}

// Test that keys holding '/' and '~' are escaped in pointers as RFC 6901 says, so every pointer names one field.
TEST(JsonSchema, PointerEscapes) {
    const Node s = MapOf(KeyRule::Any, Number(0, 1));
    EXPECT_EQ(ErrorOf(Validate(json::parse(R"({"a/b~c": 2})"), s, "f")), "f: /a~1b~0c: must be a number in [0, 1], got 2");
}

// Test that a duplicate key is refused with its pointer (a dotted path once showed "towers.[0]").
TEST(JsonSchema, DuplicateKeyNamedByPointer) {
    const auto read = ParseJsonInput(R"({"a": [{"b": 1, "b": 2}]})", "f.json", AnyValue());
    EXPECT_EQ(ErrorOf(read), "f.json: /a/0/b: duplicate key");
}

class HistoryTest : public InputFileTest {};

constexpr const char* kRecord = R"({"format": "cloudbench-perf/1", "id": "ID", "results": {}})";

std::string Record(const std::string& id) {
    std::string r = kRecord;
    return r.replace(r.find("ID"), 2, id);
}

// Test that lines cut short are skipped with a warning each, at most 10, then one line with the rest.
TEST_F(HistoryTest, CutShortLinesSkipped) {
    std::string text = Record("a") + "\n\n";
    for (int i = 0; i < 12; ++i) text += R"({"format": "cloudbench-perf/1", "id": "cut)" "\n";
    text += Record("b") + "\n";
    const std::string path = Write("h.jsonl", text);
    auto history = input::ReadHistory(path);
    ASSERT_TRUE(history) << history.error().message;
    ASSERT_EQ(history->records.size(), 2u);
    EXPECT_EQ(history->records[0].record["id"], "a");
    EXPECT_EQ(history->records[1].line, 15u);
    ASSERT_EQ(history->warnings.size(), 11u);
    EXPECT_EQ(history->warnings[0], path + ":3: skipped: not JSON (a write cut short?)");
    EXPECT_EQ(history->warnings[10], path + ": 2 more lines skipped: not JSON");
}

// Test that a file whose first line is not a record is not a history (a pretty-printed results.json begins "{"),
// and that a record of the wrong shape is an error naming the line and the field, not a silent skip.
TEST_F(HistoryTest, NotAHistoryAndBadRecords) {
    const std::string pretty = Write("results.json", "{\n \"format\": \"cloudbench-results/1\"\n");
    EXPECT_EQ(ErrorOf(input::ReadHistory(pretty)),
              pretty + ": not a perf history (JSON Lines of cloudbench-perf/1 records): line 1 is not a JSON object");
    const std::string stringMedian =
        Write("h.jsonl", Record("a") + "\n" +
                             R"({"format": "cloudbench-perf/1", "id": "b", "results": {"ci-small": {"cpu": {"region": )"
                             R"({"samples_ms": [1], "median_ms": "1"}}}}})" "\n");
    EXPECT_EQ(ErrorOf(input::ReadHistory(stringMedian)),
              stringMedian + ":2: /results/ci-small/cpu/region/median_ms: must be a number in [0, 1e+09] or null, "
                             "not \"1\"");
    const std::string other = Write("o.jsonl", Record("a") + "\n{\"format\": \"other\"}\n");
    EXPECT_EQ(ErrorOf(input::ReadHistory(other)),
              other + ":2: not a cloudbench-perf/1 record (a perf history holds only records)");
}

// Test that a document of another format is named by what it is, and that perf compare's sides tell a history
// (JSON Lines) from a document.
TEST_F(HistoryTest, DocumentsAndHistoriesApart) {
    const std::string sweep = Write("s.json", R"({"format": "cloudbench-sweep/1"})");
    static constexpr input::Format kResults[] = {input::Format::Results, input::Format::Count};
    EXPECT_EQ(ErrorOf(input::ReadCloudbenchFile(sweep, kResults)),
              sweep + ": not a results.json or a count output (\"format\" is \"cloudbench-sweep/1\")");
    const std::string history = Write("h.jsonl", Record("a") + "\n" + Record("b") + "\n");
    auto read = input::ReadDocumentOrHistory(history, kResults);
    ASSERT_TRUE(read) << read.error().message;
    ASSERT_TRUE(std::holds_alternative<input::History>(*read));
    EXPECT_EQ(std::get<input::History>(*read).records.size(), 2u);
    const std::string truncated = Write("t.json", "{\"format\": \"cloudbench-results/1\", \"scene\"");
    const std::string error = ErrorOf(input::ReadDocumentOrHistory(truncated, kResults));
    EXPECT_TRUE(error.starts_with(truncated + ": not a results.json or a count output, nor a perf history: line 1, column "))
        << error;
    EXPECT_NE(error.find("malformed JSON"), std::string::npos) << error;
    EXPECT_TRUE(error.ends_with("(its first line is not a record either)")) << error;
    // A record alone is a history of one, for merge and for perf compare's FILE@ID.
    const std::string one = Write("one.jsonl", Record("only"));
    auto single = input::ReadDocumentOrHistory(one, kResults);
    ASSERT_TRUE(single) << single.error().message;
    ASSERT_TRUE(std::holds_alternative<input::History>(*single));
    EXPECT_EQ(std::get<input::History>(*single).records.at(0).record["id"], "only");
}

}  // namespace
}  // namespace cb
