// The backend tables: "auto" walks a table in order and passes over a failing probe with its reason, a name is
// looked up in the same table, and the camera, display and buttons tables have the rows their READMEs name.
#include "common/backend_table.h"
#include "common/error.h"
#include "drivers/camera/camera_factory.h"
#include "drivers/display/display_backends.h"
#include "drivers/gpio/button_board.h"

#include <gtest/gtest.h>

#include <set>

namespace avatarbooth {
namespace {

// A kind whose devices are the names in `present`; `probed` records the order the probes ran in.
struct FakeSettings {
    std::set<std::string> present;
    std::vector<std::string>* probed = nullptr;
};

template <int Row>
BackendProbe probeRow(const FakeSettings& s) {
    static constexpr const char* kNames[] = {"first", "second", "last"};
    const std::string name = kNames[Row];
    if (s.probed) s.probed->push_back(name);
    if (s.present.count(name)) return {true, name + " found", "/dev/" + name};
    return {false, "no " + name + " here", ""};
}

int openNothing(const FakeSettings&) { return 0; }

using FakeBackend = Backend<FakeSettings, int (*)(const FakeSettings&)>;
constexpr FakeBackend kFake[] = {
    {"first", probeRow<0>, openNothing},
    {"second", probeRow<1>, openNothing},
    {"last", probeRow<2>, openNothing},
};
const std::span<const FakeBackend> kTable = kFake;

template <typename Entry>
std::vector<std::string> namesOf(std::span<const Entry> table) {
    std::vector<std::string> out;
    for (const Entry& e : table) out.emplace_back(e.name);
    return out;
}

TEST(BackendTable, AutoTakesTheFirstUsableInOrderAndSaysWhyTheEarlierWerePassedOver) {
    std::vector<std::string> probed;
    const FakeSettings settings{{"second", "last"}, &probed};
    const BackendChoice<FakeBackend> choice = probeBackends(kTable, settings);
    ASSERT_EQ(choice.backend, &kFake[1]);
    EXPECT_EQ(choice.probe.text, "second found");
    EXPECT_EQ(choice.probe.device, "/dev/second");
    ASSERT_EQ(choice.passed.size(), 1u);
    EXPECT_EQ(choice.passed[0].name, "first");
    EXPECT_EQ(choice.passed[0].why, "no first here");
    // A usable backend ends the walk: the ones after it are not probed.
    EXPECT_EQ(probed, (std::vector<std::string>{"first", "second"}));
    EXPECT_EQ(autoReason(choice), "auto: first: no first here");
}

TEST(BackendTable, AutoWithTheFirstUsableSaysWhatItFound) {
    const BackendChoice<FakeBackend> choice = probeBackends(kTable, FakeSettings{{"first"}, nullptr});
    EXPECT_EQ(choice.backend, &kFake[0]);
    EXPECT_TRUE(choice.passed.empty());
    EXPECT_EQ(autoReason(choice), "auto: first found");
}

TEST(BackendTable, AutoWithNothingUsablePassesOverEveryRow) {
    const BackendChoice<FakeBackend> choice = probeBackends(kTable, FakeSettings{});
    EXPECT_EQ(choice.backend, nullptr);
    EXPECT_EQ(passedOver(choice.passed), "first: no first here; second: no second here; last: no last here");
    // Walking on after a row (a display that passed its probe but did not open).
    const BackendChoice<FakeBackend> rest = probeBackends(kTable, FakeSettings{{"first", "last"}, nullptr}, 1);
    EXPECT_EQ(rest.backend, &kFake[2]);
    EXPECT_EQ(passedOver(rest.passed), "second: no second here");
}

TEST(BackendTable, NamesAreLookedUpInTheSameTable) {
    EXPECT_EQ(findBackend(kTable, "last"), &kFake[2]);
    EXPECT_EQ(findBackend(kTable, "auto"), nullptr);
    EXPECT_EQ(findBackend(kTable, "Last"), nullptr);
    EXPECT_EQ(backendWords(kTable), (std::vector<std::string>{"auto", "first", "second", "last"}));
    EXPECT_EQ(backendWordList(kTable), "auto, first, second or last");
}

TEST(BackendTable, EachDeviceKindHasOneTableInAutoOrder) {
    EXPECT_EQ(namesOf(cameraBackends()), (std::vector<std::string>{"v4l2", "libcamera", "sim"}));
    EXPECT_EQ(namesOf(displayBackends()), (std::vector<std::string>{"kms", "window", "headless"}));
    EXPECT_EQ(namesOf(buttonBackends()), (std::vector<std::string>{"gpiod", "sim"}));
}

TEST(BackendTable, CameraNamesAreTakenAsTheyAreAndUnknownOnesAreConfigErrors) {
    CameraSettings settings;
    settings.backend = "libcamera";
    settings.device = "/base/soc/i2c0mux/i2c@1/imx708@1a";
    const CameraBackendChoice named = chooseCameraBackend(settings);
    EXPECT_EQ(named.entry, &cameraBackends()[1]);
    EXPECT_FALSE(named.automatic);
    EXPECT_EQ(named.device, settings.device);
    EXPECT_EQ(named.reason, "libcamera (configured)");
    settings.backend = "sim";
    settings.simFolder = "/srv/visitor";
    EXPECT_EQ(chooseCameraBackend(settings).device, "/srv/visitor");
    EXPECT_EQ(resolvedCameraSettings(settings, chooseCameraBackend(settings)).device, settings.device);

    settings.backend = "webcam";
    try {
        chooseCameraBackend(settings);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_STREQ(e.what(), "camera.backend: unknown camera backend \"webcam\" (auto, v4l2, libcamera or sim)");
    }
}

TEST(BackendTable, ButtonNamesAreTakenUnprobedAndUnknownOnesAreConfigErrors) {
    GpioSettings settings;
    settings.backend = "gpiod";
    settings.chip = "avatarbooth-no-such-chip";
    const BackendChoice<ButtonBackend> named = chooseButtonBackend(settings);
    EXPECT_EQ(named.backend, &buttonBackends()[0]);
    EXPECT_TRUE(named.passed.empty());
    settings.backend = "wiringpi";
    try {
        chooseButtonBackend(settings);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_STREQ(e.what(), "gpio.backend: \"wiringpi\" is not a buttons backend (auto, gpiod or sim)");
    }
}

}  // namespace
}  // namespace avatarbooth
