#include "src/render/stream/ray_queue.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <numeric>

namespace nave::render {
namespace {

struct Record {
    uint64_t id;
    float payload[6];
};

std::vector<uint64_t> Ids(const std::vector<Record>& v) {
    std::vector<uint64_t> ids;
    ids.reserve(v.size());
    for (const Record& r : v) ids.push_back(r.id);
    return ids;
}

std::unique_ptr<store::SpillFile> NewSpillFile() {
    auto file = store::SpillFile::Create(std::filesystem::temp_directory_path(), "the ray queues");
    EXPECT_TRUE(file.ok()) << file.status().ToString();
    return std::move(file).value();
}

TEST(BrickQueues, SpilledRecordsComeBackOnceEachInPartialTakes) {
    BrickQueues<Record> queues(3);
    auto file = NewSpillFile();
    constexpr uint64_t kCount = 20000;  // several blocks
    for (uint64_t i = 0; i < kCount; ++i) queues.Push(1, Record{i, {float(i)}});
    queues.Push(2, Record{99, {}});
    const size_t before = queues.MemoryBytes();
    auto spilled = queues.Spill(1, *file);
    ASSERT_TRUE(spilled.ok()) << spilled.status().ToString();
    EXPECT_GT(*spilled, kCount / 2);  // all full blocks but the last
    EXPECT_LT(*spilled, kCount);
    EXPECT_EQ(queues.Waiting(1), kCount);  // spilled rays still wait
    EXPECT_EQ(queues.InMemory(1), kCount - *spilled);
    EXPECT_EQ(queues.MemoryBytes(), before - *spilled * sizeof(Record));
    // Takes of odd sizes cross the boundary between memory and disk and end inside spilled blocks.
    std::vector<uint64_t> seen;
    std::vector<Record> batch;
    while (queues.Waiting(1) > 0) {
        auto n = queues.Take(1, 3001, &batch, file.get());
        ASSERT_TRUE(n.ok()) << n.status().ToString();
        ASSERT_EQ(*n, batch.size());
        for (const Record& r : batch) {
            EXPECT_EQ(r.payload[0], float(r.id));
            seen.push_back(r.id);
        }
    }
    std::sort(seen.begin(), seen.end());
    std::vector<uint64_t> want(kCount);
    std::iota(want.begin(), want.end(), 0);
    EXPECT_EQ(seen, want);
    EXPECT_EQ(queues.MemoryBytes(), sizeof(Record));  // brick 2's one record
    EXPECT_EQ(file->stats().stored_bytes, 0u);        // every spilled block was released
    auto other = queues.Take(2, 10, &batch, file.get());
    ASSERT_TRUE(other.ok());
    EXPECT_EQ(Ids(batch), std::vector<uint64_t>{99});
}

TEST(BrickQueues, ASpillThatCannotBeReadBackIsAnErrorNamingTheBrick) {
    BrickQueues<Record> queues(8);
    auto file = NewSpillFile();
    for (uint64_t i = 0; i < 10000; ++i) queues.Push(5, Record{i, {}});
    ASSERT_TRUE(queues.Spill(5, *file).ok());
    std::vector<Record> batch;
    auto n = queues.Take(5, 10000, &batch, nullptr);  // no file to read from
    ASSERT_FALSE(n.ok());
    EXPECT_NE(n.status().message().find("brick 5"), std::string::npos) << n.status().ToString();
}

}  // namespace
}  // namespace nave::render
