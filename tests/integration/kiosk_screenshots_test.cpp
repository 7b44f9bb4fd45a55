// `avatarbooth run --screenshots DIR`: a PNG of every screen shown, each once it shows what it is for, and a screen
// left before that (a keep pressed while a reveal style was still being made) as it was last drawn, unless it was
// only passed through.
#include "kiosk/screenshots.h"
#include "test_paths.h"

#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

ScreenModel screenOf(ScreenId id, int shownForMs = 0) {
    ScreenModel m;
    m.id = id;
    m.sinceEntered = Millis(shownForMs);
    return m;
}

cv::Mat filled(int grey) { return cv::Mat(36, 64, CV_8UC3, cv::Scalar::all(grey)); }

// The grey level of a picture written, or -1 when it is missing.
int greyOf(const fs::path& file) {
    const cv::Mat m = cv::imread(file.string());
    return m.empty() ? -1 : m.at<cv::Vec3b>(10, 10)[0];
}

}  // namespace

TEST(KioskScreenshots, EveryScreenShownIsPicturedEvenWhenLeftBeforeItWasComplete) {
    const fs::path dir = test::scratchDir("kiosk_screenshots");
    {
        Screenshots shots(dir);
        cv::Mat canvas = filled(10);  // the kiosk draws every frame into the same image
        shots.frame(screenOf(ScreenId::Attract), canvas, true, true);
        // The reveal is never complete (a style still coming) in the 3 s before the visitor presses keep.
        for (const int grey : {40, 50, 60}) {
            filled(grey).copyTo(canvas);
            shots.frame(screenOf(ScreenId::Reveal, (grey - 30) * 100), canvas, false, false);
        }
        // The thanks screen: incomplete (its code still coming), then complete, then drawn again.
        filled(70).copyTo(canvas);
        shots.frame(screenOf(ScreenId::Thanks), canvas, false, true);
        filled(80).copyTo(canvas);
        shots.frame(screenOf(ScreenId::Thanks), canvas, true, true);
        filled(90).copyTo(canvas);
        shots.frame(screenOf(ScreenId::Thanks), canvas, true, true);
        // A complete screen is pictured once, at once, and not again when left.
        filled(100).copyTo(canvas);
        shots.frame(screenOf(ScreenId::Attract), canvas, true, true);
        // A countdown passed through in 0.6 s (the camera lost) is not one the visitor saw: no picture.
        for (const int ms : {0, 300, 600}) {
            filled(110).copyTo(canvas);
            shots.frame(screenOf(ScreenId::Countdown, ms), canvas, false, false);
        }
        filled(120).copyTo(canvas);
        shots.frame(screenOf(ScreenId::CameraLost), canvas, true, true);
        EXPECT_EQ(shots.written().size(), 5u);
    }
    EXPECT_EQ(greyOf(dir / "00_attract.png"), 10);
    EXPECT_EQ(greyOf(dir / "01_reveal.png"), 60);  // as last drawn, not the frame that replaced it
    EXPECT_EQ(greyOf(dir / "02_thanks.png"), 80);
    EXPECT_EQ(greyOf(dir / "03_attract.png"), 100);
    EXPECT_EQ(greyOf(dir / "04_camera_lost.png"), 120);
    EXPECT_FALSE(fs::exists(dir / "05_camera_lost.png"));
}
