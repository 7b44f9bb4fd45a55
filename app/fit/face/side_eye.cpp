#include "fit/face/side_eye.h"

#include "fit/face/profile.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace avatarbooth {

SideEyeSpot locateSideEye(const cv::Mat& bgrIn, const cv::Mat& maskIn, const cv::Mat& hairIn,
                          const std::vector<ProfilePoint>& landmarks, bool noseImageRight,
                          const SideEyeOptions& options) {
    SideEyeSpot spot;
    if (bgrIn.empty() || bgrIn.type() != CV_8UC3 || maskIn.size() != bgrIn.size() || maskIn.type() != CV_8U) return spot;
    const bool hairKnown = !hairIn.empty() && hairIn.size() == bgrIn.size() && hairIn.type() == CV_8U;
    // Work facing image-right, on mirrored copies when the face points left (never the caller's images).
    cv::Mat bgr, mask, hair;  // (empty first: cv::flip into a header of the caller's image would flip it in place)
    if (!noseImageRight) {
        cv::flip(bgrIn, bgr, 1);
        cv::flip(maskIn, mask, 1);
        if (hairKnown) cv::flip(hairIn, hair, 1);
    } else {
        bgr = bgrIn;
        mask = maskIn;
        if (hairKnown) hair = hairIn;
    }
    const auto pt = [&](const char* name) {
        cv::Point2d p = profilePoint(landmarks, name);
        if (!noseImageRight) p.x = bgrIn.cols - 1 - p.x;
        return p;
    };
    const cv::Point2d nasion = pt("nasion"), tip = pt("nose_tip"), top = pt("top_of_head");
    const double V = tip.y - top.y;
    if (V < 20.0) return spot;

    // The region searched, with room round it for the smoothing.
    const int margin = cvRound(3.0 * options.sigma * V) + 2;
    const int y0 = cvRound(nasion.y - options.above * V), y1 = cvRound(nasion.y + options.below * V);
    const cv::Rect region = cv::Rect(cvRound(tip.x - (options.furthest + 0.1) * V) - margin, y0 - margin,
                                     cvRound((options.furthest + 0.1) * V) + 2 * margin, y1 - y0 + 1 + 2 * margin) &
                            cv::Rect(0, 0, bgr.cols, bgr.rows);
    if (region.width < 8 || region.height < 8) return spot;
    // The band: on each row, from `nearest` to `furthest` behind the face's front edge, on the person and off the
    // large hair regions.
    cv::Mat band(region.size(), CV_8U, cv::Scalar(0));
    for (int y = std::max(y0, region.y); y <= std::min(y1, region.y + region.height - 1); ++y) {
        const int edge = faceFrontEdge(mask, tip.x, y);
        if (edge < 0) continue;
        const auto* row = mask.ptr<unsigned char>(y);
        for (int x = std::max(region.x, cvRound(edge - options.furthest * V)); x <= edge - cvRound(options.nearest * V); ++x)
            if (row[x]) band.at<unsigned char>(y - region.y, x - region.x) = 255;
    }
    if (hairKnown) {
        // Hair regions larger than a brow (about 0.2 V by 0.03 V) are hair, not the eye's surroundings.
        cv::Mat labels, stats, centroids;
        const int n = cv::connectedComponentsWithStats(hair(region), labels, stats, centroids, 8, CV_32S);
        const double largest = 0.01 * V * V;
        for (int y = 0; y < region.height; ++y)
            for (int x = 0; x < region.width; ++x) {
                const int l = labels.at<int>(y, x);
                if (l > 0 && l < n && stats.at<int>(l, cv::CC_STAT_AREA) > largest) band.at<unsigned char>(y, x) = 0;
            }
    }
    std::vector<unsigned char> levels;
    cv::Mat grey;
    cv::cvtColor(bgr(region), grey, cv::COLOR_BGR2GRAY);
    for (int y = 0; y < region.height; ++y)
        for (int x = 0; x < region.width; ++x)
            if (band.at<unsigned char>(y, x)) levels.push_back(grey.at<unsigned char>(y, x));
    if (levels.size() < 50) return spot;
    std::nth_element(levels.begin(), levels.begin() + static_cast<std::ptrdiff_t>(levels.size() / 2), levels.end());
    const double cheek = levels[levels.size() / 2];
    // How much darker than the cheek's median each band pixel is, smoothed over the eye's size.
    cv::Mat dark(region.size(), CV_32F, cv::Scalar(0));
    for (int y = 0; y < region.height; ++y)
        for (int x = 0; x < region.width; ++x)
            if (band.at<unsigned char>(y, x))
                dark.at<float>(y, x) = static_cast<float>(std::max(0.0, cheek - grey.at<unsigned char>(y, x)));
    cv::GaussianBlur(dark, dark, cv::Size(), std::max(1.0, options.sigma * V));
    double best = 0.0;
    cv::Point at;
    cv::minMaxLoc(dark, nullptr, &best, nullptr, &at, band);
    spot.contrast = best;
    spot.centre = cv::Point2d(at.x + region.x, at.y + region.y);
    if (!noseImageRight) spot.centre.x = bgrIn.cols - 1 - spot.centre.x;
    spot.found = best >= options.minContrast;
    return spot;
}

}  // namespace avatarbooth
