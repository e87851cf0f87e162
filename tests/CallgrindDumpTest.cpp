// The callgrind dump reader of exact mode (harness/perf/CallgrindDump.h), on
// dumps written by hand in the format of valgrind's manual ("Callgrind Format
// Specification"), and the stage brackets' names read back.
#include <gtest/gtest.h>

#include "core/base/CallgrindRequests.h"
#include "harness/perf/CallgrindDump.h"

namespace cb {
namespace {

// Three dumps in one file (--combine-dumps=yes), as callgrind 3.19 writes
// them: two stage calls and the dump at program termination. The function
// cost lines below each part are noise to the reader: only the totals count.
constexpr const char* kCombined = R"(# callgrind format
version: 1
creator: callgrind-3.19.0
pid: 4242
cmd:  ./cloudbench count ci-small
part: 1


desc: I1 cache: 
desc: D1 cache: 
desc: LL cache: 

desc: Timerange: Basic block 0 - 30475
desc: Trigger: Client Request: stage=ca backend=cpu step=10

positions: line
events: Ir
summary: 6021


ob=/tmp/t
fl=???
fn=work
0 6005
totals: 6021

part: 2

desc: Timerange: Basic block 30475 - 32482
desc: Trigger: Client Request: stage=render_splat backend=cpu step=10 camera=from the ground

positions: line
events: Ir
summary: 12019

fn=main
0 14
totals: 12019

part: 3

desc: Timerange: Basic block 32482 - 35489
desc: Trigger: Client Request: stage=render_splat backend=cpu step=10 camera=above

positions: line
events: Ir
summary: 100
totals: 100

part: 4

desc: Trigger: Program termination

positions: line
events: Ir
summary: 31548
totals: 31548
)";

// Test that each part's trigger and Ir total are read, in file order.
TEST(CallgrindDump, ReadsEachPartOfACombinedFile) {
    auto parts = ParseCallgrindDump(kCombined);
    ASSERT_TRUE(parts) << parts.error().message;
    ASSERT_EQ(parts->size(), 4u);
    EXPECT_EQ((*parts)[0].trigger, "Client Request: stage=ca backend=cpu step=10");
    EXPECT_EQ((*parts)[0].instructions, 6021u);
    EXPECT_EQ((*parts)[1].trigger, "Client Request: stage=render_splat backend=cpu step=10 camera=from the ground");
    EXPECT_EQ((*parts)[1].instructions, 12019u);
    EXPECT_EQ((*parts)[2].instructions, 100u);
    EXPECT_EQ((*parts)[3].trigger, "Program termination");
    EXPECT_EQ((*parts)[3].instructions, 31548u);
}

// Test that stage calls are summed per stage and step over cameras, and the
// program-termination part is left out.
TEST(CallgrindDump, CountsStageCallsAndSumsCameras) {
    auto parts = ParseCallgrindDump(kCombined);
    ASSERT_TRUE(parts);
    auto counts = CountStageCalls(*parts);
    ASSERT_TRUE(counts) << counts.error().message;
    ASSERT_EQ(counts->size(), 1u);
    const auto& cpu = counts->at("cpu");
    ASSERT_EQ(cpu.size(), 2u);
    EXPECT_EQ(cpu.at("ca").at(10), 6021u);
    EXPECT_EQ(cpu.at("render_splat").at(10), 12019u + 100u);
}

// Test that Ir is found by its position among several events, that a file of
// one dump with no "part:" line is one part, and that "summary:" stands in
// for a missing "totals:".
TEST(CallgrindDump, FindsIrAmongSeveralEventsInASingleDump) {
    constexpr const char* kSingle = R"(version: 1
creator: callgrind-3.19.0
desc: Trigger: Client Request: stage=smooth backend=cpu step=3
events: Dr Ir Dw
summary: 7 123456789012 9
fn=x
0 7 123456789012 9
)";
    auto parts = ParseCallgrindDump(kSingle);
    ASSERT_TRUE(parts) << parts.error().message;
    ASSERT_EQ(parts->size(), 1u);
    EXPECT_EQ((*parts)[0].instructions, 123456789012u);
}

// Test that broken dumps are refused with the line that is wrong.
TEST(CallgrindDump, RefusesDumpsWithoutIrOrTotal) {
    auto noIr = ParseCallgrindDump("part: 1\nevents: Dr Dw\ntotals: 1 2\n");
    ASSERT_FALSE(noIr);
    EXPECT_EQ(noIr.error().message, "line 2: the events do not include Ir");
    auto noTotal = ParseCallgrindDump("part: 1\nevents: Ir\nfn=x\n0 5\n");
    ASSERT_FALSE(noTotal);
    EXPECT_EQ(noTotal.error().message, "line 1: part has no \"totals:\" or \"summary:\" line");
    auto badCount = ParseCallgrindDump("part: 1\nevents: Ir\ntotals: 12x\n");
    ASSERT_FALSE(badCount);
    EXPECT_EQ(badCount.error().message, "line 3: not a count: '12x'");
    EXPECT_FALSE(ParseCallgrindDump("# callgrind format\nversion: 1\n"));
}

// Test that a stage call counted twice, or a client request that names no
// stage call, is an error rather than a silent sum.
TEST(CallgrindDump, RefusesDuplicateAndForeignClientRequests) {
    const std::vector<CallgrindPart> twice = {{"Client Request: stage=ca backend=cpu step=1", 5},
                                              {"Client Request: stage=ca backend=cpu step=1", 5}};
    EXPECT_FALSE(CountStageCalls(twice));
    const std::vector<CallgrindPart> foreign = {{"Client Request: my own dump", 5}};
    EXPECT_FALSE(CountStageCalls(foreign));
}

// Test that the names the stage brackets write read back field for field.
TEST(CallgrindDump, StageCountNamesRoundTrip) {
    const std::string plain = FormatStageCountLabel({"density", "cpu", 17, ""});
    EXPECT_EQ(plain, "stage=density backend=cpu step=17");
    auto read = ParseStageCountName(plain);
    ASSERT_TRUE(read);
    EXPECT_EQ(read->stage, "density");
    EXPECT_EQ(read->backend, "cpu");
    EXPECT_EQ(read->step, 17u);
    EXPECT_EQ(read->camera, "");
    auto camera = ParseStageCountName(FormatStageCountLabel({"render_splat", "vk", 4294967295u, "a b"}));
    ASSERT_TRUE(camera);
    EXPECT_EQ(camera->step, 4294967295u);
    EXPECT_EQ(camera->camera, "a b");
    EXPECT_FALSE(ParseStageCountName("stage=ca backend=cpu"));
    EXPECT_FALSE(ParseStageCountName("stage=ca backend=cpu step=-1"));
    EXPECT_FALSE(ParseStageCountName("stage=ca backend=cpu step=4294967296"));
    EXPECT_FALSE(ParseStageCountName("stage= backend=cpu step=1"));
}

}  // namespace
}  // namespace cb
