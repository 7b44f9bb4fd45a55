// Person/background segmentation: colour models learned per photo, relabelling with cleaning, edge refinement.
//
// Why not GrabCut: cv::grabCut takes several times the whole side-photo budget on a small copy of a booth photo
// on two cores (README, the fit's figures). The method here keeps GrabCut's idea (two colour models, re-estimated
// from the current labels, plus spatial smoothing) with cheaper parts: smoothed colour histograms instead of GMMs,
// and a Gaussian-smoothed log-likelihood ratio plus "one component without holes" instead of a graph cut.
#include "fit/face/silhouette.h"

#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace avatarbooth {
namespace {

// Colour histograms over (intensity, two chroma ratios) rather than (B, G, R):
//   I  = (B + G + R) / 3 on a square-root scale, 16 levels (finer steps in the dark),
//   c1 = (R - B) / (I + 10)            in [-1, 1],     24 levels (warm skin and hair > 0, a blue cloth < 0),
//   c2 = (G - (R + B) / 2) / (I + 10)  in [-0.6, 0.6], 16 levels (green / magenta).
// Why: on the booth's dark blue cloth, dark brown hair differs from the cloth by a few grey levels per channel
// (hair about B,G,R = 23,20,30, cloth 22,16,21 in frmdb/001) but by a clear chroma ratio (+0.3 vs 0.0), and cloth
// folds change the intensity, not the chroma. The +10 keeps the ratios steady where sensor noise dominates.
constexpr int kLevelsI = 16;
constexpr int kLevelsC1 = 24;
constexpr int kLevelsC2 = 16;
constexpr int kBins = kLevelsI * kLevelsC1 * kLevelsC2;
constexpr std::array<int, 3> kAxisLevels{kLevelsI, kLevelsC1, kLevelsC2};
constexpr std::array<int, 3> kAxisStrides{kLevelsC1 * kLevelsC2, kLevelsC2, 1};
// Working copy: long side about 480 px (reduced by a whole factor: 486 px for 972, 400 for 1200). Faces in booth
// photos are then about 100 px wide, enough for the outline; the full-resolution band refinement restores the edge.
constexpr double kWorkLongSide = 480.0;
// Log-likelihood ratios are clamped to +-kMaxLlr so one odd colour cannot dominate the smoothing.
constexpr float kMaxLlr = 8.0f;
// Relabelling rounds at the working size (the colour models converge in two to three rounds on the sample photos).
constexpr int kRounds = 3;
// Uniform floors of the two colour models: the person's colours are well sampled by the seeds, the background may
// hold colours its samples missed (a lit patch of cloth), so a colour neither model has seen leans to the
// background by log(1e-2 / 1e-3) = 2.3 nats.
constexpr double kFgFloor = 1e-3;
constexpr double kBgFloor = 1e-2;

// Tables indexed by B+G+R (0..765): the intensity level, and the factors that turn R-B and 2G-R-B into chroma
// levels. c1 = (R - B) / (I + 10) = 3 (R - B) / (sum + 30) maps [-1, 1] onto 24 levels: level = 12 + 36 (R - B) /
// (sum + 30); c2 = 1.5 (2G - R - B) / (sum + 30) maps [-0.6, 0.6] onto 16 levels: level = 8 + 20 (2G - R - B) /
// (sum + 30).
struct BinTables {
    std::array<std::uint16_t, 766> intensityOffset{};
    std::array<float, 766> c1Factor{};
    std::array<float, 766> c2Factor{};
    BinTables() {
        for (std::size_t sum = 0; sum < 766; ++sum) {
            const int level =
                std::min(kLevelsI - 1, static_cast<int>(kLevelsI * std::sqrt(static_cast<double>(sum) / 766.0)));
            intensityOffset[sum] = static_cast<std::uint16_t>(level * kAxisStrides[0]);
            c1Factor[sum] = static_cast<float>(0.5 * kLevelsC1 * 3.0 / (static_cast<double>(sum) + 30.0));
            c2Factor[sum] = static_cast<float>(kLevelsC2 / 1.2 * 1.5 / (static_cast<double>(sum) + 30.0));
        }
    }
};

const BinTables& binTables() {
    static const BinTables tables;
    return tables;
}

// Per-pixel histogram bin (CV_16U) of a BGR image.
cv::Mat binIndex(const cv::Mat& bgr) {
    const BinTables& t = binTables();
    constexpr float c1Top = kLevelsC1 - 0.001f, c2Top = kLevelsC2 - 0.001f;
    cv::Mat bins(bgr.size(), CV_16U);
    for (int y = 0; y < bgr.rows; ++y) {
        const auto* src = bgr.ptr<cv::Vec3b>(y);
        auto* dst = bins.ptr<std::uint16_t>(y);
        for (int x = 0; x < bgr.cols; ++x) {
            const int b = src[x][0], g = src[x][1], r = src[x][2];
            const auto sum = static_cast<std::size_t>(b + g + r);
            const float c1 = std::clamp(0.5f * kLevelsC1 + static_cast<float>(r - b) * t.c1Factor[sum], 0.0f, c1Top);
            const float c2 =
                std::clamp(0.5f * kLevelsC2 + static_cast<float>(2 * g - r - b) * t.c2Factor[sum], 0.0f, c2Top);
            dst[x] = static_cast<std::uint16_t>(t.intensityOffset[sum] + static_cast<int>(c1) * kAxisStrides[1] +
                                                static_cast<int>(c2));
        }
    }
    return bins;
}

// A colour density: a weighted histogram, smoothed by a binomial kernel along each axis (sigma 1 level: neighbouring
// levels share evidence; the background's is smoothed 2 levels along intensity, for shading across cloth folds),
// with a small uniform floor so unseen colours stay finite.
struct ColourModel {
    std::vector<float> logDensity = std::vector<float>(kBins, 0.0f);

    // weight: CV_32F, or CV_8U where non-zero counts 1. intensitySpread: 1 or 2 (smoothing passes along intensity).
    // floorFraction: the share of the mass spread uniformly over all bins (how much the model expects colours it
    // has not seen).
    void build(const cv::Mat& bins, const cv::Mat& weight, int intensitySpread, double floorFraction) {
        std::vector<float> h(kBins, 0.0f);
        double total = 0.0;
        for (int y = 0; y < bins.rows; ++y) {
            const auto* b = bins.ptr<std::uint16_t>(y);
            if (weight.type() == CV_8U) {
                const auto* w = weight.ptr<std::uint8_t>(y);
                for (int x = 0; x < bins.cols; ++x)
                    if (w[x]) {
                        h[b[x]] += 1.0f;
                        total += 1.0;
                    }
            } else {
                const auto* w = weight.ptr<float>(y);
                for (int x = 0; x < bins.cols; ++x)
                    if (w[x] > 0.0f) {
                        h[b[x]] += w[x];
                        total += w[x];
                    }
            }
        }
        for (int pass = 0; pass < intensitySpread; ++pass) smoothAxis(h, 0);
        smoothAxis(h, 1);
        smoothAxis(h, 2);
        const double floorMass = floorFraction * std::max(total, 1.0);
        const double norm = total + floorMass;
        for (std::size_t i = 0; i < h.size(); ++i)
            logDensity[i] = static_cast<float>(std::log((h[i] + floorMass / kBins) / norm));
    }

    // Binomial [1 4 6 4 1]/16 along one axis (sigma 1 level), replicated at the ends.
    static void smoothAxis(std::vector<float>& h, int axis) {
        static constexpr std::array<float, 5> k{1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};
        const int stride = kAxisStrides[static_cast<std::size_t>(axis)];
        const int levels = kAxisLevels[static_cast<std::size_t>(axis)];
        std::vector<float> tmp(h.size());
        for (int i = 0; i < kBins; ++i) {
            const int pos = (i / stride) % levels;
            float acc = 0.0f;
            for (int d = -2; d <= 2; ++d) {
                const int p = std::clamp(pos + d, 0, levels - 1);
                acc += k[static_cast<std::size_t>(d + 2)] * h[static_cast<std::size_t>(i + (p - pos) * stride)];
            }
            tmp[static_cast<std::size_t>(i)] = acc;
        }
        h.swap(tmp);
    }
};

// log p(colour | person) - log p(colour | background) per pixel, from the two models (CV_32F, clamped).
cv::Mat colourLlr(const cv::Mat& bins, const ColourModel& fg, const ColourModel& bg) {
    std::vector<float> lut(kBins);
    for (std::size_t i = 0; i < lut.size(); ++i)
        lut[i] = std::clamp(fg.logDensity[i] - bg.logDensity[i], -kMaxLlr, kMaxLlr);
    cv::Mat llr(bins.size(), CV_32F);
    for (int y = 0; y < bins.rows; ++y) {
        const auto* b = bins.ptr<std::uint16_t>(y);
        auto* o = llr.ptr<float>(y);
        for (int x = 0; x < bins.cols; ++x) o[x] = lut[b[x]];
    }
    return llr;
}

// Evidence from a background plate: the largest per-channel difference (after a 3x3 box blur against camera noise
// when `blur`), turned into a log-likelihood-ratio-like score: 0 at the threshold, -8 for no difference, +8 at twice
// the threshold. The full-size band step does not blur (the blur would widen the person by a pixel); it smooths the
// score instead.
cv::Mat plateLlr(const cv::Mat& bgr, const cv::Mat& plate, double threshold, bool blur) {
    cv::Mat a = bgr, b = plate, diff;
    if (blur) {
        cv::blur(bgr, a, {3, 3});
        cv::blur(plate, b, {3, 3});
    }
    cv::absdiff(a, b, diff);
    std::vector<cv::Mat> ch;
    cv::split(diff, ch);
    cv::Mat d = cv::max(ch[0], cv::max(ch[1], ch[2]));
    cv::Mat llr;
    d.convertTo(llr, CV_32F, kMaxLlr / threshold, -kMaxLlr);  // kMaxLlr * (d - T) / T
    cv::min(llr, kMaxLlr, llr);
    cv::max(llr, -kMaxLlr, llr);
    return llr;
}

// Threshold for plate differences: a multiple of the typical difference on the top/left/right borders (camera
// noise and small exposure drift), kept within [12, 40] grey levels.
double plateThreshold(const cv::Mat& bgr, const cv::Mat& plate, const cv::Mat& borderMask) {
    cv::Mat diff, grey;
    cv::absdiff(bgr, plate, diff);
    cv::cvtColor(diff, grey, cv::COLOR_BGR2GRAY);
    std::vector<std::uint8_t> v;
    for (int y = 0; y < grey.rows; ++y)
        for (int x = 0; x < grey.cols; ++x)
            if (borderMask.at<std::uint8_t>(y, x)) v.push_back(grey.at<std::uint8_t>(y, x));
    if (v.empty()) return 20.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    const double median = v[v.size() / 2];
    return std::clamp(4.0 * median + 8.0, 12.0, 40.0);
}

// The top strip and the upper 55% of the left and right strips (3% of the short side wide): taken as background.
// The bottom is not (shoulders and long hair run out of the frame there), nor the lower sides (a front photo's
// shoulders may run out of the frame at the sides: the scan's front render does, from 78% of the height down).
int borderWidth(cv::Size size) { return std::max(2, static_cast<int>(std::lround(0.03 * std::min(size.width, size.height)))); }

cv::Mat borderStrips(cv::Size size) {
    cv::Mat m = cv::Mat::zeros(size, CV_8U);
    const int w = borderWidth(size);
    const int sideEnd = static_cast<int>(0.55 * size.height);
    m.rowRange(0, w).setTo(255);
    m(cv::Rect(0, 0, w, sideEnd)).setTo(255);
    m(cv::Rect(size.width - w, 0, w, sideEnd)).setTo(255);
    return m;
}

// Fills the holes of a CV_8U 0/255 mask: background not connected to the image border becomes foreground.
void fillHoles(cv::Mat& mask) {
    cv::Mat padded;
    cv::copyMakeBorder(mask, padded, 1, 1, 1, 1, cv::BORDER_CONSTANT, 0);
    cv::floodFill(padded, cv::Point(0, 0), 128, nullptr, 0, 0, 4);
    cv::Mat inner = padded(cv::Rect(1, 1, mask.cols, mask.rows));
    mask.setTo(255, inner == 0);
}

// Keeps the one 8-connected component of a 0/255 mask that overlaps `prefer` most (or the largest when `prefer`
// is empty or overlaps none). Returns its area (0 when the mask is empty).
int keepComponent(cv::Mat& mask, const cv::Mat& prefer) {
    cv::Mat labels, stats, centroids;
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
    if (n <= 1) return 0;
    int best = 0;
    if (!prefer.empty()) {
        std::vector<int> overlap(static_cast<std::size_t>(n), 0);
        for (int y = 0; y < mask.rows; ++y) {
            const auto* l = labels.ptr<int>(y);
            const auto* p = prefer.ptr<std::uint8_t>(y);
            for (int x = 0; x < mask.cols; ++x)
                if (p[x] && l[x] > 0) ++overlap[static_cast<std::size_t>(l[x])];
        }
        const auto it = std::max_element(overlap.begin() + 1, overlap.end());
        if (*it > 0) best = static_cast<int>(it - overlap.begin());
    }
    if (best == 0) {
        int area = 0;
        for (int i = 1; i < n; ++i)
            if (stats.at<int>(i, cv::CC_STAT_AREA) > area) {
                area = stats.at<int>(i, cv::CC_STAT_AREA);
                best = i;
            }
    }
    mask = (labels == best);
    return stats.at<int>(best, cv::CC_STAT_AREA);
}

// One component, holes filled.
void cleanMask(cv::Mat& mask, const cv::Mat& prefer) {
    keepComponent(mask, prefer);
    fillHoles(mask);
}

// Pixels whose chroma ratio c1 = (R - B) / (I + 10) = 3 (R - B) / (B + G + R + 30) exceeds 0.05 (see BinTables).
cv::Mat warmMask(const cv::Mat& bgr) {
    cv::Mat m(bgr.size(), CV_8U);
    for (int y = 0; y < bgr.rows; ++y) {
        const auto* src = bgr.ptr<cv::Vec3b>(y);
        auto* dst = m.ptr<std::uint8_t>(y);
        for (int x = 0; x < bgr.cols; ++x) {
            const int b = src[x][0], g = src[x][1], r = src[x][2];
            dst[x] = 60 * (r - b) > b + g + r + 30 ? 255 : 0;
        }
    }
    return m;
}

// How rare a colour must be under `model` to stand out from the pixels of `mask` the model was learnt on: rarer
// (-log p) than all but their rarest 0.5 %, plus 1 nat. Infinite when the mask is empty.
float rarityLimit(const ColourModel& model, const cv::Mat& bins, const cv::Mat& mask) {
    std::vector<float> rarity;
    for (int y = 0; y < bins.rows; ++y) {
        const auto* b = bins.ptr<std::uint16_t>(y);
        const auto* m = mask.ptr<std::uint8_t>(y);
        for (int x = 0; x < bins.cols; ++x)
            if (m[x]) rarity.push_back(-model.logDensity[b[x]]);
    }
    if (rarity.empty()) return std::numeric_limits<float>::infinity();
    const auto q = rarity.begin() + static_cast<std::ptrdiff_t>(0.995 * static_cast<double>(rarity.size() - 1));
    std::nth_element(rarity.begin(), q, rarity.end());
    return *q + 1.0f;
}

// The border strips' pixels that are background without a plate. The left and right strips are; the top strip may
// hold a tall visitor's hair (the head at the frame's top edge: a synthetic visitor's brown hair, learnt as the
// backdrop's colour, was left out of both silhouettes and the head cut off at the hairline). The top strip's warm
// pixels (skin; brown, black, blond, red hair: warmMask) count only where the side strips' colours hold them likely
// (within their rarityLimit, as the seeds' test below). Its cold ones
// count as they are (a lit fold of a blue cloth at the top is the backdrop; left out, FRMDB 008's curls behind his
// head read as a second profile in the side guide).
cv::Mat backgroundBorder(const cv::Mat& small, const cv::Mat& bins) {
    const int w = borderWidth(bins.size());
    cv::Mat sides = borderStrips(bins.size());
    sides.rowRange(0, w).setTo(0);
    sides(cv::Rect(0, 0, w, w)).setTo(255);
    sides(cv::Rect(bins.cols - w, 0, w, w)).setTo(255);
    ColourModel sideModel;
    sideModel.build(bins, sides, 2, kBgFloor);
    const float limit = rarityLimit(sideModel, bins, sides);
    cv::Mat border = sides.clone();
    const cv::Mat warm = warmMask(small.rowRange(0, w));
    for (int y = 0; y < w; ++y) {
        const auto* b = bins.ptr<std::uint16_t>(y);
        const auto* hot = warm.ptr<std::uint8_t>(y);
        auto* m = border.ptr<std::uint8_t>(y);
        for (int x = 0; x < bins.cols; ++x)
            if (!hot[x] || -sideModel.logDensity[b[x]] <= limit) m[x] = 255;
    }
    return border;
}

// An ellipse filling the middle of a box: where a face box is surely on the person.
cv::Mat ellipseIn(cv::Size size, const cv::Rect& box, double fraction) {
    cv::Mat m = cv::Mat::zeros(size, CV_8U);
    const cv::Point centre(box.x + box.width / 2, box.y + box.height / 2);
    const cv::Size axes(std::max(1, static_cast<int>(box.width * fraction / 2)),
                        std::max(1, static_cast<int>(box.height * fraction / 2)));
    cv::ellipse(m, centre, axes, 0.0, 0.0, 360.0, 255, cv::FILLED);
    return m;
}

void checkInputs(const cv::Mat& bgr, const cv::Mat& plate) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw BoothError(ErrorKind::BadInput, "", "the photo is empty or not an 8-bit colour image");
    if (bgr.cols < 32 || bgr.rows < 32)
        throw BoothError(ErrorKind::BadInput, "", "the photo is too small to segment (under 32 px)");
    if (!plate.empty() && (plate.size() != bgr.size() || plate.type() != CV_8UC3))
        throw BoothError(ErrorKind::BadInput, "",
                         "the background plate is not an 8-bit colour image of the photo's size");
}

}  // namespace

cv::Mat segmentPerson(const cv::Mat& bgr, const cv::Mat& backgroundPlate, cv::Rect headHint) {
    checkInputs(bgr, backgroundPlate);
    const bool havePlate = !backgroundPlate.empty();
    headHint &= cv::Rect(0, 0, bgr.cols, bgr.rows);

    // --- working copy
    // An integer reduction factor: OpenCV's area resize is several times faster for those (0.5 ms instead of 6).
    const int factor = std::max(1, static_cast<int>(std::lround(std::max(bgr.cols, bgr.rows) / kWorkLongSide)));
    const double s = 1.0 / factor;
    cv::Mat small, smallPlate;
    cv::resize(bgr, small, cv::Size(bgr.cols / factor, bgr.rows / factor), 0, 0, cv::INTER_AREA);
    if (havePlate) cv::resize(backgroundPlate, smallPlate, small.size(), 0, 0, cv::INTER_AREA);
    const cv::Mat bins = binIndex(small);
    const cv::Mat border = havePlate ? borderStrips(small.size()) : backgroundBorder(small, bins);
    const double areaSmall = static_cast<double>(small.total());

    cv::Mat hintSmall;  // the head hint at the working size (empty when none)
    if (!headHint.empty()) {
        const cv::Rect r(static_cast<int>(headHint.x * s), static_cast<int>(headHint.y * s),
                         std::max(1, static_cast<int>(headHint.width * s)),
                         std::max(1, static_cast<int>(headHint.height * s)));
        hintSmall = ellipseIn(small.size(), r, 0.6);  // the central 60% of a face box is skin, eyes, nose
    }

    ColourModel fgModel, bgModel;
    bgModel.build(bins, border, 2, kBgFloor);

    // --- first labelling
    cv::Mat llr;
    double plateT = 0.0;
    cv::Mat plateEvidence;
    if (havePlate) {
        plateT = plateThreshold(small, smallPlate, border);
        plateEvidence = plateLlr(small, smallPlate, plateT, true);
        llr = plateEvidence.clone();
    } else {
        // Person colours, first guess: warm colours (R > B: skin, and brown, black, blond, red hair under the booth's
        // light) rarer on the border than nearly every border colour (the border's own 99.5th percentile of
        // -log p, plus 1 nat), and the hint's core. Cold colours are left out of the seed because a lit patch of a
        // blue cloth is as rare on the border as a face; clothes of any colour join in the later rounds when they
        // connect to the person and are unlike the background.
        cv::Mat unlike(small.size(), CV_32F);
        for (int y = 0; y < small.rows; ++y) {
            const auto* b = bins.ptr<std::uint16_t>(y);
            auto* u = unlike.ptr<float>(y);
            for (int x = 0; x < small.cols; ++x) u[x] = -bgModel.logDensity[b[x]];
        }
        const float uThr = rarityLimit(bgModel, bins, border);
        cv::Mat seed = (unlike > uThr) & (border == 0) & warmMask(small);
        if (!hintSmall.empty()) seed |= hintSmall;
        if (cv::countNonZero(seed) < 0.002 * areaSmall)
            throw BoothError(ErrorKind::NoFace, "", "nothing stands out from the background (no person found)");
        fgModel.build(bins, seed, 1, kFgFloor);
        llr = colourLlr(bins, fgModel, bgModel);
    }

    // --- relabel rounds: smooth the evidence, label, keep one component without holes, re-learn both models
    cv::Mat mask;
    const double sigma = 1.5;  // working pixels (~3 px at full size): removes single-pixel noise, keeps the nose
    for (int round = 0; round < kRounds; ++round) {
        cv::Mat smooth;
        cv::GaussianBlur(llr, smooth, {0, 0}, sigma);
        mask = smooth > 0.0f;
        cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {3, 3}));
        cleanMask(mask, hintSmall);
        if (cv::countNonZero(mask) < 0.005 * areaSmall)
            throw BoothError(ErrorKind::NoFace, "", "no person-sized region stands out from the background");
        if (round + 1 == kRounds) break;
        // Re-learn from confident pixels only: 2 px inside and 2 px outside the current edge (mixed pixels at the
        // edge would blur both models). The borders always count as background.
        cv::Mat inner, outer;
        const cv::Mat k5 = cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5});
        cv::erode(mask, inner, k5);
        cv::dilate(mask, outer, k5);
        outer = (outer == 0) | border;
        fgModel.build(bins, inner, 1, kFgFloor);
        bgModel.build(bins, outer, 2, kBgFloor);
        llr = colourLlr(bins, fgModel, bgModel);
        if (havePlate) llr = plateEvidence + 0.5 * llr;  // the plate leads; colour settles dark-on-dark edges
    }

    // --- full resolution: relabel a band around the coarse edge with the same evidence (the working-size models:
    // re-learning at full size would cost more than it gives), smoothed by 1 px. The coarse edge is within about
    // one working pixel of the true one, so the band is +-1.5 working pixels (+-4 px on a 972x544 photo).
    cv::Mat coarse;
    cv::resize(mask, coarse, bgr.size(), 0, 0, cv::INTER_LINEAR);
    coarse = coarse > 127;
    const int bandRadius = static_cast<int>(std::ceil(1.5 / s));
    const cv::Mat kBand = cv::getStructuringElement(cv::MORPH_RECT, {2 * bandRadius + 1, 2 * bandRadius + 1});
    cv::Mat grown, shrunk;
    cv::dilate(coarse, grown, kBand);
    cv::erode(coarse, shrunk, kBand);
    // Everything below works inside the box around the grown mask (plus room for the 1.5 px smoothing).
    const cv::Rect full(0, 0, bgr.cols, bgr.rows);
    const int pad = 4;
    cv::Rect roi = cv::boundingRect(grown);
    roi = cv::Rect(roi.x - pad, roi.y - pad, roi.width + 2 * pad, roi.height + 2 * pad) & full;
    cv::Mat result = cv::Mat::zeros(bgr.size(), CV_8U);
    {
        cv::Mat llrFull = colourLlr(binIndex(bgr(roi)), fgModel, bgModel);
        if (havePlate) llrFull = plateLlr(bgr(roi), backgroundPlate(roi), plateT, false) + 0.5 * llrFull;
        cv::GaussianBlur(llrFull, llrFull, {0, 0}, 1.0);
        const cv::Mat band = grown(roi) & ~shrunk(roi);
        cv::Mat r = result(roi);
        coarse(roi).copyTo(r);
        cv::Mat relabel = llrFull > 0.0f;
        relabel.copyTo(r, band);
        // Smooth edges: a Gaussian of sigma 1.5 px thresholded at half removes stair-steps and one-pixel spurs
        // (leaves a straight edge where it is, rounds corners sharper than ~2 px).
        cv::GaussianBlur(r, r, {0, 0}, 1.5);
        cv::compare(r, 127, r, cv::CMP_GT);
        // One component (the one on the coarse person's core), holes filled.
        cv::Mat core;
        cv::erode(mask, core, cv::getStructuringElement(cv::MORPH_RECT, {5, 5}));
        cv::resize(core, core, bgr.size(), 0, 0, cv::INTER_NEAREST);
        cv::Mat rr = r.clone();
        cleanMask(rr, core(roi));
        rr.copyTo(r);
    }
    return result;
}

std::vector<cv::Point> largestOutline(const cv::Mat& mask) {
    std::vector<std::vector<cv::Point>> contours;
    cv::Mat m = mask.clone();
    cv::findContours(m, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    std::size_t best = 0;
    double bestArea = -1.0;
    for (std::size_t i = 0; i < contours.size(); ++i) {
        const double a = cv::contourArea(contours[i]);
        if (a > bestArea) {
            bestArea = a;
            best = i;
        }
    }
    return contours.empty() ? std::vector<cv::Point>{} : contours[best];
}

double maskIoU(const cv::Mat& a, const cv::Mat& b) {
    CV_Assert(a.size() == b.size() && a.type() == CV_8U && b.type() == CV_8U);
    const double inter = cv::countNonZero(a & b);
    const double uni = cv::countNonZero(a | b);
    return uni == 0.0 ? 1.0 : inter / uni;
}

}  // namespace avatarbooth
