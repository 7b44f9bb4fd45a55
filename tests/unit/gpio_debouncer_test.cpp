// Debouncer: hand-made edge sequences with timestamps → the exact presses and releases expected.
#include "drivers/gpio/debouncer.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;
const SteadyTime T0 = SteadyTime{} + 1h;
using T = ButtonTransition;
using Transitions = std::vector<ButtonTransition>;

constexpr bool kHigh = true, kLow = false;

TEST(GpioDebouncer, CleanPressAndReleaseAreReportedOnTheirEdges) {
    Debouncer d({30ms, true}, kHigh, T0);
    EXPECT_FALSE(d.pressed());
    EXPECT_EQ(d.edge(kLow, T0 + 100ms), (Transitions{{true, T0 + 100ms}}));
    EXPECT_TRUE(d.pressed());
    EXPECT_EQ(d.edge(kHigh, T0 + 300ms), (Transitions{{false, T0 + 300ms}}));
    EXPECT_FALSE(d.pressed());
    EXPECT_EQ(d.advance(T0 + 10s), std::nullopt);
}

TEST(GpioDebouncer, BouncingPressAndReleaseCountOnceEach) {
    Debouncer d({30ms, true}, kHigh, T0);
    Transitions all;
    const std::pair<bool, std::chrono::microseconds> edges[] = {
        {kLow, 100000us}, {kHigh, 101000us}, {kLow, 102000us}, {kHigh, 104000us}, {kLow, 106000us},   // press
        {kHigh, 500000us}, {kLow, 501000us}, {kHigh, 503000us}, {kLow, 503500us}, {kHigh, 509000us},  // release
    };
    for (const auto& [level, t] : edges) {
        const Transitions got = d.edge(level, T0 + t);
        all.insert(all.end(), got.begin(), got.end());
        if (auto a = d.advance(T0 + t)) all.push_back(*a);
    }
    if (auto a = d.advance(T0 + 1s)) all.push_back(*a);
    EXPECT_EQ(all, (Transitions{{true, T0 + 100ms}, {false, T0 + 500ms}}));
}

TEST(GpioDebouncer, TapShorterThanThePeriodGivesPressThenReleaseAtTheWindowsEnd) {
    Debouncer d({30ms, true}, kHigh, T0);
    EXPECT_EQ(d.edge(kLow, T0 + 100ms), (Transitions{{true, T0 + 100ms}}));
    EXPECT_EQ(d.edge(kHigh, T0 + 110ms), Transitions{});
    EXPECT_EQ(d.pendingUntil(), T0 + 130ms);
    EXPECT_EQ(d.advance(T0 + 129ms), std::nullopt);
    EXPECT_EQ(d.advance(T0 + 130ms), (T{false, T0 + 130ms}));
    EXPECT_EQ(d.pendingUntil(), std::nullopt);
}

TEST(GpioDebouncer, ResultDoesNotDependOnWhenAdvanceIsCalled) {
    // Press, quick release, re-press 5 ms after the release was confirmed: the re-press waits for its window.
    Debouncer late({30ms, true}, kHigh, T0);
    Transitions lateOut;
    for (auto [level, t] : {std::pair{kLow, 100ms}, {kHigh, 110ms}, {kLow, 135ms}}) {
        const Transitions got = late.edge(level, T0 + t);
        lateOut.insert(lateOut.end(), got.begin(), got.end());
    }
    if (auto a = late.advance(T0 + 1s)) lateOut.push_back(*a);

    Debouncer eager({30ms, true}, kHigh, T0);
    Transitions eagerOut;
    for (auto [level, t] : {std::pair{kLow, 100ms}, {kHigh, 110ms}, {kLow, 135ms}}) {
        for (auto step = T0 + 90ms; step < T0 + t; step += 1ms)
            if (auto a = eager.advance(step)) eagerOut.push_back(*a);
        const Transitions got = eager.edge(level, T0 + t);
        eagerOut.insert(eagerOut.end(), got.begin(), got.end());
    }
    for (auto step = T0 + 135ms; step <= T0 + 1s; step += 1ms)
        if (auto a = eager.advance(step)) eagerOut.push_back(*a);

    const Transitions expected{{true, T0 + 100ms}, {false, T0 + 130ms}, {true, T0 + 160ms}};
    EXPECT_EQ(lateOut, expected);
    EXPECT_EQ(eagerOut, expected);
}

TEST(GpioDebouncer, ActiveHighLinePressesOnRisingEdge) {
    Debouncer d({30ms, false}, kLow, T0);
    EXPECT_FALSE(d.pressed());
    EXPECT_EQ(d.edge(kHigh, T0 + 50ms), (Transitions{{true, T0 + 50ms}}));
    EXPECT_EQ(d.edge(kLow, T0 + 90ms), (Transitions{{false, T0 + 90ms}}));
}

TEST(GpioDebouncer, ButtonHeldAtStartIsDownWithoutAPress) {
    Debouncer d({30ms, true}, kLow, T0);
    EXPECT_TRUE(d.pressed());
    EXPECT_EQ(d.advance(T0 + 1s), std::nullopt);
    // The first edge counts at once: the window before the start is treated as quiet.
    EXPECT_EQ(d.edge(kHigh, T0 + 1ms), (Transitions{{false, T0 + 1ms}}));
}

TEST(GpioDebouncer, RepeatedLevelIsNotAnEdge) {
    Debouncer d({30ms, true}, kHigh, T0);
    EXPECT_EQ(d.edge(kHigh, T0 + 100ms), Transitions{});
    EXPECT_EQ(d.edge(kLow, T0 + 200ms), (Transitions{{true, T0 + 200ms}}));
    EXPECT_EQ(d.edge(kLow, T0 + 300ms), Transitions{});
}

TEST(GpioDebouncer, ZeroPeriodReportsEveryChange) {
    Debouncer d({0ms, true}, kHigh, T0);
    EXPECT_EQ(d.edge(kLow, T0 + 1ms), (Transitions{{true, T0 + 1ms}}));
    EXPECT_EQ(d.edge(kHigh, T0 + 1ms), (Transitions{{false, T0 + 1ms}}));
    EXPECT_EQ(d.edge(kLow, T0 + 2ms), (Transitions{{true, T0 + 2ms}}));
}

TEST(GpioDebouncer, ConfigurablePeriod) {
    Debouncer d({50ms, true}, kHigh, T0);
    EXPECT_EQ(d.edge(kLow, T0), (Transitions{{true, T0}}));
    EXPECT_EQ(d.edge(kHigh, T0 + 40ms), Transitions{});  // inside 50 ms: waits
    EXPECT_EQ(d.advance(T0 + 49ms), std::nullopt);
    EXPECT_EQ(d.advance(T0 + 50ms), (T{false, T0 + 50ms}));
}

TEST(GpioDebouncer, EdgeStampedBeforeThePreviousOneIsTakenAsSimultaneous) {
    Debouncer d({30ms, true}, kHigh, T0);
    EXPECT_EQ(d.edge(kLow, T0 + 100ms), (Transitions{{true, T0 + 100ms}}));
    EXPECT_EQ(d.edge(kHigh, T0 + 90ms), Transitions{});
    EXPECT_EQ(d.pendingUntil(), T0 + 130ms);
}

}  // namespace
}  // namespace avatarbooth
