// Screen geometry: exact pixel positions after turning, letterbox rectangles and the presenter's quad.
#include "drivers/display/display_geometry.h"
#include "drivers/display/headless_display.h"

#include "common/error.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

// A W x H image whose every pixel is different: (x, y) → (x, y, 7).
cv::Mat numbered(int w, int h) {
    cv::Mat m(h, w, CV_8UC3);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) m.at<cv::Vec3b>(y, x) = {static_cast<uchar>(x), static_cast<uchar>(y), 7};
    return m;
}

TEST(DisplayGeometry, RotationFromDegrees) {
    EXPECT_EQ(rotationFromDegrees(0), Rotation::R0);
    EXPECT_EQ(rotationFromDegrees(90), Rotation::R90);
    EXPECT_EQ(rotationFromDegrees(180), Rotation::R180);
    EXPECT_EQ(rotationFromDegrees(270), Rotation::R270);
    try {
        rotationFromDegrees(45);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_STREQ(e.what(), "display.rotation: 45 is not a rotation (0, 90, 180 or 270 degrees clockwise)");
    }
    EXPECT_THROW(rotationFromDegrees(-90), BoothError);
}

TEST(DisplayGeometry, ExactPixelPositionsAfterTurning) {
    const cv::Size s(4, 3);  // W = 4, H = 3
    EXPECT_EQ(rotatedSize(s, Rotation::R90), cv::Size(3, 4));
    EXPECT_EQ(rotatedSize(s, Rotation::R180), cv::Size(4, 3));
    EXPECT_EQ(rotatedSize(s, Rotation::R270), cv::Size(3, 4));
    // 90 clockwise: the top-left corner goes to the top-right, (x, y) → (H-1-y, x).
    EXPECT_EQ(rotatedPixel({0, 0}, s, Rotation::R90), cv::Point(2, 0));
    EXPECT_EQ(rotatedPixel({3, 0}, s, Rotation::R90), cv::Point(2, 3));
    EXPECT_EQ(rotatedPixel({0, 2}, s, Rotation::R90), cv::Point(0, 0));
    EXPECT_EQ(rotatedPixel({1, 1}, s, Rotation::R90), cv::Point(1, 1));
    // 270 clockwise: the top-left corner goes to the bottom-left, (x, y) → (y, W-1-x).
    EXPECT_EQ(rotatedPixel({0, 0}, s, Rotation::R270), cv::Point(0, 3));
    EXPECT_EQ(rotatedPixel({3, 0}, s, Rotation::R270), cv::Point(0, 0));
    EXPECT_EQ(rotatedPixel({3, 2}, s, Rotation::R270), cv::Point(2, 0));
    EXPECT_EQ(rotatedPixel({1, 2}, s, Rotation::R270), cv::Point(2, 2));
    EXPECT_EQ(rotatedPixel({0, 0}, s, Rotation::R180), cv::Point(3, 2));
    EXPECT_EQ(rotatedPixel({1, 2}, s, Rotation::R0), cv::Point(1, 2));
}

TEST(DisplayGeometry, TurnedImageHasEveryPixelWhereRotatedPixelSays) {
    const cv::Mat img = numbered(5, 3);
    for (const Rotation r : {Rotation::R0, Rotation::R90, Rotation::R180, Rotation::R270}) {
        const cv::Mat turned = rotateImage(img, r);
        ASSERT_EQ(turned.size(), rotatedSize(img.size(), r));
        for (int y = 0; y < img.rows; ++y)
            for (int x = 0; x < img.cols; ++x)
                EXPECT_EQ(turned.at<cv::Vec3b>(rotatedPixel({x, y}, img.size(), r)), img.at<cv::Vec3b>(y, x))
                    << "rotation " << degrees(r) << " pixel " << x << "," << y;
    }
    // Spelled out for 90: the turned image's first row is the original's first column, bottom to top.
    const cv::Mat turned90 = rotateImage(img, Rotation::R90);
    EXPECT_EQ(turned90.at<cv::Vec3b>(0, 0), (cv::Vec3b{0, 2, 7}));
    EXPECT_EQ(turned90.at<cv::Vec3b>(0, 2), (cv::Vec3b{0, 0, 7}));
    EXPECT_EQ(turned90.at<cv::Vec3b>(4, 2), (cv::Vec3b{4, 0, 7}));
    const cv::Mat turned270 = rotateImage(img, Rotation::R270);
    EXPECT_EQ(turned270.at<cv::Vec3b>(0, 0), (cv::Vec3b{4, 0, 7}));
    EXPECT_EQ(turned270.at<cv::Vec3b>(4, 0), (cv::Vec3b{0, 0, 7}));
    EXPECT_EQ(turned270.at<cv::Vec3b>(4, 2), (cv::Vec3b{0, 2, 7}));
}

TEST(DisplayGeometry, FitRectKeepsTheAspectRatioAndCentres) {
    EXPECT_EQ(fitRect({1280, 720}, {1280, 720}), cv::Rect(0, 0, 1280, 720));
    EXPECT_EQ(fitRect({640, 360}, {1280, 720}), cv::Rect(0, 0, 1280, 720));
    EXPECT_EQ(fitRect({1280, 720}, {1080, 1920}), cv::Rect(0, 656, 1080, 608));
    EXPECT_EQ(fitRect({4, 3}, {8, 8}), cv::Rect(0, 1, 8, 6));
    EXPECT_EQ(fitRect({3, 4}, {8, 8}), cv::Rect(1, 0, 6, 8));
    EXPECT_EQ(fitRect({1920, 1080}, {1280, 1024}), cv::Rect(0, 152, 1280, 720));
    EXPECT_EQ(fitRect({0, 5}, {8, 8}), cv::Rect());
}

TEST(DisplayGeometry, ComposeForPanelTurnsAndLetterboxes) {
    const cv::Mat img = numbered(4, 2);
    // Equal size after turning: an exact turned copy.
    const cv::Mat exact = composeForPanel(img, {2, 4}, Rotation::R90);
    EXPECT_EQ(cv::norm(exact, rotateImage(img, Rotation::R90), cv::NORM_INF), 0.0);
    // 4x2 turned to 2x4 on a 4x4 panel: a 2x4 strip in the middle, black bars left and right.
    const cv::Mat boxed = composeForPanel(img, {4, 4}, Rotation::R90);
    ASSERT_EQ(boxed.size(), cv::Size(4, 4));
    for (int y = 0; y < 4; ++y) {
        EXPECT_EQ(boxed.at<cv::Vec3b>(y, 0), cv::Vec3b(0, 0, 0));
        EXPECT_EQ(boxed.at<cv::Vec3b>(y, 3), cv::Vec3b(0, 0, 0));
        EXPECT_EQ(boxed.at<cv::Vec3b>(y, 1)[2], 7);
    }
}

TEST(DisplayGeometry, QuadCoversTheFitRectWithTurnedTextureCorners) {
    // Exact size, 90: the whole screen; the panel's top-left shows the image's bottom-left (u 0, v 1).
    const auto q = panelQuad({1280, 720}, {720, 1280}, Rotation::R90);
    EXPECT_FLOAT_EQ(q[0].x, -1.0f);
    EXPECT_FLOAT_EQ(q[0].y, 1.0f);
    EXPECT_FLOAT_EQ(q[0].u, 0.0f);
    EXPECT_FLOAT_EQ(q[0].v, 1.0f);
    EXPECT_FLOAT_EQ(q[1].y, -1.0f);  // bottom-left: image bottom-right
    EXPECT_FLOAT_EQ(q[1].u, 1.0f);
    EXPECT_FLOAT_EQ(q[1].v, 1.0f);
    EXPECT_FLOAT_EQ(q[2].x, 1.0f);  // top-right: image top-left
    EXPECT_FLOAT_EQ(q[2].u, 0.0f);
    EXPECT_FLOAT_EQ(q[2].v, 0.0f);
    EXPECT_FLOAT_EQ(q[3].u, 1.0f);  // bottom-right: image top-right
    EXPECT_FLOAT_EQ(q[3].v, 0.0f);

    // 270 on a square panel: the fit rect (x 0-4 of 8, rows 2-6 → a 4x... ) in NDC.
    const auto b = panelQuad({4, 8}, {8, 8}, Rotation::R270);  // turned: 8x4 → fills 8x4 at rows 2-6
    EXPECT_FLOAT_EQ(b[0].x, -1.0f);
    EXPECT_FLOAT_EQ(b[0].y, 0.5f);
    EXPECT_FLOAT_EQ(b[3].x, 1.0f);
    EXPECT_FLOAT_EQ(b[3].y, -0.5f);
    EXPECT_FLOAT_EQ(b[0].u, 1.0f);  // top-left shows the image's top-right
    EXPECT_FLOAT_EQ(b[0].v, 0.0f);
}

TEST(DisplayHeadless, KeepsFramesAndCountsThem) {
    DisplaySettings settings;
    settings.width = 6;  // a portrait-mounted panel: 6x8 physical, frames composed at 8x6
    settings.height = 8;
    settings.rotation = 270;
    HeadlessDisplay display(settings);
    EXPECT_EQ(display.size(), cv::Size(8, 6));
    EXPECT_EQ(display.rotation(), Rotation::R270);
    EXPECT_EQ(display.frameCount(), 0u);
    EXPECT_TRUE(display.lastFrame().empty());
    const cv::Mat frame = numbered(8, 6);
    display.present(frame);
    display.present(frame);
    EXPECT_EQ(display.frameCount(), 2u);
    EXPECT_EQ(cv::norm(display.lastFrame(), frame, cv::NORM_INF), 0.0);
    const cv::Mat panel = display.lastPanelFrame();
    ASSERT_EQ(panel.size(), cv::Size(6, 8));
    EXPECT_EQ(panel.at<cv::Vec3b>(rotatedPixel({0, 0}, frame.size(), Rotation::R270)), frame.at<cv::Vec3b>(0, 0));
    EXPECT_EQ(panel.at<cv::Vec3b>(7, 0), (cv::Vec3b{0, 0, 7}));  // the frame's top-left at the panel's bottom-left
    EXPECT_EQ(display.describe(), "headless 6x8 rotated 270");
}

TEST(DisplayHeadless, FrameOfAnotherSizeIsFittedLikeAScreenWould) {
    DisplaySettings settings;
    settings.width = 8;
    settings.height = 8;
    HeadlessDisplay display(settings);
    display.present(cv::Mat(4, 8, CV_8UC3, cv::Scalar(10, 20, 30)));
    const cv::Mat& last = display.lastFrame();
    ASSERT_EQ(last.size(), cv::Size(8, 8));
    EXPECT_EQ(last.at<cv::Vec3b>(0, 0), cv::Vec3b(0, 0, 0));
    EXPECT_EQ(last.at<cv::Vec3b>(2, 0), cv::Vec3b(10, 20, 30));
    EXPECT_EQ(last.at<cv::Vec3b>(5, 7), cv::Vec3b(10, 20, 30));
    EXPECT_EQ(last.at<cv::Vec3b>(6, 7), cv::Vec3b(0, 0, 0));
}

TEST(DisplayHeadless, RejectsBadSettingsAndImages) {
    DisplaySettings bad;
    bad.rotation = 30;
    EXPECT_THROW(HeadlessDisplay{bad}, BoothError);
    bad = {};
    bad.width = 0;
    EXPECT_THROW(HeadlessDisplay{bad}, BoothError);
    bad = {};
    bad.everyNthFrame = 5;  // without a folder
    EXPECT_THROW(HeadlessDisplay{bad}, BoothError);
    HeadlessDisplay ok(DisplaySettings{});
    EXPECT_EQ(ok.size(), cv::Size(1280, 720));
    EXPECT_THROW(ok.present(cv::Mat(10, 10, CV_8UC1)), BoothError);
}

}  // namespace
}  // namespace avatarbooth
