// Displays as the booth opens them: headless screenshots on disk identical to what was presented, every N-th
// frame written, kms and window failing clearly on a machine without /dev/dri and without $DISPLAY, and "auto".
#include "drivers/display/display_factory.h"
#include "drivers/display/headless_display.h"
#include "drivers/display/kms_display.h"
#include "drivers/display/window_display.h"

#include "common/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <sys/stat.h>

#include <cstdlib>
#include <filesystem>
#include <optional>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

cv::Mat pattern(cv::Size s) {
    cv::Mat m(s, CV_8UC3);
    cv::randu(m, cv::Scalar::all(0), cv::Scalar::all(256));
    return m;
}

// Sets an environment variable for one scope and puts the old value back.
class EnvOverride {
public:
    EnvOverride(const char* name, const char* value) : name_(name) {
        if (const char* old = std::getenv(name)) old_ = old;
        if (value != nullptr) ::setenv(name, value, 1);
        else ::unsetenv(name);
    }
    ~EnvOverride() {
        if (old_) ::setenv(name_, old_->c_str(), 1);
        else ::unsetenv(name_);
    }

private:
    const char* name_;
    std::optional<std::string> old_;
};

bool machineHasDrm() { return fs::exists("/dev/dri"); }

TEST(DisplayScreens, HeadlessScreenshotIsExactlyWhatWasPresented) {
    const fs::path dir = test::scratchDir("display_screenshot");
    DisplaySettings settings;
    settings.width = 320;
    settings.height = 240;
    HeadlessDisplay display(settings);
    const cv::Mat frame = pattern({320, 240});
    display.present(pattern({320, 240}));
    display.present(frame);
    const fs::path shot = dir / "screen.png";
    display.writeScreenshot(shot);
    const cv::Mat read = cv::imread(shot.string(), cv::IMREAD_COLOR);
    ASSERT_EQ(read.size(), frame.size());
    EXPECT_EQ(cv::norm(read, frame, cv::NORM_INF), 0.0);
    struct stat st{};
    ASSERT_EQ(::stat(shot.c_str(), &st), 0);
    EXPECT_EQ(st.st_mode & 0777, 0600u);
    // Nothing but the screenshot: the temporary name is gone.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(DisplayScreens, HeadlessWritesEveryNthFrame) {
    const fs::path dir = test::scratchDir("display_every_nth");
    DisplaySettings settings;
    settings.width = 64;
    settings.height = 48;
    settings.everyNthFrame = 3;
    settings.framesDir = (dir / "frames").string();
    HeadlessDisplay display(settings);
    std::vector<cv::Mat> frames;
    for (int i = 0; i < 7; ++i) {
        frames.push_back(pattern({64, 48}));
        display.present(frames.back());
    }
    EXPECT_EQ(display.frameCount(), 7u);
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir / "frames")) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"frame_000003.png", "frame_000006.png"}));
    EXPECT_EQ(cv::norm(cv::imread((dir / "frames" / "frame_000006.png").string()), frames[5], cv::NORM_INF), 0.0);
}

TEST(DisplayScreens, ScreenshotBeforeAnyFrameOrIntoAMissingFolderFails) {
    const fs::path dir = test::scratchDir("display_screenshot_fail");
    HeadlessDisplay display(DisplaySettings{});
    EXPECT_THROW(display.writeScreenshot(dir / "x.png"), BoothError);
    display.present(pattern(display.size()));
    try {
        display.writeScreenshot(dir / "missing" / "x.png");
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Output);
        EXPECT_NE(std::string(e.what()).find("missing/x.png"), std::string::npos) << e.what();
    }
}

TEST(DisplayScreens, KmsFailsClearlyWithoutADrmDevice) {
    if (machineHasDrm()) GTEST_SKIP() << "this machine has /dev/dri; the no-device path cannot be checked here";
    try {
        KmsDisplay display{DisplaySettings{}};
        FAIL() << "opened a KMS display without /dev/dri";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_EQ(e.where(), "/dev/dri");
        EXPECT_NE(std::string(e.what()).find("no DRM device"), std::string::npos) << e.what();
    }
    std::string why;
    EXPECT_FALSE(kmsScreenAvailable("", "", &why));
    EXPECT_NE(why.find("no DRM device"), std::string::npos) << why;
}

TEST(DisplayScreens, KmsOnANamedMissingDeviceNamesIt) {
    DisplaySettings settings;
    settings.drmDevice = "/dev/dri/card77";
    try {
        KmsDisplay display{settings};
        FAIL() << "opened a missing device";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_EQ(std::string(e.what()).rfind("/dev/dri/card77: no DRM device /dev/dri/card77", 0), 0u) << e.what();
    }
}

TEST(DisplayScreens, WindowFailsClearlyWithoutDisplayVariable) {
    EnvOverride noX("DISPLAY", nullptr);
    try {
        WindowDisplay display{DisplaySettings{}};
        FAIL() << "opened a window without $DISPLAY";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_STREQ(e.what(),
                     "$DISPLAY: is not set: there is no X server to open the window on (use the kms or headless "
                     "display)");
    }
}

TEST(DisplayScreens, WindowOnAnUnreachableServerNamesIt) {
    EnvOverride deadX("DISPLAY", ":97");
    try {
        WindowDisplay display{DisplaySettings{}};
        FAIL() << "opened a window on :97";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_EQ(e.where(), "$DISPLAY=:97");
    }
}

TEST(DisplayScreens, AutoFallsBackToHeadlessAndSaysWhy) {
    if (machineHasDrm()) GTEST_SKIP() << "this machine has /dev/dri";
    EnvOverride noX("DISPLAY", nullptr);
    DisplaySettings settings;
    settings.rotation = 90;
    const OpenedDisplay opened = createDisplay(settings);
    ASSERT_NE(dynamic_cast<HeadlessDisplay*>(opened.display.get()), nullptr);
    EXPECT_EQ(opened.display->size(), cv::Size(720, 1280));
    EXPECT_EQ(opened.description,
              "display: headless 1280x720 rotated 90 (auto: kms: no DRM device (no /dev/dri/card*: no GPU or display "
              "controller, or its driver is not loaded); window: $DISPLAY is not set)");
}

TEST(DisplayScreens, AutoWithAnUnreachableXServerStillEndsHeadless) {
    if (machineHasDrm()) GTEST_SKIP() << "this machine has /dev/dri";
    EnvOverride deadX("DISPLAY", ":97");
    const OpenedDisplay opened = createDisplay(DisplaySettings{});
    ASSERT_NE(dynamic_cast<HeadlessDisplay*>(opened.display.get()), nullptr);
    EXPECT_NE(opened.description.find("window: $DISPLAY=:97: cannot open the X display"), std::string::npos)
        << opened.description;
}

TEST(DisplayScreens, NamedBackendsAndBadNames) {
    DisplaySettings settings;
    settings.backend = "headless";
    EXPECT_EQ(createDisplay(settings).description, "display: headless 1280x720");
    settings.backend = "framebuffer";
    try {
        createDisplay(settings);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_STREQ(e.what(), "display.backend: \"framebuffer\" is not a display (auto, kms, window or headless)");
    }
    settings.backend = "kms";
    if (!machineHasDrm()) {
        try {
            createDisplay(settings);
            FAIL() << "no error";
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Device);
        }
    }
    settings.backend = "headless";
    settings.rotation = 100;
    EXPECT_THROW(createDisplay(settings), BoothError);
}

}  // namespace
}  // namespace avatarbooth
