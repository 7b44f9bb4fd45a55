#include "fit/face/ear_locator.h"

#include "fit/face/profile.h"

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <optional>

namespace avatarbooth {

namespace {

// The photo round the head's side, facing image-right (mirrored when the face points left).
struct SideCrop {
    cv::Mat bgr, mask, hair;  // hair: CV_8U, 255 on hair (all 0 when none is known)
    cv::Point origin;         // the crop's top-left corner in the facing-right photo
    cv::Point2d tip;          // facing-right photo pixels
    double V = 0.0;           // the nose tip's height under the top of the head (pixels)
};

// The edges' directions, angle doubled (an edge and its reverse alike): two channels, m cos 2a and m sin 2a, with m
// the edge's strength saturating at `knee` (so that hair's many strong edges do not outweigh the ear's).
std::pair<cv::Mat, cv::Mat> edgeDirections(const cv::Mat& grey, double knee) {
    cv::Mat gx, gy;
    cv::Sobel(grey, gx, CV_32F, 1, 0);
    cv::Sobel(grey, gy, CV_32F, 0, 1);
    cv::Mat c(grey.size(), CV_32F), s(grey.size(), CV_32F);
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x) {
            const double u = gx.at<float>(y, x), v = gy.at<float>(y, x), m2 = u * u + v * v;
            const double m = std::sqrt(m2), w = m2 > 0.0 ? (m / (m + knee)) / m2 : 0.0;
            c.at<float>(y, x) = static_cast<float>((u * u - v * v) * w);
            s.at<float>(y, x) = static_cast<float>(2.0 * u * v * w);
        }
    return {c, s};
}

// One size of the template and its score at every place searched.
struct SizedScore {
    double scale = 0.0, f = 0.0;  // the size against the template's at the photo's V; template pixels to photo pixels
    cv::Mat mask;                 // the window (CV_8U), at this size
    cv::Mat score;                // CV_32F; element (x, y) is the window's top-left corner at first + (x, y)
    cv::Point first;
};

// The template at `scale`, correlated with the photo's edge directions (pc, ps) at the places whose ear middle lies
// within the search round `expected`: only those are ever taken, so the rest of the crop (as wide again as the
// search, to hold the window) is not correlated.
SizedScore sizedScore(const SideCrop& c, const EarTemplate& ear, const cv::Point2d& expected, const EarLocatorOptions& o,
                      const cv::Mat& pc, const cv::Mat& ps, double scale, double pxPerMm, double blur) {
    SizedScore out;
    out.scale = scale;
    out.f = ear.mmPerPixel * pxPerMm * scale;
    cv::Mat templ;
    cv::resize(ear.shade, templ, {}, out.f, out.f, cv::INTER_AREA);
    cv::resize(ear.mask, out.mask, templ.size(), 0, 0, cv::INTER_NEAREST);
    if (templ.cols >= pc.cols || templ.rows >= pc.rows || templ.cols < 6 || templ.rows < 6) return out;
    cv::GaussianBlur(templ, templ, {0, 0}, blur);
    const int g = std::max(1, cvRound(2.0 * pxPerMm));
    cv::dilate(out.mask, out.mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * g + 1, 2 * g + 1}));
    auto [tc, ts] = edgeDirections(templ, 0.05);
    tc.setTo(0.0f, out.mask == 0);
    ts.setTo(0.0f, out.mask == 0);
    double weight = 0.0;
    for (int y = 0; y < tc.rows; ++y)
        for (int x = 0; x < tc.cols; ++x) weight += std::hypot(tc.at<float>(y, x), ts.at<float>(y, x));
    if (weight <= 0.0) return out;
    // The window corners whose ear middle lies in the search (a pixel more each way), within the crop.
    const cv::Point2d middle(c.origin.x + ear.centre.x * out.f, c.origin.y + ear.centre.y * out.f);
    const int x0 = std::max(0, static_cast<int>(std::floor(expected.x - o.searchAlong * c.V - middle.x)) - 1);
    const int y0 = std::max(0, static_cast<int>(std::floor(expected.y - o.searchUpDown * c.V - middle.y)) - 1);
    const int x1 = std::min(pc.cols - tc.cols, static_cast<int>(std::ceil(expected.x + o.searchAlong * c.V - middle.x)) + 1);
    const int y1 = std::min(pc.rows - tc.rows, static_cast<int>(std::ceil(expected.y + o.searchUpDown * c.V - middle.y)) + 1);
    if (x1 < x0 || y1 < y0) return out;
    const cv::Rect under(x0, y0, x1 - x0 + tc.cols, y1 - y0 + tc.rows);
    cv::Mat sc, ss;
    cv::matchTemplate(pc(under), tc, sc, cv::TM_CCORR);
    cv::matchTemplate(ps(under), ts, ss, cv::TM_CCORR);
    out.score = (sc + ss) / weight;
    out.first = {x0, y0};
    return out;
}

// The best place of one size whose window is not mostly hair and lies on the person: its score and the ear's middle
// there (facing-right pixels), or nothing.
std::optional<std::pair<float, cv::Point2d>> bestPlace(const SideCrop& c, const EarTemplate& ear, const cv::Point2d& expected,
                                                        const EarLocatorOptions& o, const SizedScore& sized) {
    if (sized.score.empty()) return std::nullopt;
    const double f = sized.f;
    const cv::Mat& tmask = sized.mask;
    const auto middleAt = [&](const cv::Point& p) { return cv::Point2d(c.origin.x + p.x + ear.centre.x * f, c.origin.y + p.y + ear.centre.y * f); };
    // The places within the search.
    std::vector<std::pair<float, cv::Point>> places;
    for (int y = 0; y < sized.score.rows; ++y)
        for (int x = 0; x < sized.score.cols; ++x) {
            const cv::Point p = sized.first + cv::Point(x, y);
            const cv::Point2d centre = middleAt(p);
            const float v = sized.score.at<float>(y, x);
            if (std::isfinite(v) && std::abs(centre.x - expected.x) <= o.searchAlong * c.V &&
                std::abs(centre.y - expected.y) <= o.searchUpDown * c.V)
                places.emplace_back(v, p);
        }
    // How many of the window's pixels lie on hair and on the person: counted pixel by pixel for the best places in
    // turn (the best is usually taken), then at every searched place at once (where hair covers the ear thousands
    // of places are turned down, and counting each in turn took 450 ms: FRMDB 007), taking the best of the rest
    // that passes.
    constexpr std::size_t kCountedOneByOne = 16;
    const auto better = [](const auto& a, const auto& b) { return a.first > b.first; };
    const auto counted = places.begin() + static_cast<std::ptrdiff_t>(std::min(kCountedOneByOne, places.size()));
    std::partial_sort(places.begin(), counted, places.end(), better);
    std::vector<cv::Point> window;
    cv::findNonZero(tmask, window);
    const int windowSize = static_cast<int>(window.size());
    const cv::Rect searched(sized.first, cv::Size(sized.score.cols + tmask.cols - 1, sized.score.rows + tmask.rows - 1));
    // Element (x, y) of the counts: the window's top-left corner at sized.first + (x, y).
    const auto countsUnder = [&](const cv::Mat& pixels) {
        const cv::Mat onPixels = pixels(searched) != 0, inWindow = tmask != 0;
        cv::Mat on, inside, counts;
        onPixels.convertTo(on, CV_32F, 1.0 / 255.0);
        inWindow.convertTo(inside, CV_32F, 1.0 / 255.0);
        cv::matchTemplate(on, inside, counts, cv::TM_CCORR);
        return counts;
    };
    const auto passes = [&](int onHair, int onPerson) { return 2 * onHair <= windowSize && onPerson >= 0.95 * static_cast<double>(windowSize); };
    for (auto it = places.begin(); it != counted; ++it) {
        int onHair = 0, onPerson = 0;
        for (const cv::Point& q : window) {
            onHair += c.hair.at<unsigned char>(it->second + q) != 0;
            onPerson += c.mask.at<unsigned char>(it->second + q) != 0;
        }
        if (passes(onHair, onPerson)) return std::make_pair(it->first, middleAt(it->second));
    }
    if (counted == places.end()) return std::nullopt;
    const cv::Mat hairCount = countsUnder(c.hair), personCount = countsUnder(c.mask);
    auto taken = places.end();
    for (auto it = counted; it != places.end(); ++it) {
        const cv::Point at = it->second - sized.first;
        if ((taken == places.end() || it->first > taken->first) &&
            passes(cvRound(hairCount.at<float>(at)), cvRound(personCount.at<float>(at))))
            taken = it;
    }
    if (taken == places.end()) return std::nullopt;
    return std::make_pair(taken->first, middleAt(taken->second));
}

// How well the photo's edges run along the template's (the helix's rim, the antihelix, the
// concha's edge), at each of the sizes: the mean over the template's edges of cos 2(angle difference), weighted by
// both strengths; random edges (hair, stubble) average out. Windows mostly on hair or off the person do not count.
// Facing-right pixels of the ear's middle and the best score, or nothing.
std::optional<std::pair<cv::Point2d, double>> templatePeak(const SideCrop& c, const EarTemplate& ear,
                                                           const cv::Point2d& expected, const EarLocatorOptions& o,
                                                           double* scaleOut) {
    const double pxPerMm = c.V / ear.noseTipToTop;
    cv::Mat grey;
    cv::cvtColor(c.bgr, grey, cv::COLOR_BGR2GRAY);
    grey.convertTo(grey, CV_32F, 1.0 / 255.0);
    const double blur = std::max(0.5, 0.6 * pxPerMm);
    cv::GaussianBlur(grey, grey, {0, 0}, blur);
    const auto [pc, ps] = edgeDirections(grey, 0.05);
    // Each size on a thread of its own: the correlations are most of the locator's time, and where hair covers the
    // ear, turning its thousands of places down. Each size's best place that is not mostly hair and lies on the
    // person; the best of those wins (the first size on a tie).
    std::vector<SizedScore> sizes(o.scales.size());
    std::vector<std::optional<std::pair<float, cv::Point2d>>> taken(sizes.size());
    cv::parallel_for_(cv::Range(0, static_cast<int>(sizes.size())), [&](const cv::Range& r) {
        for (int i = r.start; i < r.end; ++i) {
            const auto k = static_cast<std::size_t>(i);
            sizes[k] = sizedScore(c, ear, expected, o, pc, ps, o.scales[k], pxPerMm, blur);
            taken[k] = bestPlace(c, ear, expected, o, sizes[k]);
        }
    });
    double best = -2.0;
    cv::Point2d at;
    for (std::size_t i = 0; i < sizes.size(); ++i)
        if (taken[i] && taken[i]->first > best) {
            best = taken[i]->first;
            at = taken[i]->second;
            *scaleOut = sizes[i].scale;
        }
    if (best < -1.0) return std::nullopt;
    return std::make_pair(at, best);
}

}  // namespace

EarSpot locateEar(const cv::Mat& bgrIn, const cv::Mat& maskIn, const cv::Mat& hairIn,
                  const std::vector<ProfilePoint>& landmarks, bool noseImageRight, const EarTemplate& ear,
                  const EarLocatorOptions& o) {
    EarSpot spot;
    if (bgrIn.empty() || maskIn.size() != bgrIn.size() || ear.empty()) return spot;
    const int W = bgrIn.cols;
    const auto canon = [&](const char* name) {
        cv::Point2d p = profilePoint(landmarks, name);
        if (!noseImageRight) p.x = W - 1 - p.x;
        return p;
    };
    SideCrop c;
    c.tip = canon("nose_tip");
    c.V = c.tip.y - canon("top_of_head").y;
    if (c.V < 20.0) return spot;
    const double V = c.V, pxPerMm = V / ear.noseTipToTop;
    const cv::Point2d expected(c.tip.x - ear.behindNoseTip * V, c.tip.y - ear.aboveNoseTip * V);
    const double biggest = o.scales.empty() ? 1.0 : *std::max_element(o.scales.begin(), o.scales.end());
    const double tw = ear.shade.cols * ear.mmPerPixel * pxPerMm * biggest, th = ear.shade.rows * ear.mmPerPixel * pxPerMm * biggest;
    // The search, with the largest template's size round it.
    const cv::Rect wanted(cvRound(expected.x - o.searchAlong * V - tw), cvRound(expected.y - o.searchUpDown * V - th),
                          cvRound(2 * o.searchAlong * V + 2 * tw), cvRound(2 * o.searchUpDown * V + 2 * th));
    const cv::Rect taken = noseImageRight ? wanted : cv::Rect(W - wanted.x - wanted.width, wanted.y, wanted.width, wanted.height);
    const cv::Rect inPhoto = taken & cv::Rect(0, 0, W, bgrIn.rows);
    if (inPhoto.width < 8 || inPhoto.height < 8) return spot;
    c.bgr = bgrIn(inPhoto).clone();
    c.mask = maskIn(inPhoto).clone();
    c.hair = hairIn.size() == bgrIn.size() ? hairIn(inPhoto).clone() : cv::Mat(c.mask.size(), CV_8U, cv::Scalar(0));
    if (!noseImageRight)
        for (cv::Mat* m : {&c.bgr, &c.mask, &c.hair}) cv::flip(*m, *m, 1);
    c.origin = {noseImageRight ? inPhoto.x : W - inPhoto.x - inPhoto.width, inPhoto.y};

    double scale = 0.0;
    const auto edges = templatePeak(c, ear, expected, o, &scale);
    if (!edges) return spot;
    spot.centre = edges->first;
    if (!noseImageRight) spot.centre.x = W - 1 - spot.centre.x;
    spot.score = edges->second;
    spot.scale = scale;
    spot.found = spot.score >= o.minScore;
    return spot;
}

}  // namespace avatarbooth
