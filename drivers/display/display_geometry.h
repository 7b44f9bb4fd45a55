// Screen geometry as pure functions: rotation of frames for the panel, letterboxing, and the textured quad that
// does both on the GPU. The CPU (headless) and GPU (kms, window) paths share these, so they agree pixel for pixel.
#pragma once

#include <opencv2/core.hpp>

#include <array>

namespace avatarbooth {

// How far the image is turned clockwise on its way to the panel.
enum class Rotation { R0 = 0, R90 = 90, R180 = 180, R270 = 270 };

// 0, 90, 180 or 270 → Rotation; anything else is BoothError(BadConfig) naming display.rotation.
Rotation rotationFromDegrees(int degrees);
int degrees(Rotation r);

// The size of an image of size `s` once turned by `r` (width and height swap at 90 and 270). Applied to the
// panel's size it gives the size to compose at (turning by 90 and by 270 both swap).
cv::Size rotatedSize(cv::Size s, Rotation r);

// Where pixel `p` of an image of size `image` lands after turning by `r` clockwise. At 90: (x, y) → (H-1-y, x);
// at 180: (W-1-x, H-1-y); at 270: (y, W-1-x).
cv::Point rotatedPixel(cv::Point p, cv::Size image, Rotation r);

// `bgr` turned by `r` clockwise (a copy; cv::rotate).
cv::Mat rotateImage(const cv::Mat& bgr, Rotation r);

// The largest rectangle of `content`'s aspect ratio inside `area`, centred (integer pixels; equal sizes give the
// whole area).
cv::Rect fitRect(cv::Size content, cv::Size area);

// What the panel shows for `bgr`: turned by `r`, scaled to fitRect (bilinear) and centred on black. Equal sizes
// give an exact (turned) copy.
cv::Mat composeForPanel(const cv::Mat& bgr, cv::Size panel, Rotation r);

// One corner of the full-screen quad: position in normalised device coordinates (y up) and texture coordinates
// (u right, v down: row 0 of the image is v = 0).
struct QuadVertex {
    float x, y, u, v;
};

// The quad drawing `image` on a panel of size `panel` as composeForPanel does, as a triangle strip: the panel's
// top-left, bottom-left, top-right, bottom-right corners of fitRect.
std::array<QuadVertex, 4> panelQuad(cv::Size image, cv::Size panel, Rotation r);

}  // namespace avatarbooth
