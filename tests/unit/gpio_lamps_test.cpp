// Lamps: patterns evaluated in time (blink, flash), the driver switching lamps only on change, sim and line lamps.
#include "drivers/gpio/lamps.h"

#include "common/error.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;
const SteadyTime kLampsT0 = SteadyTime{} + 1h;

TEST(GpioLamps, SteadyAndOff) {
    EXPECT_TRUE(LampPattern::steady().isOn(kLampsT0));
    EXPECT_FALSE(LampPattern::off().isOn(kLampsT0));
    EXPECT_EQ(LampPattern::steady().nextChange(kLampsT0), std::nullopt);
    EXPECT_EQ(LampPattern::off().nextChange(kLampsT0), std::nullopt);
}

TEST(GpioLamps, BlinkIsOnForTheFirstPartOfEachPeriod) {
    const auto p = LampPattern::blink(1s, kLampsT0 + 10s);
    EXPECT_FALSE(p.isOn(kLampsT0 + 9999ms));
    EXPECT_TRUE(p.isOn(kLampsT0 + 10s));
    EXPECT_TRUE(p.isOn(kLampsT0 + 10499ms));
    EXPECT_FALSE(p.isOn(kLampsT0 + 10500ms));
    EXPECT_FALSE(p.isOn(kLampsT0 + 10999ms));
    EXPECT_TRUE(p.isOn(kLampsT0 + 11s));
    EXPECT_TRUE(p.isOn(kLampsT0 + 1h + 10s + 100ms));
    EXPECT_EQ(p.nextChange(kLampsT0), kLampsT0 + 10s);
    EXPECT_EQ(p.nextChange(kLampsT0 + 10200ms), kLampsT0 + 10500ms);
    EXPECT_EQ(p.nextChange(kLampsT0 + 10700ms), kLampsT0 + 11s);
    EXPECT_EQ(p.nextChange(kLampsT0 + 10500ms), kLampsT0 + 11s);

    const auto short_on = LampPattern::blink(400ms, kLampsT0, 0.25);
    EXPECT_TRUE(short_on.isOn(kLampsT0 + 99ms));
    EXPECT_FALSE(short_on.isOn(kLampsT0 + 100ms));
    EXPECT_TRUE(short_on.isOn(kLampsT0 + 400ms));
}

TEST(GpioLamps, FlashIsOnePulse) {
    const auto p = LampPattern::flash(200ms, kLampsT0 + 5s);
    EXPECT_FALSE(p.isOn(kLampsT0 + 4999ms));
    EXPECT_TRUE(p.isOn(kLampsT0 + 5s));
    EXPECT_TRUE(p.isOn(kLampsT0 + 5199ms));
    EXPECT_FALSE(p.isOn(kLampsT0 + 5200ms));
    EXPECT_FALSE(p.isOn(kLampsT0 + 60s));
    EXPECT_EQ(p.nextChange(kLampsT0 + 4s), kLampsT0 + 5s);
    EXPECT_EQ(p.nextChange(kLampsT0 + 5100ms), kLampsT0 + 5200ms);
    EXPECT_EQ(p.nextChange(kLampsT0 + 6s), std::nullopt);
}

TEST(GpioLamps, BlinkNeedsAPeriod) {
    EXPECT_THROW(LampPattern::blink(0ms, kLampsT0), BoothError);
}

TEST(GpioLamps, DriverRecordsExactlyTheChangesOfAttractThenCapture) {
    ManualClock clock(kLampsT0);
    SimLamps lamps({"start", "retake", "flash"}, clock);
    LampDriver driver(lamps);
    // Attract: the start lamp blinks with a 1 s period.
    driver.setPattern("start", LampPattern::blink(1s, kLampsT0));
    for (auto t = kLampsT0; t <= kLampsT0 + 2s; t += 250ms) {
        clock.sleepUntil(t);
        driver.update(t);
    }
    // Capture: start lamp steady, the flash pulses 150 ms.
    clock.sleepUntil(kLampsT0 + 2100ms);
    driver.setPattern("start", LampPattern::steady());
    driver.setPattern("flash", LampPattern::flash(150ms, kLampsT0 + 2100ms));
    driver.update(clock.now());
    EXPECT_EQ(driver.nextChange(clock.now()), kLampsT0 + 2250ms);
    clock.sleepUntil(*driver.nextChange(clock.now()));
    driver.update(clock.now());
    EXPECT_EQ(driver.nextChange(clock.now()), std::nullopt);

    using C = SimLamps::Change;
    EXPECT_EQ(lamps.changes(), (std::vector<C>{{"start", true, kLampsT0},
                                               {"start", false, kLampsT0 + 500ms},
                                               {"start", true, kLampsT0 + 1s},
                                               {"start", false, kLampsT0 + 1500ms},
                                               {"start", true, kLampsT0 + 2s},
                                               {"flash", true, kLampsT0 + 2100ms},
                                               {"flash", false, kLampsT0 + 2250ms}}));
    EXPECT_TRUE(lamps.isOn("start"));
    EXPECT_FALSE(lamps.isOn("retake"));
}

TEST(GpioLamps, SimLampsKeepOnlyTheMostRecentChanges) {
    ManualClock clock(kLampsT0);
    SimLamps lamps({"start"}, clock);
    // A week of blinking start lamp (2 changes a second) would be a million changes; a booth keeps the last few.
    const std::size_t n = 3 * SimLamps::kKeptChanges + 5;
    for (std::size_t i = 0; i < n; ++i) {
        clock.sleepUntil(kLampsT0 + std::chrono::milliseconds(500 * i));
        lamps.set("start", i % 2 == 0);
        ASSERT_LE(lamps.changes().size(), SimLamps::kKeptChanges);
    }
    const auto& kept = lamps.changes();
    ASSERT_GE(kept.size(), SimLamps::kKeptChanges / 2);
    // The newest, in order, ending with the last change made.
    for (std::size_t k = 0; k < kept.size(); ++k) {
        const std::size_t i = n - kept.size() + k;
        EXPECT_EQ(kept[k], (SimLamps::Change{"start", i % 2 == 0, kLampsT0 + std::chrono::milliseconds(500 * i)})) << k;
    }
}

TEST(GpioLamps, UnknownLampIsAConfigError) {
    ManualClock clock(kLampsT0);
    SimLamps lamps({"start"}, clock);
    LampDriver driver(lamps);
    try {
        driver.setPattern("strobe", LampPattern::steady());
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_STREQ(e.what(), "lamp \"strobe\": no such lamp (lamps: start)");
    }
    EXPECT_THROW(lamps.set("strobe", true), BoothError);
}

// Output lines that remember every level written.
class RecordingOutputs final : public RawOutputLines {
public:
    explicit RecordingOutputs(std::vector<std::pair<std::size_t, bool>>& log) : log_(log) {}
    void set(std::size_t line, bool high) override { log_.emplace_back(line, high); }
    std::string describe() const override { return "recording"; }

private:
    std::vector<std::pair<std::size_t, bool>>& log_;
};

TEST(GpioLamps, LineLampsDriveActiveLowAndActiveHighLines) {
    std::vector<std::pair<std::size_t, bool>> log;
    LineLamps lamps(std::make_unique<RecordingOutputs>(log), {"start", "flash"}, {false, true});
    // All off at start: the active-low flash relay gets a high line.
    EXPECT_EQ(log, (std::vector<std::pair<std::size_t, bool>>{{0, false}, {1, true}}));
    log.clear();
    lamps.set("start", true);
    lamps.set("flash", true);
    lamps.set("flash", false);
    EXPECT_EQ(log, (std::vector<std::pair<std::size_t, bool>>{{0, true}, {1, false}, {1, true}}));
    EXPECT_TRUE(lamps.isOn("start"));
    EXPECT_FALSE(lamps.isOn("flash"));
    EXPECT_EQ(lamps.names(), (std::vector<std::string>{"start", "flash"}));
}

}  // namespace
}  // namespace avatarbooth

namespace avatarbooth {
namespace {

TEST(GpioLamps, AttractThenCaptureScenes) {
    ManualClock clock(kLampsT0);
    SimLamps lamps({"start", "retake", "flash"}, clock);
    LampDriver driver(lamps);
    lamps.set("retake", true);  // left on by an earlier screen
    showAttractLamps(driver, kLampsT0);
    for (auto t : {kLampsT0, kLampsT0 + 600ms, kLampsT0 + 1s}) {
        clock.sleepUntil(t);
        driver.update(t);
    }
    flashForCapture(driver, kLampsT0 + 1100ms, 100ms);
    for (auto t : {kLampsT0 + 1100ms, kLampsT0 + 1200ms}) {
        clock.sleepUntil(t);
        driver.update(t);
    }
    using C = SimLamps::Change;
    EXPECT_EQ(lamps.changes(), (std::vector<C>{{"retake", true, kLampsT0},
                                               {"retake", false, kLampsT0},
                                               {"start", true, kLampsT0},
                                               {"start", false, kLampsT0 + 600ms},
                                               {"start", true, kLampsT0 + 1s},
                                               {"flash", true, kLampsT0 + 1100ms},
                                               {"flash", false, kLampsT0 + 1200ms}}));
}

TEST(GpioLamps, ScenesSkipLampsTheBoothDoesNotHave) {
    ManualClock clock(kLampsT0);
    SimLamps lamps({"start"}, clock);
    LampDriver driver(lamps);
    showAttractLamps(driver, kLampsT0);
    flashForCapture(driver, kLampsT0);
    driver.update(kLampsT0);
    EXPECT_EQ(lamps.changes(), (std::vector<SimLamps::Change>{{"start", true, kLampsT0}}));
}

}  // namespace
}  // namespace avatarbooth
