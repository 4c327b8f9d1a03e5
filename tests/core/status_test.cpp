#include "src/core/status.h"

#include <gtest/gtest.h>

namespace nave {
namespace {

StatusOr<int> Half(int x) {
    if (x % 2 != 0) return InvalidArgumentError("{} is odd", x);
    return x / 2;
}

Status Quarter(int x, int* out) {
    NAVE_ASSIGN_OR_RETURN(int h, Half(x));
    NAVE_ASSIGN_OR_RETURN(*out, Half(h));
    return Status::Ok();
}

TEST(StatusTest, OkAndErrorsCarryCodeAndMessage) {
    EXPECT_TRUE(Status::Ok().ok());
    Status s = DataLossError("brick {} @0x{:x}", 12, 255);
    EXPECT_FALSE(s.ok());
    EXPECT_EQ(s.code(), StatusCode::kDataLoss);
    EXPECT_EQ(s.ToString(), "data loss: brick 12 @0xff");
    EXPECT_EQ(s.WithContext("abbey.nave").message(), "abbey.nave: brick 12 @0xff");
}

TEST(StatusTest, AssignOrReturnPropagatesTheFirstError) {
    int out = -1;
    EXPECT_TRUE(Quarter(8, &out).ok());
    EXPECT_EQ(out, 2);
    Status s = Quarter(6, &out);  // 6 / 2 = 3 is odd
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(s.message(), "3 is odd");
}

TEST(CheckDeathTest, CheckEqPrintsBothOperands) {
    int a = 3, b = 4;
    EXPECT_DEATH(NAVE_CHECK_EQ(a, b) << "context", "a == b.*3 vs 4.*context");
}

}  // namespace
}  // namespace nave
