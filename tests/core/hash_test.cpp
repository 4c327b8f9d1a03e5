#include "src/core/hash.h"

#include <gtest/gtest.h>

#include <string>

namespace nave {
namespace {

TEST(HashTest, StreamingEqualsOneShotWhateverThePieces) {
    std::string bytes;
    for (int i = 0; i < 10000; ++i) bytes.push_back(char(i * 7 + i / 13));
    const uint64_t whole = Checksum64(bytes.data(), bytes.size());
    for (size_t piece : {size_t(1), size_t(7), size_t(32), size_t(1000), bytes.size()}) {
        StreamingChecksum64 sum;
        for (size_t at = 0; at < bytes.size(); at += piece)
            sum.Update(bytes.data() + at, std::min(piece, bytes.size() - at));
        EXPECT_EQ(sum.Digest(), whole) << piece;
    }
    StreamingChecksum64 empty;
    EXPECT_EQ(empty.Digest(), Checksum64("", 0));
    EXPECT_NE(Checksum64(bytes.data(), bytes.size() - 1), whole);
}

}  // namespace
}  // namespace nave
