// Kitamura's two-view toon character, second half: outline correspondence, orthographic billboards, turntable.
#include "reveal/toon/toon_billboard.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "fit/face/profile.h"
#include "fit/face/silhouette.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <optional>
#include <tuple>

namespace avatarbooth::toon {

namespace {

// The closed outline resampled to n points equally spaced by arc length.
std::vector<cv::Point2d> resample(const std::vector<cv::Point>& contour, int n) {
    std::vector<cv::Point2d> out;
    if (contour.empty()) return std::vector<cv::Point2d>(static_cast<std::size_t>(n), cv::Point2d(0, 0));
    std::vector<double> cumulative(contour.size() + 1, 0.0);
    for (std::size_t i = 0; i < contour.size(); ++i) {
        const cv::Point d = contour[(i + 1) % contour.size()] - contour[i];
        cumulative[i + 1] = cumulative[i] + std::hypot(d.x, d.y);
    }
    const double total = cumulative.back();
    std::size_t seg = 0;
    for (int k = 0; k < n; ++k) {
        const double s = total * k / n;
        while (seg + 1 < contour.size() && cumulative[seg + 1] <= s) ++seg;
        const double len = cumulative[seg + 1] - cumulative[seg];
        const double t = len > 0 ? (s - cumulative[seg]) / len : 0.0;
        const cv::Point2d p0 = contour[seg], p1 = contour[(seg + 1) % contour.size()];
        out.push_back(p0 + (p1 - p0) * t);
    }
    return out;
}

// Angle of the principal axis of a point set about its mean.
double principalAngle(const std::vector<cv::Point2d>& pts) {
    double sxx = 0, syy = 0, sxy = 0;
    for (const cv::Point2d& p : pts) {
        sxx += p.x * p.x;
        syy += p.y * p.y;
        sxy += p.x * p.y;
    }
    return 0.5 * std::atan2(2.0 * sxy, sxx - syy);
}

}  // namespace

ContourCorrespondence correspondContours(const Region& a, const Region& b, int points) {
    ContourCorrespondence out;
    out.a = resample(a.contour, points);
    std::vector<cv::Point2d> pb = resample(b.contour, points);
    for (auto& p : out.a) p -= a.centroid;
    for (auto& p : pb) p -= b.centroid;
    // Align b's principal axis with a's (both ways round: an axis has no sign), then pick the cyclic shift.
    const double base = principalAngle(out.a) - principalAngle(pb);
    double bestCost = std::numeric_limits<double>::infinity();
    int bestShift = 0;
    for (double turn : {0.0, CV_PI}) {
        const double c = std::cos(base + turn), s = std::sin(base + turn);
        for (int shift = 0; shift < points; ++shift) {
            double cost = 0.0;
            for (int i = 0; i < points; ++i) {
                const cv::Point2d q = pb[static_cast<std::size_t>((i + shift) % points)];
                const cv::Point2d r(c * q.x - s * q.y, s * q.x + c * q.y);
                const cv::Point2d d = out.a[static_cast<std::size_t>(i)] - r;
                cost += d.dot(d);
            }
            if (cost < bestCost) {
                bestCost = cost;
                bestShift = shift;
            }
        }
    }
    out.b.resize(static_cast<std::size_t>(points));
    for (int i = 0; i < points; ++i)
        out.b[static_cast<std::size_t>(i)] = pb[static_cast<std::size_t>((i + bestShift) % points)];
    return out;
}

ToonModel buildToonModel(const cv::Mat& drawingA, const cv::Mat& maskA, const DrawingView& viewA,
                         const cv::Mat& drawingB, const cv::Mat& maskB, const DrawingView& viewB,
                         const cv::Mat& outlineA, const cv::Mat& outlineB, int minRegionArea) {
    ToonModel model;
    model.viewA = viewA;
    model.viewB = viewB;
    model.regionsA = splitRegions(drawingA, maskA, outlineA, 60, minRegionArea);
    model.regionsB = splitRegions(drawingB, maskB, outlineB, 60, minRegionArea);
    const auto match = matchRegions(model.regionsA, model.regionsB, viewA.direction, viewB.direction);
    for (std::size_t i = 0; i < match.size(); ++i) {
        if (!match[i]) continue;
        const Region& a = model.regionsA.regions[i];
        const Region& b = model.regionsB.regions[*match[i]];
        model.pairs.push_back(placePair(a, b, i, *match[i], viewA, viewB));
        model.contours.push_back(correspondContours(a, b));
    }
    return model;
}

namespace {

std::size_t backdropsOf(const ToonModel& model) { return std::min(model.backdropPairs, model.pairs.size()); }

// Draws the billboards into `canvas` (CV_8UC3, its size is the render size) and, when `alpha` is not null, their
// coverage into *alpha (CV_8U, cleared by the caller).
void drawToon(const ToonModel& model, double yawDeg, cv::Mat& canvas, cv::Mat* alpha, double unitsPerPixel,
              int outlineWidth) {
    const cv::Size size = canvas.size();
    const double yaw = std::clamp(std::abs(yawDeg), 0.0, 90.0);
    const double span = model.viewB.direction.thetaDeg - model.viewA.direction.thetaDeg;
    const double t = span != 0.0 ? std::clamp((yaw - model.viewA.direction.thetaDeg) / span, 0.0, 1.0) : 0.0;
    DrawingView camera;
    camera.direction.thetaDeg = yaw;
    camera.direction.phiDeg = (1.0 - t) * model.viewA.direction.phiDeg + t * model.viewB.direction.phiDeg;
    camera.centre = {(size.width - 1) / 2.0, (size.height - 1) / 2.0};
    camera.unitsPerPixel = unitsPerPixel;
    const glm::dvec3 towards = camera.direction.towardsCamera();

    struct Item {
        double depth, area;
        std::size_t pair;
        glm::dvec3 position;
    };
    std::vector<Item> items;
    for (std::size_t k = 0; k < model.pairs.size(); ++k) {
        const PlacedPair& p = model.pairs[k];
        const glm::dvec3 pos = (1.0 - t) * p.positionA + t * p.positionB;
        const double area = (1.0 - t) * model.regionsA.regions[p.regionA].area + t * model.regionsB.regions[p.regionB].area;
        items.push_back({glm::dot(pos, towards), area, k, pos});
    }
    // How deep each region sits inside others in its drawing (regions are drawn with their holes filled: a ring of
    // hair round the face covers the face unless the face comes after it). Mixed between the views like the rest.
    auto nesting = [&](const Regions& regions, auto regionOf) {
        std::vector<double> level(model.pairs.size(), 0.0);
        for (std::size_t k = backdropsOf(model); k < model.pairs.size(); ++k) {
            const Region& inner = regions.regions[regionOf(model.pairs[k])];
            if (inner.contour.empty()) continue;
            const cv::Point2f probe = inner.contour.front();
            for (std::size_t j = backdropsOf(model); j < model.pairs.size(); ++j) {
                const Region& outer = regions.regions[regionOf(model.pairs[j])];
                if (j == k || outer.area <= inner.area || outer.contour.empty() || !outer.bbox.contains(inner.contour.front()))
                    continue;
                if (cv::pointPolygonTest(outer.contour, probe, false) > 0) level[k] += 1.0;
            }
        }
        return level;
    };
    const std::vector<double> levelA = nesting(model.regionsA, [](const PlacedPair& p) { return p.regionA; });
    const std::vector<double> levelB = nesting(model.regionsB, [](const PlacedPair& p) { return p.regionB; });
    std::vector<double> level(model.pairs.size());
    for (std::size_t k = 0; k < level.size(); ++k) level[k] = (1.0 - t) * levelA[k] + t * levelB[k];
    // Painter's order: the backdrop, then outer regions before the regions inside them (at each view exactly the
    // drawing's own order), then far first; at equal depth the larger region first, so inner parts stay on top.
    const std::size_t backdrops = model.backdropPairs;
    std::sort(items.begin(), items.end(), [backdrops, &level](const Item& x, const Item& y) {
        if ((x.pair < backdrops) != (y.pair < backdrops)) return x.pair < backdrops;
        const double lx = std::round(level[x.pair]), ly = std::round(level[y.pair]);
        if (lx != ly) return lx < ly;
        if (std::abs(x.depth - y.depth) > 1e-9) return x.depth < y.depth;
        return x.area > y.area;
    });
    constexpr int kShift = 4;  // sub-pixel drawing
    for (const Item& item : items) {
        const PlacedPair& p = model.pairs[item.pair];
        const ContourCorrespondence& cc = model.contours[item.pair];
        const cv::Point2d centre = camera.project(item.position);
        std::vector<cv::Point> poly;
        for (std::size_t i = 0; i < cc.a.size(); ++i) {
            const cv::Point2d off = (cc.a[i] * model.viewA.unitsPerPixel * (1.0 - t) +
                                     cc.b[i] * model.viewB.unitsPerPixel * t) / unitsPerPixel;
            const cv::Point2d q = (centre + off) * static_cast<double>(1 << kShift);
            poly.emplace_back(cvRound(q.x), cvRound(q.y));
        }
        const cv::Vec3d rgb = (1.0 - t) * model.regionsA.regions[p.regionA].colour + t * model.regionsB.regions[p.regionB].colour;
        const cv::Scalar bgr(rgb[2] * 255.0, rgb[1] * 255.0, rgb[0] * 255.0);
        const std::vector<std::vector<cv::Point>> polys{poly};
        cv::fillPoly(canvas, polys, bgr, cv::LINE_AA, kShift);
        if (outlineWidth > 0) cv::polylines(canvas, polys, true, cv::Scalar(20, 20, 20), outlineWidth, cv::LINE_AA, kShift);
        if (alpha) {
            cv::fillPoly(*alpha, polys, cv::Scalar(255), cv::LINE_AA, kShift);
            if (outlineWidth > 0) cv::polylines(*alpha, polys, true, cv::Scalar(255), outlineWidth, cv::LINE_AA, kShift);
        }
    }
    if (yawDeg < 0.0) {  // the other side: the side drawing mirrored
        cv::flip(canvas, canvas, 1);
        if (alpha) cv::flip(*alpha, *alpha, 1);
    }
}

}  // namespace

cv::Mat renderToon(const ToonModel& model, double yawDeg, cv::Size size, double unitsPerPixel, int outlineWidth,
                   cv::Mat* coverage) {
    cv::Mat canvas(size, CV_8UC3, cv::Scalar(255, 255, 255));
    cv::Mat mask;
    if (coverage) mask = cv::Mat::zeros(size, CV_8U);
    drawToon(model, yawDeg, canvas, coverage ? &mask : nullptr, unitsPerPixel, outlineWidth);
    if (coverage) *coverage = mask;
    return canvas;
}

double toonRadius(const ToonModel& model) {
    double radius = 0.0;
    for (std::size_t k = 0; k < model.pairs.size(); ++k) {
        double reachA = 0.0, reachB = 0.0;
        for (const cv::Point2d& p : model.contours[k].a) reachA = std::max(reachA, cv::norm(p));
        for (const cv::Point2d& p : model.contours[k].b) reachB = std::max(reachB, cv::norm(p));
        radius = std::max({radius, glm::length(model.pairs[k].positionA) + reachA * model.viewA.unitsPerPixel,
                           glm::length(model.pairs[k].positionB) + reachB * model.viewB.unitsPerPixel});
    }
    return radius;
}

cv::Mat renderToonBgra(const ToonModel& model, double yawDeg, cv::Size size, double radius, int outlineWidth) {
    CV_Assert(size.width > 0 && size.height > 0);
    if (radius <= 0.0) radius = toonRadius(model);
    // Interpolated positions and outlines stay within the radius at every yaw (both ends do, and the renderer mixes
    // them linearly), so the head never leaves the frame while it turns; 2 % spare for the outline's width.
    const double unitsPerPixel = std::max(radius, 1e-9) * 2.0 * 1.02 / std::min(size.width, size.height);
    // Dark under the coverage's soft edge: the edge is the dark outline, so straight alpha shows no light fringe.
    cv::Mat canvas(size, CV_8UC3, cv::Scalar(20, 20, 20)), alpha(size, CV_8U, cv::Scalar(0));
    drawToon(model, yawDeg, canvas, &alpha, unitsPerPixel, outlineWidth);
    cv::Mat bgra;
    cv::Mat channels[4];
    cv::split(canvas, channels);
    channels[3] = alpha;
    cv::merge(channels, 4, bgra);
    return bgra;
}

ToonModel toonFromPhotos(const cv::Mat& frontBgr, const cv::Mat& frontMask, const cv::Mat& sideBgr,
                         const cv::Mat& sideMask, bool sideNoseImageRight, int colours, int headHeightPx,
                         const ToonLandmarks& landmarks) {
    std::vector<cv::Vec3b> frontFeatureColours;
    std::vector<std::string> frontFeatureNames;
    auto prepare = [&](const cv::Mat& bgr, const cv::Mat& mask, bool mirror, const char* which, bool isFront) {
        if (bgr.empty() || mask.empty() || cv::countNonZero(mask > 127) == 0)
            throw BoothError(ErrorKind::NoFace, which, "no head mask to draw the toon from");
        const cv::Rect box = cv::boundingRect(mask > 127);
        const int pad = std::max(4, box.height / 20);
        const cv::Rect padded = (box + cv::Size(2 * pad, 2 * pad) - cv::Point(pad, pad)) & cv::Rect(0, 0, bgr.cols, bgr.rows);
        const double scale = static_cast<double>(headHeightPx) / box.height;
        cv::Mat photo, m;
        cv::resize(bgr(padded), photo, cv::Size(), scale, scale, cv::INTER_AREA);
        cv::resize(mask(padded), m, photo.size(), 0, 0, cv::INTER_NEAREST);
        if (mirror) {
            cv::flip(photo, photo, 1);
            cv::flip(m, m, 1);
        }
        // Photo pixels to drawing pixels: the crop, the scale (pixel centres), the mirror.
        auto toDrawing = [&](cv::Point2d p) {
            cv::Point2d q((p.x - padded.x + 0.5) * scale - 0.5, (p.y - padded.y + 0.5) * scale - 0.5);
            if (mirror) q.x = photo.cols - 1 - q.x;
            return q;
        };
        DrawingGuide guide;
        if (isFront && landmarks.front) {
            std::array<cv::Point2d, 68> points;
            for (std::size_t i = 0; i < points.size(); ++i) points[i] = toDrawing((*landmarks.front)[i]);
            guide = frontDrawingGuide(points);
        } else if (!isFront && !landmarks.side.empty()) {
            std::map<std::string, cv::Point2d> points;
            for (const auto& [name, p] : landmarks.side) points[name] = toDrawing(p);
            guide = sideDrawingGuide(points);
            // The side's face parts in the front's colours: one person's eyes, brows and lips, and the regions match.
            for (FeatureShape& f : guide.features)
                for (std::size_t i = 0; i < frontFeatureNames.size(); ++i)
                    if (frontFeatureNames[i] == f.name) {
                        f.colour = frontFeatureColours[i];
                        break;
                    }
        }
        ToonDrawing drawing = toonDrawing(photo, m, colours, 2, guide);
        if (isFront)
            for (std::size_t i = 0; i < guide.features.size(); ++i) {
                frontFeatureNames.push_back(guide.features[i].name);
                frontFeatureColours.push_back(drawing.featureColours[i]);
            }
        const cv::Rect b2 = cv::boundingRect(drawing.mask);
        return std::tuple{drawing, cv::Point2d(b2.x + (b2.width - 1) / 2.0, b2.y + (b2.height - 1) / 2.0), guide};
    };
    auto [front, frontCentre, frontGuide] = prepare(frontBgr, frontMask, false, "front photo", true);
    // Theta 90 looks from +x (the character's left): the face points to image left, so a nose-right photo flips.
    auto [side, sideCentre, sideGuide] = prepare(sideBgr, sideMask, sideNoseImageRight, "side photo", false);
    DrawingView a, b;
    a.direction = {0.0, 0.0};
    a.centre = frontCentre;
    b.direction = {90.0, 0.0};
    b.centre = sideCentre;
    // The drawing already joined shading patches under 1/400 of the head's height squared to their neighbours; what
    // is smaller now is a face part painted from the landmarks (an iris, a nostril), kept down to 20 pixels.
    ToonModel model = buildToonModel(front.bgr, front.mask, a, side.bgr, side.mask, b, front.outline, side.outline, 20);
    model.guideA = frontGuide;
    model.guideB = sideGuide;
    // The face parts are known in both views (the same landmarks placed them): a front part takes the side's part of
    // its name as its match, where the similarity's pixel positions (different axes in the two views) would often
    // pick the skin or the hair beside it.
    auto regionAt = [](const Regions& regions, const std::vector<cv::Point2d>& polygon) -> std::optional<std::size_t> {
        if (polygon.empty()) return std::nullopt;
        cv::Point2d c(0, 0);
        for (const auto& p : polygon) c += p;
        c /= static_cast<double>(polygon.size());
        const cv::Point q(cvRound(c.x), cvRound(c.y));
        if (!cv::Rect(0, 0, regions.labels.cols, regions.labels.rows).contains(q)) return std::nullopt;
        const int label = regions.labels.at<int>(q);
        for (std::size_t i = 0; i < regions.regions.size(); ++i)
            if (label > 0 && regions.regions[i].label == label) return i;
        return std::nullopt;
    };
    for (const FeatureShape& fa : frontGuide.features) {
        const auto ra = regionAt(model.regionsA, fa.polygon);
        if (!ra) continue;
        std::optional<std::size_t> rb;
        for (const FeatureShape& fb : sideGuide.features)
            if (fb.name == fa.name && (rb = regionAt(model.regionsB, fb.polygon))) break;
        if (!rb) continue;
        const Region& regionA = model.regionsA.regions[*ra];
        const Region& regionB = model.regionsB.regions[*rb];
        bool found = false;
        for (std::size_t k = 0; k < model.pairs.size(); ++k)
            if (model.pairs[k].regionA == *ra) {
                model.pairs[k] = placePair(regionA, regionB, *ra, *rb, a, b);
                model.contours[k] = correspondContours(regionA, regionB);
                found = true;
            }
        if (!found) {
            model.pairs.push_back(placePair(regionA, regionB, *ra, *rb, a, b));
            model.contours.push_back(correspondContours(regionA, regionB));
        }
    }
    // The whole head as one more region per view, drawn behind the others: what stays unmatched leaves no hole.
    auto silhouette = [](const ToonDrawing& d, Regions& regions) {
        Region r;
        std::vector<std::vector<cv::Point>> contours;
        cv::findContours(d.mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
        r.contour = *std::max_element(contours.begin(), contours.end(), [](const auto& x, const auto& y) {
            return cv::contourArea(x) < cv::contourArea(y);
        });
        r.bbox = cv::boundingRect(r.contour);
        r.bboxCentre = {r.bbox.x + (r.bbox.width - 1) / 2.0, r.bbox.y + (r.bbox.height - 1) / 2.0};
        const cv::Moments m = cv::moments(d.mask, true);
        r.centroid = {m.m10 / m.m00, m.m01 / m.m00};
        r.area = m.m00;
        const cv::Scalar mean = cv::mean(d.bgr, d.mask & ~d.outline);
        r.colour = {mean[2] / 255.0, mean[1] / 255.0, mean[0] / 255.0};
        r.label = -1;  // not in Regions::labels
        regions.regions.push_back(r);
        return regions.regions.size() - 1;
    };
    const std::size_t ia = silhouette(front, model.regionsA), ib = silhouette(side, model.regionsB);
    model.pairs.insert(model.pairs.begin(), placePair(model.regionsA.regions[ia], model.regionsB.regions[ib], ia, ib, a, b));
    model.contours.insert(model.contours.begin(), correspondContours(model.regionsA.regions[ia], model.regionsB.regions[ib]));
    model.backdropPairs = 1;
    return model;
}
ToonModel toonFromPhotoPair(const cv::Mat& frontBgr, const cv::Mat& sideBgr, const cv::Mat& plate, int colours,
                            const std::optional<std::array<cv::Point2d, 68>>& frontLandmarks) {
    const SideAnalysis profile = analyseSidePhoto(sideBgr, plate);
    // Both photos come from the same camera at the same height: the side photo's chin row cuts both masks to the head.
    const int chin = static_cast<int>(profilePoint(profile.landmarks, "chin").y) + 1;
    cv::Mat frontMask = segmentPerson(frontBgr, plate), sideMask = profile.mask.clone();
    frontMask.rowRange(std::clamp(chin, 0, frontMask.rows), frontMask.rows).setTo(0);
    sideMask.rowRange(std::clamp(chin, 0, sideMask.rows), sideMask.rows).setTo(0);
    ToonLandmarks landmarks;
    landmarks.front = frontLandmarks;
    for (const ProfilePoint& p : profile.landmarks) landmarks.side[p.name] = p.px;
    return toonFromPhotos(frontBgr, frontMask, sideBgr, sideMask, profile.noseImageRight, colours, 320, landmarks);
}

std::vector<std::pair<std::string, std::string>> turntableFrames(const ToonModel& model, int frames, cv::Size size,
                                                                 double unitsPerPixel) {
    std::vector<std::pair<std::string, std::string>> out;
    for (int i = 0; i < frames; ++i) {
        const double yaw = frames > 1 ? -90.0 + 180.0 * i / (frames - 1) : 0.0;
        char name[32];
        std::snprintf(name, sizeof name, "turntable_%03d.png", i);
        out.emplace_back(name, encodeImage(renderToon(model, yaw, size, unitsPerPixel), ".png"));
    }
    return out;
}

std::vector<std::filesystem::path> writeTurntable(const ToonModel& model, const std::filesystem::path& directory,
                                                  int frames, cv::Size size, double unitsPerPixel) {
    std::error_code ec;
    std::filesystem::create_directories(directory, ec);
    if (ec) throw BoothError(ErrorKind::Output, directory.string(), "cannot create the folder: " + ec.message());
    std::vector<std::filesystem::path> out;
    for (const auto& [name, png] : turntableFrames(model, frames, size, unitsPerPixel)) {
        writeFileAtomically(directory / name, png);
        out.push_back(directory / name);
    }
    return out;
}

}  // namespace avatarbooth::toon
