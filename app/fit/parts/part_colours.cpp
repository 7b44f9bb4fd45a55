// Iris and brow colours from the front photo (part_colours.h).
#include "fit/parts/part_colours.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace avatarbooth {
namespace {

struct Pixel {
    double grey;
    cv::Vec3d bgr;
};

// The per-channel median of some pixels.
cv::Vec3d medianColour(const std::vector<Pixel>& pixels) {
    cv::Vec3d out;
    for (int k = 0; k < 3; ++k) {
        std::vector<double> v;
        v.reserve(pixels.size());
        for (const auto& p : pixels) v.push_back(p.bgr[k]);
        std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
        out[k] = v[v.size() / 2];
    }
    return out;
}

// The pixels of `image` under `mask` (within `box`), by brightness.
std::vector<Pixel> pixelsUnder(const cv::Mat& image, const cv::Mat& mask, const cv::Rect& box) {
    std::vector<Pixel> out;
    for (int r = box.y; r < box.y + box.height; ++r)
        for (int c = box.x; c < box.x + box.width; ++c)
            if (mask.at<std::uint8_t>(r, c)) {
                const cv::Vec3b p = image.at<cv::Vec3b>(r, c);
                out.push_back({0.114 * p[0] + 0.587 * p[1] + 0.299 * p[2], cv::Vec3d(p[0], p[1], p[2])});
            }
    std::sort(out.begin(), out.end(), [](const Pixel& a, const Pixel& b) { return a.grey < b.grey; });
    return out;
}

double distance(const cv::Point2d& a, const cv::Point2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

}  // namespace

std::optional<cv::Vec3d> measureIrisColour(const cv::Mat& front, const FaceLandmarks& lm) {
    if (front.empty() || front.type() != CV_8UC3) return std::nullopt;
    const cv::Rect whole(0, 0, front.cols, front.rows);
    std::vector<Pixel> iris;
    for (const int first : {36, 42}) {
        std::vector<cv::Point> outline;
        for (int k = first; k < first + 6; ++k)
            outline.emplace_back(cvRound(lm.points[static_cast<std::size_t>(k)].x), cvRound(lm.points[static_cast<std::size_t>(k)].y));
        const cv::Rect box = cv::boundingRect(outline) & whole;
        if (box.width < 6 || box.height < 3) continue;
        cv::Mat mask(front.size(), CV_8U, cv::Scalar(0));
        cv::fillConvexPoly(mask, outline, cv::Scalar(255), cv::LINE_8);
        // The lids' edges and lashes lie on the outline itself.
        cv::erode(mask(box), mask(box), cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
        const std::vector<Pixel> pixels = pixelsUnder(front, mask, box);
        if (pixels.size() < 12) continue;
        // The eye's opening splits into the white and highlights (bright) and the iris, pupil and lashes (dark):
        // Otsu's threshold on brightness between them; of the dark side, the darkest quarter is pupil, lash and
        // shadow, the rest is iris.
        std::vector<double> grey;
        for (const auto& p : pixels) grey.push_back(p.grey);
        double bestScore = -1.0;
        std::size_t split = pixels.size() / 2;
        double sumAll = 0.0;
        for (const double g : grey) sumAll += g;
        double sumLow = 0.0;
        for (std::size_t i = 1; i < grey.size(); ++i) {
            sumLow += grey[i - 1];
            const double n0 = static_cast<double>(i), n1 = static_cast<double>(grey.size() - i);
            const double m0 = sumLow / n0, m1 = (sumAll - sumLow) / n1;
            const double score = n0 * n1 * (m1 - m0) * (m1 - m0);
            if (score > bestScore) bestScore = score, split = i;
        }
        const std::size_t from = split / 4;
        iris.insert(iris.end(), pixels.begin() + static_cast<std::ptrdiff_t>(from), pixels.begin() + static_cast<std::ptrdiff_t>(split));
    }
    if (iris.size() < 8) return std::nullopt;
    return medianColour(iris);
}

std::optional<cv::Vec3d> measureBrowColour(const cv::Mat& front, const FaceLandmarks& lm) {
    if (front.empty() || front.type() != CV_8UC3) return std::nullopt;
    // A brow is about an eighth of the distance between the eyes' outer corners thick.
    const double thickness = std::max(2.0, distance(lm.points[36], lm.points[45]) / 8.0);
    cv::Mat mask(front.size(), CV_8U, cv::Scalar(0));
    for (const int first : {17, 22}) {
        std::vector<cv::Point> line;
        // dlib puts the points on the brow's upper half: the band is centred a little below them.
        for (int k = first; k < first + 5; ++k)
            line.emplace_back(cvRound(lm.points[static_cast<std::size_t>(k)].x),
                              cvRound(lm.points[static_cast<std::size_t>(k)].y + 0.3 * thickness));
        for (const auto& p : line)
            if (!cv::Rect(0, 0, front.cols, front.rows).contains(p)) return std::nullopt;
        cv::polylines(mask, std::vector<std::vector<cv::Point>>{line}, false, cv::Scalar(255), cvRound(thickness), cv::LINE_8);
    }
    const std::vector<Pixel> pixels = pixelsUnder(front, mask, cv::Rect(0, 0, front.cols, front.rows));
    if (pixels.size() < 20) return std::nullopt;
    // The darkest quarter: the hairs, not the skin between and around them.
    return medianColour(std::vector<Pixel>(pixels.begin(), pixels.begin() + static_cast<std::ptrdiff_t>(pixels.size() / 4)));
}

PartColours measurePartColours(const cv::Mat& front, const FaceLandmarks& landmarks) {
    PartColours out;
    if (const auto iris = measureIrisColour(front, landmarks)) out["eyes"] = *iris;
    if (const auto brows = measureBrowColour(front, landmarks)) out["eyebrows"] = *brows;
    return out;
}

}  // namespace avatarbooth
