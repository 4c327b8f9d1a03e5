// The progress bar's arithmetic: how far work is and how long it has left, with a total, a
// deadline (a render's time limit) or both; rates that show their motion however slow.

#include "src/core/progress.h"

#include <gtest/gtest.h>

#include <chrono>
#include <thread>

namespace nave {
namespace {

class ProgressTest : public ::testing::Test {
  protected:
    void SetUp() override { ProgressBar::SetEnabled(false); }
    void TearDown() override { ProgressBar::SetEnabled(true); }
};

TEST_F(ProgressTest, RatesShowTheirMotionHoweverSlow) {
    EXPECT_EQ(FormatRate(2.4e6), "2.40 M/s");
    EXPECT_EQ(FormatRate(31.04), "31.0/s");
    EXPECT_EQ(FormatRate(2.5), "2.50/s");
    EXPECT_EQ(FormatRate(0.0833), "0.083/s");  // an SPPM iteration every 12 s
    EXPECT_EQ(FormatRate(0), "0.000/s");
}

TEST_F(ProgressTest, WithATotalTheUnitsMeasureTheWork) {
    ProgressBar bar("work", 200, "units");
    EXPECT_EQ(bar.Fraction(), 0.0);
    EXPECT_LT(bar.SecondsLeft(), 0.0);  // nothing done: no rate to tell
    bar.Add(50);
    EXPECT_DOUBLE_EQ(bar.Fraction(), 0.25);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    // Three times as much to do as done so far, at the same rate.
    const double elapsed = bar.ElapsedSeconds();
    EXPECT_NEAR(bar.SecondsLeft(), 3 * elapsed, 0.5 * elapsed);
    bar.Add(1000);  // more than the total
    EXPECT_EQ(bar.Fraction(), 1.0);
    EXPECT_EQ(bar.SecondsLeft(), 0.0);
}

TEST_F(ProgressTest, ADeadlineFillsTheBarAndBoundsTheTimeLeft) {
    // A render of 64 iterations under a time limit that ends it after the first few.
    ProgressBar bar("photon mapping", 64, "iterations");
    bar.SetDeadline(0.05);
    bar.Add(1);
    const double left = bar.SecondsLeft();
    EXPECT_GE(left, 0.0);
    EXPECT_LE(left, 0.05);  // not the 63 iterations' ETA: the limit comes first
    std::this_thread::sleep_for(std::chrono::milliseconds(60));
    EXPECT_EQ(bar.Fraction(), 1.0);  // the time is up, whatever the count says
    EXPECT_EQ(bar.SecondsLeft(), 0.0);
}

TEST_F(ProgressTest, ADeadlineFarAwayLeavesTheUnitsInCharge) {
    ProgressBar bar("render", 4, "passes");
    bar.SetDeadline(3600);
    bar.Add(2);
    EXPECT_DOUBLE_EQ(bar.Fraction(), 0.5);  // two of four passes, a second of an hour
    EXPECT_LT(bar.SecondsLeft(), 60.0);     // the passes' ETA, not the hour
    ProgressBar unknown("render", 0, "passes");
    unknown.SetDeadline(10);
    EXPECT_GT(unknown.SecondsLeft(), 9.0);  // no total: the deadline alone
}

}  // namespace
}  // namespace nave
