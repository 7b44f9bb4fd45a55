// The KMS screen against the kernel's vkms driver: KmsDisplay's whole GBM/EGL/KMS sequence (Mesa's kms_swrast,
// llvmpipe, on a KMS-only device), the mode the kernel command line chose, page flips paced by the refresh, the
// pixels that were scanned out read back through vkms's writeback connector (and the scanned-out framebuffer),
// a screen unplugged (the connector's forced status) or its driver taken away, and the kiosk's screen (behind
// ReopeningDisplay) switched off and on while frames keep coming, or off when the booth starts.
#include "kernel_guest.h"
#include "kms_scanout.h"

#include "common/error.h"
#include "drivers/display/display_factory.h"
#include "drivers/display/kms_display.h"
#include "drivers/display/reopening_display.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

// The mode tests/kernel/run.sh asks for on the guest's command line (video=Virtual-1:640x360@60): the booth's
// small test screen, and a mode vkms does not list itself (the kernel adds it from the command line).
const cv::Size kPanel(640, 360);

class Vkms : public ::testing::Test {
protected:
    void SetUp() override {
        AVATARBOOTH_REQUIRE_KERNEL_GUEST();
        card_ = kernel_test::vkmsCard();
        if (card_.empty()) {
            ASSERT_EQ(kernel_test::modprobe("vkms enable_writeback=1"), 0) << "modprobe vkms failed";
            card_ = kernel_test::vkmsCard();
        }
        ASSERT_FALSE(card_.empty()) << "vkms loaded but no /dev/dri/card* is vkms";
        const std::string name = fs::path(card_).filename().string();
        status_ = "/sys/class/drm/" + name + "-Virtual-1/status";
        ASSERT_TRUE(kernel_test::writeFile(status_, "detect"));
        settings_.backend = "kms";
        settings_.drmDevice = card_;
    }

    std::string card_, status_;
    DisplaySettings settings_;
};

// A test card: coloured blocks, a gradient row and one-pixel marks at the corners, so that a shift, a swap of
// channels, a flip or scaling shows.
cv::Mat testCard(cv::Size size, int variant) {
    cv::Mat m(size, CV_8UC3, cv::Scalar(40, 40, 40));
    const cv::Scalar colours[] = {{0, 0, 255}, {0, 255, 0}, {255, 0, 0}, {255, 255, 255}};
    const int w = size.width / 4, h = size.height / 4;
    for (int i = 0; i < 4; ++i)
        cv::rectangle(m, cv::Rect(w / 4 + (i % 2) * 2 * w, h / 4 + (i / 2) * 2 * h, w, h), colours[(i + variant) % 4],
                      cv::FILLED);
    for (int x = 0; x < size.width; ++x) {
        const auto v = static_cast<unsigned char>(x % 256);
        m.at<cv::Vec3b>(size.height / 2, x) = cv::Vec3b(v, static_cast<unsigned char>(255 - v), 128);
    }
    m.at<cv::Vec3b>(0, 0) = {0, 0, 255};
    m.at<cv::Vec3b>(0, size.width - 1) = {0, 255, 0};
    m.at<cv::Vec3b>(size.height - 1, 0) = {255, 0, 0};
    m.at<cv::Vec3b>(size.height - 1, size.width - 1) = {255, 255, 0};
    return m;
}

double maxDifference(const cv::Mat& a, const cv::Mat& b) {
    if (a.size() != b.size()) return 255.0;
    cv::Mat diff;
    cv::absdiff(a, b, diff);
    double most = 0.0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &most);
    return most;
}

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

TEST_F(Vkms, KmsDisplayScansOutItsFramesExactlyAndTheWritebackReadsThemBack) {
    const auto opening = std::chrono::steady_clock::now();
    KmsDisplay display(settings_);
    const double openSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - opening).count();
    std::printf("[vkms] %s, opened in %.2f s\n", display.describe().c_str(), openSeconds);
    EXPECT_EQ(display.size(), kPanel) << "not the mode of the kernel's video= (USERDEF): " << display.describe();
    EXPECT_NE(display.describe().find(card_ + " Virtual-1"), std::string::npos) << display.describe();
    EXPECT_NE(display.describe().find("llvmpipe"), std::string::npos) << display.describe();

    // Each frame, then what vkms composed for the panel at the next refresh (writeback), then the framebuffer the
    // CRTC scans out (GETFB2): the quad presenter draws a frame of the panel's size pixel for pixel.
    for (int variant = 0; variant < 2; ++variant) {
        const cv::Mat frame = testCard(display.size(), variant);
        display.present(frame);
        const cv::Mat written = display.readBack();
        ASSERT_EQ(written.size(), kPanel);
        EXPECT_EQ(maxDifference(written, frame), 0.0) << "variant " << variant;
        EXPECT_EQ(written.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 255));
        EXPECT_EQ(written.at<cv::Vec3b>(kPanel.height - 1, kPanel.width - 1), cv::Vec3b(255, 255, 0));
        std::string why;
        const cv::Mat scanned = kernel_test::readScanout(card_, why);
        ASSERT_FALSE(scanned.empty()) << why;
        EXPECT_EQ(maxDifference(scanned, frame), 0.0) << "variant " << variant;
    }
}

TEST_F(Vkms, PageFlipsLandOnTheRefreshAndPaceTheFrames) {
    KmsDisplay display(settings_);
    const double hz = display.refreshHz();
    EXPECT_NEAR(hz, 60.0, 1.0);
    const double period = 1.0 / hz;
    const cv::Mat a = testCard(display.size(), 0), b = testCard(display.size(), 1);
    display.present(a);  // the mode set
    std::vector<KmsDisplay::Flip> flips;
    std::vector<std::chrono::steady_clock::time_point> returned;
    constexpr int kFrames = 40;
    for (int i = 0; i < kFrames; ++i) {
        display.present(i % 2 ? a : b);
        returned.push_back(std::chrono::steady_clock::now());
        flips.push_back(display.lastFlip());
    }
    // The kernel's own record: each flip on a later refresh than the one before, and its time that many refresh
    // periods later (vkms times its vblanks with an hrtimer of the mode's frame duration).
    std::vector<double> perRefresh, refreshesPerFrame, presentInterval;
    for (int i = 1; i < kFrames; ++i) {
        const auto refreshes = static_cast<std::int64_t>(flips[i].sequence) - flips[i - 1].sequence;
        ASSERT_GE(refreshes, 1) << "two flips on one refresh at frame " << i;
        const double dt = std::chrono::duration<double>(flips[i].time - flips[i - 1].time).count();
        perRefresh.push_back(dt / static_cast<double>(refreshes));
        refreshesPerFrame.push_back(static_cast<double>(refreshes));
        presentInterval.push_back(std::chrono::duration<double>(returned[i] - returned[i - 1]).count());
        EXPECT_NEAR(dt / static_cast<double>(refreshes), period, 0.05 * period) << "frame " << i;
    }
    // The flip event's time is the refresh's, on the clock the booth measures with, and recent.
    const double age = std::chrono::duration<double>(returned.back() - flips.back().time).count();
    EXPECT_GE(age, -0.001);
    EXPECT_LT(age, 0.5);
    // present() waits for its flip: never more frames than refreshes.
    const double seconds = std::chrono::duration<double>(returned.back() - returned.front()).count();
    const double rate = (kFrames - 1) / seconds;
    EXPECT_LE(rate, hz * 1.02);
    std::printf("[vkms] %d flips: refresh %.3f Hz (period %.2f ms); between flips median %.3f ms per refresh, %.0f "
                "refreshes per frame (median); present() every %.1f ms (median), %.1f frames/s\n",
                kFrames, hz, period * 1e3, median(perRefresh) * 1e3, median(refreshesPerFrame),
                median(presentInterval) * 1e3, rate);
}

TEST_F(Vkms, ARotatedPanelGetsTheFrameTurnedClockwise) {
    settings_.rotation = 90;
    KmsDisplay display(settings_);
    ASSERT_EQ(display.size(), cv::Size(kPanel.height, kPanel.width));
    const cv::Mat frame = testCard(display.size(), 0);
    display.present(frame);
    cv::Mat turned;
    cv::rotate(frame, turned, cv::ROTATE_90_CLOCKWISE);  // pixel (x, y) of a W x H frame at (H-1-y, x)
    const cv::Mat written = display.readBack();
    EXPECT_EQ(maxDifference(written, turned), 0.0);
    EXPECT_EQ(written.at<cv::Vec3b>(0, kPanel.width - 1), cv::Vec3b(0, 0, 255));  // the frame's top-left corner
}

// What `backend = "auto"` does on a board with a screen: kms, on the screen the kernel has.
TEST_F(Vkms, AutoChoosesTheKmsScreen) {
    DisplaySettings settings;
    settings.backend = "auto";
    const OpenedDisplay opened = createDisplay(settings);
    ASSERT_TRUE(opened.display);
    EXPECT_EQ(opened.description.rfind("display: kms " + card_ + " Virtual-1 640x360", 0), 0u) << opened.description;
    const cv::Mat frame = testCard(opened.display->size(), 0);
    opened.display->present(frame);
    ASSERT_NE(opened.reopening, nullptr) << "the KMS screen is opened behind its reopening wrapper";
    auto* kms = dynamic_cast<KmsDisplay*>(opened.reopening->current());
    ASSERT_NE(kms, nullptr);
    EXPECT_EQ(maxDifference(kms->readBack(), frame), 0.0);
}

// An unplugged screen: the connector's status forced to "off" through sysfs, what the kernel reports when a
// cable is pulled (vkms on 6.1 has no hot-plug of its own: see tests/kernel/README.md). The CRTC keeps running
// and flips keep completing, so only the connector's status tells.
TEST_F(Vkms, AnUnpluggedScreenIsADeviceErrorAndAReplugGivesItBack) {
    {
        KmsDisplay display(settings_);
        const cv::Mat frame = testCard(display.size(), 0);
        display.present(frame);
        display.present(frame);
        ASSERT_TRUE(kernel_test::writeFile(status_, "off"));
        try {
            display.present(frame);
            ADD_FAILURE() << "present() went on after the screen was unplugged";
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
            EXPECT_NE(std::string(e.what()).find("disconnected"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("Virtual-1"), std::string::npos) << e.what();
            std::printf("[vkms] unplugged: %s\n", e.what());
        }
    }
    std::string why;
    EXPECT_FALSE(kmsScreenAvailable(card_, "", &why));
    EXPECT_NE(why.find("no screen connected"), std::string::npos) << why;
    EXPECT_THROW(KmsDisplay{settings_}, BoothError);

    ASSERT_TRUE(kernel_test::writeFile(status_, "detect"));
    EXPECT_TRUE(kmsScreenAvailable(card_, "", &why)) << why;
    KmsDisplay display(settings_);
    const cv::Mat frame = testCard(display.size(), 1);
    display.present(frame);
    EXPECT_EQ(maxDifference(display.readBack(), frame), 0.0);
}

// Presents `frame` as the kiosk does (a frame every 33 ms at most: present() does not pace a lost screen) until
// `done` or `limit`; returns the frames presented.
template <typename Done>
int presentUntil(Display& display, const cv::Mat& frame, Done done, std::chrono::milliseconds limit) {
    int frames = 0;
    for (const auto end = std::chrono::steady_clock::now() + limit; !done() && std::chrono::steady_clock::now() < end; ++frames) {
        const auto next = std::chrono::steady_clock::now() + std::chrono::milliseconds(33);
        display.present(frame);
        std::this_thread::sleep_until(next);
    }
    return frames;
}

// The booth's screen switched off and on while it runs: the display opened as the kiosk opens it (createDisplay,
// behind ReopeningDisplay) survives the connector going "off" -- present() goes on without throwing, the DRM node
// is closed (so vkms could even be unloaded), the status says so -- and after "detect" it is reopened by itself
// within the 2 s retry interval, in the same mode, and the kernel shows the frames pixel for pixel again.
TEST_F(Vkms, TheKioskScreenSwitchedOffAndOnComesBackByItself) {
    const OpenedDisplay opened = createDisplay(settings_);
    ASSERT_NE(opened.reopening, nullptr);
    ReopeningDisplay& display = *opened.reopening;
    const cv::Mat before = testCard(display.size(), 0);
    display.present(before);
    display.present(before);
    ASSERT_TRUE(display.status().ok);

    ASSERT_TRUE(kernel_test::writeFile(status_, "off"));
    const auto off = std::chrono::steady_clock::now();
    const int whileOff = presentUntil(display, before, [] { return false; }, std::chrono::milliseconds(3000));
    DisplayStatus s = display.status();
    EXPECT_FALSE(s.ok);
    EXPECT_NE(s.message.find("Virtual-1"), std::string::npos) << s.message;
    EXPECT_NE(s.message.find("lost, retrying every 2 s"), std::string::npos) << s.message;
    EXPECT_GE(s.failedReopens, 1) << "no reopen tried in 3 s";
    EXPECT_LE(s.failedReopens, 2) << "reopens tried more often than every 2 s";
    EXPECT_GE(s.framesDropped, static_cast<std::uint64_t>(whileOff) - 1);
    EXPECT_EQ(display.current(), nullptr);
    EXPECT_EQ(display.size(), kPanel);
    std::printf("[vkms] screen off: %d frames presented in %.1f s without it, %d reopens failed: %s\n", whileOff,
                std::chrono::duration<double>(std::chrono::steady_clock::now() - off).count(), s.failedReopens, s.lastError.c_str());

    ASSERT_TRUE(kernel_test::writeFile(status_, "detect"));
    const auto on = std::chrono::steady_clock::now();
    const cv::Mat after = testCard(display.size(), 1);
    presentUntil(display, after, [&] { return display.status().ok; }, std::chrono::milliseconds(6000));
    const double backSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - on).count();
    s = display.status();
    ASSERT_TRUE(s.ok) << s.lastError;
    EXPECT_EQ(s.recoveries, 1);
    // The retry interval, and an open under emulation (0.2-3.6 s measured, the first in a process loading Mesa).
    EXPECT_LT(backSeconds, 2.0 + 3.0) << "not back within the retry interval";
    EXPECT_EQ(display.size(), kPanel) << "not the same mode after the screen came back";
    display.present(after);
    auto* kms = dynamic_cast<KmsDisplay*>(display.current());
    ASSERT_NE(kms, nullptr);
    EXPECT_EQ(maxDifference(kms->readBack(), after), 0.0);
    std::string why;
    const cv::Mat scanned = kernel_test::readScanout(card_, why);
    ASSERT_FALSE(scanned.empty()) << why;
    EXPECT_EQ(maxDifference(scanned, after), 0.0);
    std::printf("[vkms] screen back %.2f s after detect: %s\n", backSeconds, display.describe().c_str());
}

// `backend = "auto"` on a board whose monitor is off at start-up (the connector reports no screen, no X display):
// not headless for good, but the KMS screen waited for, at the configured size until it comes with its own mode.
TEST_F(Vkms, AutoWithTheScreenOffAtStartWaitsForItInsteadOfRunningHeadless) {
    ASSERT_TRUE(kernel_test::writeFile(status_, "off"));
    DisplaySettings settings;
    settings.backend = "auto";
    settings.drmDevice = card_;  // vkms's, whatever other card (virtio-gpu) the guest has at the time
    std::string what;
    EXPECT_TRUE(displayWaitsForScreen(settings, &what));
    EXPECT_NE(what.find(card_ + " Virtual-1 not connected"), std::string::npos) << what;
    EXPECT_EQ(what.find("Writeback"), std::string::npos) << "a writeback connector is no place for a screen: " << what;
    const OpenedDisplay opened = createDisplay(settings);
    ASSERT_NE(opened.reopening, nullptr) << opened.description;
    EXPECT_EQ(opened.description, "display: kms " + card_ + " waiting for a screen (auto: kms: " + card_ +
                                      ": no screen connected (Virtual-1 not connected); window: $DISPLAY is not set)")
        << opened.description;
    ReopeningDisplay& display = *opened.reopening;
    EXPECT_FALSE(display.status().ok);
    EXPECT_NE(display.status().message.find("not connected yet"), std::string::npos) << display.status().message;
    EXPECT_EQ(display.size(), cv::Size(1280, 720)) << "the configured size while waiting";
    presentUntil(display, testCard(display.size(), 0), [] { return false; }, std::chrono::milliseconds(500));

    ASSERT_TRUE(kernel_test::writeFile(status_, "detect"));
    presentUntil(display, testCard(display.size(), 0), [&] { return display.status().ok; },
                 std::chrono::milliseconds(6000));
    ASSERT_TRUE(display.status().ok) << display.status().lastError;
    EXPECT_EQ(display.status().recoveries, 0) << "a first connection is not a recovery";
    ASSERT_EQ(display.size(), kPanel) << "the screen's own mode once it is there";
    const cv::Mat frame = testCard(display.size(), 1);
    display.present(frame);
    auto* kms = dynamic_cast<KmsDisplay*>(display.current());
    ASSERT_NE(kms, nullptr);
    EXPECT_EQ(maxDifference(kms->readBack(), frame), 0.0);
}

// The device itself going away: an open DRM node pins its driver (the file's owner is vkms), so the module cannot
// be removed under a running screen; once the screen is closed it can, and the display then finds no device.
TEST_F(Vkms, TheDriverStaysWhileTheScreenIsOpenAndItsRemovalIsANoDeviceError) {
    {
        KmsDisplay display(settings_);
        display.present(testCard(display.size(), 0));
        EXPECT_NE(kernel_test::run("rmmod vkms 2>/dev/null"), 0) << "vkms unloaded under an open screen";
        EXPECT_TRUE(fs::exists(card_));
    }
    ASSERT_EQ(kernel_test::run("rmmod vkms"), 0);
    EXPECT_FALSE(fs::exists(card_));
    try {
        KmsDisplay display(DisplaySettings{});
        ADD_FAILURE() << "a display opened without a DRM device: " << display.describe();
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_NE(std::string(e.what()).find("no DRM device"), std::string::npos) << e.what();
    }
    ASSERT_EQ(kernel_test::modprobe("vkms enable_writeback=1"), 0);
    card_ = kernel_test::vkmsCard();
    ASSERT_FALSE(card_.empty());
    settings_.drmDevice = card_;
    KmsDisplay display(settings_);
    const cv::Mat frame = testCard(display.size(), 1);
    display.present(frame);
    EXPECT_EQ(maxDifference(display.readBack(), frame), 0.0);
}

}  // namespace
}  // namespace avatarbooth
