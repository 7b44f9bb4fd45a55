// The V4L2 backend without a camera: missing devices, nodes that are no cameras, and listing. The real-device
// tests (vivid under qemu) come with the kernel test suite.
#include "test_paths.h"

#include "drivers/camera/camera_factory.h"
#include "drivers/camera/v4l2_camera.h"

#include <gtest/gtest.h>

#include <fstream>

using namespace avatarbooth;
using namespace std::chrono_literals;

namespace {

CameraSettings v4l2(const std::string& device) {
    CameraSettings s;
    s.backend = "v4l2";
    s.device = device;
    return s;
}

// Runs `open` and returns the BoothError it throws.
template <typename F>
BoothError errorFrom(F open) {
    try {
        open();
    } catch (const BoothError& e) {
        return e;
    }
    ADD_FAILURE() << "expected a BoothError";
    return BoothError(ErrorKind::Internal, "", "none");
}

}  // namespace

TEST(CameraV4l2, MissingDeviceIsADeviceErrorNamingIt) {
    const auto e = errorFrom([] { V4l2Camera camera(v4l2("/dev/video99")); });
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_EQ(e.where(), "/dev/video99");
    EXPECT_EQ(std::string(e.what()),
              "/dev/video99: no such camera device (is the camera plugged in? `avatarbooth check` lists the cameras)");
    // Through the factory (the one way to open a camera, behind reopening): the same error, not a fallback; the
    // camera starts out lost and says why.
    const auto viaFactory = openReopeningCamera(v4l2("/dev/video99"));
    EXPECT_FALSE(viaFactory->status().ok);
    EXPECT_EQ(viaFactory->status().lastError, std::string(e.what()));
}

TEST(CameraV4l2, FilesThatAreNoVideoDevicesAreRefused) {
    const auto file = test::scratchDir("camera_v4l2_file") / "video0";
    std::ofstream(file) << "not a device";
    auto e = errorFrom([&] { V4l2Camera camera(v4l2(file.string())); });
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_NE(std::string(e.what()).find(file.string() + ": is not a V4L2 video device (VIDIOC_QUERYCAP: "),
              std::string::npos) << e.what();
    e = errorFrom([] { V4l2Camera camera(v4l2("/dev/null")); });
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_NE(std::string(e.what()).find("/dev/null: is not a V4L2 video device"), std::string::npos) << e.what();
}

TEST(CameraV4l2, ProbingAndListingNeverThrow) {
    const auto info = probeV4l2Device("/dev/video99");
    EXPECT_EQ(info.path, "/dev/video99");
    EXPECT_FALSE(info.canCapture);
    EXPECT_EQ(info.error, "cannot open: No such file or directory");

    const auto nodes = listV4l2Nodes();
    const auto cameras = listCameras();
    std::size_t v4l2Entries = 0;
    for (const auto& c : cameras) {
        std::printf("%s %s %s: %s%s\n", c.backend.c_str(), c.device.c_str(), c.name.c_str(), c.formats.c_str(),
                    c.usable ? "" : " (not usable)");
        if (c.backend == "v4l2") {
            EXPECT_EQ(c.device, nodes[v4l2Entries]);
            ++v4l2Entries;
        }
    }
    EXPECT_EQ(v4l2Entries, nodes.size());
}

TEST(CameraV4l2, ReopeningAMissingDeviceStartsLostAndSaysSo) {
    auto settings = v4l2("/dev/video99");
    settings.reopenFirstDelaySeconds = 0.01;
    auto camera = openReopeningCamera(settings);
    const auto status = camera->status();
    EXPECT_FALSE(status.ok);
    EXPECT_EQ(status.message, "camera /dev/video99 not found, retrying");
    EXPECT_NE(status.lastError.find("no such camera device"), std::string::npos);
    EXPECT_FALSE(camera->nextFrame(50ms));
    EXPECT_GE(camera->status().failedReopens, 1);
    EXPECT_THROW(camera->captureStill(), CameraGoneError);
}
