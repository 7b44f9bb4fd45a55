// booth.toml: the shipped reference equals the built-in defaults, values land in the parts' settings, and every
// kind of mistake is an error naming the file, the line and the key.
#include "test_paths.h"

#include "config/booth_config.h"
#include "common/error.h"

#include <gtest/gtest.h>

using namespace avatarbooth;

namespace {

const std::filesystem::path kShipped = std::filesystem::path(AVATARBOOTH_TEST_SOURCE_DIR) / "app/assets/booth.toml";

// The message of the BadConfig error the text raises ("" when it raises none).
std::string errorOf(const std::string& text) {
    try {
        parseBoothConfig(text, "booth.toml");
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig) << e.what();
        return e.what();
    }
    return "";
}

}  // namespace

TEST(Config, ShippedReferenceEqualsTheDefaults) {
    const BoothConfig shipped = loadBoothConfig(kShipped);
    const BoothConfig defaults = parseBoothConfig("", "empty.toml");
    EXPECT_EQ(shipped.fit.settings.landmarkModel, defaults.fit.settings.landmarkModel);
    EXPECT_EQ(shipped.fit.settings.head.rbf.kernel, defaults.fit.settings.head.rbf.kernel);
    EXPECT_DOUBLE_EQ(shipped.fit.settings.head.rbf.unitMm, defaults.fit.settings.head.rbf.unitMm);
    EXPECT_EQ(shipped.fit.settings.texture.size, defaults.fit.settings.texture.size);
    EXPECT_EQ(shipped.fit.settings.previewSize, defaults.fit.settings.previewSize);
    EXPECT_EQ(shipped.camera.backend, defaults.camera.backend);
    EXPECT_EQ(shipped.camera.previewWidth, defaults.camera.previewWidth);
    EXPECT_EQ(shipped.camera.previewHeight, defaults.camera.previewHeight);
    EXPECT_DOUBLE_EQ(shipped.camera.previewFps, defaults.camera.previewFps);
    EXPECT_EQ(shipped.camera.stillWarmupFrames, defaults.camera.stillWarmupFrames);
    EXPECT_EQ(shipped.camera.simNoise, defaults.camera.simNoise);
    EXPECT_DOUBLE_EQ(shipped.camera.reopenMaxDelaySeconds, defaults.camera.reopenMaxDelaySeconds);
    EXPECT_EQ(shipped.buttons.chip, defaults.buttons.chip);
    EXPECT_EQ(shipped.buttons.debounceMs, defaults.buttons.debounceMs);
    ASSERT_EQ(shipped.buttons.buttons.size(), defaults.buttons.buttons.size());
    for (std::size_t i = 0; i < shipped.buttons.buttons.size(); ++i) {
        EXPECT_EQ(shipped.buttons.buttons[i].name, defaults.buttons.buttons[i].name);
        EXPECT_EQ(shipped.buttons.buttons[i].offset, defaults.buttons.buttons[i].offset);
        EXPECT_EQ(shipped.buttons.buttons[i].activeLow, defaults.buttons.buttons[i].activeLow);
        EXPECT_EQ(shipped.buttons.buttons[i].bias, defaults.buttons.buttons[i].bias);
    }
    ASSERT_EQ(shipped.buttons.lamps.size(), defaults.buttons.lamps.size());
    for (std::size_t i = 0; i < shipped.buttons.lamps.size(); ++i) {
        EXPECT_EQ(shipped.buttons.lamps[i].name, defaults.buttons.lamps[i].name);
        EXPECT_EQ(shipped.buttons.lamps[i].offset, defaults.buttons.lamps[i].offset);
    }
    EXPECT_EQ(shipped.buttons.keys, defaults.buttons.keys);
    EXPECT_EQ(shipped.display.backend, defaults.display.backend);
    EXPECT_EQ(shipped.display.width, defaults.display.width);
    EXPECT_EQ(shipped.display.height, defaults.display.height);
    EXPECT_EQ(shipped.screen.language, defaults.screen.language);
    EXPECT_EQ(shipped.screen.startButtonOnLeft, defaults.screen.startButtonOnLeft);
    EXPECT_EQ(shipped.flow.countdown, defaults.flow.countdown);
    EXPECT_EQ(shipped.flow.steadyOk, defaults.flow.steadyOk);
    EXPECT_EQ(shipped.flow.guideAbsentTimeout, defaults.flow.guideAbsentTimeout);
    EXPECT_EQ(shipped.flow.guideMaxTime, defaults.flow.guideMaxTime);
    EXPECT_EQ(shipped.flow.captureTimeout, defaults.flow.captureTimeout);
    EXPECT_EQ(shipped.flow.processingTimeout, defaults.flow.processingTimeout);
    EXPECT_EQ(shipped.flow.revealTimeout, defaults.flow.revealTimeout);
    EXPECT_EQ(shipped.flow.retakeChoiceTimeout, defaults.flow.retakeChoiceTimeout);
    EXPECT_EQ(shipped.flow.thanksTime, defaults.flow.thanksTime);
    EXPECT_EQ(shipped.flow.thanksMinTime, defaults.flow.thanksMinTime);
    EXPECT_EQ(shipped.flow.cameraLostTimeout, defaults.flow.cameraLostTimeout);
    EXPECT_EQ(shipped.flow.pressGuard, defaults.flow.pressGuard);
    EXPECT_EQ(shipped.flow.lockCombo, defaults.flow.lockCombo);
    EXPECT_EQ(shipped.flow.lockHold, defaults.flow.lockHold);
    EXPECT_EQ(shipped.flow.operatorTimeout, defaults.flow.operatorTimeout);
    EXPECT_DOUBLE_EQ(shipped.guidance.oval.height, defaults.guidance.oval.height);
    EXPECT_DOUBLE_EQ(shipped.guidance.oval.aspect, defaults.guidance.oval.aspect);
    EXPECT_EQ(shipped.sessions.directory, defaults.sessions.directory);
    EXPECT_EQ(shipped.sessions.photoRetention, defaults.sessions.photoRetention);
    EXPECT_EQ(shipped.sessions.sessionRetention, defaults.sessions.sessionRetention);
    EXPECT_EQ(shipped.sessions.codeLength, defaults.sessions.codeLength);
    EXPECT_EQ(shipped.animation.style, defaults.animation.style);
    EXPECT_DOUBLE_EQ(shipped.animation.fps, defaults.animation.fps);
    EXPECT_EQ(shipped.animation.inbetweenOmissions, defaults.animation.inbetweenOmissions);
    EXPECT_NEAR(shipped.animation.holdFraction, defaults.animation.holdFraction, 1e-12);
}

TEST(Config, ValuesLandInTheirSettings) {
    const BoothConfig c = parseBoothConfig(R"(
[fit]
rbf_kernel = "tps"
rbf_unit_mm = 30
[camera]
backend = "sim"
sim_folder = "/srv/visitor"
preview_fps = 15
[buttons]
debounce_ms = 50
[[buttons.button]]
name = "start"
offset = 5
active_low = false
bias = "pull-down"
[display]
rotation = 90
[screen]
language = "ja"
[flow]
countdown_s = 2.5
lock_combo = "service"
[guidance.oval]
height = 0.6
[sessions]
photo_retention_hours = 1.5
[animation]
style = "full"
)", "booth.toml");
    EXPECT_EQ(c.fit.settings.head.rbf.kernel, RbfKernel::ThinPlate);
    EXPECT_DOUBLE_EQ(c.fit.settings.head.rbf.unitMm, 30.0);
    EXPECT_EQ(c.camera.backend, "sim");
    EXPECT_EQ(c.camera.simFolder, "/srv/visitor");
    EXPECT_DOUBLE_EQ(c.camera.previewFps, 15.0);
    EXPECT_EQ(c.buttons.debounceMs, 50);
    ASSERT_EQ(c.buttons.buttons.size(), 1u);  // the table replaces the default list
    EXPECT_EQ(c.buttons.buttons[0].offset, 5u);
    EXPECT_FALSE(c.buttons.buttons[0].activeLow);
    EXPECT_EQ(c.buttons.buttons[0].bias, LineBias::PullDown);
    EXPECT_EQ(c.display.rotation, 90);
    EXPECT_EQ(c.screen.language, Language::Japanese);
    EXPECT_EQ(c.flow.countdown, Millis(2500));
    EXPECT_EQ(c.flow.lockCombo, std::vector<Button>{Button::Service});
    EXPECT_DOUBLE_EQ(c.guidance.oval.height, 0.6);
    EXPECT_DOUBLE_EQ(c.screen.oval.height, 0.6);  // the screen draws the oval the guidance measures against
    EXPECT_EQ(c.sessions.photoRetention, std::chrono::seconds(5400));
    EXPECT_EQ(c.animation.style, AnimationStyle::Full);
}

TEST(Config, MistakesNameFileLineAndKey) {
    EXPECT_EQ(errorOf("[camera]\nbackend = \"v4l2\"\n"), "");
    EXPECT_EQ(errorOf("[camera]\n\ndevise = \"/dev/video0\"\n"),
              "booth.toml:3: camera.devise: unknown key (see the reference booth.toml for the keys there are)");
    EXPECT_EQ(errorOf("[camra]\n"), "booth.toml:1: camra: unknown table (see the reference booth.toml for the keys there are)");
    EXPECT_EQ(errorOf("[camera]\npreview_fps = \"fast\"\n"), "booth.toml:2: camera.preview_fps: expected a number");
    EXPECT_EQ(errorOf("[camera]\npreview_width = 12.5\n"), "booth.toml:2: camera.preview_width: expected a whole number");
    EXPECT_EQ(errorOf("[buttons]\ndebounce_ms = 5000\n"), "booth.toml:2: buttons.debounce_ms: must be between 0 and 1000, got 5000");
    EXPECT_EQ(errorOf("[camera]\nbackend = \"webcam\"\n"),
              "booth.toml:2: camera.backend: \"webcam\" is not one of \"auto\", \"v4l2\", \"libcamera\" or \"sim\"");
    EXPECT_EQ(errorOf("[display]\nrotation = 45\n"), "booth.toml:2: display.rotation: must be 0, 90, 180 or 270");
    EXPECT_EQ(errorOf("[flow]\nlock_combo = \"start+coin\"\n"),
              "booth.toml:2: flow.lock_combo: \"coin\" is not a button (start, retake, service; joined by +)");
    EXPECT_EQ(errorOf("[[buttons.button]]\nname = \"start\"\noffset = 4\n[[buttons.lamp]]\nname = \"flash\"\noffset = 4\n"),
              "booth.toml:4: buttons.lamp: line 4 is used twice");
    EXPECT_EQ(errorOf("[[buttons.button]]\nname = \"start\"\npin = 4\n"),
              "booth.toml:3: buttons.button[0].pin: unknown key (see the reference booth.toml for the keys there are)");
    EXPECT_EQ(errorOf("[fit]\nbase_mesh = \"head.glb\"\n"),
              "booth.toml:2: fit.base_mesh: give both base_mesh and base_features, or neither");
    EXPECT_EQ(errorOf("[sessions]\nphoto_retention_hours = 48\nsession_retention_days = 1\n"),
              "booth.toml:3: sessions.session_retention_days: sessions would be deleted before their photos' retention ends");
    // Not TOML at all: the parser's own message, with the line.
    const std::string bad = errorOf("[camera]\nbackend = \"sim\n");
    EXPECT_EQ(bad.rfind("booth.toml:2: not valid TOML: ", 0), 0u) << bad;
}

TEST(Config, MissingFileIsBadInput) {
    try {
        loadBoothConfig("/nonexistent/booth.toml");
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadInput);
        EXPECT_STREQ(e.what(), "/nonexistent/booth.toml: cannot read the configuration file");
    }
}
