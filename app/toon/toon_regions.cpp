// Kitamura's two-view toon character, first half: drawings, regions, matching and Algorithm 1 (METHODS §3.2).
#include "toon/toon_regions.h"

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

ToonDrawing toonDrawing(const cv::Mat& photoBgr, const cv::Mat& headMask, int colours, int outlineWidth) {
    CV_Assert(photoBgr.type() == CV_8UC3 && headMask.size() == photoBgr.size());
    ToonDrawing out;
    out.mask = headMask > 127;
    out.bgr = cv::Mat(photoBgr.size(), CV_8UC3, cv::Scalar(255, 255, 255));
    out.outline = cv::Mat(photoBgr.size(), CV_8U, cv::Scalar(0));
    std::vector<cv::Point> inPixels;
    cv::findNonZero(out.mask, inPixels);
    if (static_cast<int>(inPixels.size()) < colours) return out;
    // Sizes follow the head: the mask's height (photos come scaled to ~320 px of head, but any size works).
    const cv::Rect head = cv::boundingRect(out.mask);
    const double unit = head.height / 320.0;
    // Mean shift flattens skin shading and pores into patches while keeping the edges of eyes, brows and hair; a
    // bilateral pass then evens what is left. (Bilateral alone left shading bands that k-means cut into many patches.)
    cv::Mat smooth, shifted;
    cv::pyrMeanShiftFiltering(photoBgr, shifted, std::max(4.0, 8.0 * unit), 20.0, 1);
    cv::bilateralFilter(shifted, smooth, 7, 30.0, 5.0);
    // k-means in Lab with the lightness weighted down: shading changes lightness much more than hue, so the skin stays
    // one cluster under the booth's side light while hair, eyes, lips and brows (different chroma or much darker)
    // keep theirs.
    cv::Mat lab;
    cv::cvtColor(smooth, lab, cv::COLOR_BGR2Lab);
    constexpr float kLightnessWeight = 0.5f;
    cv::Mat samples(static_cast<int>(inPixels.size()), 3, CV_32F);
    for (int i = 0; i < samples.rows; ++i) {
        const cv::Vec3b p = lab.at<cv::Vec3b>(inPixels[static_cast<std::size_t>(i)]);
        samples.at<float>(i, 0) = p[0] * kLightnessWeight;
        samples.at<float>(i, 1) = p[1];
        samples.at<float>(i, 2) = p[2];
    }
    cv::Mat clusterOf, centres;
    cv::setRNGSeed(7);  // the same photo gives the same drawing
    cv::kmeans(samples, colours, clusterOf, cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 20, 1.0),
               3, cv::KMEANS_PP_CENTERS, centres);
    // Clusters that differ in lightness only (the same material lit differently: skin in light and in shade, hair
    // with its sheen) become one: chroma (a, b) within kSameChroma and raw lightness within kSameLightness. Lips,
    // eyes and hair differ in chroma or by much more lightness and stay apart. k-means alone cuts the skin, the
    // largest area, into bands whatever the weights.
    constexpr double kSameChroma = 6.0, kSameLightness = 40.0;
    std::vector<int> merged(static_cast<std::size_t>(colours));
    for (int k = 0; k < colours; ++k) merged[static_cast<std::size_t>(k)] = k;
    std::vector<int> clusterSize(static_cast<std::size_t>(colours), 0);
    for (int i = 0; i < samples.rows; ++i) ++clusterSize[static_cast<std::size_t>(clusterOf.at<int>(i))];
    for (int a = 0; a < colours; ++a)
        for (int b = a + 1; b < colours; ++b) {
            const double dl = std::abs(centres.at<float>(a, 0) - centres.at<float>(b, 0)) / kLightnessWeight;
            const double dc = std::hypot(centres.at<float>(a, 1) - centres.at<float>(b, 1),
                                         centres.at<float>(a, 2) - centres.at<float>(b, 2));
            if (dl > kSameLightness || dc > kSameChroma) continue;
            const int ra = merged[static_cast<std::size_t>(a)], rb = merged[static_cast<std::size_t>(b)];
            if (ra == rb) continue;
            for (int& m : merged)
                if (m == rb) m = ra;
        }
    {
        // Merged centres: the size-weighted mean of their members.
        cv::Mat joined(centres.size(), centres.type(), cv::Scalar(0));
        std::vector<double> weight(static_cast<std::size_t>(colours), 0.0);
        for (int k = 0; k < colours; ++k) {
            const int m = merged[static_cast<std::size_t>(k)];
            cv::Mat into = joined.row(m);
            into += centres.row(k) * clusterSize[static_cast<std::size_t>(k)];
            weight[static_cast<std::size_t>(m)] += clusterSize[static_cast<std::size_t>(k)];
        }
        for (int k = 0; k < colours; ++k)
            if (weight[static_cast<std::size_t>(k)] > 0) {
                cv::Mat row = joined.row(k);
                row /= weight[static_cast<std::size_t>(k)];
            }
        centres = joined;
    }
    cv::Mat index(photoBgr.size(), CV_8U, cv::Scalar(255));
    std::vector<cv::Vec3d> sum(static_cast<std::size_t>(colours), cv::Vec3d(0, 0, 0));
    std::vector<double> n(static_cast<std::size_t>(colours), 0.0);
    for (int i = 0; i < samples.rows; ++i) {
        const int k = merged[static_cast<std::size_t>(clusterOf.at<int>(i))];
        const cv::Point p = inPixels[static_cast<std::size_t>(i)];
        index.at<uchar>(p) = static_cast<uchar>(k);
        const cv::Vec3b bgr = smooth.at<cv::Vec3b>(p);
        sum[static_cast<std::size_t>(k)] += cv::Vec3d(bgr[0], bgr[1], bgr[2]);
        n[static_cast<std::size_t>(k)] += 1.0;
    }
    cv::medianBlur(index, index, 5);  // removes single-pixel islands between clusters
    index.setTo(255, ~out.mask);
    // Patches under 1/400 of the head height squared (a 16 px square at 320 px: an eye's parts) go to the touching
    // patch of the nearest colour, so every region left is a face part, not a shading fleck.
    mergeSmallPatches(index, centres, std::max(30, cvRound(head.height * head.height / 400.0)));
    // Edges: where the patch colour changes, and the head's own boundary.
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
    for (int r = 0; r < index.rows; ++r)
        for (int c = 0; c < index.cols; ++c) {
            const uchar k = index.at<uchar>(r, c);
            if (!out.mask.at<uchar>(r, c)) continue;
            if (out.outline.at<uchar>(r, c)) {
                out.bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(0, 0, 0);
            } else if (k != 255) {
                // The cluster's mean photo colour (the Lab centre is weighted, so it is not a colour to show).
                const cv::Vec3d m = sum[k] / std::max(1.0, n[k]);
                out.bgr.at<cv::Vec3b>(r, c) = cv::Vec3b(cv::saturate_cast<uchar>(m[0]), cv::saturate_cast<uchar>(m[1]),
                                                        cv::saturate_cast<uchar>(m[2]));
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
