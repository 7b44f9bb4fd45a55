// Rotation, letterboxing and the presenter's quad.
#include "drivers/display/display_geometry.h"

#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace avatarbooth {

Rotation rotationFromDegrees(int deg) {
    switch (deg) {
        case 0: return Rotation::R0;
        case 90: return Rotation::R90;
        case 180: return Rotation::R180;
        case 270: return Rotation::R270;
        default:
            throw BoothError(ErrorKind::BadConfig, "display.rotation",
                             std::to_string(deg) + " is not a rotation (0, 90, 180 or 270 degrees clockwise)");
    }
}

int degrees(Rotation r) { return static_cast<int>(r); }

cv::Size rotatedSize(cv::Size s, Rotation r) {
    return (r == Rotation::R90 || r == Rotation::R270) ? cv::Size(s.height, s.width) : s;
}

cv::Point rotatedPixel(cv::Point p, cv::Size image, Rotation r) {
    switch (r) {
        case Rotation::R0: return p;
        case Rotation::R90: return {image.height - 1 - p.y, p.x};
        case Rotation::R180: return {image.width - 1 - p.x, image.height - 1 - p.y};
        case Rotation::R270: return {p.y, image.width - 1 - p.x};
    }
    return p;
}

cv::Mat rotateImage(const cv::Mat& bgr, Rotation r) {
    cv::Mat out;
    switch (r) {
        case Rotation::R0: out = bgr.clone(); break;
        case Rotation::R90: cv::rotate(bgr, out, cv::ROTATE_90_CLOCKWISE); break;
        case Rotation::R180: cv::rotate(bgr, out, cv::ROTATE_180); break;
        case Rotation::R270: cv::rotate(bgr, out, cv::ROTATE_90_COUNTERCLOCKWISE); break;
    }
    return out;
}

cv::Rect fitRect(cv::Size content, cv::Size area) {
    if (content.width <= 0 || content.height <= 0 || area.width <= 0 || area.height <= 0) return {};
    if (content == area) return {0, 0, area.width, area.height};
    // Compare content.w/content.h with area.w/area.h in integers: the limiting side takes the whole area.
    const long long cw = content.width, ch = content.height, aw = area.width, ah = area.height;
    int w = 0, h = 0;
    if (cw * ah >= aw * ch) {
        w = area.width;
        h = static_cast<int>(std::max(1LL, (aw * ch + cw / 2) / cw));
    } else {
        h = area.height;
        w = static_cast<int>(std::max(1LL, (ah * cw + ch / 2) / ch));
    }
    return {(area.width - w) / 2, (area.height - h) / 2, w, h};
}

cv::Mat composeForPanel(const cv::Mat& bgr, cv::Size panel, Rotation r) {
    const cv::Mat turned = rotateImage(bgr, r);
    if (turned.size() == panel) return turned;
    cv::Mat out(panel, CV_8UC3, cv::Scalar::all(0));
    const cv::Rect rect = fitRect(turned.size(), panel);
    if (rect.area() > 0) cv::resize(turned, out(rect), rect.size(), 0, 0, cv::INTER_LINEAR);
    return out;
}

std::array<QuadVertex, 4> panelQuad(cv::Size image, cv::Size panel, Rotation r) {
    const cv::Rect rect = fitRect(rotatedSize(image, r), panel);
    const auto ndcX = [&](int px) { return 2.0f * static_cast<float>(px) / static_cast<float>(panel.width) - 1.0f; };
    const auto ndcY = [&](int py) { return 1.0f - 2.0f * static_cast<float>(py) / static_cast<float>(panel.height); };
    const float left = ndcX(rect.x), right = ndcX(rect.x + rect.width);
    const float top = ndcY(rect.y), bottom = ndcY(rect.y + rect.height);
    // Texture coordinates of the image corner that lands on each panel corner (TL, BL, TR, BR of the panel).
    struct UV {
        float u, v;
    };
    std::array<UV, 4> uv{};
    switch (r) {
        case Rotation::R0: uv = {{{0, 0}, {0, 1}, {1, 0}, {1, 1}}}; break;
        case Rotation::R90: uv = {{{0, 1}, {1, 1}, {0, 0}, {1, 0}}}; break;
        case Rotation::R180: uv = {{{1, 1}, {1, 0}, {0, 1}, {0, 0}}}; break;
        case Rotation::R270: uv = {{{1, 0}, {0, 0}, {1, 1}, {0, 1}}}; break;
    }
    return {{{left, top, uv[0].u, uv[0].v},
             {left, bottom, uv[1].u, uv[1].v},
             {right, top, uv[2].u, uv[2].v},
             {right, bottom, uv[3].u, uv[3].v}}};
}

}  // namespace avatarbooth
