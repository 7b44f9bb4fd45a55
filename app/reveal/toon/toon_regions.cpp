// Kitamura's two-view toon character, first half: drawings, regions, matching and Algorithm 1 (METHODS §3.2).
#include "reveal/toon/toon_regions.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <numbers>

namespace avatarbooth::toon {

namespace {
constexpr double kDeg = std::numbers::pi / 180.0;

glm::dvec3 projectOntoLine(const glm::dvec3& p, const Line3& line) {
    return line.point + line.direction * glm::dot(p - line.point, line.direction);
}
}  // namespace

glm::dvec3 ViewDirection::towardsCamera() const {
    const double t = thetaDeg * kDeg, f = phiDeg * kDeg;
    return {std::sin(t) * std::cos(f), std::sin(f), std::cos(t) * std::cos(f)};
}
glm::dvec3 ViewDirection::imageRight() const {
    const double t = thetaDeg * kDeg;
    return {std::cos(t), 0.0, -std::sin(t)};
}
glm::dvec3 ViewDirection::imageUp() const { return glm::normalize(glm::cross(towardsCamera(), imageRight())); }

glm::dvec3 DrawingView::pointOnLine(cv::Point2d pixel) const {
    return direction.imageRight() * ((pixel.x - centre.x) * unitsPerPixel) +
           direction.imageUp() * ((centre.y - pixel.y) * unitsPerPixel);
}
cv::Point2d DrawingView::project(glm::dvec3 point) const {
    return {centre.x + glm::dot(point, direction.imageRight()) / unitsPerPixel,
            centre.y - glm::dot(point, direction.imageUp()) / unitsPerPixel};
}

Regions splitRegions(const cv::Mat& drawingBgr, const cv::Mat& mask, const cv::Mat& outlineIn, int outlineMaxGrey,
                     int minArea) {
    CV_Assert(drawingBgr.type() == CV_8UC3);
    const int rows = drawingBgr.rows, cols = drawingBgr.cols;
    cv::Mat inside = mask.empty() ? cv::Mat(rows, cols, CV_8U, cv::Scalar(255)) : (mask > 127);
    cv::Mat outline;
    if (!outlineIn.empty()) {
        outline = outlineIn > 127;
    } else {
        cv::Mat grey;
        cv::cvtColor(drawingBgr, grey, cv::COLOR_BGR2GRAY);
        outline = grey <= outlineMaxGrey;
    }
    outline &= inside;

    // Flood fill: 4-connected runs of the same colour (within a small tolerance against JPEG-like noise).
    cv::Mat labels(rows, cols, CV_32S, cv::Scalar(0));
    std::vector<std::vector<cv::Point>> pixelsOf(1);
    std::vector<cv::Point> stack;
    auto same = [&](const cv::Vec3b& a, const cv::Vec3b& b) {
        return std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2]) <= 24;
    };
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            if (!inside.at<uchar>(r, c) || outline.at<uchar>(r, c) || labels.at<int>(r, c)) continue;
            const int label = static_cast<int>(pixelsOf.size());
            const cv::Vec3b seed = drawingBgr.at<cv::Vec3b>(r, c);
            std::vector<cv::Point> pixels;
            stack.assign(1, {c, r});
            labels.at<int>(r, c) = label;
            while (!stack.empty()) {
                const cv::Point p = stack.back();
                stack.pop_back();
                pixels.push_back(p);
                const cv::Point next[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
                for (const cv::Point& q : next) {
                    if (q.x < 0 || q.y < 0 || q.x >= cols || q.y >= rows) continue;
                    if (!inside.at<uchar>(q) || outline.at<uchar>(q) || labels.at<int>(q)) continue;
                    if (!same(drawingBgr.at<cv::Vec3b>(q), seed)) continue;
                    labels.at<int>(q) = label;
                    stack.push_back(q);
                }
            }
            pixelsOf.push_back(std::move(pixels));
        }
    }
    // Small regions are noise: they become outline and go to their nearest real region below.
    std::vector<int> relabel(pixelsOf.size(), 0);
    int kept = 0;
    for (std::size_t i = 1; i < pixelsOf.size(); ++i) {
        if (static_cast<int>(pixelsOf[i].size()) >= minArea) {
            relabel[i] = ++kept;
        } else {
            for (const cv::Point& p : pixelsOf[i]) outline.at<uchar>(p) = 255;
        }
    }
    Regions out;
    out.labels = cv::Mat(rows, cols, CV_32S, cv::Scalar(0));
    std::vector<cv::Vec3d> colourSum(static_cast<std::size_t>(kept) + 1, cv::Vec3d(0, 0, 0));
    std::vector<double> colourCount(static_cast<std::size_t>(kept) + 1, 0.0);
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < cols; ++c) {
            const int l = relabel[static_cast<std::size_t>(labels.at<int>(r, c))];
            out.labels.at<int>(r, c) = l;
            if (l) {
                const cv::Vec3b bgr = drawingBgr.at<cv::Vec3b>(r, c);
                colourSum[static_cast<std::size_t>(l)] += cv::Vec3d(bgr[2], bgr[1], bgr[0]) / 255.0;
                colourCount[static_cast<std::size_t>(l)] += 1.0;
            }
        }
    }
    if (kept == 0) return out;

    // Each outline pixel goes to the nearest region pixel (so regions touch and billboards leave no gaps).
    cv::Mat notRegion = (out.labels == 0) & inside;  // the outline pixels to hand out
    cv::Mat source;
    cv::bitwise_not(out.labels != 0, source);  // distanceTransform measures to the zero (region) pixels
    cv::Mat dist, nearest;
    cv::distanceTransform(source, dist, nearest, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
    // A region pixel carries its own pixel label: that gives the label -> region table.
    double maxLabel = 0.0;
    cv::minMaxLoc(nearest, nullptr, &maxLabel);
    std::vector<int> regionOfZero(static_cast<std::size_t>(maxLabel) + 1, 0);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            if (source.at<uchar>(r, c) == 0)
                regionOfZero[static_cast<std::size_t>(nearest.at<int>(r, c))] = out.labels.at<int>(r, c);
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c)
            if (notRegion.at<uchar>(r, c)) {
                const int z = nearest.at<int>(r, c);
                if (z > 0 && z < static_cast<int>(regionOfZero.size()))
                    out.labels.at<int>(r, c) = regionOfZero[static_cast<std::size_t>(z)];
            }

    // Per region: the outer contour with holes filled, its area, bounding box and centroid.
    for (int l = 1; l <= kept; ++l) {
        cv::Mat own = out.labels == l;
        std::vector<std::vector<cv::Point>> contours;
        cv::findContours(own, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
        if (contours.empty()) continue;
        cv::Mat filled(rows, cols, CV_8U, cv::Scalar(0));
        cv::drawContours(filled, contours, -1, cv::Scalar(255), cv::FILLED);
        const auto largest = std::max_element(contours.begin(), contours.end(), [](const auto& a, const auto& b) {
            return cv::contourArea(a) < cv::contourArea(b);
        });
        Region region;
        region.label = l;
        region.colour = colourSum[static_cast<std::size_t>(l)] / std::max(1.0, colourCount[static_cast<std::size_t>(l)]);
        region.area = cv::countNonZero(filled);
        region.bbox = cv::boundingRect(filled);
        region.bboxCentre = {region.bbox.x + (region.bbox.width - 1) / 2.0, region.bbox.y + (region.bbox.height - 1) / 2.0};
        const cv::Moments m = cv::moments(filled, true);
        region.centroid = {m.m10 / m.m00, m.m01 / m.m00};
        region.contour = *largest;
        out.regions.push_back(std::move(region));
    }
    return out;
}

namespace {

// Merges every 4-connected patch of `index` (cluster numbers, 255 outside the mask) smaller than `minArea` into the
// touching patch whose cluster colour (`centres`, Lab rows) is closest, smallest patches first, so what remains are
// patches of at least minArea (or patches with no neighbour). Region-adjacency merging with union-find.
void mergeSmallPatches(cv::Mat& index, const cv::Mat& centres, int minArea) {
    const int rows = index.rows, cols = index.cols;
    cv::Mat patch(rows, cols, CV_32S, cv::Scalar(-1));
    std::vector<int> cluster, area;
    std::vector<cv::Point> stack;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const uchar k = index.at<uchar>(r, c);
            if (k == 255 || patch.at<int>(r, c) >= 0) continue;
            const int id = static_cast<int>(cluster.size());
            int n = 0;
            stack.assign(1, {c, r});
            patch.at<int>(r, c) = id;
            while (!stack.empty()) {
                const cv::Point p = stack.back();
                stack.pop_back();
                ++n;
                const cv::Point next[4] = {{p.x + 1, p.y}, {p.x - 1, p.y}, {p.x, p.y + 1}, {p.x, p.y - 1}};
                for (const cv::Point& q : next) {
                    if (q.x < 0 || q.y < 0 || q.x >= cols || q.y >= rows) continue;
                    if (index.at<uchar>(q) != k || patch.at<int>(q) >= 0) continue;
                    patch.at<int>(q) = id;
                    stack.push_back(q);
                }
            }
            cluster.push_back(k);
            area.push_back(n);
        }
    const std::size_t count = cluster.size();
    std::vector<std::vector<int>> neighbours(count);
    auto link = [&](int a, int b) {
        if (a < 0 || b < 0 || a == b) return;
        neighbours[static_cast<std::size_t>(a)].push_back(b);
        neighbours[static_cast<std::size_t>(b)].push_back(a);
    };
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const int a = patch.at<int>(r, c);
            if (c + 1 < cols) link(a, patch.at<int>(r, c + 1));
            if (r + 1 < rows) link(a, patch.at<int>(r + 1, c));
        }
    std::vector<int> parent(count);
    for (std::size_t i = 0; i < count; ++i) parent[i] = static_cast<int>(i);
    std::function<int(int)> root = [&](int x) {
        while (parent[static_cast<std::size_t>(x)] != x) x = parent[static_cast<std::size_t>(x)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(x)])];
        return x;
    };
    auto colourDistance = [&](int ka, int kb) { return cv::norm(centres.row(ka), centres.row(kb), cv::NORM_L2SQR); };
    // Smallest first; a merged patch's area grows, so recheck until none is small (bounded: each merge removes one).
    for (bool merged = true; merged;) {
        merged = false;
        std::vector<int> order;
        for (std::size_t i = 0; i < count; ++i)
            if (root(static_cast<int>(i)) == static_cast<int>(i) && area[i] < minArea) order.push_back(static_cast<int>(i));
        std::sort(order.begin(), order.end(), [&](int a, int b) { return area[static_cast<std::size_t>(a)] < area[static_cast<std::size_t>(b)]; });
        for (int p : order) {
            if (root(p) != p || area[static_cast<std::size_t>(p)] >= minArea) continue;
            int best = -1;
            double bestDistance = 0.0;
            for (int q : neighbours[static_cast<std::size_t>(p)]) {
                const int rq = root(q);
                if (rq == p) continue;
                const double d = colourDistance(cluster[static_cast<std::size_t>(p)], cluster[static_cast<std::size_t>(rq)]);
                if (best < 0 || d < bestDistance || (d == bestDistance && area[static_cast<std::size_t>(rq)] > area[static_cast<std::size_t>(best)])) {
                    best = rq;
                    bestDistance = d;
                }
            }
            if (best < 0) continue;
            parent[static_cast<std::size_t>(p)] = best;
            area[static_cast<std::size_t>(best)] += area[static_cast<std::size_t>(p)];
            auto& into = neighbours[static_cast<std::size_t>(best)];
            const auto& from = neighbours[static_cast<std::size_t>(p)];
            into.insert(into.end(), from.begin(), from.end());
            // Keep the lists short: roots only, once each.
            for (int& q : into) q = root(q);
            std::sort(into.begin(), into.end());
            into.erase(std::unique(into.begin(), into.end()), into.end());
            merged = true;
        }
    }
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) {
            const int a = patch.at<int>(r, c);
            if (a >= 0) index.at<uchar>(r, c) = static_cast<uchar>(cluster[static_cast<std::size_t>(root(a))]);
        }
}

}  // namespace

namespace {

std::vector<cv::Point2d> ellipsePolygon(cv::Point2d centre, double rx, double ry, int n = 16) {
    std::vector<cv::Point2d> out;
    for (int i = 0; i < n; ++i) {
        const double a = 2.0 * std::numbers::pi * i / n;
        out.emplace_back(centre.x + rx * std::cos(a), centre.y + ry * std::sin(a));
    }
    return out;
}

cv::Point2d meanOf(const std::array<cv::Point2d, 68>& p, int from, int to) {
    cv::Point2d sum(0, 0);
    for (int i = from; i <= to; ++i) sum += p[static_cast<std::size_t>(i)];
    return sum / static_cast<double>(to - from + 1);
}

// The polygon scaled about its centre (sx across, sy down), at least `minHeight` high.
std::vector<cv::Point2d> scaled(std::vector<cv::Point2d> poly, double s, double minHeight = 0.0) {
    cv::Point2d c(0, 0);
    double top = 1e18, bottom = -1e18;
    for (const auto& q : poly) {
        c += q;
        top = std::min(top, q.y);
        bottom = std::max(bottom, q.y);
    }
    c /= static_cast<double>(poly.size());
    const double sy = std::max(s, bottom > top ? minHeight / (bottom - top) : s);
    for (auto& q : poly) q = {c.x + (q.x - c.x) * s, c.y + (q.y - c.y) * sy};
    return poly;
}

// The part of `shape` inside the convex `within` (an iris inside its eye).
std::vector<cv::Point2d> clippedTo(const std::vector<cv::Point2d>& shape, const std::vector<cv::Point2d>& within) {
    std::vector<cv::Point2f> a(shape.begin(), shape.end()), b, hull, out;
    for (const auto& q : within) b.emplace_back(q);
    cv::convexHull(b, hull);
    cv::intersectConvexConvex(a, hull, out, true);
    return {out.begin(), out.end()};
}

}  // namespace

DrawingGuide frontDrawingGuide(const std::array<cv::Point2d, 68>& p) {
    DrawingGuide g;
    const cv::Point2d eyeR = meanOf(p, 36, 41), eyeL = meanOf(p, 42, 47);
    const double d = cv::norm(eyeL - eyeR);  // the eyes' distance: the face's own unit
    if (!(d > 1.0)) return g;
    using Tone = FeatureShape::Tone;
    // Brows: dlib's points run along the brow's middle; a band 0.13 d thick, its ends tapered.
    for (int from : {17, 22}) {
        std::vector<cv::Point2d> poly;
        for (int i = from; i < from + 5; ++i) {
            const double taper = (i == from || i == from + 4) ? 0.5 : 1.0;
            poly.push_back(p[static_cast<std::size_t>(i)] + cv::Point2d(0, -0.05 * d * taper));
        }
        for (int i = from + 4; i >= from; --i) {
            const double taper = (i == from || i == from + 4) ? 0.5 : 1.0;
            poly.push_back(p[static_cast<std::size_t>(i)] + cv::Point2d(0, 0.08 * d * taper));
        }
        g.features.push_back({"brow", poly, Tone::Dark, {}});
    }
    // Eyes a little larger and opener than the photo's (a drawing's eyes read at a glance), the iris inside.
    for (int from : {36, 42}) {
        std::vector<cv::Point2d> eye(p.begin() + from, p.begin() + from + 6);
        eye = scaled(eye, 1.2, 0.2 * d);
        const cv::Point2d c = meanOf(p, from, from + 5);
        g.features.push_back({"eye", eye, Tone::Light, {}});
        g.features.push_back({"iris", clippedTo(ellipsePolygon(c, 0.11 * d, 0.11 * d), eye), Tone::Dark, {}});
    }
    // Nostrils: beside the nose's base (31 .. 35), just above it.
    const double nostrilY = -0.04 * d;
    g.features.push_back({"nostril", ellipsePolygon((p[31] + p[32]) * 0.5 + cv::Point2d(0, nostrilY), 0.06 * d, 0.035 * d), Tone::Dark, {}});
    g.features.push_back({"nostril", ellipsePolygon((p[34] + p[35]) * 0.5 + cv::Point2d(0, nostrilY), 0.06 * d, 0.035 * d), Tone::Dark, {}});
    // Lips: the outer lip line, at least 0.16 d high (closed lips are thin).
    g.features.push_back({"mouth", scaled({p.begin() + 48, p.begin() + 60}, 1.05, 0.16 * d), Tone::Middle, {}});
    // Bare skin: the cheeks between the jaw, the mouth's corner and the nose.
    g.skinSamples.push_back({p[1], p[3], p[48], p[31]});
    g.skinSamples.push_back({p[15], p[13], p[54], p[35]});
    return g;
}

DrawingGuide sideDrawingGuide(const std::map<std::string, cv::Point2d>& profile) {
    DrawingGuide g;
    auto at = [&](const char* name) -> std::optional<cv::Point2d> {
        const auto it = profile.find(name);
        if (it == profile.end()) return std::nullopt;
        return it->second;
    };
    const auto nasion = at("nasion"), sub = at("subnasale"), tip = at("nose_tip"), upper = at("upper_lip"),
               lower = at("lower_lip"), glabella = at("glabella"), ear = at("ear_hole");
    if (!nasion || !sub || !tip || !upper || !lower || !glabella) return g;
    const double h = sub->y - nasion->y;  // nasion to subnasale, about 50 mm on an adult
    if (!(h > 1.0)) return g;
    using Tone = FeatureShape::Tone;
    // The face points to -x: "back" is +x. Fractions of h from average adult proportions (the cornea about 10 mm
    // behind the nasion and 10 mm below it, the visible eye about 20 mm long in profile, the brow 15 mm above the
    // eye, the mouth's corner 25 mm behind the lips).
    const cv::Point2d eyeFront(nasion->x + 0.22 * h, nasion->y + 0.22 * h);
    const std::vector<cv::Point2d> eye{eyeFront, {eyeFront.x + 0.2 * h, eyeFront.y - 0.12 * h},
                                       {eyeFront.x + 0.42 * h, eyeFront.y - 0.02 * h},
                                       {eyeFront.x + 0.18 * h, eyeFront.y + 0.1 * h}};
    g.features.push_back({"eye", eye, Tone::Light, {}});
    g.features.push_back({"iris", clippedTo(ellipsePolygon({eyeFront.x + 0.1 * h, eyeFront.y - 0.01 * h}, 0.07 * h, 0.12 * h), eye),
                          Tone::Dark, {}});
    const double browY = eyeFront.y - 0.32 * h;
    const double browX = glabella->x + 0.12 * h;
    g.features.push_back({"brow",
                          {{browX, browY - 0.04 * h}, {browX + 0.3 * h, browY - 0.08 * h}, {browX + 0.62 * h, browY - 0.02 * h},
                           {browX + 0.6 * h, browY + 0.05 * h}, {browX + 0.3 * h, browY + 0.02 * h}, {browX, browY + 0.06 * h}},
                          Tone::Dark, {}});
    g.features.push_back({"nostril", ellipsePolygon({tip->x + 0.3 * h, sub->y - 0.07 * h}, 0.1 * h, 0.05 * h), Tone::Dark, {}});
    const double lipFront = std::max(upper->x, lower->x) + 0.03 * h, mouthY = (upper->y + lower->y) / 2.0;
    g.features.push_back({"mouth",
                          {{upper->x + 0.03 * h, upper->y - 0.1 * h}, {lipFront + 0.45 * h, mouthY - 0.03 * h},
                           {lipFront + 0.45 * h, mouthY + 0.03 * h}, {lower->x + 0.03 * h, lower->y + 0.1 * h},
                           {std::min(upper->x, lower->x) + 0.02 * h, mouthY}},
                          Tone::Middle, {}});
    // Bare skin: the cheek, between the nose and the ear at the nose's height.
    const cv::Point2d cheek = ear ? cv::Point2d((tip->x + 2.0 * ear->x) / 3.0, tip->y) : cv::Point2d(tip->x + 0.9 * h, tip->y);
    g.skinSamples.push_back(ellipsePolygon(cheek, 0.25 * h, 0.25 * h));
    return g;
}

ToonDrawing toonDrawing(const cv::Mat& photoBgr, const cv::Mat& headMask, int colours, int outlineWidth,
                        const DrawingGuide& guide) {
    CV_Assert(photoBgr.type() == CV_8UC3 && headMask.size() == photoBgr.size());
    ToonDrawing out;
    out.mask = headMask > 127;
    out.bgr = cv::Mat(photoBgr.size(), CV_8UC3, cv::Scalar(255, 255, 255));
    out.outline = cv::Mat(photoBgr.size(), CV_8U, cv::Scalar(0));
    out.featureColours.assign(guide.features.size(), cv::Vec3b(0, 0, 0));
    std::vector<cv::Point> inPixels;
    cv::findNonZero(out.mask, inPixels);
    colours = std::clamp(colours, 2, 16);
    if (static_cast<int>(inPixels.size()) < colours) return out;
    // Sizes follow the head: the mask's height (photos come scaled to ~320 px of head, but any size works).
    const cv::Rect head = cv::boundingRect(out.mask);
    const double unit = head.height / 320.0;
    // Mean shift flattens skin shading and pores into patches while keeping the edges of eyes, brows and hair; a
    // bilateral pass then evens what is left.
    cv::Mat smooth, shifted;
    cv::pyrMeanShiftFiltering(photoBgr, shifted, std::max(4.0, 8.0 * unit), 20.0, 1);
    cv::bilateralFilter(shifted, smooth, 7, 30.0, 5.0);
    cv::Mat lab;
    cv::cvtColor(smooth, lab, cv::COLOR_BGR2Lab);

    // The skin's colour: the median Lab of the guide's bare-skin areas, else of the middle of the head.
    cv::Mat skinArea(photoBgr.size(), CV_8U, cv::Scalar(0));
    for (const auto& poly : guide.skinSamples) {
        std::vector<cv::Point> q;
        for (const auto& p : poly) q.emplace_back(cvRound(p.x), cvRound(p.y));
        if (q.size() >= 3) cv::fillPoly(skinArea, std::vector<std::vector<cv::Point>>{q}, cv::Scalar(255));
    }
    skinArea &= out.mask;
    if (cv::countNonZero(skinArea) < 30) {
        skinArea.setTo(0);
        const cv::Rect middle(head.x + head.width * 35 / 100, head.y + head.height * 45 / 100, std::max(1, head.width * 3 / 10),
                              std::max(1, head.height / 4));
        skinArea(middle & cv::Rect(0, 0, skinArea.cols, skinArea.rows)).setTo(255);
        skinArea &= out.mask;
    }
    cv::Vec3f skinRef(0, 0, 0);
    {
        std::vector<float> ch[3];
        for (int r = 0; r < lab.rows; ++r)
            for (int c = 0; c < lab.cols; ++c)
                if (skinArea.at<uchar>(r, c)) {
                    const cv::Vec3b v = lab.at<cv::Vec3b>(r, c);
                    for (int k = 0; k < 3; ++k) ch[k].push_back(v[k]);
                }
        for (int k = 0; k < 3; ++k)
            if (!ch[k].empty()) {
                std::nth_element(ch[k].begin(), ch[k].begin() + static_cast<std::ptrdiff_t>(ch[k].size() / 2), ch[k].end());
                skinRef[k] = ch[k][ch[k].size() / 2];
            }
    }
    // Skin: the skin's hue (a, b within kSkinChroma) at any lightness from kSkinDarker below it to anything above:
    // light and shade on one face change lightness far more than hue, and hair, lips and eyes differ in hue or are
    // much darker. (OpenCV's 8-bit Lab: L scaled to 0..255, a and b offset by 128.)
    constexpr float kSkinChroma = 14.0f, kSkinDarker = 75.0f;
    constexpr float kLightnessWeight = 0.5f;
    std::vector<cv::Point> otherPixels;
    cv::Mat index(photoBgr.size(), CV_8U, cv::Scalar(255));
    for (const cv::Point& p : inPixels) {
        const cv::Vec3b v = lab.at<cv::Vec3b>(p);
        // Highlights wash the hue out towards grey: the lighter, the more chroma distance is allowed.
        const float lighter = std::max(0.0f, v[0] - skinRef[0]);
        const bool skin = std::hypot(v[1] - skinRef[1], v[2] - skinRef[2]) <= kSkinChroma * (1.0f + lighter / 40.0f) &&
                          v[0] >= skinRef[0] - kSkinDarker;
        if (skin) {
            index.at<uchar>(p) = 0;
        } else {
            otherPixels.push_back(p);
        }
    }
    // The rest: k-means in Lab with the lightness weighted down, clusters differing in lightness only merged (hair
    // with its sheen).
    const int others = std::min(colours - 1, static_cast<int>(otherPixels.size()));
    cv::Mat centres(1 + std::max(others, 0), 3, CV_32F, cv::Scalar(0));
    centres.at<float>(0, 0) = skinRef[0] * kLightnessWeight;
    centres.at<float>(0, 1) = skinRef[1];
    centres.at<float>(0, 2) = skinRef[2];
    if (others >= 1) {
        cv::Mat samples(static_cast<int>(otherPixels.size()), 3, CV_32F);
        for (int i = 0; i < samples.rows; ++i) {
            const cv::Vec3b p = lab.at<cv::Vec3b>(otherPixels[static_cast<std::size_t>(i)]);
            samples.at<float>(i, 0) = p[0] * kLightnessWeight;
            samples.at<float>(i, 1) = p[1];
            samples.at<float>(i, 2) = p[2];
        }
        cv::Mat clusterOf, otherCentres;
        cv::setRNGSeed(7);  // the same photo gives the same drawing
        cv::kmeans(samples, others, clusterOf, cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 1.0),
                   2, cv::KMEANS_PP_CENTERS, otherCentres);
        constexpr double kSameChroma = 6.0, kSameLightness = 40.0;
        std::vector<int> merged(static_cast<std::size_t>(others));
        for (int k = 0; k < others; ++k) merged[static_cast<std::size_t>(k)] = k;
        for (int a = 0; a < others; ++a)
            for (int b = a + 1; b < others; ++b) {
                const double dl = std::abs(otherCentres.at<float>(a, 0) - otherCentres.at<float>(b, 0)) / kLightnessWeight;
                const double dc = std::hypot(otherCentres.at<float>(a, 1) - otherCentres.at<float>(b, 1),
                                             otherCentres.at<float>(a, 2) - otherCentres.at<float>(b, 2));
                if (dl > kSameLightness || dc > kSameChroma) continue;
                const int ra = merged[static_cast<std::size_t>(a)], rb = merged[static_cast<std::size_t>(b)];
                for (int& m : merged)
                    if (m == rb) m = ra;
            }
        for (int k = 0; k < others; ++k) otherCentres.row(merged[static_cast<std::size_t>(k)]).copyTo(centres.row(1 + merged[static_cast<std::size_t>(k)]));
        for (int i = 0; i < samples.rows; ++i)
            index.at<uchar>(otherPixels[static_cast<std::size_t>(i)]) =
                static_cast<uchar>(1 + merged[static_cast<std::size_t>(clusterOf.at<int>(i))]);
    }
    // Majority filter: each pixel takes the label most common around it, which smooths the regions' boundaries and
    // removes thin shading streaks (a median of label numbers would invent labels between them).
    {
        const int radius = std::max(2, cvRound(4.0 * unit));
        const int labels = centres.rows;
        cv::Mat best(index.size(), CV_32F, cv::Scalar(-1.0f)), chosen = index.clone();
        for (int k = 0; k < labels; ++k) {
            cv::Mat votes;
            cv::Mat(index == k).convertTo(votes, CV_32F, 1.0 / 255.0);
            cv::blur(votes, votes, cv::Size(2 * radius + 1, 2 * radius + 1));
            cv::Mat better = votes > best;
            votes.copyTo(best, better);
            chosen.setTo(k, better);
        }
        index = chosen;
        index.setTo(255, ~out.mask);
    }
    // Patches under 1/400 of the head height squared (a 16 px square at 320 px) go to the touching patch of the
    // nearest colour, so every region left is a part of the head, not a shading fleck.
    mergeSmallPatches(index, centres, std::max(30, cvRound(head.height * head.height / 400.0)));

    // Colours: each label's mean photo colour (smoothed); the skin's from the skin pixels.
    std::vector<cv::Vec3d> sum(256, cv::Vec3d(0, 0, 0));
    std::vector<double> n(256, 0.0);
    for (const cv::Point& p : inPixels) {
        const uchar k = index.at<uchar>(p);
        if (k == 255) continue;
        const cv::Vec3b bgr = smooth.at<cv::Vec3b>(p);
        sum[k] += cv::Vec3d(bgr[0], bgr[1], bgr[2]);
        n[k] += 1.0;
    }
    std::vector<cv::Vec3b> colourOf(256, cv::Vec3b(0, 0, 0));
    for (int k = 0; k < 255; ++k) {
        const cv::Vec3d m = sum[static_cast<std::size_t>(k)] / std::max(1.0, n[static_cast<std::size_t>(k)]);
        colourOf[static_cast<std::size_t>(k)] = cv::Vec3b(cv::saturate_cast<uchar>(m[0]), cv::saturate_cast<uchar>(m[1]),
                                                          cv::saturate_cast<uchar>(m[2]));
    }
    out.skinColour = colourOf[0];

    // The face parts, painted over in order (an iris after its eye), each a label of its own with its own colour.
    int nextLabel = centres.rows;
    for (std::size_t f = 0; f < guide.features.size() && nextLabel < 255; ++f) {
        const FeatureShape& shape = guide.features[f];
        std::vector<cv::Point> q;
        for (const auto& p : shape.polygon) q.emplace_back(cvRound(p.x), cvRound(p.y));
        if (q.size() < 3) continue;
        cv::Mat area(photoBgr.size(), CV_8U, cv::Scalar(0));
        cv::fillPoly(area, std::vector<std::vector<cv::Point>>{q}, cv::Scalar(255));
        area &= out.mask;
        std::vector<cv::Point> pixels;
        cv::findNonZero(area, pixels);
        if (pixels.empty()) continue;
        cv::Vec3b colour;
        if (shape.colour) {
            colour = *shape.colour;
        } else {
            // The photo's own pixels under it, by lightness: the darker third, the lighter third or the middle half.
            std::vector<std::pair<int, cv::Vec3b>> byLight;
            for (const cv::Point& p : pixels) byLight.emplace_back(lab.at<cv::Vec3b>(p)[0], smooth.at<cv::Vec3b>(p));
            std::sort(byLight.begin(), byLight.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
            const std::size_t m = byLight.size();
            std::size_t from = m / 4, to = m - m / 4;
            if (shape.tone == FeatureShape::Tone::Dark) from = 0, to = std::max<std::size_t>(1, m / 3);
            if (shape.tone == FeatureShape::Tone::Light) from = m - std::max<std::size_t>(1, m / 3), to = m;
            cv::Vec3d s(0, 0, 0);
            for (std::size_t i = from; i < to; ++i) s += cv::Vec3d(byLight[i].second[0], byLight[i].second[1], byLight[i].second[2]);
            s /= static_cast<double>(std::max<std::size_t>(1, to - from));
            colour = cv::Vec3b(cv::saturate_cast<uchar>(s[0]), cv::saturate_cast<uchar>(s[1]), cv::saturate_cast<uchar>(s[2]));
        }
        out.featureColours[f] = colour;
        colourOf[static_cast<std::size_t>(nextLabel)] = colour;
        index.setTo(nextLabel, area);
        ++nextLabel;
    }

    // Edges: where the label changes, and the head's own boundary.
    cv::Mat edges(photoBgr.size(), CV_8U, cv::Scalar(0));
    for (int r = 0; r + 1 < index.rows; ++r)
        for (int c = 0; c + 1 < index.cols; ++c) {
            const uchar v = index.at<uchar>(r, c);
            if (v != index.at<uchar>(r, c + 1) || v != index.at<uchar>(r + 1, c)) edges.at<uchar>(r, c) = 255;
        }
    if (outlineWidth > 1) {
        cv::dilate(edges, edges, cv::getStructuringElement(cv::MORPH_ELLIPSE, {outlineWidth, outlineWidth}));
    }
    out.outline = edges & out.mask;
    for (const cv::Point& p : inPixels) {
        const uchar k = index.at<uchar>(p);
        if (out.outline.at<uchar>(p)) {
            out.bgr.at<cv::Vec3b>(p) = cv::Vec3b(0, 0, 0);
        } else if (k != 255) {
            out.bgr.at<cv::Vec3b>(p) = colourOf[k];
        }
    }
    return out;
}

double regionSimilarity(const Region& a, const Region& b, const ViewDirection& viewA, const ViewDirection& viewB,
                        double colourThreshold) {
    const double colourDistance = cv::norm(a.colour - b.colour);
    if (colourThreshold - colourDistance < 0.0) return 0.0;  // J = H(T_c - C), H(0) = 1
    const double wx = viewA.thetaDeg == viewB.thetaDeg ? 1.0 : 0.5;
    const double wy = viewA.phiDeg == viewB.phiDeg ? 1.0 : 0.5;
    const double meanArea = (a.area + b.area) / 2.0;
    return std::exp(-wx * std::abs(a.bboxCentre.x - b.bboxCentre.x)) *
           std::exp(-wy * std::abs(a.bboxCentre.y - b.bboxCentre.y)) *
           std::exp(-std::abs(a.area - b.area) / std::max(meanArea, 1e-12));
}

std::vector<std::optional<std::size_t>> matchRegions(const Regions& a, const Regions& b, const ViewDirection& viewA,
                                                     const ViewDirection& viewB, double colourThreshold) {
    std::vector<std::optional<std::size_t>> out(a.regions.size());
    for (std::size_t i = 0; i < a.regions.size(); ++i) {
        double best = 0.0;
        for (std::size_t j = 0; j < b.regions.size(); ++j) {
            const double s = regionSimilarity(a.regions[i], b.regions[j], viewA, viewB, colourThreshold);
            if (s > best) {
                best = s;
                out[i] = j;
            }
        }
    }
    return out;
}

glm::dvec3 algorithm1(const std::vector<Line3>& lines, int maxIterations, double tolerance) {
    glm::dvec3 current(0.0);
    if (lines.empty()) return current;
    for (int i = 0; i < maxIterations; ++i) {
        glm::dvec3 sum(0.0);
        for (const Line3& line : lines) sum += projectOntoLine(current, line);
        const glm::dvec3 next = sum / static_cast<double>(lines.size());
        const double moved = glm::length(next - current);
        current = next;
        if (moved < tolerance) break;
    }
    return current;
}

std::optional<glm::dvec3> closestPointOfLines(const std::vector<Line3>& lines) {
    glm::dmat3 a(0.0);
    glm::dvec3 rhs(0.0);
    for (const Line3& line : lines) {
        const glm::dvec3 d = glm::normalize(line.direction);
        const glm::dmat3 p = glm::dmat3(1.0) - glm::outerProduct(d, d);
        a += p;
        rhs += p * line.point;
    }
    if (std::abs(glm::determinant(a)) < 1e-12) return std::nullopt;
    return glm::inverse(a) * rhs;
}

PlacedPair placePair(const Region& a, const Region& b, std::size_t indexA, std::size_t indexB,
                     const DrawingView& viewA, const DrawingView& viewB) {
    PlacedPair out;
    out.regionA = indexA;
    out.regionB = indexB;
    const glm::dvec3 dirA = viewA.direction.towardsCamera(), dirB = viewB.direction.towardsCamera();
    out.position = algorithm1({{viewA.pointOnLine(a.bboxCentre), dirA}, {viewB.pointOnLine(b.bboxCentre), dirB}});
    out.positionA = projectOntoLine(out.position, {viewA.pointOnLine(a.centroid), dirA});
    out.positionB = projectOntoLine(out.position, {viewB.pointOnLine(b.centroid), dirB});
    return out;
}

}  // namespace avatarbooth::toon
