// The V4L2 backend against the kernel's vivid driver: format negotiation, streaming through our capture code
// (sizes, sequence numbers, timestamps, colour bars after our YUYV conversion), stills, and recovery when vivid's
// disconnect control pulls the device away while streaming.
#include "kernel_guest.h"
#include "vivid_node.h"

#include "drivers/camera/camera_factory.h"
#include "drivers/camera/frame_conversion.h"
#include "drivers/camera/v4l2_camera.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;
using kernel_test::vividNode;

class Vivid : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!kernel_test::inGuest()) return;
        // One instance with only a video capture node: the booth's case, a plain webcam.
        loaded_ = kernel_test::modprobe("vivid n_devs=1 node_types=0x1") == 0;
    }
    void SetUp() override {
        AVATARBOOTH_REQUIRE_KERNEL_GUEST();
        ASSERT_TRUE(loaded_) << "modprobe vivid failed";
        node_ = vividNode();
        ASSERT_FALSE(node_.empty()) << "vivid loaded but no vivid capture node found";
        settings_.backend = "v4l2";
        settings_.device = node_;
        settings_.previewWidth = 640;
        settings_.previewHeight = 360;
        settings_.previewFps = 30;
        settings_.stillWidth = 1280;
        settings_.stillHeight = 720;
        settings_.stillWarmupFrames = 1;
    }
    static inline bool loaded_ = false;
    std::string node_;
    CameraSettings settings_;
};

// A pixel of vivid's 75% colour bars, named by which of B, G, R are lit (75% of 235 ≈ 190 after conversion to
// full-range BGR; off channels near 0). "?" for anything in between.
std::string colourName(const cv::Vec3b& p) {
    std::string bits;
    for (int c = 0; c < 3; ++c) {
        if (p[c] > 150 && p[c] < 230) bits += '1';
        else if (p[c] < 40) bits += '0';
        else return "?";
    }
    static const std::pair<const char*, const char*> names[] = {
        {"111", "white"}, {"011", "yellow"}, {"110", "cyan"}, {"010", "green"},
        {"101", "magenta"}, {"001", "red"}, {"100", "blue"}, {"000", "black"}};
    for (const auto& [b, n] : names)
        if (bits == b) return n;
    return "?";
}

// The colours along a row, left to right, as runs at least 3% of the width wide (edges between bars are
// blended by the chroma subsampling).
std::vector<std::string> barsAlong(const cv::Mat& image, int row) {
    std::vector<std::string> runs;
    std::string current;
    int length = 0;
    const int minRun = image.cols * 3 / 100;
    auto flush = [&] {
        if (length >= minRun && current != "?" && (runs.empty() || runs.back() != current)) runs.push_back(current);
    };
    for (int x = 0; x < image.cols; ++x) {
        const std::string name = colourName(image.at<cv::Vec3b>(row, x));
        if (name == current) {
            ++length;
        } else {
            flush();
            current = name;
            length = 1;
        }
    }
    flush();
    return runs;
}

const std::vector<std::string> kColourBars = {"white", "yellow", "cyan", "green", "magenta", "red", "blue", "black"};

std::string join(const std::vector<std::string>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : " ") + x;
    return s;
}

TEST_F(Vivid, ProbeSeesACaptureDeviceOfferingYuyv) {
    const V4l2DeviceInfo info = probeV4l2Device(node_);
    EXPECT_TRUE(info.error.empty()) << info.error;
    EXPECT_TRUE(info.canCapture);
    EXPECT_FALSE(info.mediaControllerCentric);
    const bool yuyv = std::any_of(info.formats.begin(), info.formats.end(),
                                  [](const V4l2Format& f) { return f.fourcc == fourccCode('Y', 'U', 'Y', 'V'); });
    EXPECT_TRUE(yuyv) << "vivid offers no YUYV";
    // The camera list (what `avatarbooth check` prints) shows it usable.
    bool listed = false;
    for (const auto& c : listCameras())
        if (c.backend == "v4l2" && c.device == node_) listed = c.usable;
    EXPECT_TRUE(listed);
}

TEST_F(Vivid, StreamsYuyvFramesWithSequenceTimestampsAndColourBars) {
    V4l2Camera camera(settings_);
    const CameraDescription d = camera.describe();
    EXPECT_EQ(d.backend, "v4l2");
    EXPECT_EQ(d.preview.pixelFormat, "YUYV");
    EXPECT_EQ(d.preview.width, 640);
    EXPECT_EQ(d.preview.height, 360);

    std::uint64_t lastSequence = 0;
    std::chrono::nanoseconds lastTime{0}, firstTime{0};
    cv::Mat last;
    const int n = 10;
    for (int i = 0; i < n; ++i) {
        const auto frame = camera.nextFrame(10s);
        ASSERT_TRUE(frame.has_value()) << "no frame " << i << " within 10 s";
        const auto now = std::chrono::steady_clock::now().time_since_epoch();
        EXPECT_EQ(frame->image.cols, 640);
        EXPECT_EQ(frame->image.rows, 360);
        EXPECT_EQ(frame->image.type(), CV_8UC3);
        // Timestamps are CLOCK_MONOTONIC exposure times: in the recent past, strictly increasing. vivid stamps a
        // frame with the time its period is due, which under emulation can run a frame or so ahead of our clock
        // read after the dequeue (measured 12 ms on a fresh CI machine): allow two frame periods.
        EXPECT_LE(frame->timestamp, now + std::chrono::nanoseconds(std::chrono::milliseconds(67)));
        EXPECT_GT(frame->timestamp, now - std::chrono::nanoseconds(5s));
        if (i > 0) {
            EXPECT_GT(frame->sequence, lastSequence);
            EXPECT_GT(frame->timestamp, lastTime);
        } else {
            EXPECT_EQ(frame->sequence, 0u);
            firstTime = frame->timestamp;
        }
        lastSequence = frame->sequence;
        lastTime = frame->timestamp;
        last = frame->image;
    }
    // Sequence numbers count the frames the device delivered (a gap = frames we dropped: in the emulated guest
    // our conversion is slower than vivid's 30 fps, so there are gaps). They must agree with the timestamps: the
    // mean time per sequence step is the nominal frame interval, give or take emulation jitter.
    ASSERT_GT(lastSequence, 0u);
    const double perStepMs = std::chrono::duration<double, std::milli>(lastTime - firstTime).count() /
                             static_cast<double>(lastSequence);
    const double nominalMs = 1000.0 / d.preview.fps;
    EXPECT_GT(perStepMs, 0.5 * nominalMs) << lastSequence << " steps";
    EXPECT_LT(perStepMs, 2.0 * nominalMs) << lastSequence << " steps";
    EXPECT_EQ(join(barsAlong(last, last.rows * 3 / 4)), join(kColourBars)) << "row " << last.rows * 3 / 4;
}

TEST_F(Vivid, StillAtAnotherSizeSwitchesFormatAndComesBack) {
    V4l2Camera camera(settings_);
    ASSERT_TRUE(camera.nextFrame(10s).has_value());
    const CameraFrame still = camera.captureStill();
    EXPECT_EQ(still.image.cols, 1280);
    EXPECT_EQ(still.image.rows, 720);
    EXPECT_EQ(still.sequence, 0u);
    EXPECT_EQ(join(barsAlong(still.image, still.image.rows * 3 / 4)), join(kColourBars));
    const auto after = camera.nextFrame(10s);
    ASSERT_TRUE(after.has_value());
    EXPECT_EQ(after->image.cols, 640);
    EXPECT_GT(after->sequence, 0u);
    EXPECT_EQ(camera.describe().still.width, 1280);
}

TEST_F(Vivid, MjpegWhereOffered) {
    const V4l2DeviceInfo info = probeV4l2Device(node_);
    const bool mjpeg = std::any_of(info.formats.begin(), info.formats.end(),
                                   [](const V4l2Format& f) { return f.fourcc == fourccCode('M', 'J', 'P', 'G'); });
    if (!mjpeg) GTEST_SKIP() << "vivid (this kernel) offers no MJPEG; MJPEG decoding is covered by unit tests only";
    settings_.stillWidth = 640;
    settings_.stillHeight = 360;
    V4l2Camera camera(settings_);
    const auto frame = camera.nextFrame(10s);
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->image.cols, 640);
}

TEST_F(Vivid, DisconnectWhileStreamingIsRecoveredByReopening) {
    settings_.reopenFirstDelaySeconds = 0.2;
    settings_.reopenMaxDelaySeconds = 1;
    auto camera = openReopeningCamera(settings_);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(camera->nextFrame(10s).has_value());
    EXPECT_TRUE(camera->status().ok);

    // vivid's "Disconnect" control unregisters the node as an unplug would; the driver brings it back once the
    // last file handle is closed, which our ReopeningCamera does when it sees the error.
    ASSERT_EQ(kernel_test::run("v4l2-ctl -d " + node_ + " -c disconnect=1"), 0);
    bool lost = false;
    for (int i = 0; i < 50 && !lost; ++i) {
        camera->nextFrame(100ms);
        const CameraStatus s = camera->status();
        lost = !s.ok || s.recoveries > 0;
    }
    ASSERT_TRUE(lost) << "the camera never noticed the disconnect";
    const std::string error = camera->status().lastError;
    EXPECT_NE(error.find("disconnected"), std::string::npos) << error;

    std::optional<CameraFrame> frame;
    for (int i = 0; i < 60 && !frame; ++i) frame = camera->nextFrame(500ms);
    ASSERT_TRUE(frame.has_value()) << "no frame after the disconnect: " << camera->status().message;
    const CameraStatus s = camera->status();
    EXPECT_TRUE(s.ok) << s.message;
    EXPECT_EQ(s.recoveries, 1);
    EXPECT_GE(frame->sequence, 3u) << "sequence numbers continue after the last frame before the disconnect";
    EXPECT_EQ(frame->image.cols, 640);
    EXPECT_EQ(join(barsAlong(frame->image, frame->image.rows * 3 / 4)), join(kColourBars));
}

// Unplugging by unloading the module: the kernel refuses to unload vivid while any file handle on its node is open
// (opening a V4L2 node takes a reference on the driver's module), streaming or not -- `rmmod` says "in use". Once
// vivid's disconnect control has made us close the node (our ReopeningCamera closes it on the error and waits
// before reopening), rmmod succeeds: the node is gone, the camera keeps trying, and when the module is loaded again
// the camera comes back by itself. (Runs last: it reloads vivid with the suite's arguments.)
TEST_F(Vivid, UnloadedWhileLostAndLoadedAgainIsRecovered) {
    settings_.reopenFirstDelaySeconds = 2;  // the window in which nothing holds the node and rmmod may run
    settings_.reopenMaxDelaySeconds = 2;
    auto camera = openReopeningCamera(settings_);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(camera->nextFrame(10s).has_value());
    EXPECT_NE(kernel_test::run("rmmod vivid 2>/dev/null"), 0) << "vivid unloaded while we stream from it";
    EXPECT_GT(std::stoi(kernel_test::readFile("/sys/module/vivid/refcnt")), 0);

    ASSERT_EQ(kernel_test::run("v4l2-ctl -d " + node_ + " -c disconnect=1"), 0);
    bool lost = false;
    for (int i = 0; i < 50 && !lost; ++i) {
        camera->nextFrame(100ms);
        lost = !camera->status().ok;
    }
    ASSERT_TRUE(lost) << "the camera never noticed the disconnect";
    bool unloaded = false;
    for (int i = 0; i < 40 && !unloaded; ++i) {
        unloaded = kernel_test::run("rmmod vivid 2>/dev/null") == 0;
        if (!unloaded) std::this_thread::sleep_for(50ms);
    }
    ASSERT_TRUE(unloaded) << "rmmod vivid still refused after our camera closed the node";
    EXPECT_TRUE(vividNode().empty());
    for (int i = 0; i < 10; ++i) EXPECT_FALSE(camera->nextFrame(200ms).has_value()) << "a frame without vivid";
    EXPECT_FALSE(camera->status().ok);

    ASSERT_EQ(kernel_test::modprobe("vivid n_devs=1 node_types=0x1"), 0);
    std::optional<CameraFrame> frame;
    for (int i = 0; i < 60 && !frame; ++i) frame = camera->nextFrame(500ms);
    ASSERT_TRUE(frame.has_value()) << "no frame after vivid came back: " << camera->status().message;
    EXPECT_TRUE(camera->status().ok) << camera->status().message;
    EXPECT_GE(camera->status().recoveries, 1);
    EXPECT_EQ(frame->image.cols, 640);
    EXPECT_EQ(join(barsAlong(frame->image, frame->image.rows * 3 / 4)), join(kColourBars));
}

}  // namespace
}  // namespace avatarbooth
