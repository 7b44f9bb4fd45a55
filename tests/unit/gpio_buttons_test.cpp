// Buttons: debounced lines and scripted timelines on a hand-driven clock, the hold (operator lock) detector,
// keyboard keys and merged sources.
#include "drivers/gpio/button_timeline.h"
#include "drivers/gpio/buttons.h"
#include "drivers/gpio/debounced_buttons.h"
#include "drivers/gpio/keyboard_buttons.h"

#include "common/error.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;
using enum ButtonAction;
const std::vector<std::string> kButtons{"start", "retake"};

// A sim button set: the script through the same debouncing as the hardware, on a manual clock.
struct Scripted {
    ManualClock clock;
    SteadyTime t0 = clock.now();
    DebouncedButtons buttons;

    explicit Scripted(const std::string& script, std::chrono::milliseconds debounce = 30ms)
        : buttons(std::make_unique<ScriptedLines>(parseButtonTimeline(script, "test", kButtons), clock, clock.now(),
                                                  "test"),
                  {{"start", {debounce, false}}, {"retake", {debounce, false}}}) {}
};

TEST(GpioButtons, BouncingTapIsOnePressAndOneRelease) {
    Scripted s("at 1s tap start 200ms bounce 4\n");
    EXPECT_EQ(s.buttons.poll(10s), (ButtonEvent{"start", Press, s.t0 + 1s}));
    EXPECT_EQ(s.clock.now(), s.t0 + 1s);  // waited exactly until the edge
    EXPECT_TRUE(s.buttons.isDown("start"));
    EXPECT_EQ(s.buttons.poll(10s), (ButtonEvent{"start", Release, s.t0 + 1200ms}));
    EXPECT_FALSE(s.buttons.isDown("start"));
    EXPECT_FALSE(s.buttons.finished());  // the release's bounces are still to come
    EXPECT_EQ(s.buttons.poll(1s), std::nullopt);
    EXPECT_EQ(s.clock.now(), s.t0 + 2200ms);
    EXPECT_TRUE(s.buttons.finished());
}

TEST(GpioButtons, PollTimesOutWithoutAnEventAndLeavesItForLater) {
    Scripted s("at 5s press retake\n");
    EXPECT_EQ(s.buttons.poll(2s), std::nullopt);
    EXPECT_EQ(s.clock.now(), s.t0 + 2s);
    EXPECT_EQ(s.buttons.poll(0ms), std::nullopt);
    EXPECT_EQ(s.clock.now(), s.t0 + 2s);
    EXPECT_FALSE(s.buttons.finished());
    EXPECT_EQ(s.buttons.poll(3s), (ButtonEvent{"retake", Press, s.t0 + 5s}));
    EXPECT_TRUE(s.buttons.isDown("retake"));
    EXPECT_FALSE(s.buttons.isDown("start"));
    EXPECT_FALSE(s.buttons.isDown("nonexistent"));
}

TEST(GpioButtons, TapShorterThanDebounceIsReleasedAtTheEndOfTheWindow) {
    Scripted s("at 1s tap start 10ms\n");
    EXPECT_EQ(s.buttons.poll(10s), (ButtonEvent{"start", Press, s.t0 + 1s}));
    EXPECT_EQ(s.buttons.poll(10s), (ButtonEvent{"start", Release, s.t0 + 1030ms}));
    EXPECT_EQ(s.clock.now(), s.t0 + 1030ms);  // woke for the window's end, not later
}

TEST(GpioButtons, TwoButtonsComeOutInTimeOrder) {
    Scripted s("at 1s hold start 1s\nat 1.5s tap retake\n");
    std::vector<ButtonEvent> got;
    while (auto e = s.buttons.poll(5s)) got.push_back(*e);
    EXPECT_EQ(got, (std::vector<ButtonEvent>{{"start", Press, s.t0 + 1s},
                                             {"retake", Press, s.t0 + 1500ms},
                                             {"retake", Release, s.t0 + 1600ms},
                                             {"start", Release, s.t0 + 2s}}));
    EXPECT_EQ(s.buttons.names(), kButtons);
}

// Input lines whose edges are handed over in one batch, lines mixed, as the kernel's per-line queues deliver them.
class BatchLines final : public RawInputLines {
public:
    BatchLines(ManualClock& clock, std::vector<RawEdge> batch) : clock_(clock), batch_(std::move(batch)) {}
    std::vector<bool> levels() override { return {true, true}; }  // both released (active-low)
    std::vector<RawEdge> waitEdges(SteadyTime deadline) override {
        clock_.sleepUntil(deadline);
        return std::exchange(batch_, {});
    }
    SteadyTime now() const override { return clock_.now(); }
    std::string describe() const override { return "batch"; }

private:
    ManualClock& clock_;
    std::vector<RawEdge> batch_;
};

TEST(GpioButtons, EdgesOfSeveralLinesInOneBatchAreOrderedByTime) {
    ManualClock clock;
    const SteadyTime t0 = clock.now();
    // Line 1's edges come first in the batch although line 0's happened earlier.
    DebouncedButtons b(std::make_unique<BatchLines>(clock, std::vector<RawEdge>{{1, false, t0 + 5ms},
                                                                                {1, true, t0 + 6ms},
                                                                                {0, false, t0 + 1ms},
                                                                                {0, true, t0 + 2ms},
                                                                                {0, false, t0 + 3ms}}),
                       {{"start", {30ms, true}}, {"retake", {30ms, true}}});
    std::vector<ButtonEvent> got;
    while (auto e = b.poll(100ms)) got.push_back(*e);
    EXPECT_EQ(got, (std::vector<ButtonEvent>{{"start", Press, t0 + 1ms}, {"retake", Press, t0 + 5ms},
                                             {"retake", Release, t0 + 35ms}}));
    EXPECT_TRUE(b.isDown("start"));
    EXPECT_EQ(b.describe(), "batch, debounce 30 ms");
}

TEST(GpioButtons, HoldDetectorFiresOnceAfterTheCombinationIsHeldLongEnough) {
    const SteadyTime t0 = SteadyTime{} + 1h;
    HoldDetector lock({"start", "retake"}, 5s);
    lock.observe({"start", Press, t0});
    EXPECT_EQ(lock.due(), std::nullopt);
    lock.observe({"retake", Press, t0 + 1s});
    EXPECT_EQ(lock.due(), t0 + 6s);
    EXPECT_FALSE(lock.fired(t0 + 5900ms));
    EXPECT_TRUE(lock.fired(t0 + 6s));
    EXPECT_FALSE(lock.fired(t0 + 7s));  // once per hold
    lock.observe({"retake", Release, t0 + 8s});
    lock.observe({"other", Press, t0 + 8500ms});  // not part of the combination
    lock.observe({"retake", Press, t0 + 9s});
    EXPECT_FALSE(lock.fired(t0 + 13s));
    EXPECT_TRUE(lock.fired(t0 + 14s));
}

TEST(GpioButtons, HoldDetectorIsResetByAnyRelease) {
    const SteadyTime t0 = SteadyTime{} + 1h;
    HoldDetector lock({"start", "retake"}, 3s);
    lock.observe({"start", Press, t0});
    lock.observe({"retake", Press, t0});
    lock.observe({"start", Release, t0 + 2s});
    EXPECT_FALSE(lock.fired(t0 + 10s));
    lock.observe({"start", Press, t0 + 11s});
    EXPECT_FALSE(lock.fired(t0 + 13900ms));
    EXPECT_TRUE(lock.fired(t0 + 14s));
}

TEST(GpioButtons, HoldDetectorOnScriptedOperatorLock) {
    Scripted s("at 1s tap start\nat 3s hold start+retake 5s\n");
    HoldDetector lock({"start", "retake"}, 5s);
    std::optional<SteadyTime> firedAt;
    while (auto e = s.buttons.poll(10s)) {
        if (lock.fired(e->time)) firedAt = e->time;
        lock.observe(*e);
    }
    // The lock fires at the first check at or after 8 s: here, the release event stamped 8 s.
    EXPECT_EQ(firedAt, s.t0 + 8s);
}

TEST(GpioButtons, KeyboardKeysPressButtonsAndFoldAutoRepeat) {
    const SteadyTime t0 = SteadyTime{} + 1h;
    KeyboardButtons k({{"space", "start"}, {"Return", "start"}, {"r", "retake"}}, kButtons);
    EXPECT_FALSE(k.feed("x", true, t0));
    EXPECT_TRUE(k.feed("space", true, t0 + 1ms));
    EXPECT_TRUE(k.feed("space", true, t0 + 2ms));   // auto-repeat
    EXPECT_TRUE(k.feed("Return", true, t0 + 3ms));  // a second key for the same button
    EXPECT_TRUE(k.feed("space", false, t0 + 4ms));  // Return still holds it
    EXPECT_TRUE(k.feed("Return", false, t0 + 5ms));
    EXPECT_TRUE(k.feed("r", true, t0 + 6ms));
    std::vector<ButtonEvent> got;
    while (auto e = k.poll(0ms)) got.push_back(*e);
    EXPECT_EQ(got, (std::vector<ButtonEvent>{{"start", Press, t0 + 1ms}, {"start", Release, t0 + 5ms},
                                             {"retake", Press, t0 + 6ms}}));
    EXPECT_TRUE(k.isDown("retake"));
    EXPECT_FALSE(k.isDown("start"));
}

TEST(GpioButtons, KeyMappedToAnUnknownButtonIsAConfigError) {
    try {
        KeyboardButtons k({{"q", "quit"}}, kButtons);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_STREQ(e.what(), "key \"q\": is mapped to the unknown button \"quit\"");
    }
}

TEST(GpioButtons, MergedSourcesDeliverKeysBetweenScriptedEvents) {
    ManualClock clock;
    const SteadyTime t0 = clock.now();
    std::vector<std::unique_ptr<Buttons>> sources;
    sources.push_back(std::make_unique<DebouncedButtons>(
        std::make_unique<ScriptedLines>(parseButtonTimeline("at 1s press start\nat 2s release start", "t", kButtons),
                                        clock, t0, "t"),
        std::vector<DebouncedLine>{{"start", {30ms, false}}, {"retake", {30ms, false}}}));
    auto keys = std::make_unique<KeyboardButtons>(std::map<std::string, std::string>{{"r", "retake"}}, kButtons);
    KeyboardButtons* keyboard = keys.get();
    sources.push_back(std::move(keys));
    MergedButtons merged(std::move(sources));

    EXPECT_EQ(merged.poll(5s), (ButtonEvent{"start", Press, t0 + 1s}));
    keyboard->feed("r", true, t0 + 1100ms);
    EXPECT_EQ(merged.poll(5s), (ButtonEvent{"retake", Press, t0 + 1100ms}));
    EXPECT_TRUE(merged.isDown("start"));
    EXPECT_TRUE(merged.isDown("retake"));
    EXPECT_EQ(merged.poll(5s), (ButtonEvent{"start", Release, t0 + 2s}));
    EXPECT_TRUE(merged.finished());
    EXPECT_EQ(merged.poll(0ms), std::nullopt);
    EXPECT_EQ(merged.names(), kButtons);
    EXPECT_EQ(merged.describe(), "sim timeline t (2 edges), debounce 30 ms + keyboard: r=retake");
}

}  // namespace
}  // namespace avatarbooth
