// The simulated camera replaying real photos (FRMDB, read in place through links): a 1920x1080 front photo is
// previewed at 1280x720 and captured at full size, exactly as the file decodes.
#include "test_paths.h"

#include "drivers/camera/sim_camera.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fs = std::filesystem;
using namespace avatarbooth;
using namespace std::chrono_literals;

TEST(CameraSimData, RealPhotosPreviewSmallerAndCaptureAtFullSize) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const auto person = test::sharedData() / "frmdb" / "001";
    const auto folder = test::scratchDir("camera_sim_frmdb");
    fs::create_symlink(person / "001_hd_frontal.jpg", folder / "front.jpg");
    fs::create_symlink(person / "Img_13.jpg", folder / "side.jpg");

    auto controls = std::make_shared<SimCameraControls>();
    SimCameraOptions options;
    options.folder = folder;
    SimCamera camera(options, controls, std::make_shared<ManualClock>(SteadyTime{}));
    const auto d = camera.describe();
    EXPECT_EQ(d.preview.width, 1280);
    EXPECT_EQ(d.preview.height, 720);
    EXPECT_EQ(d.still.width, 1920);
    EXPECT_EQ(d.still.height, 1080);

    controls->setScene(SimScene::Front);
    const cv::Mat front = cv::imread((person / "001_hd_frontal.jpg").string());
    const auto still = camera.captureStill();
    EXPECT_EQ(still.image.size(), cv::Size(1920, 1080));
    EXPECT_EQ(cv::norm(still.image, front, cv::NORM_INF), 0.0);

    cv::Mat expected;
    cv::resize(front, expected, {1280, 720}, 0, 0, cv::INTER_AREA);
    const auto frame = camera.nextFrame(1s);
    ASSERT_TRUE(frame);
    EXPECT_EQ(cv::norm(frame->image, expected, cv::NORM_INF), 2.0);  // the preview is the photo plus +-2 of noise

    controls->setScene(SimScene::Side);
    EXPECT_EQ(cv::norm(camera.captureStill().image, cv::imread((person / "Img_13.jpg").string()), cv::NORM_INF), 0.0);
    EXPECT_EQ(camera.nextFrame(1s)->image.size(), cv::Size(1280, 720));
}
