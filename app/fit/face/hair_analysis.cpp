// Hair and beard from the two photos: skin and hair colour models from the face's own windows, then the share of
// hair pixels in windows placed by the landmarks in millimetres (the eye distance gives the front's scale, the
// nasion-to-chin height ties the side's to it).
#include "fit/face/hair_analysis.h"

#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

namespace avatarbooth {
namespace {

// The eye distance the fit assumes (head_fit.cpp: the one length orthographic photos cannot give).
constexpr double kEyeDistanceMm = 63.0;

cv::Mat toLab(const cv::Mat& bgr) {
    cv::Mat f, lab;
    bgr.convertTo(f, CV_32F, 1.0 / 255.0);
    cv::cvtColor(f, lab, cv::COLOR_BGR2Lab);
    return lab;
}

// Lightness counts half: shading moves L* across a head far more than it moves the chroma.
double labDistance(const cv::Vec3f& a, const cv::Vec3d& b) {
    const double dl = 0.5 * (a[0] - b[0]), da = a[1] - b[1], db = a[2] - b[2];
    return std::sqrt(dl * dl + da * da + db * db);
}

double median(std::vector<double>& v) {
    if (v.empty()) return 0.0;
    const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
    std::nth_element(v.begin(), mid, v.end());
    return *mid;
}

// Per-channel medians of the pixels of `image` (3 channels) for which `take(x, y)` holds.
template <typename T>
std::pair<cv::Vec3d, std::size_t> channelMedians(const cv::Mat& image, cv::Rect window,
                                                 const std::function<bool(int, int)>& take) {
    window &= cv::Rect(0, 0, image.cols, image.rows);
    std::array<std::vector<double>, 3> channels;
    for (int y = window.y; y < window.y + window.height; ++y)
        for (int x = window.x; x < window.x + window.width; ++x)
            if (take(x, y)) {
                const auto& p = image.at<cv::Vec<T, 3>>(y, x);
                for (int c = 0; c < 3; ++c) channels[static_cast<std::size_t>(c)].push_back(p[c]);
            }
    const std::size_t n = channels[0].size();
    return {cv::Vec3d(median(channels[0]), median(channels[1]), median(channels[2])), n};
}

// An ellipse's bounding box and membership test.
struct Ellipse {
    cv::Point2d centre;
    double rx = 1.0, ry = 1.0;
    cv::Rect box() const {
        return cv::Rect(cv::Point(static_cast<int>(std::floor(centre.x - rx)), static_cast<int>(std::floor(centre.y - ry))),
                        cv::Point(static_cast<int>(std::ceil(centre.x + rx)) + 1, static_cast<int>(std::ceil(centre.y + ry)) + 1));
    }
    bool contains(int x, int y) const {
        const double u = (x - centre.x) / rx, v = (y - centre.y) / ry;
        return u * u + v * v <= 1.0;
    }
};

cv::Rect rectOf(double x0, double y0, double x1, double y1) {
    return cv::Rect(cv::Point(static_cast<int>(std::lround(std::min(x0, x1))), static_cast<int>(std::lround(std::min(y0, y1)))),
                    cv::Point(static_cast<int>(std::lround(std::max(x0, x1))), static_cast<int>(std::lround(std::max(y0, y1)))));
}

void checkPhoto(const cv::Mat& photo, const cv::Mat& mask, const char* what) {
    if (photo.empty() || photo.type() != CV_8UC3)
        throw BoothError(ErrorKind::BadInput, what, "must be a non-empty BGR image for the hair analysis");
    if (mask.size() != photo.size() || mask.type() != CV_8U)
        throw BoothError(ErrorKind::BadInput, what, "its person mask must be CV_8U and of the photo's size");
}

// Nearer the hair's colour than the skin's, and not far from it (a shirt, the backdrop).
bool isHairColour(const cv::Vec3f& lab, const cv::Vec3d& hairLab, const cv::Vec3d& skinLab) {
    const double dh = labDistance(lab, hairLab);
    return dh < labDistance(lab, skinLab) && dh < 22.0;
}

// The colour models and the windows, shared by the estimate and the overlay.
struct Analysis {
    cv::Mat frontLab, sideLab, side, sideMask;  // the side canonical: nose to the image's right
    cv::Vec3d skinLab{0, 0, 0};
    cv::Vec3d hairLab{0, 0, 0};
    bool hair = false;
    std::vector<cv::Rect> crown;  // one column strip each
    std::array<cv::Rect, 2> temples;  // beside the face, from the image's top to the eyes
    std::array<cv::Rect, 2> besideFace, belowChin;
    cv::Rect chest;  // front: the clothes under the neck, 70-100 mm under the chin, 40 mm either side of the middle
    cv::Rect behindHead, downTheBack;
    std::array<Ellipse, 2> cheeks, jaw;
    Ellipse chin, upperLip;
    // The hair pixels of each photo (CV_8U): hair-coloured, in the silhouette, and joined to the crown's hair (a
    // dark shirt under short hair is no hair: the neck's skin lies between).
    cv::Mat frontHair, sideHair;

    bool isHair(const cv::Vec3f& lab) const { return hair && isHairColour(lab, hairLab, skinLab); }
};

// A skin pixel is within this distance (labDistance) of the cheeks' median; the crown's pixels farther off are
// hair (or a hat).
constexpr double kSkinRadius = 14.0;

double share(const cv::Mat& hair, cv::Rect window) {
    if (window.area() <= 0) return 0.0;
    return static_cast<double>(cv::countNonZero(hair(window & cv::Rect(0, 0, hair.cols, hair.rows)))) /
           static_cast<double>(window.area());
}

// The hair-coloured pixels of the silhouette that are joined to the crown's (`crown`: where the head's top is).
// Bridges thinner than about 3 mm (the shadowed edge of a neck between short hair and a dark shirt) are cut first.
cv::Mat hairJoinedToCrown(const cv::Mat& lab, const cv::Mat& mask, const std::vector<cv::Rect>& crown, const Analysis& a,
                          double pxPerMm) {
    cv::Mat hair(mask.size(), CV_8U, cv::Scalar(0));
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x)
            if (mask.at<std::uint8_t>(y, x) && a.isHair(lab.at<cv::Vec3f>(y, x))) hair.at<std::uint8_t>(y, x) = 255;
    const int k = 2 * static_cast<int>(std::lround(1.5 * pxPerMm)) + 1;
    cv::morphologyEx(hair, hair, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {k, k}));
    cv::Mat labels;
    const int n = cv::connectedComponents(hair, labels, 8, CV_32S);
    std::vector<bool> keep(static_cast<std::size_t>(n), false);
    for (const cv::Rect& r : crown) {
        const cv::Rect in = r & cv::Rect(0, 0, mask.cols, mask.rows);
        for (int y = in.y; y < in.y + in.height; ++y)
            for (int x = in.x; x < in.x + in.width; ++x) keep[static_cast<std::size_t>(labels.at<int>(y, x))] = true;
    }
    keep[0] = false;
    for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x)
            if (!keep[static_cast<std::size_t>(labels.at<int>(y, x))]) hair.at<std::uint8_t>(y, x) = 0;
    return hair;
}

// The side's crown: a band 15 mm deep under the silhouette's top, over 50 mm either side of the ear hole.
std::vector<cv::Rect> sideCrown(const cv::Mat& mask, const cv::Point2d& ear, double pxPerMm) {
    std::vector<cv::Rect> crown;
    for (int x = static_cast<int>(ear.x - 50.0 * pxPerMm); x <= static_cast<int>(ear.x + 50.0 * pxPerMm); ++x) {
        if (x < 0 || x >= mask.cols) continue;
        for (int y = 0; y < mask.rows && y < ear.y - 60.0 * pxPerMm; ++y)
            if (mask.at<std::uint8_t>(y, x)) {
                crown.push_back(cv::Rect(x, y, 1, static_cast<int>(15.0 * pxPerMm) + 1));
                break;
            }
    }
    return crown;
}

// Saturation that shading keeps: C* over L* + 16 (scaling a colour's XYZ by k scales both by k^(1/3)).
double saturation(const cv::Vec3d& lab) { return std::hypot(lab[1], lab[2]) / (std::max(0.0, lab[0]) + 16.0); }

double hueDegrees(const cv::Vec3d& lab) { return std::atan2(lab[2], lab[1]) * 180.0 / 3.14159265358979323846; }

// The hairline's share (HairEvidence::hairline) of one crown column: going up from `from` to `to` (rows, from > to) in
// `lab` (blurred), the largest change within `step` rows over the change from the first row to the last.
double hairlineShare(const cv::Mat& lab, int x, int from, int to, int step) {
    if (from - to <= step) return 0.0;
    const auto at = [&](int y) { return lab.at<cv::Vec3f>(y, x); };
    double largest = 0.0;
    for (int y = from - step; y >= to; --y) largest = std::max(largest, labDistance(at(y), cv::Vec3d(at(y + step))));
    return largest / std::max(1.0, labDistance(at(to), cv::Vec3d(at(from))));
}

Analysis analyse(const HairPhotos& photos, HairEstimate& out, const HairOptions& options) {
    checkPhoto(photos.front, photos.frontMask, "front photo");
    checkPhoto(photos.side, photos.sideMask, "side photo");
    for (const char* name : {"nasion", "chin", "ear_hole"})
        if (!photos.sidePoints.count(name))
            throw BoothError(ErrorKind::BadInput, "side photo", std::string("has no profile landmark '") + name + "' for the hair analysis");
    const auto& p = photos.frontPoints;
    const auto mean = [&](int from, int to) {
        cv::Point2d m(0, 0);
        for (int k = from; k <= to; ++k) m += p[static_cast<std::size_t>(k)];
        return m / static_cast<double>(to - from + 1);
    };
    const cv::Point2d eyeR = mean(36, 41), eyeL = mean(42, 47);
    const double eyePx = cv::norm(eyeL - eyeR);
    if (!(eyePx > 4.0)) throw BoothError(ErrorKind::BadInput, "front photo", "its eyes are too close together for the hair analysis");
    const double mm = eyePx / kEyeDistanceMm;  // front pixels per millimetre
    const double midX = 0.5 * (eyeR.x + eyeL.x);

    Analysis a;
    a.frontLab = toLab(photos.front);
    const cv::Mat& fm = photos.frontMask;
    const auto inFront = [&](int x, int y) { return fm.at<std::uint8_t>(y, x) != 0; };

    // --- Skin: the upper cheeks under the eyes, where no beard grows and the light is the face's own.
    a.cheeks = {Ellipse{eyeR + cv::Point2d(0, 0.45 * eyePx), 0.13 * eyePx, 0.1 * eyePx},
                Ellipse{eyeL + cv::Point2d(0, 0.45 * eyePx), 0.13 * eyePx, 0.1 * eyePx}};
    std::array<std::vector<double>, 3> skin;
    std::array<std::vector<double>, 3> skinBgr;
    for (const Ellipse& e : a.cheeks) {
        const cv::Rect box = e.box() & cv::Rect(0, 0, fm.cols, fm.rows);
        for (int y = box.y; y < box.y + box.height; ++y)
            for (int x = box.x; x < box.x + box.width; ++x)
                if (e.contains(x, y) && inFront(x, y)) {
                    const cv::Vec3f& l = a.frontLab.at<cv::Vec3f>(y, x);
                    const cv::Vec3b& b = photos.front.at<cv::Vec3b>(y, x);
                    for (std::size_t c = 0; c < 3; ++c) skin[c].push_back(l[static_cast<int>(c)]), skinBgr[c].push_back(b[static_cast<int>(c)]);
                }
    }
    if (skin[0].size() < 10) throw BoothError(ErrorKind::BadInput, "front photo", "the cheeks under the eyes are outside the person's silhouette");
    a.skinLab = {median(skin[0]), median(skin[1]), median(skin[2])};
    out.skinLab = a.skinLab;
    out.skinColour = {median(skinBgr[0]), median(skinBgr[1]), median(skinBgr[2])};

    // --- Crown: a band 20 mm deep under the silhouette's top, over the middle 70 % of the face's width.
    const double browY = std::min(p[19].y, p[24].y);
    const double faceLeft = p[0].x, faceRight = p[16].x, faceWidth = faceRight - faceLeft;
    std::size_t crownPixels = 0, farPixels = 0;
    std::array<std::vector<double>, 3> hairLab, hairBgr;
    // Adds the pixel to the hair's colour sample when it is unlike the cheeks' skin; whether it was.
    const auto sampleUnlikeSkin = [&](int x, int y) {
        const cv::Vec3f& l = a.frontLab.at<cv::Vec3f>(y, x);
        if (labDistance(l, a.skinLab) <= kSkinRadius) return false;
        const cv::Vec3b& b = photos.front.at<cv::Vec3b>(y, x);
        for (std::size_t c = 0; c < 3; ++c) hairLab[c].push_back(l[static_cast<int>(c)]), hairBgr[c].push_back(b[static_cast<int>(c)]);
        return true;
    };
    for (int x = static_cast<int>(faceLeft + 0.15 * faceWidth); x <= static_cast<int>(faceRight - 0.15 * faceWidth); ++x) {
        if (x < 0 || x >= fm.cols) continue;
        int top = -1;
        for (int y = 0; y < fm.rows && y < browY; ++y)
            if (fm.at<std::uint8_t>(y, x)) { top = y; break; }
        if (top < 0 || top > browY - 50.0 * mm) continue;  // no head over the brows here
        const int bottom = std::min(static_cast<int>(top + 20.0 * mm), fm.rows - 1);
        a.crown.push_back(cv::Rect(x, top, 1, bottom - top + 1));
        for (int y = top + 1; y <= bottom; ++y) {
            if (!inFront(x, y)) continue;
            ++crownPixels;
            if (sampleUnlikeSkin(x, y)) ++farPixels;
        }
    }
    out.evidence.crown = crownPixels ? static_cast<double>(farPixels) / static_cast<double>(crownPixels) : 0.0;
    cv::Vec3d crownLabSeen{0.0, 0.0, 0.0};
    if (farPixels >= 20) {
        a.hair = true;
        const cv::Vec3d crownLab{median(hairLab[0]), median(hairLab[1]), median(hairLab[2])};
        crownLabSeen = crownLab;
        out.evidence.hairFromSkin = labDistance(cv::Vec3f(crownLab), a.skinLab);

        // --- The hair's colour: the crown's pixels unlike skin and those beside the face from the head's top to the
        // eyes (the temples, or the hair falling past them). The crown alone is where the light falls hardest:
        // light blond hair read pale grey there, too far from its own strands lower down to find them
        // (HairPopulation 22 and 28, long hair read as short).
        // The silhouette can reach into a backdrop of little contrast beside the head (frmdb's dark curtains, by
        // up to 30-40 px): a pixel there nearer the backdrop's colour (the windows' pixels off the silhouette) than
        // the crown's hair is not sampled.
        const int eyeY = static_cast<int>(std::min(eyeR.y, eyeL.y));
        a.temples = {rectOf(faceLeft - 40.0 * mm, 0, faceLeft, eyeY), rectOf(faceRight, 0, faceRight + 40.0 * mm, eyeY)};
        std::array<std::vector<double>, 3> off;
        for (const cv::Rect& r : a.temples) {
            const cv::Rect t = r & cv::Rect(0, 0, fm.cols, fm.rows);
            for (int y = t.y; y < t.y + t.height; ++y)
                for (int x = t.x; x < t.x + t.width; ++x)
                    if (!inFront(x, y)) {
                        const cv::Vec3f& l = a.frontLab.at<cv::Vec3f>(y, x);
                        for (std::size_t c = 0; c < 3; ++c) off[c].push_back(l[static_cast<int>(c)]);
                    }
        }
        const bool backdropSeen = off[0].size() >= 100;
        const cv::Vec3d backdropLab = backdropSeen ? cv::Vec3d{median(off[0]), median(off[1]), median(off[2])} : cv::Vec3d{};
        for (const cv::Rect& r : a.temples) {
            const cv::Rect t = r & cv::Rect(0, 0, fm.cols, fm.rows);
            for (int x = t.x; x < t.x + t.width; ++x)
                for (int y = t.y; y < t.y + t.height; ++y) {
                    if (!inFront(x, y)) continue;
                    const cv::Vec3f& l = a.frontLab.at<cv::Vec3f>(y, x);
                    if (backdropSeen && labDistance(l, backdropLab) < labDistance(l, crownLab)) continue;
                    sampleUnlikeSkin(x, y);
                }
        }
        a.hairLab = {median(hairLab[0]), median(hairLab[1]), median(hairLab[2])};
        out.hairLab = a.hairLab;
        out.colour = {median(hairBgr[0]), median(hairBgr[1]), median(hairBgr[2])};

        // --- Hair, or the forehead's skin in the shade (HairOptions::shadeHueShift says why): the crown's colour.
        const auto [forehead, foreheadPixels] =
            channelMedians<float>(a.frontLab, rectOf(midX - 15.0 * mm, browY - 20.0 * mm, midX + 15.0 * mm, browY - 5.0 * mm), inFront);
        HairEvidence& e = out.evidence;
        e.foreheadFromSkin = labDistance(cv::Vec3f(forehead), a.skinLab);
        e.crownHueShift = std::abs(std::remainder(hueDegrees(crownLab) - hueDegrees(forehead), 360.0));
        e.crownSaturation = saturation(crownLab) / std::max(1e-3, saturation(forehead));
        // Each crown column from 10 mm over the brows (above the brows' hair) to 3 mm under the silhouette's top
        // (whose pixels mix with the backdrop), blurred by 1 mm (single hairs, the camera's noise).
        const int from = static_cast<int>(browY - 10.0 * mm);
        cv::Rect span(0, 0, 0, 0);
        for (const cv::Rect& r : a.crown) span |= cv::Rect(r.x, r.y, 1, std::max(1, from - r.y + 1));
        span &= cv::Rect(0, 0, fm.cols, fm.rows);
        std::vector<double> shares;
        if (span.area() > 0 && foreheadPixels > 0) {
            cv::Mat blurred;
            cv::GaussianBlur(a.frontLab(span), blurred, cv::Size(0, 0), 1.0 * mm);
            const int step = std::max(1, static_cast<int>(std::lround(4.0 * mm)));
            for (const cv::Rect& r : a.crown) {
                const int to = static_cast<int>(r.y + 3.0 * mm);
                if (from >= span.y + span.height || to < span.y) continue;
                shares.push_back(hairlineShare(blurred, r.x - span.x, from - span.y, to - span.y, step));
            }
        }
        e.hairline = median(shares);
        const bool foreheadIsSkin = foreheadPixels > 0 && e.foreheadFromSkin <= kSkinRadius;
        if (foreheadIsSkin && e.crownHueShift <= options.shadeHueShift && e.crownSaturation > options.shadeSaturation &&
            e.hairline <= options.hairlineStep)
            a.hair = false;
    }

    // --- Front windows: beside the jaw from the nose's base to the lower lip, and beside the neck under the chin.
    const double jawR = std::min({p[3].x, p[4].x, p[5].x}), jawL = std::max({p[11].x, p[12].x, p[13].x});
    const double besideTop = p[33].y + 4.0 * mm, besideBottom = p[57].y;
    a.besideFace = {rectOf(jawR - 30.0 * mm, besideTop, jawR - 6.0 * mm, besideBottom),
                    rectOf(jawL + 6.0 * mm, besideTop, jawL + 30.0 * mm, besideBottom)};
    const double chinY = p[8].y;
    a.belowChin = {rectOf(midX - 100.0 * mm, chinY + 10.0 * mm, midX - 55.0 * mm, chinY + 45.0 * mm),
                   rectOf(midX + 55.0 * mm, chinY + 10.0 * mm, midX + 100.0 * mm, chinY + 45.0 * mm)};
    a.chest = rectOf(midX - 40.0 * mm, chinY + 70.0 * mm, midX + 40.0 * mm, chinY + 100.0 * mm);

    // --- Side: canonical (nose right), scaled by the nasion-to-chin height against the front's.
    const bool mirror = !photos.sideNoseImageRight;
    const int sw = photos.side.cols;
    const auto canon = [&](cv::Point2d q) { return mirror ? cv::Point2d(sw - 1 - q.x, q.y) : q; };
    if (mirror) {
        cv::flip(photos.side, a.side, 1);
        cv::flip(photos.sideMask, a.sideMask, 1);
    } else {
        a.side = photos.side;
        a.sideMask = photos.sideMask;
    }
    a.sideLab = toLab(a.side);
    const cv::Point2d nasion = canon(photos.sidePoints.at("nasion")), chinS = canon(photos.sidePoints.at("chin"));
    const cv::Point2d ear = canon(photos.sidePoints.at("ear_hole"));
    const double heightMm = (p[8].y - p[27].y) / mm;
    const double smm = heightMm > 1.0 ? std::abs(chinS.y - nasion.y) / heightMm : mm;  // side pixels per millimetre
    // A ponytail hangs from the back of the head, below it: windows under the rearmost point of the head's outline
    // (hair included: the tied tail's end) 25-70 mm over the ear hole, not at a distance from the ear (heads and hair
    // volumes differ: HairPopulation's ponytails 12 and 16 hung 160-200 mm behind the ear hole, past windows set
    // 65-160 mm behind it). Under short hair these windows hold the backdrop, and the nape's skin at their edge.
    int backX = std::numeric_limits<int>::max();
    for (int y = std::max(0, static_cast<int>(ear.y - 70.0 * smm)); y <= static_cast<int>(ear.y - 25.0 * smm) && y < a.sideMask.rows; ++y)
        for (int x = 0; x < static_cast<int>(ear.x) && x < a.sideMask.cols; ++x)
            if (a.sideMask.at<std::uint8_t>(y, x)) {
                backX = std::min(backX, x);
                break;
            }
    if (backX == std::numeric_limits<int>::max()) backX = static_cast<int>(ear.x - 100.0 * smm);  // no outline there
    a.behindHead = rectOf(backX - 25.0 * smm, ear.y + 48.0 * smm, backX + 45.0 * smm, ear.y + 70.0 * smm);
    a.downTheBack = rectOf(backX - 30.0 * smm, ear.y + 75.0 * smm, backX + 40.0 * smm, ear.y + 100.0 * smm);
    if (a.hair) {
        // The hair's colour from the side photo's crown too (a band 15 mm deep under its outline, 50 mm either side
        // of the ear hole): its pixels unlike skin, but not those nearer the backdrop's colour (the same columns over
        // the outline) than the front crown's hair. The side sees the hair in another light than the front's top
        // light: HairPopulation's colour error dE median 10.2 -> 8.7, worst 24.4 -> 22.1.
        const std::vector<cv::Rect> band = sideCrown(a.sideMask, ear, smm);
        std::array<std::vector<double>, 3> off;
        for (const cv::Rect& r : band)
            for (int y = std::max(0, r.y - static_cast<int>(20.0 * smm)); y < r.y; ++y) {
                const cv::Vec3f& l = a.sideLab.at<cv::Vec3f>(y, r.x);
                for (std::size_t c = 0; c < 3; ++c) off[c].push_back(l[static_cast<int>(c)]);
            }
        const bool seen = off[0].size() >= 100;
        const cv::Vec3d backdrop = seen ? cv::Vec3d{median(off[0]), median(off[1]), median(off[2])} : cv::Vec3d{};
        for (const cv::Rect& r : band)
            for (int y = r.y + 1; y < std::min(r.y + r.height, a.sideMask.rows); ++y) {
                if (!a.sideMask.at<std::uint8_t>(y, r.x)) continue;
                const cv::Vec3f& l = a.sideLab.at<cv::Vec3f>(y, r.x);
                if (labDistance(l, a.skinLab) <= kSkinRadius) continue;
                if (seen && labDistance(l, backdrop) < labDistance(l, crownLabSeen)) continue;
                const cv::Vec3b& b = a.side.at<cv::Vec3b>(y, r.x);
                for (std::size_t c = 0; c < 3; ++c) hairLab[c].push_back(l[static_cast<int>(c)]), hairBgr[c].push_back(b[static_cast<int>(c)]);
            }
        a.hairLab = {median(hairLab[0]), median(hairLab[1]), median(hairLab[2])};
        out.hairLab = a.hairLab;
        out.colour = {median(hairBgr[0]), median(hairBgr[1]), median(hairBgr[2])};
    }
    // The front's hair is what joins the crown or the temples (where the hair's colour was read).
    std::vector<cv::Rect> frontSeeds = a.crown;
    frontSeeds.insert(frontSeeds.end(), a.temples.begin(), a.temples.end());
    a.frontHair = hairJoinedToCrown(a.frontLab, photos.frontMask, frontSeeds, a, mm);
    a.sideHair = hairJoinedToCrown(a.sideLab, a.sideMask, sideCrown(a.sideMask, ear, smm), a, smm);

    // --- Beard windows: the chin between the lower lip and the chin's edge, the upper lip, the jaw beside the mouth.
    a.chin = Ellipse{0.5 * (p[57] + p[8]), 0.14 * eyePx, 0.3 * std::abs(p[8].y - p[57].y)};
    a.upperLip = Ellipse{0.5 * (p[33] + p[51]), 0.22 * eyePx, 0.3 * std::abs(p[51].y - p[33].y)};
    a.jaw = {Ellipse{0.5 * (p[5] + p[48]), 0.09 * eyePx, 0.09 * eyePx}, Ellipse{0.5 * (p[11] + p[54]), 0.09 * eyePx, 0.09 * eyePx}};
    return a;
}

}  // namespace

std::optional<HairStyle> hairStyleFromString(std::string_view name) {
    for (const HairStyle s : kHairStyles)
        if (name == toString(s)) return s;
    return std::nullopt;
}

HairEstimate estimateHair(const HairPhotos& photos, const HairOptions& options) {
    HairEstimate out;
    const Analysis a = analyse(photos, out, options);
    HairEvidence& e = out.evidence;
    e.besideFace = 0.5 * (share(a.frontHair, a.besideFace[0]) + share(a.frontHair, a.besideFace[1]));
    e.belowChin = 0.5 * (share(a.frontHair, a.belowChin[0]) + share(a.frontHair, a.belowChin[1]));
    e.behindHead = share(a.sideHair, a.behindHead);
    e.downTheBack = share(a.sideHair, a.downTheBack);
    // The clothes under the neck (when the photo shows them: half the chest window on the person): the share of
    // their pixels of the hair's colour. Of the hair's own colour, they fill the windows beside the neck as hair
    // would (HairPopulation 29's brown bob over a brown shirt read long).
    if (a.hair) {
        const cv::Rect chest = a.chest & cv::Rect(0, 0, photos.frontMask.cols, photos.frontMask.rows);
        int onPerson = 0, hairColoured = 0;
        for (int y = chest.y; y < chest.y + chest.height; ++y)
            for (int x = chest.x; x < chest.x + chest.width; ++x)
                if (photos.frontMask.at<std::uint8_t>(y, x)) {
                    ++onPerson;
                    hairColoured += a.isHair(a.frontLab.at<cv::Vec3f>(y, x));
                }
        if (2 * onPerson >= std::max(1, a.chest.area()))
            e.clothesAsHair = static_cast<double>(hairColoured) / onPerson;
    }
    const bool clothesLikeHair = e.clothesAsHair > options.clothesAsHair;
    const bool tiedBack = e.downTheBack > options.ponytail && e.behindHead > options.ponytail;

    // Long hair shows beside the neck in the front photo (unless the clothes there are of its colour: then the side
    // photo's hair down the back says it); a ponytail only down the back in the side photo, with
    // nothing beside the face, hanging from the back of the head down (a dark shirt under short hair fills the lower
    // window alone); a bob beside the face down to the jaw (filling it, when the side shows hair tied back). The
    // side's windows sit where hoods and collars often are, so the front decides where it can.
    // Few crown pixels unlike skin is no hair, unless a hairline shows: hair of the skin's own colour.
    if (!a.hair || (e.crown < options.bald && e.hairline <= options.hairlineStep)) out.style = HairStyle::None;
    else if (e.belowChin > options.long_ && e.besideFace > options.longBeside &&
             (!clothesLikeHair || e.downTheBack > options.longDownTheBack))
        out.style = HairStyle::Long;
    else if (e.besideFace > (tiedBack ? options.tiedBackBeside : options.beside)) out.style = HairStyle::Bob;
    else if (tiedBack) out.style = HairStyle::Ponytail;
    else out.style = HairStyle::Short;
    if (out.style == HairStyle::None) out.colour = {0, 0, 0};

    // Beard and moustache: lightness under the upper cheeks'.
    const auto lightness = [&](const Ellipse& el) {
        return channelMedians<float>(a.frontLab, el.box(), [&](int x, int y) {
                   return el.contains(x, y) && photos.frontMask.at<std::uint8_t>(y, x) != 0;
               }).first[0];
    };
    const auto bgr = [&](const Ellipse& el) {
        return channelMedians<std::uint8_t>(photos.front, el.box(), [&](int x, int y) { return el.contains(x, y); }).first;
    };
    e.chinDarkening = a.skinLab[0] - lightness(a.chin);
    e.upperLipDarkening = a.skinLab[0] - lightness(a.upperLip);
    e.jawDarkening = a.skinLab[0] - std::max(lightness(a.jaw[0]), lightness(a.jaw[1]));
    out.beard = e.chinDarkening > options.beardDarkening && e.jawDarkening > 0.5 * options.beardDarkening;
    out.moustache = e.upperLipDarkening > options.moustacheDarkening;
    if (out.beard) out.beardColour = bgr(a.chin);
    else if (out.moustache) out.beardColour = bgr(a.upperLip);
    return out;
}

cv::Mat hairPixels(const cv::Mat& bgr, const cv::Mat& personMask, const HairEstimate& estimate) {
    checkPhoto(bgr, personMask, "photo");
    cv::Mat out(bgr.size(), CV_8U, cv::Scalar(0));
    if (estimate.style == HairStyle::None) return out;
    // Only the person's pixels can be hair: the box round them is converted, not the whole frame.
    const cv::Rect box = cv::boundingRect(personMask);
    if (box.empty()) return out;
    const cv::Mat lab = toLab(bgr(box));
    for (int y = 0; y < box.height; ++y)
        for (int x = 0; x < box.width; ++x)
            if (personMask.at<std::uint8_t>(box.y + y, box.x + x) &&
                isHairColour(lab.at<cv::Vec3f>(y, x), estimate.hairLab, estimate.skinLab))
                out.at<std::uint8_t>(box.y + y, box.x + x) = 255;
    return out;
}

std::pair<cv::Mat, cv::Mat> drawHairOverlay(const HairPhotos& photos, const HairEstimate& estimate) {
    HairEstimate scratch;
    const Analysis a = analyse(photos, scratch, HairOptions{});
    const auto tint = [&](cv::Mat& canvas, const cv::Mat& hair) {
        for (int y = 0; y < canvas.rows; ++y)
            for (int x = 0; x < canvas.cols; ++x)
                if (hair.at<std::uint8_t>(y, x)) canvas.at<cv::Vec3b>(y, x) = 0.5 * canvas.at<cv::Vec3b>(y, x) + 0.5 * cv::Vec3b(255, 0, 255);
    };
    cv::Mat front = photos.front.clone(), side = a.side.clone();
    tint(front, a.frontHair);
    tint(side, a.sideHair);
    const cv::Scalar yellow(0, 255, 255), cyan(255, 255, 0);
    for (const auto& r : a.crown) cv::rectangle(front, r, cv::Scalar(0, 160, 255), 1);
    for (const auto& r : a.besideFace) cv::rectangle(front, r, yellow, 2);
    for (const auto& r : a.belowChin) cv::rectangle(front, r, cyan, 2);
    cv::rectangle(side, a.behindHead, yellow, 2);
    cv::rectangle(side, a.downTheBack, cyan, 2);
    for (const Ellipse* el : {&a.cheeks[0], &a.cheeks[1], &a.jaw[0], &a.jaw[1], &a.chin, &a.upperLip})
        cv::ellipse(front, el->centre, cv::Size(static_cast<int>(el->rx), static_cast<int>(el->ry)), 0, 0, 360, cv::Scalar(0, 255, 0), 1);
    const std::string label = std::string(toString(estimate.style)) + (estimate.beard ? " +beard" : "") +
                              (estimate.moustache ? " +moustache" : "");
    const double scale = std::max(0.6, front.cols / 1000.0);
    cv::putText(front, label, cv::Point(10, static_cast<int>(30 * scale)), cv::FONT_HERSHEY_SIMPLEX, scale, yellow, 2);
    cv::rectangle(front, cv::Rect(10, static_cast<int>(40 * scale), static_cast<int>(40 * scale), static_cast<int>(40 * scale)),
                  cv::Scalar(estimate.colour[0], estimate.colour[1], estimate.colour[2]), cv::FILLED);
    if (!photos.sideNoseImageRight) cv::flip(side, side, 1);
    return {front, side};
}

}  // namespace avatarbooth
