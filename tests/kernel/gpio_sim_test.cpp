// The GPIO backend against the kernel's gpio-sim (configfs): buttons and lamps opened from our settings, presses
// made with the sim's `pull` attribute (bouncing included) arriving as single debounced presses, lamps showing in
// the sim's `value` files, and our errors for a missing chip and for a line that is already in use.
#include "kernel_guest.h"

#include "drivers/gpio/button_board.h"
#include "drivers/gpio/gpiod_lines.h"

#include "common/error.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using kernel_test::readFile;
using kernel_test::writeFile;

constexpr const char* kSimLabel = "avatarbooth-sim";
const fs::path kSimConfig = "/sys/kernel/config/gpio-sim/avatarbooth";

class GpioSim : public ::testing::Test {
protected:
    // One simulated chip of 8 lines labelled "avatarbooth-sim", made live through configfs.
    static void SetUpTestSuite() {
        if (!kernel_test::inGuest()) return;
        if (kernel_test::modprobe("gpio-sim") != 0) return;
        // configfs is a module in Debian's kernel, loaded with gpio-sim: mount it now.
        kernel_test::run("mountpoint -q /sys/kernel/config || mount -t configfs none /sys/kernel/config");
        if (!fs::exists("/sys/kernel/config/gpio-sim")) return;
        fs::create_directories(kSimConfig / "bank0");
        if (!writeFile(kSimConfig / "bank0/num_lines", "8") || !writeFile(kSimConfig / "bank0/label", kSimLabel) ||
            !writeFile(kSimConfig / "live", "1"))
            return;
        chip_ = readFile(kSimConfig / "bank0/chip_name");
        sim_ = fs::path("/sys/devices/platform") / readFile(kSimConfig / "dev_name") / chip_;
        ready_ = !chip_.empty() && fs::exists(sim_ / "sim_gpio0/pull");
    }
    void SetUp() override {
        AVATARBOOTH_REQUIRE_KERNEL_GUEST();
        ASSERT_TRUE(ready_) << "gpio-sim chip not set up (modprobe gpio-sim, configfs)";
        // Buttons idle: the line pulled up, as the button's pull-up holds it on the board.
        for (int line = 0; line < 2; ++line) ASSERT_TRUE(pull(line, true));
        settings_.backend = "gpiod";
        settings_.chip = kSimLabel;
        settings_.buttons = {{"start", 0}, {"retake", 1}};
        settings_.lamps = {{"start", 4}, {"retake", 5}, {"flash", 6, true}};
        settings_.debounceMs = 80;
        settings_.consumer = "avatarbooth-test";
    }
    static bool pull(int line, bool up) {
        return writeFile(sim_ / ("sim_gpio" + std::to_string(line)) / "pull", up ? "pull-up" : "pull-down");
    }
    static std::string value(int line) { return readFile(sim_ / ("sim_gpio" + std::to_string(line)) / "value"); }

    // Every event until none has come for `quiet`.
    static std::vector<ButtonEvent> drain(Buttons& buttons, std::chrono::milliseconds quiet = 600ms) {
        std::vector<ButtonEvent> events;
        while (auto e = buttons.poll(quiet)) events.push_back(*e);
        return events;
    }

    static inline bool ready_ = false;
    static inline std::string chip_;
    static inline fs::path sim_;
    GpioSettings settings_;
};

std::string describe(const std::vector<ButtonEvent>& events) {
    std::string s;
    for (const auto& e : events) s += e.button + (e.action == ButtonAction::Press ? " press; " : " release; ");
    return s;
}

TEST_F(GpioSim, APressThroughTheSimsPullIsOnePressAndOneRelease) {
    SteadyClock clock;
    ButtonBoard board = openButtonBoard(settings_, clock);
    EXPECT_NE(board.description.find("gpiod"), std::string::npos) << board.description;
    EXPECT_TRUE(drain(*board.buttons, 300ms).empty()) << "events without a press";

    const auto before = std::chrono::steady_clock::now();
    ASSERT_TRUE(pull(0, false));  // pressed: the button shorts the line to ground
    std::this_thread::sleep_for(300ms);
    ASSERT_TRUE(pull(0, true));
    const auto events = drain(*board.buttons);
    ASSERT_EQ(events.size(), 2u) << describe(events);
    EXPECT_EQ(events[0].button, "start");
    EXPECT_EQ(events[0].action, ButtonAction::Press);
    EXPECT_EQ(events[1].action, ButtonAction::Release);
    // Edge times are the kernel's CLOCK_MONOTONIC stamps, on our clock: after we started, 300 ms apart or more.
    EXPECT_GE(events[0].time, before);
    EXPECT_GE(events[1].time - events[0].time, 250ms);
    EXPECT_FALSE(board.buttons->isDown("start"));
}

TEST_F(GpioSim, ABouncingPressInsideTheDebounceTimeIsOnePress) {
    SteadyClock clock;
    ButtonBoard board = openButtonBoard(settings_, clock);
    ASSERT_TRUE(drain(*board.buttons, 300ms).empty());
    // Contact bounce: five edges back to back (well inside 80 ms even in the emulated guest), ending pressed.
    const auto start = std::chrono::steady_clock::now();
    for (bool up : {false, true, false, true, false}) ASSERT_TRUE(pull(1, up));
    const auto bounced = std::chrono::steady_clock::now() - start;
    std::this_thread::sleep_for(400ms);
    // Released with bounce too.
    for (bool up : {true, false, true}) ASSERT_TRUE(pull(1, up));
    const auto events = drain(*board.buttons);
    ASSERT_LT(bounced, 80ms) << "the guest was too slow to bounce within the debounce time";
    ASSERT_EQ(events.size(), 2u) << describe(events);
    EXPECT_EQ(events[0].button, "retake");
    EXPECT_EQ(events[0].action, ButtonAction::Press);
    EXPECT_EQ(events[1].button, "retake");
    EXPECT_EQ(events[1].action, ButtonAction::Release);
}

TEST_F(GpioSim, LampsShowInTheSimsValueFiles) {
    SteadyClock clock;
    ButtonBoard board = openButtonBoard(settings_, clock);
    ASSERT_TRUE(board.lamps);
    // All off at the start; the active-low flash lamp is off with its line high.
    EXPECT_EQ(value(4), "0");
    EXPECT_EQ(value(5), "0");
    EXPECT_EQ(value(6), "1");
    board.lamps->set("start", true);
    EXPECT_EQ(value(4), "1");
    EXPECT_EQ(value(5), "0");
    board.lamps->set("flash", true);
    EXPECT_EQ(value(6), "0");
    board.lamps->set("start", false);
    board.lamps->set("flash", false);
    EXPECT_EQ(value(4), "0");
    EXPECT_EQ(value(6), "1");
}

TEST_F(GpioSim, AMissingChipIsAClearDeviceError) {
    settings_.chip = "avatarbooth-no-such-chip";
    SteadyClock clock;
    try {
        openButtonBoard(settings_, clock);
        FAIL() << "opened a chip that does not exist";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_NE(std::string(e.where()).find("avatarbooth-no-such-chip"), std::string::npos) << e.where();
        // It lists the chips that are there: the sim's.
        EXPECT_NE(std::string(e.what()).find(chip_), std::string::npos) << e.what();
    }
    std::string why;
    EXPECT_TRUE(gpiodChipAvailable(kSimLabel, &why)) << why;
}

TEST_F(GpioSim, ALineAlreadyInUseIsAClearDeviceErrorNamingItsUser) {
    SteadyClock clock;
    ButtonBoard board = openButtonBoard(settings_, clock);
    try {
        openGpiodInputLines(kSimLabel, {{0, LineBias::PullUp, "second start button"}}, "intruder");
        FAIL() << "requested a line that is in use";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_NE(std::string(e.where()).find("line 0"), std::string::npos) << e.where();
        EXPECT_NE(std::string(e.what()).find("already in use by \"avatarbooth-test\""), std::string::npos)
            << e.what();
    }
    try {
        openGpiodOutputLines(kSimLabel, {{4, false, "second lamp"}}, "intruder");
        FAIL() << "requested a lamp line that is in use";
    } catch (const BoothError& e) {
        EXPECT_NE(std::string(e.what()).find("already in use"), std::string::npos) << e.what();
    }
}

TEST_F(GpioSim, AButtonHeldWhenTheBoardOpensIsDownAndTheOtherIsNot) {
    // gpio-sim applies a requested bias as its pull, which would lift the held line: the lines are taken as they are
    // (bias "as-is", as with external pull-ups).
    for (auto& b : settings_.buttons) b.bias = LineBias::AsIs;
    ASSERT_TRUE(pull(1, false));  // retake held down while the booth starts
    SteadyClock clock;
    ButtonBoard board = openButtonBoard(settings_, clock);
    EXPECT_TRUE(board.buttons->isDown("retake"));
    EXPECT_FALSE(board.buttons->isDown("start"));
    ASSERT_TRUE(pull(1, true));
    const auto events = drain(*board.buttons);
    ASSERT_EQ(events.size(), 1u) << describe(events);
    EXPECT_EQ(events[0].button, "retake");
    EXPECT_EQ(events[0].action, ButtonAction::Release);
}

TEST_F(GpioSim, TheChipOpensByPathNameAndNumberAsByLabel) {
    const std::string number = chip_.substr(std::string("gpiochip").size());
    for (const std::string& name : {"/dev/" + chip_, chip_, number}) {
        SCOPED_TRACE(name);
        settings_.chip = name;
        SteadyClock clock;
        ButtonBoard board = openButtonBoard(settings_, clock);
        EXPECT_NE(board.description.find(std::string("[") + kSimLabel + "]"), std::string::npos) << board.description;
    }
}

TEST_F(GpioSim, ALineTheChipDoesNotHaveIsAClearDeviceError) {
    try {
        openGpiodInputLines(kSimLabel, {{9, LineBias::PullUp, "start button"}}, "avatarbooth-test");
        FAIL() << "requested line 9 of an 8-line chip";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_NE(std::string(e.where()).find("line 9 (start button)"), std::string::npos) << e.where();
        EXPECT_NE(std::string(e.what()).find("the chip has 8 lines (0-7)"), std::string::npos) << e.what();
    }
}

// libgpiod 2.x asks the kernel to filter glitches on the button lines (a few ms, below the software debounce);
// 1.6's uAPI cannot, and the kernel then reports no debounce.
TEST_F(GpioSim, TheKernelDebouncesTheButtonLinesWhereLibgpiodCan) {
    std::cout << "[ backend  ] " << gpiodLibraryVersion() << ", kernel debounce " << (gpiodKernelDebounce() ? "yes" : "no")
              << std::endl;
    SteadyClock clock;
    ButtonBoard board = openButtonBoard(settings_, clock);
    std::string chipName;
    const auto lines = gpiodLineStatus(kSimLabel, {0, 1, 4}, &chipName);
    ASSERT_EQ(lines.size(), 3u);
    const auto expected = gpiodKernelDebounce() ? std::chrono::microseconds(5000) : std::chrono::microseconds(0);
    for (int i : {0, 1}) {
        EXPECT_TRUE(lines[i].used);
        EXPECT_EQ(lines[i].consumer, "avatarbooth-test");
        EXPECT_EQ(lines[i].kernelDebounce, expected) << "line " << lines[i].offset;
    }
    EXPECT_EQ(lines[2].kernelDebounce, std::chrono::microseconds(0)) << "a lamp is an output, never debounced";
    if (gpiodKernelDebounce()) {
        EXPECT_NE(board.description.find("kernel debounce 5000 us"), std::string::npos) << board.description;
    }
    // A press still arrives as one press and one release through the kernel's filter.
    ASSERT_TRUE(pull(0, false));
    std::this_thread::sleep_for(200ms);
    ASSERT_TRUE(pull(0, true));
    const auto events = drain(*board.buttons);
    ASSERT_EQ(events.size(), 2u) << describe(events);
    EXPECT_EQ(events[0].action, ButtonAction::Press);
}

}  // namespace
}  // namespace avatarbooth
