// RecentTimings: the kiosk's frame-time figures in memory that does not grow with the run.
#include "common/recent_timings.h"

#include <gtest/gtest.h>

using avatarbooth::RecentTimings;

TEST(RecentTimings, EmptyGivesZeros) {
    const RecentTimings t;
    EXPECT_TRUE(t.empty());
    EXPECT_EQ(t.count(), 0u);
    EXPECT_EQ(t.median(), 0.0);
    EXPECT_EQ(t.slowest(), 0.0);
}

TEST(RecentTimings, MedianOfFewerThanKept) {
    RecentTimings t(10);
    for (const double d : {5.0, 1.0, 4.0, 2.0, 3.0}) t.add(d);
    EXPECT_EQ(t.median(), 3.0);
    t.add(6.0);  // even count: the upper of the two middle ones
    EXPECT_EQ(t.median(), 4.0);
    EXPECT_EQ(t.count(), 6u);
    EXPECT_EQ(t.slowest(), 6.0);
}

TEST(RecentTimings, KeepsOnlyTheMostRecentForTheMedianButCountsAndMaxesTheWholeRun) {
    RecentTimings t(3);
    t.add(100.0);  // the slowest, soon pushed out of the recent three
    for (const double d : {1.0, 2.0, 3.0}) t.add(d);
    EXPECT_EQ(t.median(), 2.0);
    t.add(10.0);  // recent: 2, 3, 10
    EXPECT_EQ(t.median(), 3.0);
    t.add(20.0);
    t.add(30.0);  // recent: 10, 20, 30
    EXPECT_EQ(t.median(), 20.0);
    EXPECT_EQ(t.count(), 7u);
    EXPECT_EQ(t.slowest(), 100.0);
}

TEST(RecentTimings, ALongRunHoldsNoMoreThanItKeeps) {
    RecentTimings t(2000);
    // A million frames, the last 2000 of them at 0.5 and everything before at 1.0: the median is the recent one.
    for (int i = 0; i < 1'000'000; ++i) t.add(i < 998'000 ? 1.0 : 0.5);
    EXPECT_EQ(t.median(), 0.5);
    EXPECT_EQ(t.count(), 1'000'000u);
    EXPECT_EQ(t.slowest(), 1.0);
}

TEST(RecentTimings, NegativeAndZeroDurationsAreKeptAsGiven) {
    RecentTimings t(4);
    t.add(-1.0);
    EXPECT_EQ(t.slowest(), -1.0);  // the first one is the slowest so far, whatever its sign
    t.add(0.0);
    EXPECT_EQ(t.slowest(), 0.0);
    EXPECT_EQ(t.median(), 0.0);
}
