// Profile landmarks from a head's silhouette outline, and the side-photo analysis built on them.
//
// Landmark definitions (soft tissue, face pointing +x, y down; V = nose tip height below the top of the head, the
// scale every window below is measured in; for an adult V is about 14.5 cm, 62% of the 23 cm vertex-to-chin height):
//   top_of_head   vertex: the highest point (middle of the topmost run when the top is flat).
//   nose_tip      pronasale: the most forward point of the face; found as the forward bulge that stands out most
//                 (see noseCandidate) and is the most forward of those that pass.
//   nasion        the deepest point of the concavity between the forehead and the nose: first the deepest point
//                 under the chord from the profile point 0.45 V above the nose tip to the nose tip (the nasion sits
//                 0.20-0.26 V above it on the sample profiles), then again under the chord from the glabella to the
//                 nose tip.
//   glabella      the most forward point of the brow within 0.2 V (~3 cm) above the nasion.
//   forehead      the profile point half-way in height between the top of the head and the glabella.
//   subnasale     the deepest point under the chord from the nose tip to the upper lip.
//   upper_lip,    labrale superius / inferius: the two most prominent forward bulges between the nose tip and the
//   lower_lip     chin (prominence = depth of the dips on both sides).
//   chin          soft-tissue pogonion: the most forward point of the chin (see the chin block below).
//   throat        cervical point: the deepest point under the chord from the chin to the front of the neck
//                 0.45 V (~6.5 cm) below the chin.
//   back_of_head  opisthocranion: the most backward point of the outline between 0.1 V below the top and 0.15 V
//                 below the glabella (with hair, the hair's outline: a silhouette cannot see the skull).
//   ear_hole      porion, estimated (see estimateEarHole).
#include "fit/face/profile.h"

#include "common/error.h"
#include "fit/fit_error.h"
#include "fit/face/landmarks68.h"
#include "fit/face/silhouette.h"

#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <mutex>
#include <optional>

namespace avatarbooth {
namespace {

using Curve = std::vector<cv::Point2d>;

// Resampling step: 1/600 of the outline's height (0.7 px on a 420 px tall head-and-shoulders outline; 0.4 mm on a
// 250 mm base-head outline): fine enough that no landmark moves by more than half a step.
constexpr double kStepsPerHeight = 600.0;
// Smoothing of the resampled outline before looking for extrema: sigma 0.004 of the outline's height (1.7 px on
// the frmdb photos): removes the pixel staircase and single-pixel noise of a mask's outline, keeps the lips.
constexpr double kSmoothSigmaPerHeight = 0.004;
// Hysteresis for "this is a real bulge/dip" on the outline before the scale is known: 0.2% of the outline height.
constexpr double kCandidateHysteresis = 0.002;
// Hysteresis for the lips and chin, once the scale V is known: 0.006 V (about 0.9 mm).
constexpr double kFeatureHysteresis = 0.006;
// A nose stands out from the profile by at least 3.5% of V on both sides (5 mm; real noses: 15-25 mm above,
// 12-20 mm below). A front view's silhouette rarely has one; the plausibility checks in fitProfile catch the rest.
constexpr double kMinNoseProminence = 0.035;
// The head around a nose candidate must be at least 0.8 V long at half its height (real heads: ~1.3 V). This
// keeps the chest or a shoulder, far below the head, from passing as a nose.
constexpr double kMinHeadLengthOverV = 0.8;
// Direction the chin is looked for along: 20 degrees below forward. A chin outline receding at less than 20 degrees
// from the vertical still yields its lowest forward point, and the under-chin (running back at 45-80 degrees) and
// bumps under the jaw score lower; a lower lip scores higher only when it stands in front of the chin by more than
// 0.36 times its height above it (handled below).
constexpr double kChinTilt = 20.0 * CV_PI / 180.0;

// ---------------------------------------------------------------------------------------------- curve helpers

double signedArea(const Curve& c) {
    double a = 0.0;
    for (std::size_t i = 0, n = c.size(); i < n; ++i) {
        const cv::Point2d& p = c[i];
        const cv::Point2d& q = c[(i + 1) % n];
        a += p.x * q.y - q.x * p.y;
    }
    return 0.5 * a;
}

// Points every `step` along the closed polygon's arc length.
Curve resampleClosed(const Curve& in, double step) {
    Curve out;
    const std::size_t n = in.size();
    double carry = 0.0;  // arc length left over from the previous edge before the next sample
    for (std::size_t i = 0; i < n; ++i) {
        const cv::Point2d a = in[i];
        const cv::Point2d b = in[(i + 1) % n];
        const double len = cv::norm(b - a);
        if (len <= 0.0) continue;
        double t = carry;
        while (t < len) {
            out.push_back(a + (b - a) * (t / len));
            t += step;
        }
        carry = t - len;
    }
    return out;
}

// Gaussian smoothing of a closed curve (sigma in samples).
Curve smoothClosed(const Curve& c, double sigma) {
    const int n = static_cast<int>(c.size());
    const int r = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
    std::vector<double> k(static_cast<std::size_t>(2 * r + 1));
    double sum = 0.0;
    for (int d = -r; d <= r; ++d) sum += k[static_cast<std::size_t>(d + r)] = std::exp(-0.5 * d * d / (sigma * sigma));
    for (double& w : k) w /= sum;
    Curve out(c.size());
    for (int i = 0; i < n; ++i) {
        cv::Point2d acc(0.0, 0.0);
        for (int d = -r; d <= r; ++d)
            acc += c[static_cast<std::size_t>(((i + d) % n + n) % n)] * k[static_cast<std::size_t>(d + r)];
        out[static_cast<std::size_t>(i)] = acc;
    }
    return out;
}

struct Extremum {
    int index;
    bool isMax;
};

// Alternating local maxima and minima of v[from..to] with hysteresis: an extremum counts once the values have moved
// `delta` away from it. The ends of the range are not reported.
std::vector<Extremum> zigzag(const std::vector<double>& v, int from, int to, double delta) {
    std::vector<Extremum> out;
    int dir = 0;
    int ext = from;
    for (int i = from + 1; i <= to; ++i) {
        const double x = v[static_cast<std::size_t>(i)];
        if (dir == 0) {
            if (x - v[static_cast<std::size_t>(from)] >= delta) dir = +1, ext = i;
            else if (v[static_cast<std::size_t>(from)] - x >= delta) dir = -1, ext = i;
        } else if (dir > 0) {
            if (x > v[static_cast<std::size_t>(ext)]) ext = i;
            else if (v[static_cast<std::size_t>(ext)] - x >= delta) {
                out.push_back({ext, true});
                dir = -1;
                ext = i;
            }
        } else {
            if (x < v[static_cast<std::size_t>(ext)]) ext = i;
            else if (x - v[static_cast<std::size_t>(ext)] >= delta) {
                out.push_back({ext, false});
                dir = +1;
                ext = i;
            }
        }
    }
    return out;
}

// --------------------------------------------------------------------------------------- the profile chains

// The outline as seen from the top of the head: the front chain runs from the top forward and down the face to
// the outline's lowest level; x values of the smoothed chain for extrema, raw points for the answers.
struct Chain {
    Curve pts;     // smoothed
    Curve raw;     // resampled, unsmoothed (same indices)
    std::vector<double> x;
    int size() const { return static_cast<int>(pts.size()); }
    const cv::Point2d& p(int i) const { return pts[static_cast<std::size_t>(i)]; }
    double y(int i) const { return pts[static_cast<std::size_t>(i)].y; }
    double xv(int i) const { return x[static_cast<std::size_t>(i)]; }
};

Chain makeChain(const Curve& smooth, const Curve& raw, int start, int dir, double yStop) {
    Chain c;
    const int n = static_cast<int>(smooth.size());
    for (int k = 0; k < n; ++k) {
        const auto i = static_cast<std::size_t>(((start + dir * k) % n + n) % n);
        c.pts.push_back(smooth[i]);
        c.raw.push_back(raw[i]);
        c.x.push_back(smooth[i].x);
        if (smooth[i].y >= yStop) break;
    }
    return c;
}

int argmaxX(const Chain& c, int a, int b) {
    int best = a;
    for (int i = a; i <= b; ++i)
        if (c.xv(i) > c.xv(best)) best = i;
    return best;
}

// The point of c[a..b] deepest behind the chord from c[a] to c[b] (for a chord running down the face, "behind"
// is towards -x): the bottom of a concavity.
int deepestUnderChord(const Chain& c, int a, int b) {
    if (b - a < 2) return a;
    const cv::Point2d A = c.p(a), d = c.p(b) - A;
    const double len = cv::norm(d);
    if (len <= 0.0) return (a + b) / 2;
    const cv::Point2d n(-d.y / len, d.x / len);
    int best = a + 1;
    double bestDepth = -std::numeric_limits<double>::infinity();
    for (int i = a + 1; i < b; ++i) {
        const double depth = (c.p(i) - A).dot(n);
        if (depth > bestDepth) {
            bestDepth = depth;
            best = i;
        }
    }
    return best;
}

// First index walking from `from` in direction `dir` (within the chain) whose y passes `level` (>= when going down
// the chain, <= when going up it); the chain's end when none does.
int walkToLevel(const Chain& c, int from, int dir, double level) {
    int i = from;
    while (i + dir >= 0 && i + dir < c.size()) {
        i += dir;
        if (dir > 0 ? c.y(i) >= level : c.y(i) <= level) return i;
    }
    return i;
}

// Head length (x extent of the whole outline) per height, for the nose candidate check.
struct WidthProfile {
    double y0 = 0.0, step = 1.0;
    std::vector<double> lo, hi;
    WidthProfile(const Curve& c, double yTop, double yBottom, double stepIn) : y0(yTop), step(stepIn) {
        const auto rows = static_cast<std::size_t>(std::max(1.0, std::ceil((yBottom - yTop) / step)) + 1);
        lo.assign(rows, std::numeric_limits<double>::infinity());
        hi.assign(rows, -std::numeric_limits<double>::infinity());
        for (const auto& p : c) {
            const auto r = static_cast<std::size_t>(std::clamp((p.y - y0) / step, 0.0, static_cast<double>(rows - 1)));
            lo[r] = std::min(lo[r], p.x);
            hi[r] = std::max(hi[r], p.x);
        }
    }
    double at(double y) const {
        const auto r = static_cast<std::size_t>(std::clamp((y - y0) / step, 0.0, static_cast<double>(lo.size() - 1)));
        return hi[r] >= lo[r] ? hi[r] - lo[r] : 0.0;
    }
};

struct NoseChoice {
    int index = -1;
    double prominence = 0.0;
};

// Nose tip candidates: the forward bulges of the front chain (local maxima of x) that stand out by
// kMinNoseProminence * V on both sides (V = their own height below the top: the candidate's own scale) within
// 0.4 V above (the nasion is 0.20-0.26 V above the tip) and 0.3 V below (subnasale and lips), on a head at least
// kMinHeadLengthOverV * V long at half that height; the most forward first. Hair can make such a bulge too: a
// fringe or a quiff standing as far forward as the nose (fitProfile tries the next when the face below one is no
// face).
std::vector<NoseChoice> noseCandidates(const Chain& f, double yTop, const WidthProfile& widths, double outlineHeight) {
    std::vector<NoseChoice> out;
    const auto ext = zigzag(f.x, 0, f.size() - 1, kCandidateHysteresis * outlineHeight);
    for (const auto& e : ext) {
        if (!e.isMax) continue;
        const int m = e.index;
        const double V = f.y(m) - yTop;
        if (V < 0.05 * outlineHeight) continue;  // a bump on the crown, not a face
        double minUp = f.xv(m), minDown = f.xv(m);
        for (int i = m - 1; i >= 0 && f.y(i) >= f.y(m) - 0.4 * V; --i) minUp = std::min(minUp, f.xv(i));
        for (int i = m + 1; i < f.size() && f.y(i) <= f.y(m) + 0.3 * V; ++i) minDown = std::min(minDown, f.xv(i));
        const double prominence = std::min(f.xv(m) - minUp, f.xv(m) - minDown) / V;
        if (prominence < kMinNoseProminence) continue;
        if (widths.at(yTop + 0.5 * V) < kMinHeadLengthOverV * V) continue;
        out.push_back({m, prominence});
    }
    std::stable_sort(out.begin(), out.end(),
                     [&](const NoseChoice& a, const NoseChoice& b) { return f.xv(a.index) > f.xv(b.index); });
    return out;
}

ProfileFit fail(std::string why) {
    ProfileFit f;
    f.failure = std::move(why);
    return f;
}

}  // namespace

// Porion (ear hole) estimate. A silhouette does not show the ear, so it is placed by proportions, in a frame
// aligned with the face: the soft-tissue facial line nasion-chin stands about perpendicular to the Frankfurt plane
// (Holdaway's soft-tissue facial angle, about 91 degrees), so turning the profile until that line is vertical
// undoes most of the head's pitch. In that frame the porion lies kEarBehindNasion V behind the nasion and
// kEarBelowNasion V below it. Distances are in V (nose tip below the top of the head), not in head length, because
// hair makes the back of the head a poor reference. Sources:
//  - anthropometry: the porion is level with the orbitale (Frankfurt plane), whose rim is about 25 mm below the
//    nasion (0.17 V); tragion-nasion about 118 mm, with half the tragion breadth (72 mm) and the height removed,
//    leaves about 90 mm (0.62 V) behind the nasion;
//  - ear canals marked by hand on 6 frmdb profiles (002, 003 both sides, 001 left, 006 right) and the scan's +090
//    render: 0.62-0.80 V behind the nasion (mean 0.72), 0.16-0.29 V below it (mean 0.23; the marks are on the
//    centre of the opening, a little below the porion, the top of the canal).
// Measured error of the estimate: about 5% of the head height on the scan (tests/data/profile_data_test.cpp).
constexpr double kEarBehindNasion = 0.72;
constexpr double kEarBelowNasion = 0.21;

cv::Point2d estimateEarHole(const cv::Point2d& nasion, const cv::Point2d& chin, double V) {
    // Rotation about the nasion that makes nasion->chin point straight down (+y), undone on the way out.
    const double theta = std::atan2(chin.x - nasion.x, chin.y - nasion.y);
    const double c = std::cos(theta), s = std::sin(theta);
    const cv::Point2d q(-kEarBehindNasion * V, kEarBelowNasion * V);
    return nasion + cv::Point2d(q.x * c + q.y * s, -q.x * s + q.y * c);
}

namespace {

// Where the front chain reaches the collar when the clothes are not in the outline, after `from` and at least `minY`
// down: the chain's end when the walk down to the neck (`neckLow`) stopped there short of its level (the outline's
// lowest level is the neck's cut), else the first point from which the chain runs back along the collar (0.25 V back
// while dropping less than 0.05 V: long hair hangs lower at the back), anywhere down the rest of the chain. -1 when
// neither.
int collarIndex(const Chain& f, int from, int neckLow, double minY, double V) {
    if (neckLow == f.size() - 1 && f.y(neckLow) >= minY) return neckLow;
    for (int i = from + 1; i < f.size(); ++i) {
        if (f.y(i) < minY) continue;
        for (int j = i + 1; j < f.size() && f.y(j) - f.y(i) <= 0.05 * V; ++j)
            if (f.xv(i) - f.xv(j) >= 0.25 * V) return i;
    }
    return -1;
}

// The landmarks of a profile whose nose tip is `nose` (the rest of fitProfile), or why that is no profile.
ProfileFit fitFromNoseTip(const Chain& f, const Chain& b, const NoseChoice& nose, double yTop) {
    const int iNose = nose.index;
    const double V = f.y(iNose) - yTop;

    ProfileFit fit;
    fit.noseProminence = nose.prominence;
    auto warn = [&](std::string w) { fit.warnings.push_back(std::move(w)); };

    // --- nasion, glabella, forehead
    const int iAbove = walkToLevel(f, iNose, -1, f.y(iNose) - 0.45 * V);
    int iNasion = deepestUnderChord(f, iAbove, iNose);
    const int iBrowWindow = walkToLevel(f, iNasion, -1, f.y(iNasion) - 0.2 * V);
    const int iGlabella = argmaxX(f, iBrowWindow, iNasion);
    if (iGlabella < iNasion) iNasion = deepestUnderChord(f, iGlabella, iNose);
    else warn("no brow bulge above the nasion: glabella set at the nasion");
    const int iForehead = walkToLevel(f, 0, +1, 0.5 * (yTop + f.y(iGlabella)));

    // --- below the nose. First a throat: the deepest point under the chord from the mouth (0.25 V below the nose
    // tip: between the lips) to the neck 1.1 V below the nose tip (or the outline's lowest level).
    const int iMouth = walkToLevel(f, iNose, +1, f.y(iNose) + 0.25 * V);
    const int iNeckLow = walkToLevel(f, iMouth, +1, f.y(iNose) + 1.1 * V);
    int iThroat = deepestUnderChord(f, iMouth, iNeckLow);
    // Without a plate, clothes as cold as the backdrop are left out of the silhouette (segmentPerson): the outline's
    // front ends at the collar, or runs back along it to long hair's ends, and a straight neck shows no throat under
    // that chord (synthetic visitors in blue and teal shirts; the next bulge down, the lips, was then taken for the
    // nose). The chin is then sought down to the collar.
    const int iCollar = iThroat <= iMouth + 1 ? collarIndex(f, iMouth, iNeckLow, f.y(iNose) + 0.5 * V, V) : -1;
    if (iCollar > iMouth + 2) iThroat = iCollar;
    if (iThroat <= iMouth + 1) return fail("no chin and throat below the nose");
    // Chin. First the most forward point along a direction kChinTilt below the horizontal: where the chin's
    // outline turns from running down to running back. It finds the chin whether or not it bulges (a receding
    // chin, a head tipped down, a dark beard lost to the background) and passes over bumps under the jaw.
    const auto ext = zigzag(f.x, iNose, iThroat, kFeatureHysteresis * V);
    const double ca = std::cos(kChinTilt), sa = std::sin(kChinTilt);
    auto tilted = [&](int i) { return f.xv(i) * ca + f.y(i) * sa; };
    int iChin = iMouth + 1;
    for (int i = iMouth + 1; i < iThroat; ++i)
        if (tilted(i) > tilted(iChin)) iChin = i;
    // Less than 0.33 V below the nose tip it is more likely the lower lip (0.2-0.34 V below it on the sample
    // profiles; chins 0.35-0.57 V): then a bulge further down that stands 0.1 V in front of the throat and at
    // most 0.15 V behind this point is the chin.
    if (f.y(iChin) - f.y(iNose) < 0.33 * V) {
        int lower = -1;
        for (const auto& e : ext)
            if (e.isMax && e.index > iChin && f.y(e.index) - f.y(iNose) >= 0.33 * V &&
                f.xv(iChin) - f.xv(e.index) <= 0.15 * V && f.xv(e.index) - f.xv(iThroat) >= 0.1 * V &&
                (lower < 0 || tilted(e.index) > tilted(lower)))
                lower = e.index;
        if (lower >= 0) iChin = lower;
        else warn("chin high under the mouth: it may be the lower lip");
    }
    // Pogonion: when the point lies on the lower slope of a bulge whose top (a local maximum of x, no dip in
    // between) is at most 0.12 V above it, the top is the most forward point of the chin.
    for (const auto& e : ext) {
        if (!e.isMax || e.index <= iMouth || e.index >= iChin || f.y(e.index) < f.y(iChin) - 0.12 * V) continue;
        double lowest = f.xv(e.index);
        for (int i = e.index; i <= iChin; ++i) lowest = std::min(lowest, f.xv(i));
        if (lowest >= f.xv(iChin) - kFeatureHysteresis * V) {
            iChin = e.index;
            break;
        }
    }
    // The throat again, from the chin: the deepest point under the chord from the chin to the neck 0.45 V below it.
    // At the collar (above), a straight neck may show none under that chord either: the collar is the throat.
    const int iLow = walkToLevel(f, iChin, +1, f.y(iChin) + 0.45 * V);
    iThroat = deepestUnderChord(f, iChin, iCollar < 0 ? iLow : std::min(iCollar, iLow));
    bool atCollar = iCollar >= 0;
    if (f.xv(iChin) - f.xv(iThroat) < 0.1 * V) {
        const int collar = iCollar >= 0 ? iCollar : collarIndex(f, iChin, iNeckLow, f.y(iNose) + 0.5 * V, V);
        if (collar > iChin && f.xv(iChin) - f.xv(collar) >= 0.1 * V) {
            iThroat = collar;
            atCollar = true;
        }
    }
    if (atCollar) warn("the outline ends at the collar (clothes left out of the silhouette?): throat sought above it");
    fit.throatAtCollar = atCollar;

    // Lip candidates: bulges strictly between the nose and the chin, away from both by 0.04 V (the nose's underside
    // and the chin's own slope), ranked by prominence (depth of the dips on both sides).
    struct Bulge {
        int index;
        double prominence;
    };
    std::vector<Bulge> bulges;
    for (std::size_t k = 0; k < ext.size(); ++k) {
        const auto& e = ext[k];
        if (!e.isMax || e.index <= iNose || e.index >= iChin) continue;
        if (f.y(e.index) < f.y(iNose) + 0.04 * V || f.y(e.index) > f.y(iChin) - 0.04 * V) continue;
        const double left = k > 0 ? f.xv(ext[k - 1].index) : f.xv(iNose);
        const double right = k + 1 < ext.size() ? f.xv(ext[k + 1].index) : f.xv(iChin);
        bulges.push_back({e.index, std::min(f.xv(e.index) - left, f.xv(e.index) - right)});
    }
    std::sort(bulges.begin(), bulges.end(), [](const Bulge& p, const Bulge& q) { return p.prominence > q.prominence; });
    int iUpper = -1, iLower = -1;
    const double yMid = 0.5 * (f.y(iNose) + f.y(iChin));
    if (bulges.size() >= 2) {
        iUpper = std::min(bulges[0].index, bulges[1].index);
        iLower = std::max(bulges[0].index, bulges[1].index);
    } else if (bulges.size() == 1 && f.y(bulges[0].index) <= yMid) {
        iUpper = bulges[0].index;
        iLower = argmaxX(f, walkToLevel(f, iUpper, +1, f.y(iUpper) + 0.06 * V),
                         walkToLevel(f, iChin, -1, f.y(iChin) - 0.1 * V));
        warn("lower lip not separated from the chin: set at the most forward point between");
    } else if (bulges.size() == 1) {
        iLower = bulges[0].index;
        iUpper = argmaxX(f, walkToLevel(f, iNose, +1, f.y(iNose) + 0.08 * V),
                         walkToLevel(f, iLower, -1, f.y(iLower) - 0.06 * V));
        warn("upper lip not separated from the nose: set at the most forward point between");
    } else {
        const int iMid = walkToLevel(f, iNose, +1, yMid);
        iUpper = argmaxX(f, walkToLevel(f, iNose, +1, f.y(iNose) + 0.1 * V), iMid);
        iLower = argmaxX(f, iMid, walkToLevel(f, iChin, -1, f.y(iChin) - 0.1 * V));
        warn("lips not found as bulges: set at the most forward points of the upper and lower half of the mouth");
    }
    if (!(iNose < iUpper && iUpper < iLower && iLower < iChin))
        return fail("the mouth between nose and chin is too small");
    const int iSubnasale = deepestUnderChord(f, iNose, iUpper);

    // --- back of the head: the most backward point of the back chain in its band, the middle of the run within
    // 0.002 V (0.3 mm) of it (hair hanging straight down makes a long flat run)
    const double backTop = yTop + 0.1 * V, backBottom = f.y(iGlabella) + 0.15 * V;
    int iBack = -1;
    for (int i = 0; i < b.size(); ++i)
        if (b.y(i) >= backTop && b.y(i) <= backBottom && (iBack < 0 || b.xv(i) < b.xv(iBack))) iBack = i;
    if (iBack < 0) return fail("the outline has no back of the head");
    {
        const double tol = b.xv(iBack) + 0.002 * V;
        int lo = iBack, hi = iBack;
        while (lo > 0 && b.xv(lo - 1) <= tol && b.y(lo - 1) >= backTop) --lo;
        while (hi + 1 < b.size() && b.xv(hi + 1) <= tol && b.y(hi + 1) <= backBottom) ++hi;
        iBack = (lo + hi) / 2;
    }

    auto at = [&](int i) { return f.raw[static_cast<std::size_t>(i)]; };
    const cv::Point2d back = b.raw[static_cast<std::size_t>(iBack)];
    const cv::Point2d ear = estimateEarHole(at(iNasion), at(iChin), V);
    fit.landmarks = {{"top_of_head", at(0)},       {"forehead", at(iForehead)},   {"glabella", at(iGlabella)},
                     {"nasion", at(iNasion)},      {"nose_tip", at(iNose)},       {"subnasale", at(iSubnasale)},
                     {"upper_lip", at(iUpper)},    {"lower_lip", at(iLower)},     {"chin", at(iChin)},
                     {"throat", at(iThroat)},      {"back_of_head", back},        {"ear_hole", ear}};
    // Plausibility: proportions far outside any adult face mean the bulge taken for a nose is something else (a
    // lock of hair at the back of the head, an ear or a cheek in a front view). Bounds are the range measured on
    // the 16 frmdb profiles and the scan (in brackets) widened by about half of it:
    //   nasion above the nose tip          0.10-0.38 V  [0.20-0.26; 0.12-0.15 on MakeHuman visitors turned 20
    //                                                  degrees either way, where the far brow and eye, or the near
    //                                                  ones, fill the concavity and its deepest point moves down]
    //   chin below the nose tip            0.22-0.75 V  [0.25-0.57]
    //   chin in front of the throat        >= 0.1 V     [0.18-0.40] (the jaw's underside)
    //   glabella to back of head           0.9-2.0 V    [1.12-1.62] (head length, with hair)
    const double rNasion = (f.y(iNose) - f.y(iNasion)) / V;
    const double rChin = (f.y(iChin) - f.y(iNose)) / V;
    const double rJaw = (f.xv(iChin) - f.xv(iThroat)) / V;
    const double rLength = (f.xv(iGlabella) - b.xv(iBack)) / V;
    auto fmt = [](double v) { return cv::format("%.2f", v); };
    if (rNasion < 0.10 || rNasion > 0.38)
        return fail("implausible profile: nasion " + fmt(rNasion) + " V above the nose tip (expected 0.10-0.38)");
    if (rChin < 0.22 || rChin > 0.75)
        return fail("implausible profile: chin " + fmt(rChin) + " V below the nose tip (expected 0.22-0.75)");
    if (rJaw < 0.1) return fail("implausible profile: no jaw between chin and throat (" + fmt(rJaw) + " V)");
    if (rLength < 0.9 || rLength > 2.0)
        return fail("implausible profile: head length " + fmt(rLength) + " V (expected 0.9-2.0)");

    // Anatomical order, top to bottom, along the chain (ties allowed only glabella/nasion).
    const int order[] = {0, iForehead, iGlabella, iNasion, iNose, iSubnasale, iUpper, iLower, iChin, iThroat};
    for (std::size_t k = 1; k < std::size(order); ++k)
        if (order[k] < order[k - 1] || (order[k] == order[k - 1] && k != 3))
            warn(fit.landmarks[k - 1].name + " and " + fit.landmarks[k].name + " are out of order");
    fit.ok = true;
    return fit;
}

// fitProfile for a face towards +x.
ProfileFit fitProfileFacingRight(const std::vector<cv::Point2d>& outlineIn) {
    // --- clean, orient (top -> forward -> down the face), resample, smooth
    Curve outline;
    for (const auto& p : outlineIn)
        if (outline.empty() || cv::norm(p - outline.back()) > 1e-9) outline.push_back(p);
    while (outline.size() > 1 && cv::norm(outline.front() - outline.back()) <= 1e-9) outline.pop_back();
    if (outline.size() < 8) return fail("the outline has fewer than 8 points");
    double yTopRaw = outline[0].y, yBottom = outline[0].y;
    for (const auto& p : outline) yTopRaw = std::min(yTopRaw, p.y), yBottom = std::max(yBottom, p.y);
    const double height = yBottom - yTopRaw;
    if (height <= 0.0) return fail("the outline is flat");
    if (signedArea(outline) < 0.0) std::reverse(outline.begin(), outline.end());  // y down: top, then +x

    const double step = height / kStepsPerHeight;
    const Curve raw = resampleClosed(outline, step);
    if (raw.size() < 50) return fail("the outline is too short");
    const Curve smooth = smoothClosed(raw, kSmoothSigmaPerHeight * kStepsPerHeight);

    // --- top of head: the highest smoothed point, refined on the unsmoothed outline (smoothing pulls an uneven
    // apex towards its flatter side): the highest raw point within 3 sigma of it, then the middle of the raw run
    // within 0.05% of the height of that (a flat top, or a mask's top row).
    const int n = static_cast<int>(smooth.size());
    auto wrap = [n](int i) { return static_cast<std::size_t>((i % n + n) % n); };
    int iTop = 0;
    for (int i = 0; i < n; ++i)
        if (smooth[wrap(i)].y < smooth[wrap(iTop)].y) iTop = i;
    {
        const int w = static_cast<int>(std::ceil(3.0 * kSmoothSigmaPerHeight * kStepsPerHeight));
        int best = iTop;
        for (int d = -w; d <= w; ++d)
            if (raw[wrap(iTop + d)].y < raw[wrap(best)].y) best = iTop + d;
        const double tol = raw[wrap(best)].y + 0.0005 * height;
        int lo = 0, hi = 0;
        while (lo > -n / 2 && raw[wrap(best + lo - 1)].y <= tol) --lo;
        while (hi < n / 2 && raw[wrap(best + hi + 1)].y <= tol) ++hi;
        iTop = static_cast<int>(wrap(best + (lo + hi) / 2));
    }
    const double yTop = smooth[static_cast<std::size_t>(iTop)].y;
    const double yStop = yBottom - 0.5 * step;  // the chains end where they first reach the outline's lowest level

    const Chain f = makeChain(smooth, raw, iTop, +1, yStop);
    const Chain b = makeChain(smooth, raw, iTop, -1, yStop);
    const WidthProfile widths(smooth, yTop, yBottom, 2.0 * step);

    // --- nose tip: the most forward candidate whose face below and above makes a plausible profile
    const std::vector<NoseChoice> noses = noseCandidates(f, yTop, widths, height);
    if (noses.empty()) return fail("no nose-like forward bulge on the outline");
    ProfileFit first;
    for (std::size_t k = 0; k < noses.size(); ++k) {
        ProfileFit fit = fitFromNoseTip(f, b, noses[k], yTop);
        if (fit.ok) {
            if (k > 0)
                fit.warnings.push_back(cv::format("the most forward bulge (%.2f of the outline's height below its top) "
                                                  "is no nose (%s): taken for hair",
                                                  (f.y(noses[0].index) - yTop) / height, first.failure.c_str()));
            return fit;
        }
        if (k == 0) first = std::move(fit);
    }
    return first;
}

}  // namespace

bool profileFacesRight(const ProfileFit& right, const ProfileFit& left) {
    if (!right.ok || !left.ok) return right.ok;
    // FRMDB 008's curls behind his head made a profile facing back, throat at the collar, more prominent than his face.
    if (right.throatAtCollar != left.throatAtCollar) return !right.throatAtCollar;
    return right.noseProminence >= left.noseProminence;
}

ProfileFit fitProfile(const std::vector<cv::Point2d>& outlineIn, bool noseRight) {
    if (!noseRight) {
        // Mirror (x -> -x), fit, mirror the answers back.
        std::vector<cv::Point2d> mirrored(outlineIn);
        for (auto& p : mirrored) p.x = -p.x;
        ProfileFit fit = fitProfile(mirrored, true);
        for (auto& lm : fit.landmarks) lm.px.x = -lm.px.x;
        return fit;
    }
    return fitProfileFacingRight(outlineIn);
}


std::vector<ProfilePoint> findProfileLandmarks(const std::vector<cv::Point2d>& outline, bool noseRight,
                                               std::vector<std::string>* warnings) {
    ProfileFit fit = fitProfile(outline, noseRight);
    if (!fit.ok) throw BoothError(ErrorKind::NoFace, "", "no profile found: " + fit.failure);
    if (warnings) warnings->insert(warnings->end(), fit.warnings.begin(), fit.warnings.end());
    return std::move(fit.landmarks);
}

cv::Point2d profilePoint(const std::vector<ProfilePoint>& points, std::string_view name) {
    for (const auto& p : points)
        if (p.name == name) return p.px;
    throw BoothError(ErrorKind::Internal, "", "profile point '" + std::string(name) + "' is missing");
}

// ------------------------------------------------------------------------------------------ side photo analysis

FrontalFaceCheck::FrontalFaceCheck(const std::filesystem::path& dir) {
    const std::filesystem::path candidates[] = {
        dir.parent_path() / "lbpcascades" / "lbpcascade_frontalface_improved.xml",
        dir / "lbpcascade_frontalface_improved.xml", dir / "haarcascade_frontalface_alt2.xml"};
    for (const auto& c : candidates) {
        std::error_code ec;
        if (std::filesystem::is_regular_file(c, ec) && cascade_.load(c.string())) {
            source_ = c.string();
            break;
        }
    }
}

std::vector<cv::Rect> FrontalFaceCheck::detect(const cv::Mat& grey, int minSize, int maxSize) {
    std::lock_guard<std::mutex> lock(mutex_);  // detectMultiScale is not safe to call concurrently
    std::vector<cv::Rect> faces;
    // minNeighbors 4: on the frmdb fronts the cascade's merged boxes carry many raw hits, false hits few.
    cascade_.detectMultiScale(grey, faces, 1.1, 4, 0, cv::Size(minSize, minSize), cv::Size(maxSize, maxSize));
    return faces;
}

namespace {

// Looks for a frontal face on the head: the top of the silhouette's box (1.2 box widths tall), scaled to 200 px
// wide, where a frontal face is 40-200 px. Returns the box in photo pixels, or nothing.
std::optional<cv::Rect> findFrontalFace(const cv::Mat& bgr, const cv::Mat& mask, FrontalFaceCheck& check) {
    const cv::Rect box = cv::boundingRect(mask);
    if (box.empty()) return std::nullopt;
    cv::Rect roi(box.x, box.y, box.width, std::min(box.height, static_cast<int>(1.2 * box.width)));
    roi &= cv::Rect(0, 0, bgr.cols, bgr.rows);
    const double scale = std::min(1.0, 200.0 / roi.width);
    cv::Mat grey;
    cv::cvtColor(bgr(roi), grey, cv::COLOR_BGR2GRAY);
    cv::resize(grey, grey, {}, scale, scale, cv::INTER_AREA);
    cv::equalizeHist(grey, grey);
    const int minSide = std::min(grey.cols, grey.rows);
    const auto faces = check.detect(grey, std::max(24, minSide / 5), minSide);
    if (faces.empty()) return std::nullopt;
    const auto& f = *std::max_element(faces.begin(), faces.end(),
                                      [](const cv::Rect& a, const cv::Rect& b) { return a.area() < b.area(); });
    return cv::Rect(roi.x + static_cast<int>(f.x / scale), roi.y + static_cast<int>(f.y / scale),
                    static_cast<int>(f.width / scale), static_cast<int>(f.height / scale));
}

}  // namespace

// The turn from the near eye. Seen in profile the eye lies about 0.1 V behind the nose bridge's outline; turned
// towards the camera it moves back (the face shows more: 60 degrees from the front, about 0.2 V), turned past the
// profile it moves onto the outline and under the brow. Past about 110 degrees the eye is hidden and the darkest
// pixels are the cheek's shadow or hair: the cue saturates there, and a dark-skinned face can read as turned the
// other way. So it only confirms the ear (turnedPastProfile). Calibration: README, issue 22.
constexpr double kEyeBehindAtProfile = 0.10;
constexpr double kEyeBehindPerDegree = 0.0033;

namespace {

// The ear: the skin's folds behind the cheek, on the rows from 0.2 V above the nose tip to 0.15 V below it (the
// concha and the tragus; the top of the ear is the first part hair covers). Only pixels of the cheek's colour
// (in YCrCb's chroma) with skin of that colour 0.03 V to either side count, so that a hairline's edge does not.
// Returns each 0.01 V wide column's mean gradient there, from the nasion back (none when no cheek is seen).
std::vector<double> earColumns(const cv::Mat& bgr, const cv::Mat& mask, const cv::Point2d& nasion,
                               const cv::Point2d& tip, double V, const std::function<int(int)>& frontEdge) {
    // Filtered only around the face and the ear (a preview frame is the camera's whole picture), in the frame's
    // coordinates: the images below are views of the region inside full-frame headers.
    const int margin = cvRound(0.1 * V) + 4;
    const double top = std::min(nasion.y, tip.y - 0.2 * V);
    const cv::Rect region = cv::Rect(cvRound(nasion.x - 1.1 * V) - margin, cvRound(top) - margin,
                                     cvRound(1.1 * V + (tip.x - nasion.x)) + 2 * margin,
                                     cvRound(tip.y + 0.15 * V - top) + 2 * margin) &
                            cv::Rect(0, 0, bgr.cols, bgr.rows);
    if (region.empty()) return {};
    cv::Mat smooth, ycc, luma, gx, gy, grad, inner;
    cv::GaussianBlur(bgr(region), smooth, {0, 0}, std::max(0.8, 0.008 * V));
    cv::cvtColor(smooth, ycc, cv::COLOR_BGR2YCrCb);
    cv::extractChannel(ycc, luma, 0);
    luma.convertTo(luma, CV_32F);
    cv::Sobel(luma, gx, CV_32F, 1, 0);
    cv::Sobel(luma, gy, CV_32F, 0, 1);
    cv::magnitude(gx, gy, grad);
    const int r = cvRound(0.04 * V);
    cv::erode(mask(region), inner, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
    auto inRegion = [&](int x, int y) { return region.contains(cv::Point(x, y)); };
    auto innerAt = [&](int x, int y) { return inRegion(x, y) && inner.at<unsigned char>(y - region.y, x - region.x); };
    auto yccAt = [&](int x, int y) { return ycc.at<cv::Vec3b>(y - region.y, x - region.x); };
    // The cheek's chroma: the median on the lower 60% of the rows from the nasion to the nose tip (a head turned
    // past the profile has its nasion only 0.15 V above the tip), 0.12-0.25 V behind the face's edge.
    std::vector<int> cr, cb;
    const int cheekTop = std::max(0, cvRound(nasion.y + 0.4 * (tip.y - nasion.y)));
    for (int y = cheekTop; y <= std::min(bgr.rows - 1, cvRound(tip.y)); ++y) {
        const int edge = frontEdge(y);
        if (edge < 0) continue;
        for (int x = std::max(0, cvRound(edge - 0.25 * V)); x <= edge - 0.12 * V; ++x)
            if (innerAt(x, y)) {
                const cv::Vec3b p = yccAt(x, y);
                cr.push_back(p[1]);
                cb.push_back(p[2]);
            }
    }
    if (cr.size() < 20) return {};  // no cheek seen
    std::nth_element(cr.begin(), cr.begin() + cr.size() / 2, cr.end());
    std::nth_element(cb.begin(), cb.begin() + cb.size() / 2, cb.end());
    const int cr0 = cr[cr.size() / 2], cb0 = cb[cb.size() / 2];
    constexpr int kChroma = 10;  // of 255: the cheek's colour under the booth's light, shading included
    constexpr int kColumns = 100;  // 0.01 V each: 1 V behind the nasion
    const int y0 = std::max(0, cvRound(tip.y - 0.2 * V)), y1 = std::min(bgr.rows - 1, cvRound(tip.y + 0.15 * V));
    const int side = cvRound(0.03 * V);
    std::vector<double> column(kColumns, 0.0);
    for (int y = y0; y <= y1; ++y) {
        auto cheekSkin = [&](int x) {
            if (!innerAt(x, y)) return false;
            const cv::Vec3b p = yccAt(x, y);
            return std::abs(p[1] - cr0) <= kChroma && std::abs(p[2] - cb0) <= kChroma;
        };
        for (int c = 0; c < kColumns; ++c) {
            const int x = cvRound(nasion.x - (c + 0.5) * 0.01 * V);
            if (cheekSkin(x) && cheekSkin(x - side) && cheekSkin(x + side))
                column[static_cast<std::size_t>(c)] += grad.at<float>(y - region.y, x - region.x);
        }
    }
    for (double& c : column) c /= (y1 - y0 + 1);
    return column;
}

}  // namespace

EarPlace readEarColumns(const std::vector<double>& columns, double noseAhead, double headLength) {
    EarPlace ear;
    ear.headLength = headLength;
    const int n = static_cast<int>(columns.size());
    if (n < 30) return ear;
    std::vector<double> level(columns.size(), 0.0);
    for (int c = 0; c < n; ++c) {
        const int from = std::max(0, c - 2), to = std::min(n - 1, c + 2);
        double sum = 0.0;
        for (int d = from; d <= to; ++d) sum += columns[static_cast<std::size_t>(d)];
        level[static_cast<std::size_t>(c)] = sum / (to - from + 1);
    }
    const double cheek = std::max(1.0, *std::min_element(level.begin() + 12, level.begin() + 26));
    const auto strongest = std::max_element(level.begin() + 15, level.end());
    if (*strongest < kEarOverCheek * cheek) return ear;
    const auto front = std::find_if(level.begin() + 20, level.end(), [&](double v) { return v > kEarOverCheek * cheek; });
    if (front == level.end()) return ear;  // only the eye's corner or the nose's wing stands out
    ear.found = true;
    ear.front = (static_cast<double>(front - level.begin()) + 0.5) * 0.01 + noseAhead;
    ear.fold = (static_cast<double>(strongest - level.begin()) + 0.5) * 0.01 + noseAhead;
    return ear;
}

double degreesPastProfile(const EarPlace& ear) {
    if (!ear.found || ear.headLength <= 0.0) return 0.0;
    return std::max(0.0, (kEarShareAtProfile - ear.front / ear.headLength) / kEarSharePerDegree);
}

bool turnedPastProfile(double eyeDegrees, const EarPlace& ear) {
    return ear.found && ear.headLength > 0.0 && ear.front / ear.headLength <= kEarShareTurnBack &&
           ear.fold <= kEarFoldTurnBack && eyeDegrees >= kEyeTurnBackDegrees;
}

bool turnedShortCues(const ProfileTurn& turn) {
    if (!turn.known) return false;
    if (!turn.ear.found) return turn.degrees <= kEyeTurnMoreNoEarDegrees;
    if (turn.degrees > kEyeTurnMoreDegrees) return false;
    return turn.ear.headLength > 0.0 && turn.ear.front / turn.ear.headLength >= kEarShareTurnMore;
}

ProfileTurn estimateProfileTurn(const cv::Mat& bgrIn, const cv::Mat& maskIn, const std::vector<ProfilePoint>& landmarks,
                                bool noseImageRight) {
    ProfileTurn turn;
    if (bgrIn.empty() || maskIn.size() != bgrIn.size()) return turn;
    // Work facing image-right.
    cv::Mat bgr, mask;  // the caller's images, or mirrored copies (never flipped in place: they are the caller's)
    auto pt = [&](const char* name) {
        cv::Point2d p = profilePoint(landmarks, name);
        if (!noseImageRight) p.x = bgrIn.cols - 1 - p.x;
        return p;
    };
    if (!noseImageRight) {
        cv::flip(bgrIn, bgr, 1);
        cv::flip(maskIn, mask, 1);
    } else {
        bgr = bgrIn;
        mask = maskIn;
    }
    const cv::Point2d nasion = pt("nasion"), tip = pt("nose_tip"), top = pt("top_of_head");
    const double V = tip.y - top.y;
    if (V < 20.0) return turn;
    const std::function<int(int)> frontEdge = [&](int y) { return faceFrontEdge(mask, tip.x, y); };
    // The eye: the darkest pixels (5%) in a band from just above the nasion to 0.15 V below it, up to 0.3 V behind
    // the outline; their mean distance behind it.
    {
        std::vector<std::pair<int, double>> pixels;  // grey, distance behind the edge in V
        const int y0 = std::max(0, cvRound(nasion.y - 0.03 * V)), y1 = std::min(mask.rows - 1, cvRound(nasion.y + 0.15 * V));
        if (y1 < y0) return turn;
        // Only the band's rows in grey: the side guide passes the camera's whole frame.
        cv::Mat grey;
        cv::cvtColor(bgr.rowRange(y0, y1 + 1), grey, cv::COLOR_BGR2GRAY);
        for (int y = y0; y <= y1; ++y) {
            const int edge = frontEdge(y);
            if (edge < 0) continue;
            for (int x = std::max(0, cvRound(edge - 0.30 * V)); x <= edge - cvRound(0.02 * V); ++x)
                if (mask.at<unsigned char>(y, x)) pixels.emplace_back(grey.at<unsigned char>(y - y0, x), (edge - x) / V);
        }
        if (pixels.size() > 50) {
            std::sort(pixels.begin(), pixels.end());
            const std::size_t n = std::max<std::size_t>(5, pixels.size() / 20);
            double sum = 0.0;
            for (std::size_t i = 0; i < n; ++i) sum += pixels[i].second;
            turn.eyeBehind = sum / static_cast<double>(n);
        }
    }
    if (turn.eyeBehind <= 0.0) return turn;
    turn.degrees = (kEyeBehindAtProfile - turn.eyeBehind) / kEyeBehindPerDegree;
    turn.known = true;
    turn.ear = readEarColumns(earColumns(bgr, mask, nasion, tip, V, frontEdge), (tip.x - nasion.x) / V,
                              (pt("glabella").x - pt("back_of_head").x) / V);
    turn.pastProfile = turnedPastProfile(turn.degrees, turn.ear);
    return turn;
}

int faceFrontEdge(const cv::Mat& mask, double tipX, int y) {
    const auto* m = mask.ptr<unsigned char>(y);
    for (int x = std::min(mask.cols - 1, cvRound(tipX) + 2); x >= 0; --x)
        if (m[x]) return x;
    return -1;
}

std::optional<cv::Rect> faceOnPerson(const LandmarkDetector& detector, const cv::Mat& bgr, const cv::Mat& personMask) {
    for (const cv::Rect& f : detector.detectFaces(bgr)) {  // largest first
        const cv::Point c(f.x + f.width / 2, f.y + f.height / 2);
        if (c.inside(cv::Rect(0, 0, personMask.cols, personMask.rows)) && personMask.at<unsigned char>(c)) return f;
    }
    return std::nullopt;
}

double noseOffsetYaw(const std::array<cv::Point2d, 68>& p) {
    const cv::Point2d eyeL = p[36], eyeR = p[45], nose = p[30];
    const double eyes = cv::norm(eyeR - eyeL);
    if (eyes <= 0.0) return 0.0;
    return (nose - 0.5 * (eyeL + eyeR)).dot((eyeR - eyeL) / eyes) / eyes;
}

SideAnalysis analyseSidePhoto(const cv::Mat& bgr, const cv::Mat& backgroundPlate, const SideOptions& options) {
    SideAnalysis out;
    out.mask = segmentPerson(bgr, backgroundPlate, {});
    const auto contour = largestOutline(out.mask);
    out.outline.reserve(contour.size());
    for (const auto& p : contour) out.outline.emplace_back(p.x, p.y);

    const ProfileFit right = fitProfile(out.outline, true);
    const ProfileFit left = fitProfile(out.outline, false);

    if (options.rejectFrontViews) {
        const std::filesystem::path dir =
            options.cascadeDir.empty() ? std::filesystem::path(AVATARBOOTH_DEFAULT_CASCADE_DIR) : options.cascadeDir;
        std::optional<FrontalFaceCheck> loadedHere;
        if (!options.frontalCheck) loadedHere.emplace(dir);
        FrontalFaceCheck& check = options.frontalCheck ? *options.frontalCheck : *loadedHere;
        if (!check.available()) {
            out.warnings.push_back("no frontal-face cascade found in " + dir.string() +
                                   ": front views are recognised by their silhouette only");
        } else if (const auto face = findFrontalFace(bgr, out.mask, check)) {
            const double yaw = options.landmarkDetector ? noseOffsetYaw(options.landmarkDetector->landmarksIn(bgr, *face)) : 0.0;
            if (std::abs(yaw) > kHalfTurnedYaw) {
                // 0.28-0.38 eye widths on frmdb's 45-degree views: about 150 degrees per eye width (dlib's points
                // understate large turns), capped where the cascade stops finding faces.
                const double fromFront = std::min(75.0, 150.0 * std::abs(yaw));
                throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::TurnMore, "",
                               cv::format("the side photo is turned only about %.0f degrees from the front (both eyes "
                                          "show): turn about %.0f degrees more", fromFront, 90.0 - fromFront));
            }
            throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::NotProfile, "",
                           "this looks like a front view, not a profile (a frontal face was detected)");
        }
    }
    if (!right.ok && !left.ok) {
        const std::string noNose = "no nose stands out from either side of the head's outline: " + right.failure;
        if (!options.landmarkDetector)
            throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::NotProfile, "",
                           "this looks like a front view, not a profile (" + noNose + ")");
        // Which way to turn: the outline cannot say (see ProfileTurn), the face can. dlib's HOG detector, with its
        // filters for faces looking aside, finds the face of every synthetic visitor turned 55-66 degrees and of
        // none turned 114-150 (README, issue 22); a bob hiding the face shows none either.
        const auto face = faceOnPerson(*options.landmarkDetector, bgr, out.mask);
        if (!face)
            throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::FaceHidden, "",
                           "no face shows in the side photo (" + noNose + "; no face found on the head): turned past "
                           "the profile, or hair hides the face: turn a little back towards the camera, hair behind "
                           "the ear");
        const double yaw = noseOffsetYaw(options.landmarkDetector->landmarksIn(bgr, *face));
        if (std::abs(yaw) <= kHalfTurnedYaw)
            throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::NotProfile, "",
                           "this looks like a front view, not a profile (" + noNose + "; a face looks at the camera)");
        throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::TurnMore, "",
                       "the side photo is turned short of the profile (" + noNose + "; a face turned aside shows): "
                       "turn more");
    }

    const bool useRight = profileFacesRight(right, left);
    const ProfileFit& fit = useRight ? right : left;
    const ProfileFit& other = useRight ? left : right;
    if (other.ok && other.throatAtCollar == fit.throatAtCollar && other.noseProminence > 0.7 * fit.noseProminence)
        out.warnings.push_back("facing direction uncertain: both sides of the outline have a nose-like bulge");
    out.noseImageRight = useRight;
    out.landmarks = fit.landmarks;
    // A head cut by the frame still fits, but its cut side is the frame's edge, not the head's.
    const cv::Rect box = cv::boundingRect(out.mask);
    if (box.y <= 0) out.warnings.push_back("the head runs out of the photo at the top: top of head unreliable");
    const int headTop = std::max(0, box.y);
    const int headBottom = std::clamp(cvRound(profilePoint(out.landmarks, "throat").y), headTop, out.mask.rows - 1);
    const cv::Range headRows(headTop, headBottom + 1);
    if (cv::countNonZero(out.mask(headRows, cv::Range(0, 1))) > 0 ||
        cv::countNonZero(out.mask(headRows, cv::Range(out.mask.cols - 1, out.mask.cols))) > 0)
        out.warnings.push_back("the head runs out of the photo at the side: face or back of head may be cut");
    out.warnings.insert(out.warnings.end(), fit.warnings.begin(), fit.warnings.end());
    out.turn = estimateProfileTurn(bgr, out.mask, out.landmarks, out.noseImageRight);
    if (options.refusePastProfile && out.turn.pastProfile) {
        const double past = degreesPastProfile(out.turn.ear);
        throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::TurnBack, "",
                       cv::format("the side photo is turned past the profile, about %.0f degrees from the front (the "
                                  "ear's front is %.2f of the head's length behind the nose tip, about %.2f in a "
                                  "profile): turn about %.0f degrees back",
                                  90.0 + past, out.turn.ear.front / out.turn.ear.headLength, kEarShareAtProfile,
                                  past));
    }
    if (options.refuseShortOfProfile && options.landmarkDetector && turnedShortCues(out.turn) &&
        faceOnPerson(*options.landmarkDetector, bgr, out.mask))
        throw FitError(ErrorKind::Mismatch, FitPhoto::Side, FitFault::TurnMore, "",
                       cv::format("the side photo is turned short of the profile, about 60 degrees from the front (the "
                                  "eye %.0f degrees short, the ear's front %s, and a face looking aside was found): "
                                  "turn about 30 degrees more", -out.turn.degrees,
                                  out.turn.ear.found ? cv::format("%.2f of the head's length behind the nose tip, about "
                                                                  "%.2f in a profile", out.turn.ear.front /
                                                                  out.turn.ear.headLength, kEarShareAtProfile).c_str()
                                                     : "not found"));
    return out;
}

void drawSideOverlay(cv::Mat& canvas, const SideAnalysis& analysis) {
    CV_Assert(canvas.type() == CV_8UC3);
    const double fontScale = std::max(0.35, canvas.rows / 1500.0);
    const int thick = canvas.rows > 900 ? 2 : 1;
    if (!analysis.outline.empty()) {
        std::vector<cv::Point> poly;
        poly.reserve(analysis.outline.size());
        for (const auto& p : analysis.outline) poly.emplace_back(cvRound(p.x), cvRound(p.y));
        cv::polylines(canvas, poly, true, cv::Scalar(0, 255, 0), thick, cv::LINE_AA);
    }
    for (const auto& lm : analysis.landmarks) {
        const cv::Point p(cvRound(lm.px.x), cvRound(lm.px.y));
        cv::circle(canvas, p, 3 * thick, cv::Scalar(0, 0, 255), cv::FILLED, cv::LINE_AA);
        int base = 0;
        const cv::Size ts = cv::getTextSize(lm.name, cv::FONT_HERSHEY_SIMPLEX, fontScale, 1, &base);
        // Labels go on the face's side for face points, behind for the back of the head and the ear.
        const bool behind = lm.name == "back_of_head" || lm.name == "ear_hole";
        const bool toRight = analysis.noseImageRight != behind;
        const cv::Point org = toRight ? p + cv::Point(6, ts.height / 2) : p + cv::Point(-6 - ts.width, ts.height / 2);
        cv::putText(canvas, lm.name, org, cv::FONT_HERSHEY_SIMPLEX, fontScale, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
        cv::putText(canvas, lm.name, org, cv::FONT_HERSHEY_SIMPLEX, fontScale, cv::Scalar(0, 255, 255), 1,
                    cv::LINE_AA);
    }
    int y = 20;
    for (const auto& w : analysis.warnings) {
        cv::putText(canvas, w, {8, y}, cv::FONT_HERSHEY_SIMPLEX, fontScale, cv::Scalar(0, 0, 0), 3, cv::LINE_AA);
        cv::putText(canvas, w, {8, y}, cv::FONT_HERSHEY_SIMPLEX, fontScale, cv::Scalar(0, 200, 255), 1, cv::LINE_AA);
        y += static_cast<int>(30 * fontScale) + 6;
    }
}

}  // namespace avatarbooth
