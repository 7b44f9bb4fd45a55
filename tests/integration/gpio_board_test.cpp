// Buttons and lamps opened from settings: gpiod failing clearly without the chip, "auto" falling back to the sim,
// the sim running a timeline file through debouncing, and bad settings or files named in errors.
#include "drivers/gpio/button_board.h"
#include "drivers/gpio/gpiod_lines.h"

#include "common/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using enum ButtonAction;

constexpr const char* kMissingChip = "avatarbooth-no-such-chip";

BoothError errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const BoothError& e) {
        return e;
    }
    ADD_FAILURE() << "no BoothError";
    return BoothError(ErrorKind::Internal, "", "none");
}

TEST(GpioBoard, GpiodWithAMissingChipIsADeviceErrorNamingIt) {
    GpioSettings settings;
    settings.backend = "gpiod";
    settings.chip = kMissingChip;
    ManualClock clock;
    const BoothError e = errorOf([&] { openButtonBoard(settings, clock); });
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_EQ(e.where(), std::string("GPIO chip \"") + kMissingChip + "\"");
    EXPECT_NE(std::string(e.what()).find("not found (looked for it as a label, a name like gpiochip0"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("chips here: "), std::string::npos) << e.what();

    // The line-level functions (what the gpio-sim kernel tests call) report the same.
    EXPECT_EQ(errorOf([&] { openGpiodInputLines(kMissingChip, {{17, LineBias::PullUp, "start button"}}, "t"); })
                  .kind(),
              ErrorKind::Device);
    EXPECT_EQ(errorOf([&] { openGpiodOutputLines("/dev/gpiochip-none", {{22, false, "start lamp"}}, "t"); }).kind(),
              ErrorKind::Device);
    std::string why;
    EXPECT_FALSE(gpiodChipAvailable(kMissingChip, &why));
    EXPECT_EQ(why.rfind(std::string("GPIO chip \"") + kMissingChip + "\": not found", 0), 0u) << why;
}

TEST(GpioBoard, AutoWithoutTheChipRunsTheSimAndSaysWhy) {
    const fs::path dir = test::scratchDir("gpio_board_auto");
    const fs::path script = dir / "visit.timeline";
    std::ofstream(script) << "# one visitor\nat 1s tap start bounce 3\nat 3s hold start+retake 5s\n";
    GpioSettings settings;
    settings.chip = kMissingChip;
    settings.timeline = script.string();
    ManualClock clock;
    const SteadyTime t0 = clock.now();
    ButtonBoard board = openButtonBoard(settings, clock);
    EXPECT_EQ(board.description.rfind(std::string("buttons: sim (auto: gpiod: GPIO chip \"") + kMissingChip, 0), 0u)
        << board.description;
    EXPECT_NE(board.description.find("sim timeline " + script.string() + " (18 edges), debounce 30 ms + keyboard: "
                                     "BackSpace=retake Return=start r=retake space=start; lamps: sim lamps"),
              std::string::npos)
        << board.description;
    ASSERT_NE(board.keyboard, nullptr);
    ASSERT_NE(board.simLamps, nullptr);

    std::vector<ButtonEvent> got;
    while (auto e = board.buttons->poll(10s)) got.push_back(*e);
    EXPECT_EQ(got, (std::vector<ButtonEvent>{{"start", Press, t0 + 1s},
                                             {"start", Release, t0 + 1100ms},
                                             {"start", Press, t0 + 3s},
                                             {"retake", Press, t0 + 3s},
                                             {"start", Release, t0 + 8s},
                                             {"retake", Release, t0 + 8s}}));
    EXPECT_TRUE(board.buttons->finished());

    // Keys still work after the script has run out.
    board.keyboard->feed("space", true, clock.now());
    EXPECT_EQ(board.buttons->poll(0ms), (ButtonEvent{"start", Press, clock.now()}));

    board.lamps->set("flash", true);
    EXPECT_EQ(board.simLamps->changes().size(), 1u);
    EXPECT_EQ(board.lamps->names(), (std::vector<std::string>{"start", "retake", "flash"}));
}

TEST(GpioBoard, TimelineFileErrorsNameTheFile) {
    const fs::path dir = test::scratchDir("gpio_board_timeline_errors");
    const fs::path script = dir / "bad.timeline";
    std::ofstream(script) << "at 1s tap start\n\nat 2s tap strat\n";
    GpioSettings settings;
    settings.backend = "sim";
    settings.timeline = script.string();
    ManualClock clock;
    BoothError e = errorOf([&] { openButtonBoard(settings, clock); });
    EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
    EXPECT_EQ(std::string(e.what()), script.string() + ":3: unknown button \"strat\" (buttons: start, retake)");

    settings.timeline = (dir / "missing.timeline").string();
    e = errorOf([&] { openButtonBoard(settings, clock); });
    EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
    EXPECT_EQ(std::string(e.what()), settings.timeline + ": cannot read the button timeline (missing?)");
}

TEST(GpioBoard, BadSettingsAreConfigErrorsNamingTheField) {
    ManualClock clock;
    GpioSettings s;
    s.backend = "wiringpi";
    EXPECT_STREQ(errorOf([&] { openButtonBoard(s, clock); }).what(),
                 "gpio.backend: \"wiringpi\" is not a buttons backend (auto, gpiod or sim)");
    s = {};
    s.debounceMs = 5000;
    EXPECT_STREQ(errorOf([&] { openButtonBoard(s, clock); }).what(),
                 "gpio.debounce_ms: 5000 is out of range (0-1000 ms; 30 is usual)");
    s = {};
    s.lamps.push_back({"strobe", 17});
    EXPECT_STREQ(errorOf([&] { openButtonBoard(s, clock); }).what(),
                 "gpio lamp \"strobe\": line 17 is used twice");
    s = {};
    s.buttons.push_back({"start", 5});
    EXPECT_STREQ(errorOf([&] { openButtonBoard(s, clock); }).what(), "gpio button \"start\": is configured twice");
    s = {};
    s.keys["q"] = "quit";
    EXPECT_STREQ(errorOf([&] { openButtonBoard(s, clock); }).what(),
                 "key \"q\": is mapped to the unknown button \"quit\"");
}

}  // namespace
}  // namespace avatarbooth
