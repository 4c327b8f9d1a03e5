// Inputs on which fuzz_store (tests/fuzz, docs/fuzzing.md) found the store reader crashing or
// reporting undefined behaviour, each kept as found in tests/fixtures/stores/fuzz/ (the target's
// input: a mode byte, then the file, resealed when the mode is odd). They are read exactly as the
// target reads them and must now give an error naming the file, the brick and the problem.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>

#include "fuzz/store_reseal.h"
#include "src/core/file.h"
#include "store/store_reader.h"
#include "test_util.h"

namespace nave::store {
namespace {

using ::testing::HasSubstr;

// Opens a fuzz_store input as the target does and returns the first brick error.
Status ReadFuzzInput(const std::string& name, const std::filesystem::path& as) {
    const auto input =
        ReadFileToString(std::filesystem::path(NAVE_TEST_FIXTURES) / "stores/fuzz" / name);
    NAVE_CHECK(input.ok()) << input.status().ToString();
    std::string bytes = input->substr(1);
    if ((*input)[0] & 1) fuzz::ResealStore(bytes);
    std::ofstream(as, std::ios::binary | std::ios::trunc) << bytes;
    NAVE_ASSIGN_OR_RETURN(auto store, Store::Open(as));
    for (uint32_t b = 0; b < store->bricks().size(); ++b)
        NAVE_RETURN_IF_ERROR(store->VerifyBrick(b));
    return Status::Ok();
}

// A damaged Draco position plus the brick's base overflowed int32 (UBSan: signed integer overflow
// in DecodeMeshSection); the sum is now taken in 64 bits and refused outside the grid.
TEST(StoreFuzzRegression, PositionBeyondTheInt32GridIsDataLoss) {
    test::ScratchDir dir;
    const Status s = ReadFuzzInput("position_sum_overflow.fuzz", dir / "overflow.nave");
    EXPECT_EQ(s.code(), StatusCode::kDataLoss) << s.ToString();
    EXPECT_THAT(s.message(), HasSubstr((dir / "overflow.nave").string() + " brick "));
    EXPECT_THAT(s.message(), HasSubstr("outside the int32 grid"));
}

}  // namespace
}  // namespace nave::store
