#include "src/core/duration.h"

#include <gtest/gtest.h>

namespace nave {
namespace {

TEST(DurationTest, UnitsAndPlainSeconds) {
    const std::pair<const char*, double> cases[] = {{"0", 0},     {"45", 45},     {"90s", 90},
                                                    {"10m", 600}, {"1.5h", 5400}, {"2d", 172800},
                                                    {"0.5s", 0.5}};
    for (const auto& [text, seconds] : cases) {
        auto d = ParseDuration(text, "--every");
        ASSERT_TRUE(d.ok()) << text << ": " << d.status().ToString();
        EXPECT_DOUBLE_EQ(*d, seconds) << text;
    }
}

TEST(DurationTest, MalformedIsRefusedNamingTheOptionAndTheForm) {
    for (const char* bad : {"", "m", "10x", "10 m", "-5m", "ten", "1e999", "5mm", "nan", "inf"}) {
        auto d = ParseDuration(bad, "--every");
        ASSERT_FALSE(d.ok()) << bad;
        EXPECT_EQ(d.status().code(), StatusCode::kInvalidArgument);
        EXPECT_NE(d.status().message().find(std::string("--every ") + bad), std::string::npos)
            << d.status().message();
        EXPECT_NE(d.status().message().find("90s, 10m, 1.5h or 2d"), std::string::npos);
    }
}

}  // namespace
}  // namespace nave
