// booth.toml: the schema's printed default parses back to the built-in defaults and is the shipped file, the
// README's reference is the schema's, every key lands in its setting, and every kind of mistake is an error naming
// the file, the line and the key.
#include "test_paths.h"

#include "config/booth_config.h"
#include "config/config_schema.h"
#include "common/error.h"
#include "drivers/camera/camera_backends.h"
#include "drivers/display/display_backends.h"
#include "drivers/gpio/button_backends.h"

#include "config_error_of.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

using namespace avatarbooth;

namespace {

const std::filesystem::path kSource = AVATARBOOTH_TEST_SOURCE_DIR;
const std::filesystem::path kShipped = kSource / "app/assets/booth.toml";
constexpr const char* kRegenerate = "run tests/update_config_reference.sh (after building avatarbooth) to regenerate it";

std::string readText(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

using avatarbooth::test::errorOf;


// Field by field, every setting the file can hold (independently of the schema's own get()).
void expectSameSettings(const BoothConfig& shipped, const BoothConfig& defaults) {
    EXPECT_EQ(shipped.fit.baseMesh, defaults.fit.baseMesh);
    EXPECT_EQ(shipped.fit.baseFeatures, defaults.fit.baseFeatures);
    EXPECT_EQ(shipped.camera.device, defaults.camera.device);
    EXPECT_EQ(shipped.camera.stillWidth, defaults.camera.stillWidth);
    EXPECT_EQ(shipped.camera.stillHeight, defaults.camera.stillHeight);
    EXPECT_EQ(shipped.camera.bufferCount, defaults.camera.bufferCount);
    EXPECT_EQ(shipped.camera.simFolder, defaults.camera.simFolder);
    EXPECT_DOUBLE_EQ(shipped.camera.simFps, defaults.camera.simFps);
    EXPECT_EQ(shipped.camera.simRealTime, defaults.camera.simRealTime);
    EXPECT_DOUBLE_EQ(shipped.camera.reopenFirstDelaySeconds, defaults.camera.reopenFirstDelaySeconds);
    EXPECT_EQ(shipped.buttons.backend, defaults.buttons.backend);
    EXPECT_EQ(shipped.buttons.consumer, defaults.buttons.consumer);
    EXPECT_EQ(shipped.buttons.timeline, defaults.buttons.timeline);
    EXPECT_EQ(shipped.display.rotation, defaults.display.rotation);
    EXPECT_EQ(shipped.display.drmDevice, defaults.display.drmDevice);
    EXPECT_EQ(shipped.display.connector, defaults.display.connector);
    EXPECT_EQ(shipped.display.everyNthFrame, defaults.display.everyNthFrame);
    EXPECT_EQ(shipped.display.framesDir, defaults.display.framesDir);
    EXPECT_EQ(shipped.display.windowTitle, defaults.display.windowTitle);
    EXPECT_EQ(shipped.screen.fonts.regular, defaults.screen.fonts.regular);
    EXPECT_EQ(shipped.screen.fonts.bold, defaults.screen.fonts.bold);
    EXPECT_EQ(shipped.screen.fonts.japanese, defaults.screen.fonts.japanese);
    EXPECT_EQ(shipped.screen.stringsFile, defaults.screen.stringsFile);
    EXPECT_DOUBLE_EQ(shipped.guidance.oval.centreX, defaults.guidance.oval.centreX);
    EXPECT_DOUBLE_EQ(shipped.guidance.oval.centreY, defaults.guidance.oval.centreY);
    EXPECT_DOUBLE_EQ(shipped.screen.oval.height, defaults.screen.oval.height);
    for (std::size_t i = 0; i < std::min(shipped.buttons.lamps.size(), defaults.buttons.lamps.size()); ++i)
        EXPECT_EQ(shipped.buttons.lamps[i].activeLow, defaults.buttons.lamps[i].activeLow);
    EXPECT_EQ(shipped.fit.settings.landmarkModel, defaults.fit.settings.landmarkModel);
    EXPECT_EQ(shipped.fit.settings.head.rbf.kernel, defaults.fit.settings.head.rbf.kernel);
    EXPECT_DOUBLE_EQ(shipped.fit.settings.head.rbf.unitMm, defaults.fit.settings.head.rbf.unitMm);
    EXPECT_EQ(shipped.fit.settings.texture.size, defaults.fit.settings.texture.size);
    EXPECT_EQ(shipped.fit.previewSize, defaults.fit.previewSize);
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
    EXPECT_DOUBLE_EQ(shipped.animation.holdFraction, defaults.animation.holdFraction);
}

// Every key through the schema: the value read from `a` equals the one read from `b`.
void expectSameKeys(const BoothConfig& a, const BoothConfig& b) {
    for (const ConfigTable& table : configTables()) {
        if (table.kind == ConfigTableKind::StringMap) {
            BoothConfig ca = a, cb = b;
            EXPECT_EQ(table.map(ca), table.map(cb)) << table.name;
            continue;
        }
        const std::size_t n = table.kind == ConfigTableKind::Repeated ? table.count(a) : 1;
        if (table.kind == ConfigTableKind::Repeated) {
            ASSERT_EQ(n, table.count(b)) << table.name;
        }
        for (const ConfigKey& k : configKeys()) {
            if (k.table != table.name) continue;
            for (std::size_t i = 0; i < n; ++i) {
                EXPECT_EQ(k.get(a, i), k.get(b, i)) << k.table << "." << k.name << " [" << i << "]";
            }
        }
    }
}

}  // namespace

TEST(Config, PrintedDefaultParsesBackToTheStructDefaults) {
    const BoothConfig printed = parseBoothConfig(renderDefaultConfig(), "default.toml");
    const BoothConfig defaults;
    expectSameSettings(printed, defaults);
    expectSameKeys(printed, defaults);
    // An empty file is the same configuration.
    expectSameKeys(parseBoothConfig("", "empty.toml"), defaults);
}

TEST(Config, ShippedFileIsThePrintedDefault) {
    EXPECT_EQ(readText(kShipped), renderDefaultConfig())
        << "app/assets/booth.toml differs from `avatarbooth config --print-default`: " << kRegenerate;
    expectSameSettings(loadBoothConfig(kShipped), BoothConfig{});
}

TEST(Config, ReadmeReferenceIsGenerated) {
    const std::string readme = readText(kSource / "README.md");
    const std::string begin = "<!-- config-reference:begin -->\n", end = "<!-- config-reference:end -->";
    const auto b = readme.find(begin);
    const auto e = readme.find(end);
    ASSERT_NE(b, std::string::npos) << "README.md has no " << begin;
    ASSERT_NE(e, std::string::npos) << "README.md has no " << end;
    ASSERT_LT(b, e);
    EXPECT_EQ(readme.substr(b + begin.size(), e - b - begin.size()), renderConfigReference())
        << "the README's config reference differs from `avatarbooth config --reference`: " << kRegenerate;
}

TEST(Config, SchemaDefaultsAreAllowedValues) {
    const BoothConfig defaults;
    std::set<std::string> names;
    for (const ConfigKey& k : configKeys()) {
        const std::string key = k.table + "." + k.name;
        EXPECT_TRUE(names.insert(key).second) << key << " is in the schema twice";
        EXPECT_FALSE(k.doc.empty()) << key << " has no doc";
        EXPECT_TRUE(std::any_of(configTables().begin(), configTables().end(), [&](const ConfigTable& t) { return t.name == k.table; }))
            << key << ": no such table";
        const std::size_t n = k.table.starts_with("buttons.") ? 2 : 1;
        for (std::size_t i = 0; i < n; ++i) {
            const ConfigValue v = k.get(defaults, i);
            if (k.type == ConfigType::Choice) {
                EXPECT_NE(std::find(k.choices.begin(), k.choices.end(), std::get<std::string>(v)), k.choices.end()) << key;
            }
            if (k.type == ConfigType::Integer) {
                const auto x = static_cast<double>(std::get<long long>(v));
                EXPECT_TRUE(x >= k.min && x <= k.max) << key;
            }
            if (k.type == ConfigType::Number || k.type == ConfigType::Seconds) {
                EXPECT_TRUE(std::get<double>(v) >= k.min && std::get<double>(v) <= k.max) << key;
            }
            if (k.type == ConfigType::WordList) {
                const auto& list = std::get<std::vector<std::string>>(v);
                EXPECT_GE(list.size(), k.minCount) << key;
                for (const auto& w : list) EXPECT_NE(std::find(k.choices.begin(), k.choices.end(), w), k.choices.end()) << key;
            }
        }
    }
}

// Each key, set to a value other than its default in a file of its own, arrives in its setting: no key of the
// schema is left unread or written to the wrong field.
TEST(Config, EveryKeyLandsInItsSetting) {
    const BoothConfig defaults;
    for (const ConfigKey& k : configKeys()) {
        const std::string key = k.table + "." + k.name;
        const ConfigValue before = k.get(defaults, 0);
        std::vector<ConfigValue> candidates;
        switch (k.type) {
            case ConfigType::String:
            case ConfigType::Path: candidates = {std::string("/srv/other")}; break;
            case ConfigType::Bool: candidates = {!std::get<bool>(before)}; break;
            case ConfigType::Integer:
                candidates = {static_cast<long long>(k.min), static_cast<long long>(k.max)};
                break;
            case ConfigType::Number:
            case ConfigType::Seconds: candidates = {k.min, k.max, (k.min + k.max) / 2}; break;
            case ConfigType::Choice:
                for (const auto& c : k.choices) candidates.emplace_back(c);
                break;
            case ConfigType::ButtonCombo: candidates = {std::string("service"), std::string("retake+service")}; break;
            case ConfigType::WordList:
                candidates = {std::vector<std::string>{k.choices.back()},
                              std::vector<std::string>{k.choices.front(), k.choices.back()}};
                break;
        }
        // Text keys whose words are checked: values of their shape.
        if (key == "share.listen") candidates = {std::string("127.0.0.1:8080"), std::string("[::1]:443")};
        if (key == "share.base_url") candidates = {std::string("https://booth.example")};
        if (key == "print.queue") candidates = {std::string("Canon_SELPHY_CP1500")};
        // A repeated table's element needs its required keys; fit's base head needs both files.
        std::string head = "[" + k.table + "]\n";
        if (k.table == "buttons.button" || k.table == "buttons.lamp")
            head = "[[" + k.table + "]]\n" + (k.name == "name" ? "" : "name = \"start\"\n");
        if (key == "fit.base_mesh") head += "base_features = \"f.json\"\n";
        if (key == "fit.base_features") head += "base_mesh = \"m.glb\"\n";
        if (key == "stage.map") head += "enabled = false\n";  // an enabled stage reads its map at once
        if (key == "share.tls_certificate") head += "tls_key = \"k.pem\"\n";
        if (key == "share.tls_key") head += "tls_certificate = \"c.pem\"\n";
        bool landed = false;
        std::string errors;
        for (const ConfigValue& v : candidates) {
            if (v == before) continue;
            try {
                const BoothConfig c = parseBoothConfig(head + k.name + " = " + tomlValue(v) + "\n", "booth.toml");
                EXPECT_EQ(k.get(c, 0), v) << key << " = " << tomlValue(v);
                landed = true;
                break;
            } catch (const BoothError& e) {
                errors += std::string(e.what()) + "\n";  // a rule across keys refused this one: try the next
            }
        }
        EXPECT_TRUE(landed) << key << ": no value other than the default was accepted:\n" << errors;
    }
    // Key bindings: the table replaces the defaults.
    const BoothConfig keys = parseBoothConfig("[buttons.keys]\nF1 = \"service\"\n", "booth.toml");
    EXPECT_EQ(keys.buttons.keys, (std::map<std::string, std::string>{{"F1", "service"}}));
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

// The words a backend key allows are the device kind's table's names after "auto", nothing written twice.
TEST(Config, BackendWordsComeFromTheBackendTables) {
    const auto quotedList = [](const std::vector<std::string>& words) {
        std::string s;
        for (std::size_t i = 0; i < words.size(); ++i)
            s += (i ? (i + 1 == words.size() ? " or \"" : ", \"") : "\"") + words[i] + "\"";
        return s;
    };
    EXPECT_EQ(errorOf("[camera]\nbackend = \"webcam\"\n"),
              "booth.toml:2: camera.backend: \"webcam\" is not one of " + quotedList(backendWords(cameraBackends())));
    EXPECT_EQ(errorOf("[buttons]\nbackend = \"wiringpi\"\n"),
              "booth.toml:2: buttons.backend: \"wiringpi\" is not one of " + quotedList(backendWords(buttonBackends())));
    EXPECT_EQ(errorOf("[display]\nbackend = \"fbdev\"\n"),
              "booth.toml:2: display.backend: \"fbdev\" is not one of " + quotedList(backendWords(displayBackends())));
    EXPECT_EQ(errorOf("[display]\nbackend = \"fbdev\"\n"),
              "booth.toml:2: display.backend: \"fbdev\" is not one of \"auto\", \"kms\", \"window\" or \"headless\"");
    for (const ConfigKey& k : configKeys()) {
        if (k.name != "backend") continue;
        const std::vector<std::string> table = k.table == "camera"    ? backendWords(cameraBackends())
                                               : k.table == "buttons" ? backendWords(buttonBackends())
                                                                      : backendWords(displayBackends());
        EXPECT_EQ(k.choices, table) << k.table;
    }
}

// More broken files, one per kind of check the schema drives: the line named is the offending value's.
TEST(Config, BrokenFilesNameFileLineAndKey) {
    // Wrong types.
    EXPECT_EQ(errorOf("[camera]\nsim_real_time = \"yes\"\n"), "booth.toml:2: camera.sim_real_time: expected true or false");
    EXPECT_EQ(errorOf("[fit]\nlandmark_model = 5\n"), "booth.toml:2: fit.landmark_model: expected a string in quotes");
    EXPECT_EQ(errorOf("[flow]\ncountdown_s = \"3\"\n"), "booth.toml:2: flow.countdown_s: expected a number");
    EXPECT_EQ(errorOf("guidance = 3\n"), "booth.toml:1: guidance: expected a table ([guidance])");
    EXPECT_EQ(errorOf("[buttons]\nbutton = 17\n"), "booth.toml:2: buttons.button: expected tables ([[buttons.button]])");
    // Out of range, in nested and repeated tables too.
    EXPECT_EQ(errorOf("[guidance.oval]\n\nheight = 1.5\n"), "booth.toml:3: guidance.oval.height: must be between 0.2 and 1, got 1.5");
    EXPECT_EQ(errorOf("[[buttons.lamp]]\nname = \"flash\"\noffset = 2048\n"),
              "booth.toml:3: buttons.lamp[0].offset: must be between 0 and 1023, got 2048");
    EXPECT_EQ(errorOf("[flow]\ncountdown_s = 0.5\n"), "booth.toml:2: flow.countdown_s: must be between 1 and 10, got 0.5");
    EXPECT_EQ(errorOf("[display]\nrotation = 360\n"), "booth.toml:2: display.rotation: must be 0, 90, 180 or 270");
    // Bad choices.
    EXPECT_EQ(errorOf("[[buttons.button]]\nname = \"start\"\nbias = \"up\"\n"),
              "booth.toml:3: buttons.button[0].bias: \"up\" is not one of \"pull-up\", \"pull-down\", \"disabled\" or \"as-is\"");
    EXPECT_EQ(errorOf("[screen]\nlanguage = \"de\"\n"), "booth.toml:2: screen.language: \"de\" is not one of \"en\" or \"ja\"");
    EXPECT_EQ(errorOf("[buttons.keys]\nspace = \"start\"\nx = \"exit\"\n"),
              "booth.toml:3: buttons.keys.x: \"exit\" is not one of \"start\", \"retake\" or \"service\"");
    EXPECT_EQ(errorOf("[flow]\nlock_combo = \"\"\n"), "booth.toml:2: flow.lock_combo: name at least one button");
    // Unknown keys in nested and repeated tables; a missing required key names its element's line.
    EXPECT_EQ(errorOf("[guidance.oval]\nwidth = 0.5\n"),
              "booth.toml:2: guidance.oval.width: unknown key (see the reference booth.toml for the keys there are)");
    EXPECT_EQ(errorOf("[[buttons.lamp]]\nname = \"flash\"\n[[buttons.lamp]]\noffset = 5\n"),
              "booth.toml:3: buttons.lamp[1].name: every [[buttons.lamp]] needs a name");
    EXPECT_EQ(errorOf("[camera]\nreopen_first_delay_s = 10\nreopen_max_delay_s = 2\n"),
              "booth.toml:3: camera.reopen_max_delay_s: must not be shorter than reopen_first_delay_s");
    EXPECT_EQ(errorOf("[flow]\nthanks_min_time_s = 30\n"),
              "booth.toml:2: flow.thanks_min_time_s: must not be longer than thanks_time_s");
}

// Every mistake in the file at once, in the order of the lines (not the schema's), each reading as it does alone.
TEST(Config, EveryMistakeIsReportedAtOnce) {
    const std::string text = "[flow]\ncountdown_s = 0.5\n\n[camera]\nsim_real_time = \"yes\"\n\n[display]\nrotation = 360\n";
    try {
        parseBoothConfig(text, "booth.toml");
        FAIL() << "no error";
    } catch (const ConfigErrors& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), "booth.toml:2");
        ASSERT_EQ(e.mistakes().size(), 3u) << e.what();
        EXPECT_STREQ(e.mistakes()[0].what(), "booth.toml:2: flow.countdown_s: must be between 1 and 10, got 0.5");
        EXPECT_STREQ(e.mistakes()[1].what(), "booth.toml:5: camera.sim_real_time: expected true or false");
        EXPECT_STREQ(e.mistakes()[2].what(), "booth.toml:8: display.rotation: must be 0, 90, 180 or 270");
        EXPECT_EQ(std::string(e.what()), std::string(e.mistakes()[0].what()) + "\n" + e.mistakes()[1].what() + "\n" +
                                             e.mistakes()[2].what());
    }
    // Unknown keys are all named, not only the first.
    EXPECT_EQ(errorOf("[camera]\nbakend = \"sim\"\ndevise = \"/dev/video0\"\n"),
              "booth.toml:2: camera.bakend: unknown key (see the reference booth.toml for the keys there are)\n"
              "booth.toml:3: camera.devise: unknown key (see the reference booth.toml for the keys there are)");
    // A rule across a table's keys is not checked while one of them is wrong: it would blame a key that is right.
    EXPECT_EQ(errorOf("[camera]\nreopen_first_delay_s = \"10\"\nreopen_max_delay_s = 0.2\n"),
              "booth.toml:2: camera.reopen_first_delay_s: expected a number");
}

TEST(Config, DurationsRoundToTheMillisecond) {
    const BoothConfig c = parseBoothConfig("[flow]\npress_guard_s = 0.29\nlock_hold_s = 2.0006\n", "booth.toml");
    EXPECT_EQ(c.flow.pressGuard, Millis(290));
    EXPECT_EQ(c.flow.lockHold, Millis(2001));
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
