// ReopeningDisplay with a scripted screen and a manual clock: losing the screen, the fixed retry interval (never a
// retry per frame), frames dropped meanwhile, the status and recovery count, a new size after the screen comes
// back, and which errors are not a lost screen.
#include "drivers/display/reopening_display.h"

#include "common/error.h"

#include <gtest/gtest.h>

#include <vector>

using namespace avatarbooth;
using namespace std::chrono_literals;

namespace {

// The "hardware": whether a screen is connected, its mode, and what reached it.
struct FakeScreen {
    bool connected = true;
    bool brokenGpu = false;  // present() fails with a non-device error (a bug, not a screen)
    cv::Size mode{640, 360};
    std::vector<std::chrono::nanoseconds> openTimes;  // when each open was attempted
    int framesShown = 0;
    int closed = 0;
    std::shared_ptr<ManualClock> clock = std::make_shared<ManualClock>(SteadyTime{});
};

class FakeDisplay : public Display {
public:
    explicit FakeDisplay(FakeScreen& screen) : screen_(screen), size_(screen.mode) {}
    ~FakeDisplay() override { ++screen_.closed; }
    void present(const cv::Mat&) override {
        if (screen_.brokenGpu) throw BoothError(ErrorKind::Internal, "fake", "shader did not compile");
        if (!screen_.connected)
            throw BoothError(ErrorKind::Device, "kms display /dev/dri/card0 HDMI-A-1",
                             "the screen was disconnected (connector HDMI-A-1 reports no screen)");
        ++screen_.framesShown;
    }
    cv::Size size() const override { return size_; }
    Rotation rotation() const override { return Rotation::R0; }
    std::vector<KeyEvent> pollKeys() override { return {KeyEvent{"space", true, {}}}; }
    std::string describe() const override {
        return "kms /dev/dri/card0 HDMI-A-1 " + std::to_string(size_.width) + "x" + std::to_string(size_.height) + "@60";
    }

private:
    FakeScreen& screen_;
    cv::Size size_;
};

ReopeningDisplay::Opener opener(FakeScreen& screen, bool badConfig = false) {
    return [&screen, badConfig]() -> std::unique_ptr<Display> {
        screen.openTimes.push_back(screen.clock->now().time_since_epoch());
        if (badConfig) throw BoothError(ErrorKind::BadConfig, "display.rotation", "45 is not a rotation");
        if (!screen.connected)
            throw BoothError(ErrorKind::Device, "/dev/dri/card0", "no screen connected (HDMI-A-1 not connected)");
        return std::make_unique<FakeDisplay>(screen);
    };
}

std::unique_ptr<ReopeningDisplay> makeDisplay(FakeScreen& screen,
                                              ReopeningDisplay::FirstOpen first = ReopeningDisplay::FirstOpen::MayWait) {
    return std::make_unique<ReopeningDisplay>(opener(screen), "kms /dev/dri", first, cv::Size(1280, 720), Rotation::R0,
                                              2s, screen.clock);
}

const cv::Mat kFrame(360, 640, CV_8UC3, cv::Scalar(1, 2, 3));

// The kiosk's loop: a frame every 33 ms for `d`.
void runFrames(ReopeningDisplay& display, FakeScreen& screen, std::chrono::milliseconds d) {
    for (auto end = screen.clock->now() + d; screen.clock->now() < end; screen.clock->advance(33ms)) display.present(kFrame);
}

TEST(DisplayReopening, ALostScreenDropsFramesAndIsReopenedEveryIntervalUntilItIsBack) {
    FakeScreen screen;
    auto display = makeDisplay(screen);
    ASSERT_EQ(screen.openTimes.size(), 1u);
    EXPECT_TRUE(display->status().ok);
    EXPECT_EQ(display->size(), cv::Size(640, 360));
    display->present(kFrame);
    EXPECT_EQ(screen.framesShown, 1);

    screen.connected = false;
    const auto lostAt = screen.clock->now().time_since_epoch();
    display->present(kFrame);  // the error: the display is closed, the booth goes on
    EXPECT_EQ(screen.closed, 1);
    EXPECT_EQ(display->current(), nullptr);
    DisplayStatus s = display->status();
    EXPECT_FALSE(s.ok);
    EXPECT_EQ(s.message, "screen kms /dev/dri/card0 HDMI-A-1 640x360@60 lost, retrying every 2 s");
    EXPECT_NE(s.lastError.find("disconnected"), std::string::npos) << s.lastError;
    EXPECT_EQ(s.framesDropped, 1u);
    EXPECT_EQ(display->size(), cv::Size(640, 360)) << "the kiosk keeps composing at the last size";
    EXPECT_NE(display->describe().find("(no screen: "), std::string::npos) << display->describe();
    EXPECT_TRUE(display->pollKeys().empty());

    // 7 s at 30 frames/s: one reopen every 2 s (at 2, 4, 6 s), not one per frame.
    runFrames(*display, screen, 7000ms);
    ASSERT_EQ(screen.openTimes.size(), 4u);
    // Each attempt on the first frame 2 s after the one before (after the loss for the first).
    for (std::size_t i = 1; i < screen.openTimes.size(); ++i) {
        const auto after = screen.openTimes[i] - (i == 1 ? lostAt : screen.openTimes[i - 1]);
        EXPECT_GE(after, std::chrono::nanoseconds(2s)) << "attempt " << i;
        EXPECT_LT(after, std::chrono::nanoseconds(2s + 34ms)) << "attempt " << i;
    }
    s = display->status();
    EXPECT_EQ(s.failedReopens, 3);
    EXPECT_EQ(s.recoveries, 0);
    EXPECT_EQ(screen.framesShown, 1);
    EXPECT_GT(s.framesDropped, 200u);
    EXPECT_NE(s.lastError.find("no screen connected"), std::string::npos) << "the last reopen's reason";

    // Switched back on: the next try (within 2 s) opens it, and frames reach it again.
    screen.connected = true;
    runFrames(*display, screen, 2100ms);
    s = display->status();
    EXPECT_TRUE(s.ok);
    EXPECT_TRUE(s.message.empty());
    EXPECT_EQ(s.recoveries, 1);
    EXPECT_EQ(s.failedReopens, 3);
    EXPECT_GT(screen.framesShown, 1);
    EXPECT_NE(display->current(), nullptr);
    EXPECT_EQ(display->pollKeys().size(), 1u);
    EXPECT_EQ(display->describe(), "kms /dev/dri/card0 HDMI-A-1 640x360@60");

    // Lost and back again: counted again, the attempt count starts afresh.
    screen.connected = false;
    runFrames(*display, screen, 3000ms);
    EXPECT_EQ(display->status().failedReopens, 1);
    screen.connected = true;
    runFrames(*display, screen, 2000ms);
    EXPECT_EQ(display->status().recoveries, 2);
}

TEST(DisplayReopening, PresentWhileLostNeverWaitsAndTriesAtMostOncePerInterval) {
    FakeScreen screen;
    auto display = makeDisplay(screen);
    screen.connected = false;
    display->present(kFrame);
    const auto before = screen.clock->now();
    for (int i = 0; i < 10000; ++i) display->present(kFrame);  // a loop that does not pace itself
    EXPECT_EQ(screen.clock->now(), before) << "present() slept";
    EXPECT_EQ(screen.openTimes.size(), 1u) << "a reopen before the interval passed";
    screen.clock->advance(1999ms);
    display->present(kFrame);
    EXPECT_EQ(screen.openTimes.size(), 1u);
    screen.clock->advance(1ms);
    display->present(kFrame);
    EXPECT_EQ(screen.openTimes.size(), 2u);
    EXPECT_EQ(display->status().framesDropped, 10003u);
}

TEST(DisplayReopening, AScreenOffAtStartIsWaitedForAndItsOwnSizeTakenWhenItComes) {
    FakeScreen screen;
    screen.connected = false;
    screen.mode = {1920, 1080};
    auto display = makeDisplay(screen);
    DisplayStatus s = display->status();
    EXPECT_FALSE(s.ok);
    EXPECT_EQ(s.message, "screen kms /dev/dri not connected yet, waiting for it every 2 s");
    EXPECT_EQ(display->size(), cv::Size(1280, 720)) << "the configured size until a screen says its own";
    EXPECT_EQ(display->describe().rfind("kms /dev/dri waiting for a screen (/dev/dri/card0: no screen connected", 0), 0u)
        << display->describe();
    runFrames(*display, screen, 1000ms);
    screen.connected = true;
    runFrames(*display, screen, 1500ms);
    s = display->status();
    EXPECT_TRUE(s.ok);
    EXPECT_EQ(s.recoveries, 0) << "a first connection is not a recovery";
    EXPECT_EQ(display->size(), cv::Size(1920, 1080));
}

TEST(DisplayReopening, AScreenBackWithAnotherModeChangesTheSize) {
    FakeScreen screen;
    auto display = makeDisplay(screen);
    screen.connected = false;
    display->present(kFrame);
    screen.mode = {1024, 768};  // another monitor plugged in
    screen.connected = true;
    runFrames(*display, screen, 2100ms);
    EXPECT_EQ(display->status().recoveries, 1);
    EXPECT_EQ(display->size(), cv::Size(1024, 768));
}

TEST(DisplayReopening, WhatIsNotALostScreenIsThrown) {
    FakeScreen screen;
    // A first open that must succeed (auto passes over it), and a configuration error, throw.
    screen.connected = false;
    EXPECT_THROW(makeDisplay(screen, ReopeningDisplay::FirstOpen::MustSucceed), BoothError);
    try {
        ReopeningDisplay d(opener(screen, true), "kms /dev/dri", ReopeningDisplay::FirstOpen::MayWait, {1280, 720},
                           Rotation::R0, 2s, screen.clock);
        ADD_FAILURE() << "a configuration error was waited on";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
    }
    // A failure of another kind while presenting (a bug) is not swallowed.
    screen.connected = true;
    auto display = makeDisplay(screen);
    screen.brokenGpu = true;
    try {
        display->present(kFrame);
        ADD_FAILURE() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Internal);
    }
    EXPECT_TRUE(display->status().ok);
}

}  // namespace
