// Narita's 21 points from the 68 landmarks, the silhouette and the ear hole (the mapping is documented in the
// header, point by point).
#include "reveal/character/narita_points.h"

#include "common/error.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace avatarbooth {
namespace {

constexpr double kStep = 0.5;  // pixels between samples along a search line


cv::Point2d mean(const std::array<cv::Point2d, 68>& p, int from, int to) {
    cv::Point2d sum(0.0, 0.0);
    for (int k = from; k <= to; ++k) sum += p[static_cast<std::size_t>(k)];
    return sum * (1.0 / (to - from + 1));
}

struct Edge {
    cv::Point2d point;
    double distance = 0.0;
    bool cut = false;  // the silhouette reached the image border or the search limit
};

// Walks from `start` along unit `dir` and returns where the silhouette ends: the last inside sample plus half a
// step, once a run of background longer than `gap` follows. Nothing when `start` is not inside (nor within gap).
std::optional<Edge> edgeAlong(const cv::Mat& mask, cv::Point2d start, cv::Point2d dir, double reach, double gap) {
    double lastInside = -1.0;
    bool cut = false;
    for (double s = 0.0;; s += kStep) {
        if (s > reach) {
            cut = lastInside >= s - kStep - 1e-9;
            break;
        }
        const cv::Point2d p = start + s * dir;
        const long ix = std::lround(p.x), iy = std::lround(p.y);
        if (ix < 0 || iy < 0 || ix >= mask.cols || iy >= mask.rows) {
            cut = lastInside >= s - kStep - 1e-9;
            break;
        }
        if (mask.at<unsigned char>(static_cast<int>(iy), static_cast<int>(ix)) != 0) {
            lastInside = s;
        } else if (s - std::max(lastInside, 0.0) > gap) {
            break;
        }
    }
    if (lastInside < 0.0) return std::nullopt;
    const double d = cut ? lastInside : lastInside + 0.5 * kStep;
    return Edge{start + d * dir, d, cut};
}

// The face's own frame: u along the eye line (image left to right), v up the face (away from the chin).
struct FaceFrame {
    cv::Point2d eyeMid, u, v;
    double eyeDistance = 0.0;
    cv::Point2d along(double t) const { return eyeMid + t * v; }
    double height(const cv::Point2d& p) const { return (p - eyeMid).dot(v); }
};

// The jaw contour's distance from the midline (along the eye line) at height t; above its first point, that
// point's distance.
double contourHalfWidth(const std::vector<cv::Point2d>& jaw, const FaceFrame& frame, double t) {
    const auto offset = [&](const cv::Point2d& q) { return std::abs((q - frame.eyeMid).dot(frame.u)); };
    if (t >= frame.height(jaw.front())) return offset(jaw.front());
    for (std::size_t i = 0; i + 1 < jaw.size(); ++i) {
        const double h0 = frame.height(jaw[i]), h1 = frame.height(jaw[i + 1]);
        if (t <= h0 && t >= h1 && h0 > h1) {
            const double a = (h0 - t) / (h0 - h1);
            return (1.0 - a) * offset(jaw[i]) + a * offset(jaw[i + 1]);
        }
    }
    return offset(jaw.back());
}

struct Outline {
    cv::Point2d point;
    bool fromSilhouette = true;
    bool cut = false;
};

// The head's outline at height t on one side: the silhouette's edge, searched outwards from `start` (on the line
// at that height), unless it is missing or lies inside the face's own landmark contour (a silhouette that cut
// into the face): then the contour's point. The head's outline is never inside the face.
Outline outlineAt(const cv::Mat& mask, const FaceFrame& frame, cv::Point2d start, cv::Point2d out, double t,
                  const std::vector<cv::Point2d>& jaw, const NaritaMappingSettings& s) {
    const double contour = contourHalfWidth(jaw, frame, t);
    const auto edge = edgeAlong(mask, start, out, s.maxReach * frame.eyeDistance, s.gapBridge * frame.eyeDistance);
    if (edge && (edge->point - frame.along(t)).dot(out) >= contour - s.contourTolerance * frame.eyeDistance)
        return {edge->point, true, edge->cut};
    return {frame.along(t) + contour * out, false, false};
}

struct EarSearch {
    bool found = false;
    double top = 0.0, bottom = 0.0;  // heights t of the notches
};

// The ear on one side (direction `out`): the profile of half-widths over the band, its upper hull, the deepest
// notch above and below the ear hole; see the header.
EarSearch findEarNotches(const cv::Mat& mask, const FaceFrame& frame, cv::Point2d out, double tHole, double L,
                         const std::vector<cv::Point2d>& jaw, const NaritaMappingSettings& s) {
    const double reach = s.maxReach * frame.eyeDistance, gap = s.gapBridge * frame.eyeDistance;
    std::vector<double> ts, ws;
    for (double t = tHole - 0.9 * L; t <= tHole + 0.9 * L; t += kStep) {
        const auto edge = edgeAlong(mask, frame.along(t), out, reach, gap);
        if (!edge || edge->cut) return {};
        ts.push_back(t);
        ws.push_back(edge->distance);
    }
    if (ts.size() < 8) return {};
    // Upper convex hull of (t, w), t increasing (monotone chain).
    std::vector<std::size_t> hull;
    for (std::size_t i = 0; i < ts.size(); ++i) {
        while (hull.size() >= 2) {
            const std::size_t a = hull[hull.size() - 2], b = hull.back();
            const double cross = (ts[b] - ts[a]) * (ws[i] - ws[a]) - (ws[b] - ws[a]) * (ts[i] - ts[a]);
            if (cross >= 0.0) hull.pop_back();  // b lies on or below the chord a-i
            else break;
        }
        hull.push_back(i);
    }
    std::vector<double> depth(ts.size(), 0.0);
    for (std::size_t h = 0; h + 1 < hull.size(); ++h) {
        const std::size_t a = hull[h], b = hull[h + 1];
        for (std::size_t i = a; i <= b; ++i) {
            const double along = (ts[i] - ts[a]) / (ts[b] - ts[a]);
            depth[i] = ws[a] + along * (ws[b] - ws[a]) - ws[i];
        }
    }
    const auto deepest = [&](double lo, double hi) {
        std::size_t best = ts.size();
        for (std::size_t i = 0; i < ts.size(); ++i)
            if (ts[i] >= lo && ts[i] <= hi && (best == ts.size() || depth[i] > depth[best])) best = i;
        return best;
    };
    const std::size_t top = deepest(tHole + 0.15 * L, tHole + 0.9 * L);
    const std::size_t bottom = deepest(tHole - 0.9 * L, tHole - 0.2 * L);
    if (top == ts.size() || bottom == ts.size()) return {};
    const double minDepth = s.minNotchDepth * frame.eyeDistance;
    if (depth[top] < minDepth || depth[bottom] < minDepth) return {};
    const double length = ts[top] - ts[bottom];
    if (length < 0.45 * L || length > 1.3 * L) return {};
    std::size_t peak = bottom;
    for (std::size_t i = bottom; i <= top; ++i)
        if (ws[i] > ws[peak]) peak = i;
    if (ws[peak] < std::max(ws[top], ws[bottom]) + minDepth) return {};
    // An ear stands out of the face: the bump must reach beyond the jaw contour (iBUG 0-8 or 16-8, which runs
    // from about the ear hole down to the chin) at its height, or it is only the face's own outline.
    const double contour = contourHalfWidth(jaw, frame, ts[peak]);
    if (ws[peak] < contour + s.minEarProtrusion * frame.eyeDistance) return {};
    // ... and it joins the head at or outside that contour (notches inside the face are the silhouette cutting in).
    for (const std::size_t notch : {top, bottom})
        if (ws[notch] < contourHalfWidth(jaw, frame, ts[notch]) - s.contourTolerance * frame.eyeDistance) return {};
    return {true, ts[top], ts[bottom]};
}

}  // namespace

std::vector<std::pair<std::string, cv::Point2d>> NaritaPoints::named() const {
    std::vector<std::pair<std::string, cv::Point2d>> out;
    for (std::size_t i = 0; i < f.size(); ++i) out.emplace_back("Pf" + std::to_string(i), f[i]);
    for (std::size_t i = 0; i < e.size(); ++i) out.emplace_back("Pe" + std::to_string(i), e[i]);
    for (std::size_t i = 0; i < a.size(); ++i) out.emplace_back("Pa" + std::to_string(i), a[i]);
    for (std::size_t i = 0; i < b.size(); ++i) out.emplace_back("Pb" + std::to_string(i), b[i]);
    out.emplace_back("Pn", n);
    out.emplace_back("Pm", m);
    out.emplace_back("brow_outer_right", browOuter[0]);
    out.emplace_back("brow_outer_left", browOuter[1]);
    return out;
}

NaritaMapping mapNaritaPoints(const NaritaMappingInput& in, const NaritaMappingSettings& settings) {
    const auto& p = in.landmarks;
    const auto at = [&](int k) { return p[static_cast<std::size_t>(k)]; };
    if (in.mask.empty() || in.mask.type() != CV_8UC1)
        throw BoothError(ErrorKind::BadInput, "", "character points: the silhouette mask is empty or not 8-bit grey");

    FaceFrame frame;
    const cv::Point2d rightEye = mean(p, 36, 41), leftEye = mean(p, 42, 47);
    frame.eyeMid = 0.5 * (rightEye + leftEye);
    frame.eyeDistance = cv::norm(leftEye - rightEye);
    if (!(frame.eyeDistance > 4.0))
        throw BoothError(ErrorKind::NoFace, "", "character points: the eye centres are less than 4 px apart");
    frame.u = (leftEye - rightEye) * (1.0 / frame.eyeDistance);
    frame.v = cv::Point2d(frame.u.y, -frame.u.x);
    if ((at(8) - frame.eyeMid).dot(frame.v) > 0.0) frame.v = -frame.v;

    NaritaMapping out;
    NaritaPoints& P = out.points;

    // Temples: the head contour at eye height.
    const std::array<cv::Point2d, 2> eyes = {rightEye, leftEye};
    const std::array<cv::Point2d, 2> outwards = {-frame.u, frame.u};
    std::array<std::vector<cv::Point2d>, 2> jaws;
    for (int k = 0; k <= 8; ++k) {
        jaws[0].push_back(at(k));
        jaws[1].push_back(at(16 - k));
    }
    const char* sideName[2] = {"right", "left"};
    for (std::size_t side = 0; side < 2; ++side) {
        const Outline temple = outlineAt(in.mask, frame, eyes[side], outwards[side], 0.0, jaws[side], settings);
        P.f[side] = temple.point;
        out.templeSource[side] = temple.fromSilhouette ? "silhouette" : "face contour";
        if (!temple.fromSilhouette)
            out.warnings.push_back(std::string("the silhouette does not reach the face's outline at eye height on the ") +
                                   sideName[side] + ": that temple is on the jaw landmarks' contour");
        else if (temple.cut)
            out.warnings.push_back(std::string("the silhouette reaches the frame or the search limit at eye height on the ") +
                                   sideName[side] + ": that temple is uncertain");
    }
    P.f[2] = at(8);

    P.e = {at(36), at(39), 0.5 * (at(37) + at(38)), at(41), at(40),
           at(45), at(42), 0.5 * (at(43) + at(44)), at(46), at(47)};
    P.b = {at(21), at(22)};
    P.browOuter = {at(17), at(26)};
    P.n = at(30);
    P.m = 0.5 * (at(62) + at(66));

    // Ears.
    const double tBrow = frame.height(mean(p, 17, 26)), tNoseBase = frame.height(at(33));
    const double L = tBrow - tNoseBase;
    if (!(L > 0.2 * frame.eyeDistance))
        throw BoothError(ErrorKind::NoFace, "", "character points: the brows are not above the nose base");
    double tHole = tBrow - 0.45 * L;
    out.earHoleSource = "canon";
    if (in.earHole) {
        tHole = frame.height(*in.earHole);
        out.earHoleSource = "side photo";
        // The ear canal lies between the brow line and the nose base (at about 0.45 L): a side photo's estimate
        // outside that is kept to its ends, so that one bad profile point cannot put the ears on the crown.
        const double lo = tNoseBase, hi = tBrow;
        if (tHole < lo || tHole > hi) {
            out.warnings.push_back("the side photo's ear hole is outside the brow-to-nose-base band: kept to its edge");
            tHole = std::clamp(tHole, lo, hi);
        }
    }
    for (std::size_t side = 0; side < 2; ++side) {
        const EarSearch ear = findEarNotches(in.mask, frame, outwards[side], tHole, L, jaws[side], settings);
        const double tTop = ear.found ? ear.top : tHole + 0.45 * L;
        const double tBottom = ear.found ? ear.bottom : tHole - 0.55 * L;
        out.earSource[side] = ear.found ? "silhouette" : "canon";
        const Outline top = outlineAt(in.mask, frame, frame.along(tTop), outwards[side], tTop, jaws[side], settings);
        const Outline bottom =
            outlineAt(in.mask, frame, frame.along(tBottom), outwards[side], tBottom, jaws[side], settings);
        P.a[2 * side] = top.point;
        P.a[2 * side + 1] = bottom.point;
        out.earPointSource[2 * side] = top.fromSilhouette ? "silhouette" : "face contour";
        out.earPointSource[2 * side + 1] = bottom.fromSilhouette ? "silhouette" : "face contour";
        if (!ear.found)
            out.warnings.push_back(std::string("the ") + sideName[side] +
                                   " ear was not found on the silhouette (hidden by hair?): estimated from the canon");
        if (!top.fromSilhouette || !bottom.fromSilhouette)
            out.warnings.push_back(std::string("the silhouette does not reach the face's outline at the ") +
                                   sideName[side] + " ear's height: put on the jaw landmarks' contour");
    }
    return out;
}

void drawNaritaPoints(cv::Mat& canvas, const NaritaMapping& mapping) {
    const NaritaPoints& P = mapping.points;
    const double scale = std::max(1.0, cv::norm(P.f[1] - P.f[0]) / 200.0);
    const int radius = static_cast<int>(std::lround(2.0 * scale));
    cv::line(canvas, P.f[0], P.f[1], cv::Scalar(80, 200, 80), 1, cv::LINE_AA);  // the face line
    for (const auto& [name, q] : P.named()) {
        const bool extra = name.rfind("brow_outer", 0) == 0;
        cv::circle(canvas, q, radius, extra ? cv::Scalar(200, 200, 0) : cv::Scalar(0, 0, 255), cv::FILLED, cv::LINE_AA);
        if (!extra)
            cv::putText(canvas, name, q + cv::Point2d(3.0 * scale, -3.0 * scale), cv::FONT_HERSHEY_SIMPLEX,
                        0.3 * scale, cv::Scalar(0, 255, 255), 1, cv::LINE_AA);
    }
}

}  // namespace avatarbooth
