// The libcamera backend where libcamera finds no camera (this machine): the error path, the listing and its own
// log. The vimc tests under qemu exercise streaming.
#include "drivers/camera/camera_factory.h"
#include "drivers/camera/libcamera_camera.h"

#include <gtest/gtest.h>

using namespace avatarbooth;

TEST(CameraLibcamera, NoCamerasFoundIsAClearDeviceError) {
    if (!listLibcameraCameras().empty()) GTEST_SKIP() << "libcamera sees a camera on this machine";
    for (const std::string id : {"", "/base/soc/i2c0mux/i2c@1/imx219@10"}) {
        CameraSettings settings;
        settings.backend = "libcamera";
        settings.device = id;
        try {
            LibcameraCamera camera(settings);
            FAIL() << "expected a BoothError";
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Device);
            EXPECT_EQ(e.where(), "libcamera");
            EXPECT_EQ(std::string(e.what()), "libcamera: no cameras found (libcamera " + libcameraVersion() + ")");
        }
    }
}

TEST(CameraLibcamera, VersionAndListingWorkWithoutCameras) {
    EXPECT_EQ(libcameraVersion().rfind("v0.", 0), 0u) << libcameraVersion();
    // Two managers in a row (libcamera allows one at a time): the shared one is released and made again.
    const auto first = listLibcameraCameras();
    const auto second = listLibcameraCameras();
    EXPECT_EQ(first.size(), second.size());
    std::size_t listed = 0;
    for (const auto& c : listCameras())
        if (c.backend == "libcamera" && c.usable) ++listed;
    EXPECT_EQ(listed, first.size());
}

// libcamera's own INFO lines (with terminal colours) used to land on stderr at every camera manager start; they
// go through our log now, where only its warnings and errors are kept.
TEST(CameraLibcamera, ItsOwnInfoLinesStayOutOfStderr) {
    testing::internal::CaptureStderr();
    (void)listLibcameraCameras();
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(err.find("INFO"), std::string::npos) << err;
    EXPECT_EQ(err.find("\x1b["), std::string::npos) << err;
}
