// src/distributed's pieces that do not need a second rank: reading another rank's messages without
// trusting them, and the thread limit a rank widens while the others of its node sleep.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

#include "distributed/message.h"
#include "util/threads.h"

namespace lat {
namespace {

std::vector<std::uint8_t> bytes_of(std::initializer_list<std::uint64_t> values) {
    std::vector<std::uint8_t> b(values.size() * 8);
    std::memcpy(b.data(), values.begin(), b.size());
    return b;
}

TEST(MessageReader, ReadsWhatIsThere) {
    const std::vector<std::uint8_t> b = bytes_of({2, 7, 9});
    dist::MessageReader in(b, "test message", 1);
    EXPECT_EQ(in.read<std::uint64_t>(), 2u);
    std::uint64_t two[2];
    in.read(two, 2);
    EXPECT_EQ(two[0], 7u);
    EXPECT_EQ(two[1], 9u);
    EXPECT_NO_THROW(in.expect_end());
}

TEST(MessageReader, ShortMessageIsAnError) {
    const std::vector<std::uint8_t> b = bytes_of({5, 1});
    dist::MessageReader in(b, "test message", 3);
    const std::uint64_t n = in.read<std::uint64_t>();
    try {
        in.take(n, 8);
        FAIL() << "read past the end";
    } catch (const dist::MessageError& e) {
        EXPECT_NE(std::string(e.what()).find("malformed test message from rank 3"), std::string::npos) << e.what();
    }
}

TEST(MessageReader, HugeCountIsAnErrorNotAnAllocation) {
    const std::vector<std::uint8_t> b = bytes_of({~std::uint64_t{0}});
    dist::MessageReader in(b, "test message", 1);
    EXPECT_THROW(in.take(in.read<std::uint64_t>(), 16), dist::MessageError);  // count * 16 overflows
}

TEST(MessageReader, LeftoverBytesAreAnError) {
    const std::vector<std::uint8_t> b = bytes_of({1, 2});
    dist::MessageReader in(b, "test message", 1);
    in.read<std::uint64_t>();
    EXPECT_THROW(in.expect_end(), dist::MessageError);
}

TEST(MarkDealt, EachItemOnce) {
    const dist::MessageReader in({}, "test message", 1);
    std::vector<bool> dealt(10);
    const std::vector<dist::Chunk> a{{0, 4}, {6, 10}};
    dist::mark_dealt(a, dealt, in);
    EXPECT_EQ(std::count(dealt.begin(), dealt.end(), true), 8);
    const std::vector<dist::Chunk> again{{3, 5}};
    EXPECT_THROW(dist::mark_dealt(again, dealt, in), dist::MessageError);
}

TEST(MarkDealt, RangesOutsideTheLoopAreErrors) {
    const dist::MessageReader in({}, "test message", 1);
    std::vector<bool> dealt(10);
    for (const dist::Chunk bad : {dist::Chunk{8, 11}, dist::Chunk{5, 4}, dist::Chunk{4294967295u, 0}}) {
        const std::vector<dist::Chunk> one{bad};
        EXPECT_THROW(dist::mark_dealt(one, dealt, in), dist::MessageError) << bad.begin << " " << bad.end;
    }
    EXPECT_EQ(std::count(dealt.begin(), dealt.end(), true), 0);
}

TEST(ThreadLimit, LimitsAndWidens) {
    if (core_count() < 2) GTEST_SKIP() << "one core";
    const ThreadLimit limit(1);
    EXPECT_EQ(thread_count(), 1);
    {
        const WiderThreads wider(2);
        EXPECT_EQ(thread_count(), 2);
    }
    EXPECT_EQ(thread_count(), 1);
}

TEST(ThreadLimit, NoLimitMeansEveryCore) {
    const ThreadLimit limit(0);
    EXPECT_EQ(thread_count(), core_count());
}

}  // namespace
}  // namespace lat
