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
#include <iterator>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

#include "core/math/Ground.h"
#include "core/math/Light.h"
#include "core/math/Splat.h"
#include "core/pipeline/LayersGpu.h"
#include "core/pipeline/MarchGpu.h"
#include "impl_vk/PushBlocks.h"

namespace cb::gpu_block_layout {
namespace {

// GL type enums as glslang's reflection prints them.
constexpr int kGlFloat = 0x1406, kGlInt = 0x1404, kGlUint = 0x1405, kGlVec2 = 0x8b50, kGlVec3 = 0x8b51,
              kGlVec4 = 0x8b52, kGlUvec3 = 0x8dc7, kGlUvec4 = 0x8dc8;

template <typename T>
constexpr int GlTypeOf() {
    if constexpr (std::is_same_v<T, float>) return kGlFloat;
    if constexpr (std::is_same_v<T, int32_t>) return kGlInt;
    if constexpr (std::is_same_v<T, uint32_t>) return kGlUint;
    if constexpr (std::is_same_v<T, std::array<float, 2>> || std::is_same_v<T, float[2]>) return kGlVec2;
    if constexpr (std::is_same_v<T, std::array<float, 3>> || std::is_same_v<T, float[3]>) return kGlVec3;
    if constexpr (std::is_same_v<T, std::array<float, 4>> || std::is_same_v<T, float[4]>) return kGlVec4;
    if constexpr (std::is_same_v<T, std::array<uint32_t, 3>> || std::is_same_v<T, uint32_t[3]>) return kGlUvec3;
    if constexpr (std::is_same_v<T, std::array<uint32_t, 4>> || std::is_same_v<T, uint32_t[4]>) return kGlUvec4;
    return 0;  // a type this test does not know: the comparison fails and names it
}

// Bytes of a member of GL type t.
constexpr size_t GlBytes(int t) {
    return t == kGlVec4 || t == kGlUvec4 ? 16 : t == kGlVec3 || t == kGlUvec3 ? 12 : t == kGlVec2 ? 8 : 4;
}

struct Member {
    std::string name;  // the GLSL member's name (nested: "light.sunRadiance")
    size_t offset;     // where the C++ struct has it
    int glType;        // what the C++ member's type is in GLSL (an array's: its element's)
    size_t count = 1;  // an array's elements (each 16 bytes apart: vec4 arrays only)
};

#define CB_MEMBER(Struct, member) \
    Member { #member, offsetof(Struct, member), GlTypeOf < std::remove_cvref_t < decltype(Struct::member)>>() }
// A std::array of vec4 rows, GLSL's vec4 member[N].
#define CB_VEC4_ARRAY_MEMBER(Struct, member)                                                            \
    Member {                                                                                            \
#member, offsetof(Struct, member), GlTypeOf < typename decltype(Struct::member)::value_type>(), \
            std::tuple_size_v < decltype(Struct::member)>                                               \
    }

// The members of LightGpu (core/math/Light.h), as a block's member `prefix` at byte `at`.
std::vector<Member> LightMembers(const std::string& prefix, size_t at) {
    std::vector<Member> light = {CB_MEMBER(LightGpu, sunRadiance),
                                 CB_MEMBER(LightGpu, phaseKind),
                                 CB_MEMBER(LightGpu, ambient),
                                 CB_MEMBER(LightGpu, phaseG),
                                 CB_MEMBER(LightGpu, pointPosition),
                                 CB_MEMBER(LightGpu, pointMinDistance2),
                                 CB_MEMBER(LightGpu, pointRadiance),
                                 CB_MEMBER(LightGpu, pointOn),
                                 CB_MEMBER(LightGpu, voxelSize),
                                 CB_MEMBER(LightGpu, mieIndexPerRadian),
                                 CB_MEMBER(LightGpu, mieCount),
                                 CB_MEMBER(LightGpu, unused),
                                 CB_MEMBER(LightGpu, phaseGForward),
                                 CB_MEMBER(LightGpu, phaseGBackward),
                                 CB_MEMBER(LightGpu, phaseBlend),
                                 CB_MEMBER(LightGpu, phaseUnused),
                                 CB_MEMBER(LightGpu, glowColor),
                                 CB_MEMBER(LightGpu, glowOn),
                                 CB_MEMBER(LightGpu, glowFade),
                                 CB_MEMBER(LightGpu, invThickness),
                                 CB_MEMBER(LightGpu, glowBlobCount),
                                 CB_MEMBER(LightGpu, glowUnused),
                                 CB_VEC4_ARRAY_MEMBER(LightGpu, glowBlobs),
                                 CB_MEMBER(LightGpu, sunDirection),
                                 CB_MEMBER(LightGpu, eyeOn),
                                 CB_MEMBER(LightGpu, eyeIntensity),
                                 CB_MEMBER(LightGpu, eyeCosCone),
                                 CB_MEMBER(LightGpu, eyeInvOneMinusCos),
                                 CB_MEMBER(LightGpu, eyeHeightGain),
                                 CB_MEMBER(LightGpu, skyRadiance),
                                 CB_MEMBER(LightGpu, skyOn),
                                 CB_MEMBER(LightGpu, skyDirection),
                                 CB_MEMBER(LightGpu, skyUnused),
                                 CB_MEMBER(LightGpu, octaves),
                                 CB_MEMBER(LightGpu, octaveAttenuation),
                                 CB_MEMBER(LightGpu, octaveContribution),
                                 CB_MEMBER(LightGpu, octaveEccentricity)};
    for (Member& m : light) m.name = prefix + m.name, m.offset += at;
    return light;
}

template <typename... Lists>
std::vector<Member> Concat(std::vector<Member> first, const Lists&... rest) {
    (first.insert(first.end(), rest.begin(), rest.end()), ...);
    return first;
}

struct Block {
    std::string glslName;  // the struct's name in GLSL (and in C++)
    std::string file;      // under core/math/
    size_t bytes;          // sizeof the C++ struct
    bool std140;           // the header promises std140 as well as std430
    std::vector<Member> members;
    bool nestsLight = false;  // has a LightGpu member (light.glsl's struct goes before it)
};

std::vector<Block> Blocks() {
    // Splat's colour[3] is GLSL's r, g, b.
    const size_t colour = offsetof(Splat, colour);
    return {
        {"MarchGpu", "march.glsl", sizeof(MarchGpu), true,
         Concat({CB_MEMBER(MarchGpu, eye),
                 CB_MEMBER(MarchGpu, focalPx),
                 CB_MEMBER(MarchGpu, forward),
                 CB_MEMBER(MarchGpu, nearPlane),
                 CB_MEMBER(MarchGpu, right),
                 CB_MEMBER(MarchGpu, farPlane),
                 CB_MEMBER(MarchGpu, up),
                 CB_MEMBER(MarchGpu, voxelSize),
                 CB_MEMBER(MarchGpu, size),
                 CB_MEMBER(MarchGpu, sigmaH),
                 CB_MEMBER(MarchGpu, baseStep),
                 CB_MEMBER(MarchGpu, kappa),
                 CB_MEMBER(MarchGpu, adaptiveStart),
                 CB_MEMBER(MarchGpu, epsilon),
                 CB_MEMBER(MarchGpu, sun),
                 CB_MEMBER(MarchGpu, powderC),
                 CB_MEMBER(MarchGpu, background),
                 CB_MEMBER(MarchGpu, flags),
                 CB_MEMBER(MarchGpu, width),
                 CB_MEMBER(MarchGpu, height),
                 CB_MEMBER(MarchGpu, seed),
                 CB_MEMBER(MarchGpu, frame),
                 CB_MEMBER(MarchGpu, lightSteps),
                 CB_MEMBER(MarchGpu, brick),
                 CB_MEMBER(MarchGpu, strideY),
                 CB_MEMBER(MarchGpu, strideZ),
                 CB_MEMBER(MarchGpu, bricks),
                 CB_MEMBER(MarchGpu, unused),
                 CB_MEMBER(MarchGpu, invSize),
                 CB_MEMBER(MarchGpu, unused2)},
                LightMembers("light.", offsetof(MarchGpu, light))),
         true},
        {"LayersGpu", "layers.glsl", sizeof(LayersGpu), true,
         Concat({CB_MEMBER(LayersGpu, eye),       CB_MEMBER(LayersGpu, focalPx),    CB_MEMBER(LayersGpu, forward),
                 CB_MEMBER(LayersGpu, nearPlane), CB_MEMBER(LayersGpu, right),      CB_MEMBER(LayersGpu, farPlane),
                 CB_MEMBER(LayersGpu, up),        CB_MEMBER(LayersGpu, voxelSize),  CB_MEMBER(LayersGpu, size),
                 CB_MEMBER(LayersGpu, sigmaH),    CB_MEMBER(LayersGpu, invSize),    CB_MEMBER(LayersGpu, spacing),
                 CB_MEMBER(LayersGpu, sun),       CB_MEMBER(LayersGpu, outer2),     CB_MEMBER(LayersGpu, background),
                 CB_MEMBER(LayersGpu, maxLength), CB_MEMBER(LayersGpu, width),      CB_MEMBER(LayersGpu, height),
                 CB_MEMBER(LayersGpu, count),     CB_MEMBER(LayersGpu, flags),      CB_MEMBER(LayersGpu, strideY),
                 CB_MEMBER(LayersGpu, strideZ),   CB_MEMBER(LayersGpu, lightScale), CB_MEMBER(LayersGpu, fadeInv2),
                 CB_MEMBER(LayersGpu, drift),     CB_MEMBER(LayersGpu, coverage),   CB_MEMBER(LayersGpu, density)},
                std::vector<Member>{CB_MEMBER(LayersGpu, inner2), CB_MEMBER(LayersGpu, halfWidth),
                                    CB_MEMBER(LayersGpu, halfHeight), CB_MEMBER(LayersGpu, billboardLength),
                                    CB_MEMBER(LayersGpu, billboardCount)},
                LightMembers("light.", offsetof(LayersGpu, light))),
         true},
        {"LightGpu", "light.glsl", sizeof(LightGpu), true, LightMembers("", 0)},
        {"GroundGpu",
         "ground.glsl",
         sizeof(GroundGpu),
         true,
         {CB_MEMBER(GroundGpu, eye),       CB_MEMBER(GroundGpu, focalPx),     CB_MEMBER(GroundGpu, forward),
          CB_MEMBER(GroundGpu, nearPlane), CB_MEMBER(GroundGpu, right),       CB_MEMBER(GroundGpu, farPlane),
          CB_MEMBER(GroundGpu, up),        CB_MEMBER(GroundGpu, voxelSize),   CB_MEMBER(GroundGpu, albedo),
          CB_MEMBER(GroundGpu, sunZ),      CB_MEMBER(GroundGpu, sunRadiance), CB_MEMBER(GroundGpu, unused0),
          CB_MEMBER(GroundGpu, ambient),   CB_MEMBER(GroundGpu, unused1),     CB_MEMBER(GroundGpu, background),
          CB_MEMBER(GroundGpu, unused2),   CB_MEMBER(GroundGpu, gridX),       CB_MEMBER(GroundGpu, gridY),
          CB_MEMBER(GroundGpu, width),     CB_MEMBER(GroundGpu, height)}},
        {"SplatFrame", "splat.glsl", sizeof(SplatFrame), false,
         Concat(
             {CB_MEMBER(SplatFrame, grid),       CB_MEMBER(SplatFrame, ranksPerChunk), CB_MEMBER(SplatFrame, axes),
              CB_MEMBER(SplatFrame, voxelCount), CB_MEMBER(SplatFrame, orderBase),     CB_MEMBER(SplatFrame, unused0),
              CB_MEMBER(SplatFrame, boxTile),    CB_MEMBER(SplatFrame, boxBand),       CB_MEMBER(SplatFrame, boxTilesX),
              CB_MEMBER(SplatFrame, boxTilesY),  CB_MEMBER(SplatFrame, width),         CB_MEMBER(SplatFrame, height),
              CB_MEMBER(SplatFrame, tilesX),     CB_MEMBER(SplatFrame, tilesY),        CB_MEMBER(SplatFrame, eye),
              CB_MEMBER(SplatFrame, nearPlane),  CB_MEMBER(SplatFrame, forward),       CB_MEMBER(SplatFrame, focalPx),
              CB_MEMBER(SplatFrame, right),      CB_MEMBER(SplatFrame, qMin),          CB_MEMBER(SplatFrame, up),
              CB_MEMBER(SplatFrame, opacity),    CB_MEMBER(SplatFrame, sun),           CB_MEMBER(SplatFrame, voxelSize),
              CB_MEMBER(SplatFrame, background), CB_MEMBER(SplatFrame, splatDiameter), CB_MEMBER(SplatFrame, origin),
              CB_MEMBER(SplatFrame, alpha),      CB_MEMBER(SplatFrame, maxPointSize),  CB_MEMBER(SplatFrame, unused1),
              CB_MEMBER(SplatFrame, unused2),    CB_MEMBER(SplatFrame, unused3)},
             LightMembers("light.", offsetof(SplatFrame, light))),
         true},
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
std::string GlslStruct(const std::string& name, const std::string& file) {
    std::ifstream in(std::filesystem::path(CLOUDBENCH_SOURCE_DIR) / "core" / "math" / file);
    std::stringstream text;
    text << in.rdbuf();
    const std::string source = text.str();
    std::smatch found;
    const std::regex declaration("struct " + name + " \\{[^}]*\\};");
    return std::regex_search(source, found, declaration) ? found.str() : "";
}

// The block's declaration, after light.glsl's LightGpu where it nests one.
std::string GlslStruct(const Block& block) {
    const std::string own = GlslStruct(block.glslName, block.file);
    if (own.empty() || !block.nestsLight) return own;
    const std::string light = GlslStruct("LightGpu", "light.glsl");
    return light.empty() ? "" : light + "\n" + own;
}

struct Reflected {
    size_t offset;
    int glType;
    size_t size;  // array elements (1 for a plain member)
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
    const std::regex entry("^" + instance + "\\.([A-Za-z0-9_.]+): offset (\\d+), type ([0-9a-f]+), size (\\d+),");
    while (std::fgets(line, sizeof line, pipe)) {
        log += line;
        std::cmatch m;
        if (std::regex_search(line, m, entry))
            members[m[1].str()] = {std::stoul(m[2].str()), int(std::stoul(m[3].str(), nullptr, 16)),
                                   std::stoul(m[4].str())};
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
    const bool isVector = first.glType != kGlFloat && first.glType != kGlInt && first.glType != kGlUint;
    const std::string lane = first.name + (isVector ? ".x" : "");
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
        EXPECT_EQ(it->second.size, member.count) << block.glslName << "." << member.name << " (" << layout << ")";
        end = std::max(end, member.offset + (member.count - 1) * 16 + GlBytes(member.glType));
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
    const size_t forward = declaration.find("vec3 forward;"), right = declaration.find("vec3 right;");
    ASSERT_NE(forward, std::string::npos);
    ASSERT_NE(right, std::string::npos);
    declaration.replace(right, 11, "vec3 forward;");
    declaration.replace(forward, 13, "vec3 right;");
    const auto reflected = Reflect(BlockShader(declaration, march, "std430"), "m", log);
    ASSERT_EQ(reflected.count("forward"), 1u) << log;
    EXPECT_NE(reflected.at("forward").offset, offsetof(MarchGpu, forward));
    EXPECT_EQ(reflected.at("forward").offset, offsetof(MarchGpu, right));
}

// ---- The Vulkan push-constant blocks (impl_vk/PushBlocks.h) against the shaders' `Params` ----

using vk::PushFloat8;  // the member types CB_VK_PUSH_BLOCKS names unqualified
using vk::PushVec3;

template <typename T>
constexpr int PushGlType() {
    if constexpr (std::is_same_v<T, PushFloat8>) return kGlFloat;  // float[8]: reflected as float, size 8
    return GlTypeOf<T>();
}
template <typename T>
constexpr size_t PushCount() {
    return std::is_same_v<T, PushFloat8> ? 8 : 1;
}

struct PushMember {
    std::string name;
    size_t offset;
    int glType;
    size_t count;  // array elements (1 for a scalar or vector)
};
struct PushBlock {
    size_t bytes;  // sizeof the C++ struct
    std::vector<PushMember> members;
};

#define CB_TEST_PUSH_MEMBER(type, name) \
    PushMember{#name, offsetof(PushStruct, name), PushGlType<type>(), PushCount<type>()},
#define CB_TEST_PUSH_BLOCK(Name, MEMBERS)                                      \
    {#Name, [] {                                                               \
         using PushStruct = vk::Name;                                          \
         return PushBlock{sizeof(PushStruct), {MEMBERS(CB_TEST_PUSH_MEMBER)}}; \
     }()},
#define CB_TEST_PUSH_SHADER(Name, shader) {#Name, shader},

const std::map<std::string, PushBlock>& PushBlocks() {
    static const std::map<std::string, PushBlock> blocks = {CB_VK_PUSH_BLOCKS(CB_TEST_PUSH_BLOCK)};
    return blocks;
}
// (block, shader file stem) for every shader with a push-constant block.
const std::vector<std::pair<std::string, std::string>>& PushShaders() {
    static const std::vector<std::pair<std::string, std::string>> shaders = {CB_VK_PUSH_SHADERS(CB_TEST_PUSH_SHADER)};
    return shaders;
}

struct ReflectedPush {
    std::map<std::string, PushMember> members;
    size_t bytes = 0;  // the block's size
    std::string log;
};

// glslangValidator's reflection of impl_vk/shaders/<stem>.comp's `Params` block, from the file itself.
ReflectedPush ReflectPush(const std::string& stem) {
    const std::filesystem::path root(CLOUDBENCH_SOURCE_DIR);
    const std::string command = std::string(CLOUDBENCH_GLSLANG_VALIDATOR) +
                                " --target-env vulkan1.2 -l -q --reflect-all-block-variables -o /dev/null -I" +
                                (root / "core" / "math").string() + " -I" + (root / "impl_vk" / "shaders").string() +
                                " " + (root / "impl_vk" / "shaders" / (stem + ".comp")).string() + " 2>&1";
    ReflectedPush out;
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return out;
    const std::regex member("^Params\\.([A-Za-z0-9_]+): offset (\\d+), type ([0-9a-f]+), size (\\d+),");
    const std::regex block("^Params: offset -1, type ffffffff, size (\\d+),");
    char line[512];
    while (std::fgets(line, sizeof line, pipe)) {
        out.log += line;
        std::cmatch m;
        if (std::regex_search(line, m, member))
            out.members[m[1].str()] = {m[1].str(), std::stoul(m[2].str()), int(std::stoul(m[3].str(), nullptr, 16)),
                                       std::stoul(m[4].str())};
        else if (std::regex_search(line, m, block))
            out.bytes = std::stoul(m[1].str());
    }
    pclose(pipe);
    return out;
}

// Every way `block` (the C++ side) differs from `reflected` (the shader's), one line each; none when they agree.
std::vector<std::string> PushDifferences(const std::string& name, const PushBlock& block,
                                         const ReflectedPush& reflected) {
    std::vector<std::string> out;
    if (reflected.members.size() != block.members.size())
        out.push_back(name + ": the shader's Params has " + std::to_string(reflected.members.size()) +
                      " members, the C++ block " + std::to_string(block.members.size()));
    for (const PushMember& m : block.members) {
        const auto it = reflected.members.find(m.name);
        if (it == reflected.members.end()) {
            out.push_back(name + "." + m.name + " is not in the shader's Params");
            continue;
        }
        const PushMember& g = it->second;
        if (g.offset != m.offset)
            out.push_back(name + "." + m.name + ": offset " + std::to_string(g.offset) + " in GLSL, " +
                          std::to_string(m.offset) + " in C++");
        if (g.glType != m.glType || g.count != m.count)
            out.push_back(name + "." + m.name + ": GL type " + std::to_string(g.glType) + " x " +
                          std::to_string(g.count) + " in GLSL, " + std::to_string(m.glType) + " x " +
                          std::to_string(m.count) + " from C++");
    }
    if (reflected.bytes != block.bytes)
        out.push_back(name + ": " + std::to_string(reflected.bytes) + " bytes in GLSL, sizeof " +
                      std::to_string(block.bytes) + " in C++");
    return out;
}

TEST(GpuBlockLayout, EveryVulkanPushBlockMemberAtItsShadersOffset) {
    if (std::string(CLOUDBENCH_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "no glslangValidator in this build";
    std::set<std::string> pushed;
    for (const auto& [name, stem] : PushShaders()) {
        pushed.insert(stem);
        const ReflectedPush reflected = ReflectPush(stem);
        ASSERT_FALSE(reflected.members.empty()) << stem << ".comp: no Params block reflected\n" << reflected.log;
        for (const std::string& difference : PushDifferences(name, PushBlocks().at(name), reflected))
            ADD_FAILURE() << stem << ".comp: " << difference;
    }
    // Every shader that declares a push-constant block is in the list.
    for (const auto& entry :
         std::filesystem::directory_iterator(std::filesystem::path(CLOUDBENCH_SOURCE_DIR) / "impl_vk" / "shaders")) {
        if (entry.path().extension() != ".comp") continue;
        std::ifstream in(entry.path());
        const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        if (text.find("layout(push_constant)") != std::string::npos) {
            EXPECT_EQ(pushed.count(entry.path().stem().string()), 1u)
                << entry.path().filename() << " has a push-constant block that CB_VK_PUSH_SHADERS does not list";
        }
    }
}

// Test that the check can fail: ShadowPush with fx and fy swapped on the C++ side differs in both offsets.
TEST(GpuBlockLayout, ASwappedPushMemberIsCaught) {
    if (std::string(CLOUDBENCH_GLSLANG_VALIDATOR).empty()) GTEST_SKIP() << "no glslangValidator in this build";
    PushBlock shadow = PushBlocks().at("ShadowPush");
    auto fx = std::find_if(shadow.members.begin(), shadow.members.end(), [](auto& m) { return m.name == "fx"; });
    auto fy = std::find_if(shadow.members.begin(), shadow.members.end(), [](auto& m) { return m.name == "fy"; });
    ASSERT_NE(fx, shadow.members.end());
    ASSERT_NE(fy, shadow.members.end());
    std::swap(fx->offset, fy->offset);
    EXPECT_EQ(PushDifferences("ShadowPush", shadow, ReflectPush("shadow")).size(), 2u);
}

}  // namespace
}  // namespace cb::gpu_block_layout
