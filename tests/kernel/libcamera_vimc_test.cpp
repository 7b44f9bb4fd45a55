// The libcamera backend against the kernel's vimc (virtual media-controller camera, built out of tree by
// tests/kernel/setup.sh): our class lists the camera, configures the viewfinder, captures frames and stills, and
// stops and restarts cleanly. libcamera only sees devices udev has initialised, so the suite runs systemd-udevd.
#include "kernel_guest.h"

#include "drivers/camera/camera_factory.h"
#include "drivers/camera/libcamera_camera.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <string>

namespace avatarbooth {
namespace {

using namespace std::chrono_literals;

class Vimc : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        if (!kernel_test::inGuest()) return;
        if (kernel_test::modprobe("vimc") != 0) return;
        udevd_ = kernel_test::run("/lib/systemd/systemd-udevd --daemon") == 0;
        ready_ = udevd_ && kernel_test::run("udevadm trigger --action=add && udevadm settle -t 60") == 0;
    }
    static void TearDownTestSuite() {
        if (udevd_) kernel_test::run("udevadm control --exit");
    }
    void SetUp() override {
        AVATARBOOTH_REQUIRE_KERNEL_GUEST();
        ASSERT_TRUE(ready_) << "vimc or udevd did not come up";
        settings_.backend = "libcamera";
        settings_.previewWidth = 320;
        settings_.previewHeight = 240;
        settings_.previewFps = 30;
        settings_.stillWidth = 640;
        settings_.stillHeight = 480;
        settings_.stillWarmupFrames = 0;
    }
    static inline bool udevd_ = false, ready_ = false;
    CameraSettings settings_;
};

TEST_F(Vimc, ListsTheVimcCamera) {
    const auto cameras = listLibcameraCameras();
    ASSERT_FALSE(cameras.empty()) << "libcamera " << libcameraVersion() << " sees no camera";
    bool found = false;
    for (const auto& c : cameras) found = found || c.id.find("vimc") != std::string::npos;
    EXPECT_TRUE(found) << cameras.front().id;
    // `avatarbooth check`'s list has it as a usable libcamera camera; "auto" leaves vimc's media-controller
    // video nodes to libcamera.
    bool listed = false;
    for (const auto& c : listCameras()) listed = listed || (c.backend == "libcamera" && c.usable);
    EXPECT_TRUE(listed);
}

TEST_F(Vimc, CapturesViewfinderFramesAndAStillThenStopsAndRestarts) {
    LibcameraCamera camera(settings_);
    const CameraDescription d = camera.describe();
    EXPECT_EQ(d.backend, "libcamera");
    // vimc aligns sizes (320 becomes 318): the accepted size is near the one asked for.
    EXPECT_NEAR(d.preview.width, 320, 8);
    EXPECT_EQ(d.preview.height, 240);
    EXPECT_NEAR(d.still.width, 640, 8);
    EXPECT_EQ(d.still.height, 480);

    for (int round = 0; round < 2; ++round) {
        SCOPED_TRACE("round " + std::to_string(round));
        std::uint64_t last = 0;
        std::chrono::nanoseconds lastTime{0};
        for (int i = 0; i < 4; ++i) {
            const auto f = camera.nextFrame(30s);
            ASSERT_TRUE(f.has_value()) << "no frame " << i;
            EXPECT_EQ(f->image.cols, d.preview.width);
            EXPECT_EQ(f->image.rows, d.preview.height);
            EXPECT_EQ(f->image.type(), CV_8UC3);
            const auto now = std::chrono::steady_clock::now().time_since_epoch();
            EXPECT_LE(f->timestamp, now);
            EXPECT_GT(f->timestamp, now - std::chrono::nanoseconds(30s));
            if (i > 0) {
                EXPECT_GT(f->sequence, last);
                EXPECT_GT(f->timestamp, lastTime);
            }
            last = f->sequence;
            lastTime = f->timestamp;
        }
        const CameraFrame still = camera.captureStill();
        EXPECT_EQ(still.image.cols, d.still.width);
        EXPECT_EQ(still.image.rows, d.still.height);
        // vimc's sensor draws a test pattern: not a black picture.
        EXPECT_GT(cv::mean(still.image)[0] + cv::mean(still.image)[1] + cv::mean(still.image)[2], 30.0);
        const auto after = camera.nextFrame(30s);
        ASSERT_TRUE(after.has_value());
        EXPECT_EQ(after->image.cols, d.preview.width);
        EXPECT_GT(after->sequence, last);
        camera.stop();
        camera.start();
    }
}

TEST_F(Vimc, AnUnknownCameraIdIsADeviceErrorListingTheCameras) {
    settings_.device = "platform/no-such-camera";
    try {
        LibcameraCamera camera(settings_);
        FAIL() << "opened a camera that does not exist";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device);
        EXPECT_NE(std::string(e.what()).find("vimc"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avatarbooth
