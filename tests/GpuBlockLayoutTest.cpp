// Test that every GPU parameter block declared twice, in C++ (core/) and in
// GLSL (core/math/), has the same members at the same offsets with the same
// types, member by member, as glslang lays the GLSL out (std430, and std140
// where the C++ header promises both). The GLSL struct is taken from its file
// as it is, put into a buffer block of a small compute shader, and
// glslangValidator's reflection (-q) gives each member's offset and GL type.
// sizeof alone would miss two swapped members of one type, or a member moved
// across a padding lane.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "core/math/Ground.h"
#include "core/math/Splat.h"
#include "core/pipeline/MarchGpu.h"

namespace cb::gpu_block_layout {
namespace {

// GL type enums as glslang's reflection prints them.
constexpr int kGlFloat = 0x1406, kGlInt = 0x1404, kGlVec4 = 0x8b52, kGlUvec4 = 0x8dc8;

template <typename T>
constexpr int GlTypeOf() {
    if constexpr (std::is_same_v<T, float>) return kGlFloat;
    if constexpr (std::is_same_v<T, int32_t>) return kGlInt;
    if constexpr (std::is_same_v<T, std::array<float, 4>> || std::is_same_v<T, float[4]>) return kGlVec4;
    if constexpr (std::is_same_v<T, std::array<uint32_t, 4>> || std::is_same_v<T, uint32_t[4]>) return kGlUvec4;
    return 0;  // a type this test does not know: the comparison fails and names it
}

struct Member {
    std::string name;  // the GLSL member's name
    size_t offset;     // where the C++ struct has it
    int glType;        // what the C++ member's type is in GLSL
};

#define CB_MEMBER(Struct, member) \
    Member { #member, offsetof(Struct, member), GlTypeOf < std::remove_cvref_t < decltype(Struct::member)>>() }

struct Block {
    std::string glslName;  // the struct's name in GLSL (and in C++)
    std::string file;      // under core/math/
    size_t bytes;          // sizeof the C++ struct
    bool std140;           // the header promises std140 as well as std430
    std::vector<Member> members;
};

std::vector<Block> Blocks() {
    // Splat's colour[3] is GLSL's r, g, b.
    const size_t colour = offsetof(Splat, colour);
    return {
        {"MarchGpu",
         "march.glsl",
         sizeof(MarchGpu),
         true,
         {CB_MEMBER(MarchGpu, eye), CB_MEMBER(MarchGpu, forward), CB_MEMBER(MarchGpu, right), CB_MEMBER(MarchGpu, up),
          CB_MEMBER(MarchGpu, size), CB_MEMBER(MarchGpu, stepping), CB_MEMBER(MarchGpu, sun),
          CB_MEMBER(MarchGpu, sunRadiance), CB_MEMBER(MarchGpu, ambient), CB_MEMBER(MarchGpu, background),
          CB_MEMBER(MarchGpu, pointPosition), CB_MEMBER(MarchGpu, pointRadiance), CB_MEMBER(MarchGpu, image),
          CB_MEMBER(MarchGpu, flags), CB_MEMBER(MarchGpu, strides), CB_MEMBER(MarchGpu, bricks)}},
        {"GroundGpu",
         "ground.glsl",
         sizeof(GroundGpu),
         true,
         {CB_MEMBER(GroundGpu, eye), CB_MEMBER(GroundGpu, forward), CB_MEMBER(GroundGpu, right),
          CB_MEMBER(GroundGpu, up), CB_MEMBER(GroundGpu, albedo), CB_MEMBER(GroundGpu, sunRadiance),
          CB_MEMBER(GroundGpu, ambient), CB_MEMBER(GroundGpu, background), CB_MEMBER(GroundGpu, grid)}},
        {"SplatFrame",
         "splat.glsl",
         sizeof(SplatFrame),
         false,
         {CB_MEMBER(SplatFrame, grid), CB_MEMBER(SplatFrame, axes), CB_MEMBER(SplatFrame, orderBase),
          CB_MEMBER(SplatFrame, boxes), CB_MEMBER(SplatFrame, image), CB_MEMBER(SplatFrame, eye),
          CB_MEMBER(SplatFrame, forward), CB_MEMBER(SplatFrame, right), CB_MEMBER(SplatFrame, up),
          CB_MEMBER(SplatFrame, sun), CB_MEMBER(SplatFrame, sunRadiance), CB_MEMBER(SplatFrame, ambient),
          CB_MEMBER(SplatFrame, background), CB_MEMBER(SplatFrame, origin), CB_MEMBER(SplatFrame, misc)}},
        {"Splat",
         "splat.glsl",
         sizeof(Splat),
         false,
         {CB_MEMBER(Splat, px), CB_MEMBER(Splat, py), CB_MEMBER(Splat, size), CB_MEMBER(Splat, alphaScale),
          Member{"r", colour, kGlFloat}, Member{"g", colour + 4, kGlFloat}, Member{"b", colour + 8, kGlFloat},
          CB_MEMBER(Splat, pad), CB_MEMBER(Splat, x0), CB_MEMBER(Splat, x1), CB_MEMBER(Splat, y0),
          CB_MEMBER(Splat, y1)}},
    };
}

// The declaration `struct NAME { ... };` as it stands in core/math/FILE.
std::string GlslStruct(const Block& block) {
    std::ifstream in(std::filesystem::path(CLOUDBENCH_SOURCE_DIR) / "core" / "math" / block.file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string source = text.str();
    std::smatch found;
    const std::regex declaration("struct " + block.glslName + " \\{[^}]*\\};");
    return std::regex_search(source, found, declaration) ? found.str() : "";
}

struct Reflected {
    size_t offset;
    int glType;
};

// glslangValidator's reflection of `instance`'s members (instance.member: offset N, type T, ...).
std::map<std::string, Reflected> Reflect(const std::string& shader, const std::string& instance, std::string& log) {
    // A name of this process and call: ctest runs this suite's tests in parallel processes.
    static int calls = 0;
    const auto path = std::filesystem::path(::testing::TempDir()) /
                      ("gpu_block_layout_" + std::to_string(getpid()) + "_" + std::to_string(calls++) + ".comp");
    std::ofstream(path) << shader;
    const std::string command =
        std::string(CLOUDBENCH_GLSLANG_VALIDATOR) + " -l -q --reflect-all-block-variables " + path.string() + " 2>&1";
    std::map<std::string, Reflected> members;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return members;
    char line[512];
    const std::regex entry("^" + instance + "\\.([A-Za-z0-9_]+): offset (\\d+), type ([0-9a-f]+),");
    while (std::fgets(line, sizeof line, pipe)) {
        log += line;
        std::cmatch m;
        if (std::regex_search(line, m, entry))
            members[m[1].str()] = {std::stoul(m[2].str()), int(std::stoul(m[3].str(), nullptr, 16))};
    }
    pclose(pipe);
    std::filesystem::remove(path);
    return members;
}

// A compute shader holding `declaration` (a struct of `block`'s GLSL name) as
// member `m` of a block laid out as `layout` ("std430": a storage buffer,
// "std140": a uniform block), which reads m's first member so that the block
// is live.
std::string BlockShader(const std::string& declaration, const Block& block, const std::string& layout) {
    const Member& first = block.members.front();
    const std::string lane = first.name + (first.glType == kGlVec4 || first.glType == kGlUvec4 ? ".x" : "");
    const std::string qualifier = layout == "std430" ? "layout(std430, binding = 0) readonly buffer Block"
                                                     : "layout(std140, binding = 0) uniform Block";
    return "#version 450\nlayout(local_size_x = 1) in;\n" + declaration + "\n" + qualifier + " { " + block.glslName +
           " m; };\nlayout(std430, binding = 1) writeonly buffer Out { uint o; };\n" + "void main() { o = uint(m." +
           lane + "); }\n";
}

void ExpectSameLayout(const Block& block, const std::string& layout) {
    const std::string declaration = GlslStruct(block);
    ASSERT_FALSE(declaration.empty()) << "no `struct " << block.glslName << " { ... };` in core/math/" << block.file;
    std::string log;
    const auto reflected = Reflect(BlockShader(declaration, block, layout), "m", log);
    ASSERT_EQ(reflected.size(), block.members.size())
        << block.glslName << " (" << layout << "): GLSL has " << reflected.size() << " members, the C++ table "
        << block.members.size() << "; glslangValidator said:\n"
        << log;
    size_t end = 0;
    for (const Member& member : block.members) {
        const auto it = reflected.find(member.name);
        ASSERT_NE(it, reflected.end()) << block.glslName << "." << member.name << " is not in the GLSL struct";
        EXPECT_EQ(it->second.offset, member.offset) << block.glslName << "." << member.name << " (" << layout << ")";
        EXPECT_EQ(it->second.glType, member.glType)
            << block.glslName << "." << member.name << " (" << layout << "): GL type 0x" << std::hex
            << it->second.glType << " in GLSL, 0x" << member.glType << " from the C++ type";
        end = std::max(end, member.offset + (member.glType == kGlVec4 || member.glType == kGlUvec4 ? 16 : 4));
    }
    EXPECT_EQ(end, block.bytes) << block.glslName << ": the C++ struct has bytes no member accounts for";
}

TEST(GpuBlockLayout, EveryMemberAtTheSameOffsetInCppAndGlsl) {
    if (std::string(CLOUDBENCH_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "no glslangValidator in this build";
    for (const Block& block : Blocks()) {
        ExpectSameLayout(block, "std430");
        if (block.std140) ExpectSameLayout(block, "std140");
    }
}

// Test that the check can fail: a GLSL twin with two members swapped is caught.
TEST(GpuBlockLayout, SwappedMembersAreCaught) {
    if (std::string(CLOUDBENCH_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "no glslangValidator in this build";
    const Block march = Blocks().front();
    std::string log;
    std::string declaration = GlslStruct(march);
    ASSERT_FALSE(declaration.empty());
    const size_t forward = declaration.find("vec4 forward;"), right = declaration.find("vec4 right;");
    ASSERT_NE(forward, std::string::npos);
    ASSERT_NE(right, std::string::npos);
    declaration.replace(right, 11, "vec4 forward;");
    declaration.replace(forward, 13, "vec4 right;");
    const auto reflected = Reflect(BlockShader(declaration, march, "std430"), "m", log);
    ASSERT_EQ(reflected.count("forward"), 1u) << log;
    EXPECT_NE(reflected.at("forward").offset, offsetof(MarchGpu, forward));
    EXPECT_EQ(reflected.at("forward").offset, offsetof(MarchGpu, right));
}

}  // namespace
}  // namespace cb::gpu_block_layout
