// NTT fitting: scale the base head per axis, measure feature and contour points, warp by RBFs, merge the views.
#include "fit/head/head_fit.h"

#include "fit/head/ears.h"

#include "common/error.h"
#include "common/landmark_names.h"
#include "fit/fit_error.h"
#include "fit/head/folds.h"
#include "fit/head/head_views.h"
#include "fit/head/modifier_fit.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <set>
#include <string_view>

namespace avatarbooth {
namespace {

// The photo a view's measurement comes from ("front" or "side"), for the error that says which to take again.
FitPhoto photoOf(const char* view) { return std::string_view(view) == "front" ? FitPhoto::Front : FitPhoto::Side; }

cv::Point2d mean(const std::map<std::string, cv::Point2d>& points, int from, int to) {
    cv::Point2d sum(0, 0);
    for (int k = from; k <= to; ++k) sum += points.at(landmarkName(k));
    return sum * (1.0 / (to - from + 1));
}

glm::dvec3 meanVertex(const Mesh& mesh, const BaseHead& base, int from, int to) {
    glm::dvec3 sum(0.0);
    for (int k = from; k <= to; ++k) sum += mesh.positions[base.frontFeatures.at(landmarkName(k))];
    return sum / static_cast<double>(to - from + 1);
}

// Walks from `start` along `dir` (pixels) and returns the last pixel inside the mask before it is left; this is
// where a half-line from the view's centre crosses the head's outline (METHODS §1 step 4).
cv::Point2d outlineCrossing(const cv::Mat& mask, const cv::Point2d& start, const cv::Point2d& dir, const char* view) {
    const double len = std::hypot(dir.x, dir.y);
    const cv::Point2d step = dir * (0.5 / len);
    cv::Point2d p = start, lastInside = start;
    bool wasInside = false;
    const double maxSteps = 2.0 * (mask.cols + mask.rows);
    for (int i = 0; i < maxSteps; ++i, p += step) {
        if (inMask(mask, p)) {
            lastInside = p;
            wasInside = true;
        } else if (wasInside) {
            return lastInside;
        } else if (i > 20) {
            break;
        }
    }
    throw FitError(ErrorKind::NoFace, photoOf(view), FitFault::NoFace, "",
                   std::string("the head's outline was not found in the ") + view +
                       " photo (the silhouette does not contain the head's centre)");
}

// Where a half-line from `start` along `dir` first crosses the polyline through `points` (in order), if it does.
std::optional<cv::Point2d> polylineCrossing(const std::vector<cv::Point2d>& points, const cv::Point2d& start,
                                            const cv::Point2d& dir) {
    std::optional<cv::Point2d> best;
    double bestT = 1e300;
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
        const cv::Point2d a = points[i], e = points[i + 1] - points[i];
        const double den = dir.x * e.y - dir.y * e.x;
        if (std::abs(den) < 1e-12) continue;
        const cv::Point2d w = a - start;
        const double t = (w.x * e.y - w.y * e.x) / den;  // along the ray
        const double s = (w.x * dir.y - w.y * dir.x) / den;  // along the segment
        if (t > 0.0 && s >= 0.0 && s <= 1.0 && t < bestT) {
            bestT = t;
            best = start + dir * t;
        }
    }
    return best;
}

cv::Point2d mirrorPoint(const cv::Point2d& p, int width, bool mirror) {
    return mirror ? cv::Point2d(width - 1 - p.x, p.y) : p;
}

const cv::Point2d& need(const std::map<std::string, cv::Point2d>& points, const std::string& name, const char* view) {
    const auto it = points.find(name);
    if (it == points.end())
        throw FitError(ErrorKind::NoFace, photoOf(view), FitFault::NoFace, "",
                       std::string("landmark '") + name + "' was not found in the " + view + " photo");
    return it->second;
}

// The feature and contour vertices one view measures, with their targets in that view's plane (METHODS §1 steps
// 3-4) and the displacements the RBF system of step 5 must reproduce. A vertex is measured once per view.
struct ViewTargets {
    explicit ViewTargets(View v) : view(v) {}
    View view;
    std::vector<glm::dvec3> centres;
    std::vector<std::vector<double>> displacements;
    std::vector<std::uint32_t> vertices;
    std::vector<std::pair<std::string, glm::dvec2>> targets;
    std::vector<glm::dvec2> outlineNormals;  // the unit normal of an outline target in the view's plane, else 0
    std::vector<glm::dvec2> measured;        // where the photo put the point, before the projection on the normal
    std::set<std::uint32_t> used;

    // A point measured on a smooth stretch of outline says only how far out the outline is there, not where along
    // it the point lies: with `normal` (the vertex normal) only the target's component along the outline's normal
    // in this view is kept, so that the surface is pushed out or in, never dragged along itself (which folds it).
    void add(const Mesh& mesh, const std::string& name, std::uint32_t v, glm::dvec2 target,
             const std::vector<glm::dvec3>* normals = nullptr) {
        addAcross(mesh, name, v, target, normals ? projectToView((*normals)[v], view) : glm::dvec2(0.0));
    }
    // The same with the normal in this view's plane given: only the target's component along it is kept (zero: the
    // point is measured both ways).
    void addAcross(const Mesh& mesh, const std::string& name, std::uint32_t v, glm::dvec2 target, const glm::dvec2& normal) {
        if (!used.insert(v).second) return;
        const glm::dvec3 c = mesh.positions[v];
        const glm::dvec2 now = projectToView(c, view);
        glm::dvec2 outlineNormal(0.0);
        measured.push_back(target);
        if (glm::length(normal) > 1e-6) {
            outlineNormal = glm::normalize(normal);
            target = now + outlineNormal * glm::dot(outlineNormal, target - now);
        }
        outlineNormals.push_back(outlineNormal);
        centres.push_back(c);
        displacements.push_back({target.x - now.x, target.y - now.y});
        vertices.push_back(v);
        targets.emplace_back(name, target);
    }
};

// The profile landmarks that are extremes or dips of a smooth stretch of outline (the most forward point of the
// brow, the chin, the lips, the deepest point of the nasion or under the chin, the highest and the most backward
// point, half-way up the forehead): their depth is measured, their height along the curve is a convention that one
// pixel of noise moves by millimetres, and pulling a vertex along the surface folds it. The nose tip and the
// subnasale are corners, measured both ways; the front photo gives the heights of the rest.
bool onSmoothOutline(const std::string& name) { return name != "nose_tip" && name != "subnasale"; }

// A contour ray's crossing (METHODS §1 step 4), as against a landmark: by the name ViewTargets gives it.
bool isContourTarget(const std::string& name) { return name.find("_contour_") != std::string::npos; }

// A point of the face's profile (HeadFitOptions::faceProfile), also by its name.
constexpr std::string_view kFaceProfilePrefix = "side_profile_";
bool isFaceProfileTarget(const std::string& name) { return name.rfind(kFaceProfilePrefix, 0) == 0; }

// The midline vertices that lie on the base head's side outline between the glabella and the throat, top to
// bottom: the head's side silhouette (drawn at 0.5 mm) holds no point 1.5 mm outside them along their normal, so
// the inner lips and what the nose hides drop out.
std::vector<std::uint32_t> faceProfileVertices(const BaseHead& base) {
    const Mesh& m = base.mesh;
    const auto top = base.sideFeatures.find("glabella"), bottom = base.sideFeatures.find("throat");
    if (top == base.sideFeatures.end() || bottom == base.sideFeatures.end()) return {};
    const double yTop = m.positions[top->second].y, yBottom = m.positions[bottom->second].y;
    glm::dvec3 lo, hi;
    m.bounds(lo, hi);
    constexpr double kMmPerPx = 0.5;
    const auto px = [&](const glm::dvec3& p) { return cv::Point2d((p.z - lo.z) / kMmPerPx + 4.0, (hi.y - p.y) / kMmPerPx + 4.0); };
    cv::Mat mask = cv::Mat::zeros(static_cast<int>((hi.y - lo.y) / kMmPerPx) + 8, static_cast<int>((hi.z - lo.z) / kMmPerPx) + 8, CV_8U);
    for (const auto& t : m.triangles) {
        const std::array<cv::Point, 3> c = {px(m.positions[t[0]]), px(m.positions[t[1]]), px(m.positions[t[2]])};
        cv::fillConvexPoly(mask, c.data(), 3, cv::Scalar(255));
    }
    std::vector<bool> rigid(m.positions.size(), false);
    for (const auto& part : base.rigidParts)
        for (const auto v : part) rigid[v] = true;
    const auto normals = m.vertexNormals();
    std::vector<std::uint32_t> out;
    for (std::uint32_t v = 0; v < m.positions.size(); ++v) {
        const glm::dvec3& p = m.positions[v];
        if (rigid[v] || std::abs(p.x) > 1e-3 || p.z < base.earHoleCentre.z || p.y > yTop || p.y < yBottom) continue;
        const glm::dvec2 n = projectToView(normals[v], View::Side);
        if (glm::length(n) < 0.5) continue;
        const glm::dvec2 out2 = projectToView(p, View::Side) + 1.5 * glm::normalize(n);
        if (!inMask(mask, px(glm::dvec3(0.0, out2.y, out2.x)))) out.push_back(v);
    }
    std::sort(out.begin(), out.end(), [&](std::uint32_t a, std::uint32_t b) { return m.positions[a].y > m.positions[b].y; });
    return out;
}

// Where the outline of `mask` crosses the segment through `at` along `dir` (pixels, unit length) within `reach`
// pixels either way: the crossing from inside to outside (going along dir) nearest `at`.
std::optional<cv::Point2d> outlineAlongNormal(const cv::Mat& mask, const cv::Point2d& at, const cv::Point2d& dir, double reach) {
    std::optional<cv::Point2d> best;
    double bestDistance = 1e300;
    bool wasInside = inMask(mask, at - dir * reach);
    for (double t = -reach + 0.5; t <= reach; t += 0.5) {
        const cv::Point2d p = at + dir * t;
        const bool in = inMask(mask, p);
        if (wasInside && !in && std::abs(t) < bestDistance) {
            bestDistance = std::abs(t);
            best = at + dir * (t - 0.25);
        }
        wasInside = in;
    }
    return best;
}

}  // namespace

bool inMask(const cv::Mat& mask, const cv::Point2d& p) {
    const int x = static_cast<int>(std::lround(p.x)), y = static_cast<int>(std::lround(p.y));
    return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<unsigned char>(y, x) != 0;
}

glm::dvec2 PhotoFrame::toHead(const cv::Point2d& px) const {
    const double u = mirrored ? imageWidth - 1 - px.x : px.x;
    return {(u - centrePx.x) * mmPerPixel + offsetMm.x, -(px.y - centrePx.y) * mmPerPixel + offsetMm.y};
}

cv::Point2d PhotoFrame::toPixel(const glm::dvec2& head) const {
    const double u = (head.x - offsetMm.x) / mmPerPixel + centrePx.x;
    return {mirrored ? imageWidth - 1 - u : u, -(head.y - offsetMm.y) / mmPerPixel + centrePx.y};
}

HeadFitOptions defaultHeadFitOptions() {
    HeadFitOptions o;
    // The chin (8), brows, nose, eye corners and the outer lips. Not the other jaw points: dlib places them on the
    // visible cheek outline, which is no fixed point of the head (it moves with the face's fullness and the slightest
    // turn): with them the synthetic visitor's detected-landmark fit is further from its true head (tests/integration).
    // (They still give the head's width for the scaling step.) Not the inner lips, which follow the mouth's opening,
    // nor the eyelids between the corners, which follow the eyes' opening: pulled to a photo's, the thin skin of the
    // lids folds over the rigid eyeball.
    o.frontLandmarks.push_back(8);
    for (int k = 17; k < 36; ++k) o.frontLandmarks.push_back(k);
    for (const int k : {36, 39, 42, 45}) o.frontLandmarks.push_back(k);
    for (int k = 48; k < 60; ++k) o.frontLandmarks.push_back(k);
    o.frontLandmarksByHeight = {18, 19, 20, 23, 24, 25, 49, 50, 52, 53, 55, 56, 58, 59};
    return o;
}

HeadFit fitHead(const BaseHead& base, const PhotoMeasurements& photos, const HeadFitOptions& options) {
    HeadFit fit;
    const Mesh& b = base.mesh;
    const auto& fp = photos.frontPoints;
    for (int k = 0; k < 68; ++k) need(fp, landmarkName(k), "front");
    if (photos.frontMask.empty() || photos.sideMask.empty())
        throw BoothError(ErrorKind::Internal, "", "fitHead needs both silhouettes");

    // --- Front frame. Absolute size: the visitor's eyes are taken to be as far apart as the base head's (the
    // one length orthographic photos cannot give); every other length is measured relative to it.
    const cv::Point2d eyeMidPx = mean(fp, 36, 47);
    const double ipdPx = cv::norm(mean(fp, 36, 41) - mean(fp, 42, 47));
    const double ipdBase = glm::distance(meanVertex(b, base, 36, 41), meanVertex(b, base, 42, 47));
    if (ipdPx < 4.0)
        throw FitError(ErrorKind::NoFace, FitPhoto::Front, FitFault::NoFace, "",
                       "the eyes in the front photo are too close together to measure");
    const double frontMmPerPx = ipdBase / ipdPx;
    // Relative to the eye midpoint, before the base head's position is known.
    const auto frontRel = [&](const cv::Point2d& px) {
        return glm::dvec2((px.x - eyeMidPx.x) * frontMmPerPx, -(px.y - eyeMidPx.y) * frontMmPerPx);
    };
    const cv::Point2d topPx = outlineCrossing(photos.frontMask, eyeMidPx, {0.0, -1.0}, "front");

    // --- Side frame: mirror so the face points right, then tie the rows to the front's heights through points
    // both photos show (least squares y = a v + b): top of head, nasion, nose tip, subnasale, upper lip.
    const bool mirror = !photos.sideNoseImageRight;
    const int sideWidth = photos.sideMask.cols;
    cv::Mat sideMask, sideHair;
    if (mirror) cv::flip(photos.sideMask, sideMask, 1); else sideMask = photos.sideMask;
    if (mirror && !photos.sideHair.empty()) cv::flip(photos.sideHair, sideHair, 1); else sideHair = photos.sideHair;
    // A crossing on hair (the pixel just inside it) farther than the slack outside where the shaped head's vertex
    // projects measures the hair, not the skull.
    const auto onBigHair = [&](const cv::Mat& hair, const cv::Point2d& hit, const cv::Point2d& vertexPx, const cv::Point2d& from,
                               double mmPerPixel) {
        if (options.hairOutlineSlackMm <= 0.0 || hair.empty()) return false;
        const cv::Point2d in = hit + (from - hit) * (2.0 / std::max(1.0, cv::norm(from - hit)));
        return inMask(hair, in) && cv::norm(hit - from) - cv::norm(vertexPx - from) > options.hairOutlineSlackMm / mmPerPixel;
    };
    const auto side = [&](const std::string& name) { return mirrorPoint(need(photos.sidePoints, name, "side"), sideWidth, mirror); };
    const std::pair<const char*, glm::dvec2> ties[] = {
        {"top_of_head", frontRel(topPx)},          {"nasion", frontRel(fp.at(landmarkName(27)))},
        {"nose_tip", frontRel(fp.at(landmarkName(30)))},    {"subnasale", frontRel(fp.at(landmarkName(33)))},
        {"upper_lip", frontRel(fp.at(landmarkName(51)))},
    };
    cv::Mat A(5, 2, CV_64F), Y(5, 1, CV_64F);
    for (int i = 0; i < 5; ++i) {
        A.at<double>(i, 0) = side(ties[i].first).y;
        A.at<double>(i, 1) = 1.0;
        Y.at<double>(i, 0) = ties[i].second.y;
    }
    cv::Mat ab;
    cv::solve(A, Y, ab, cv::DECOMP_SVD);
    const double a = ab.at<double>(0), bOffset = ab.at<double>(1);
    const double sideMmPerPx = -a;
    const double ratio = sideMmPerPx / frontMmPerPx;
    if (!(ratio > 1.0 / options.maxScaleRatio && ratio < options.maxScaleRatio))
        throw BoothError(ErrorKind::Mismatch, "",
                         "the head in the side photo is " + std::to_string(static_cast<int>(std::lround(100.0 / ratio))) +
                             "% the size of the head in the front photo: the photos do not show the same person from the "
                             "same distance");
    double tieError = 0.0;
    for (int i = 0; i < 5; ++i) {
        const double e = a * side(ties[i].first).y + bOffset - ties[i].second.y;
        tieError += e * e;
    }
    tieError = std::sqrt(tieError / 5.0);

    // --- Steps 2-4, and with a modifier basis the first fitting step between them: scale the head to the measured
    // extents, measure the feature and contour targets, fit the modifier weights to them, and again with the new
    // shape (the extents and the rays change with it); the last round's targets go to the warp.
    Mesh shaped = base.mesh;
    // Where the photos' frames sit against the head, as the modifier fit corrects them: the side frame's depth rests
    // on the ear hole's estimate (about 5 % of the head's height off, more under a bun of hair), which the profile's
    // face points correct.
    glm::dvec3 frameShift(0.0), frameAnchor(0.0);
    const std::vector<std::uint32_t> profileVertices = options.faceProfile ? faceProfileVertices(base) : std::vector<std::uint32_t>{};
    ViewTargets frontT(View::Front), sideT(View::Side);
    for (int round = 0;; ++round) {
        frontT = ViewTargets(View::Front);
        sideT = ViewTargets(View::Side);
        fit.frontRays.clear();
        fit.sideRays.clear();
        const auto pos = [&](const std::string& name) { return shaped.positions[base.sideFeatures.at(name)]; };
        const glm::dvec3 chinB = shaped.positions[base.frontFeatures.at(landmarkName(8))];
        const double heightPhoto = frontRel(topPx).y - frontRel(fp.at(landmarkName(8))).y;
        const double heightBase = pos("top_of_head").y - chinB.y;
        const double widthPhoto = std::abs(frontRel(fp.at(landmarkName(16))).x - frontRel(fp.at(landmarkName(0))).x);
        const double widthBase = std::abs(shaped.positions[base.frontFeatures.at(landmarkName(16))].x - shaped.positions[base.frontFeatures.at(landmarkName(0))].x);
        const double depthPhoto = (side("glabella").x - side("back_of_head").x) * sideMmPerPx;
        const double depthBase = pos("glabella").z - pos("back_of_head").z;
        // Measured once, on the base head: in later rounds the modifiers change the extents, and scaling them back
        // to the measured ones would undo what the modifiers found. With a modifier basis the head is scaled
        // uniformly by the face's width (dlib's jaw line: no hair in it) to start with, each round's modifier fit
        // correcting that size (ModifierFit::scaleChange), and the modifiers (the head's own
        // scale-vert/-depth among them) take its proportions from the landmarks; the height and depth include the
        // hair, and scaling by them stretched the face. They still say whether it is a head at all.
        if (round == 0) {
            fit.measuredExtents = glm::dvec3(widthPhoto / widthBase, heightPhoto / heightBase, depthPhoto / depthBase);
            fit.axisScale = base.modifiers ? glm::dvec3(fit.measuredExtents.x) : fit.measuredExtents;
        }
        for (int c = 0; c < 3; ++c)
            if (!(fit.measuredExtents[c] > 0.6 && fit.measuredExtents[c] < 1.6))
                throw BoothError(ErrorKind::Mismatch, "",
                                 std::string("the measured head ") + (c == 0 ? "width" : c == 1 ? "height" : "depth") +
                                     " is " + std::to_string(fit.measuredExtents[c]) + " times the base head's: not a plausible head");
        if (tieError > 0.06 * heightPhoto)
            throw BoothError(ErrorKind::Mismatch, "",
                             "the heights of the nose, lips and top of head disagree between the photos by " +
                                 std::to_string(static_cast<int>(tieError)) + " mm: they do not show the same head");
        if (round == 0 && tieError > 0.025 * heightPhoto)
            fit.warnings.push_back("shared heights between the photos disagree by " + std::to_string(tieError) + " mm (RMS)");
        fit.scaledBase = shaped;
        for (auto& p : fit.scaledBase.positions) p = base.earHoleCentre + (p - base.earHoleCentre) * fit.axisScale;
        const Mesh& scaled = fit.scaledBase;
        // The frames are anchored once, at the scaled base head's eye midpoint; the modifier fit's translation moves
        // them from there (a later round's eye midpoint has moved with the modifiers, which the fit already counted).
        if (round == 0) frameAnchor = meanVertex(scaled, base, 36, 47);
        const glm::dvec3 eyeMidScaled = frameAnchor;
        const glm::dvec3 earScaled = base.earHoleCentre;  // the scaling's fixed point

        fit.front = PhotoFrame{eyeMidPx, frontMmPerPx, {eyeMidScaled.x - frameShift.x, eyeMidScaled.y - frameShift.y}, false,
                               photos.frontMask.cols};
        const cv::Point2d earPx = side("ear_hole");
        fit.side = PhotoFrame{cv::Point2d(earPx.x, earPx.y), sideMmPerPx, {earScaled.z - frameShift.z, eyeMidScaled.y - frameShift.y + a * earPx.y + bOffset},
                              false, sideWidth};
        // sideCanonical works on the mirrored image; fit.side takes raw photo pixels (it mirrors u first).
        PhotoFrame sideCanonical = fit.side;
        fit.side.mirrored = mirror;

        // --- Steps 3-4: targets for the feature and contour vertices.
        const std::vector<glm::dvec3> scaledNormals = scaled.vertexNormals();
        // Contour points: along the outline's normal only (see ViewTargets::add).
        const auto addFrontContour = [&](const std::string& name, std::uint32_t v, const glm::dvec2& target) {
            frontT.add(scaled, name, v, target, &scaledNormals);
        };
        const auto addSideContour = [&](const std::string& name, std::uint32_t v, const glm::dvec2& target) {
            sideT.add(scaled, name, v, target, &scaledNormals);
        };
        // Without a modifier basis nothing else shapes the head there: every point pulls both ways, as in the paper.
        const std::set<int> byHeight = base.modifiers ? std::set<int>(options.frontLandmarksByHeight.begin(),
                                                                       options.frontLandmarksByHeight.end())
                                                      : std::set<int>{};
        for (const int k : options.frontLandmarks) {
            const std::string name = landmarkName(k);
            frontT.addAcross(scaled, name, base.frontFeatures.at(name), fit.front.toHead(fp.at(name)),
                             byHeight.count(k) ? glm::dvec2(0.0, 1.0) : glm::dvec2(0.0));
        }
        // Below the eye line the silhouette can run on into hair, a collar or the shoulders. dlib's jaw line (points
        // 0..16, a little inside the true outline: it follows the cheek) says where the face's own outline must be; a
        // crossing much farther out than it is not the face, and that ray measures nothing.
        std::vector<cv::Point2d> jawLine;
        for (int k = 0; k <= 16; ++k) jawLine.push_back(fp.at(landmarkName(k)));
        constexpr double kOutlineBeyondJaw = 1.25;
        for (const auto& cv : base.frontContour) {
            const glm::dvec3 p = scaled.positions[cv.vertex];
            const cv::Point2d dir(p.x - fit.front.offsetMm.x, -(p.y - fit.front.offsetMm.y));
            const cv::Point2d hit = outlineCrossing(photos.frontMask, eyeMidPx, dir, "front");
            if (cv.angleDeg > 180.0) {
                const auto onJaw = polylineCrossing(jawLine, eyeMidPx, dir);
                if (!onJaw || cv::norm(hit - eyeMidPx) > kOutlineBeyondJaw * cv::norm(*onJaw - eyeMidPx)) continue;
            }
            if (onBigHair(photos.frontHair, hit, fit.front.toPixel({p.x, p.y}), eyeMidPx, fit.front.mmPerPixel)) continue;
            fit.frontRays.emplace_back(eyeMidPx, hit);
            addFrontContour("front_contour_" + std::to_string(static_cast<int>(cv.angleDeg)), cv.vertex, fit.front.toHead(hit));
        }
        for (const auto& [name, v] : base.sideFeatures) {
            const auto it = photos.sidePoints.find(name);
            if (it == photos.sidePoints.end()) continue;
            const cv::Point2d at = mirrorPoint(it->second, sideWidth, mirror);
            if (onBigHair(sideHair, at, sideCanonical.toPixel(projectToView(scaled.positions[v], View::Side)), earPx,
                          sideCanonical.mmPerPixel))
                continue;
            sideT.add(scaled, name, v, sideCanonical.toHead(mirrorPoint(it->second, sideWidth, mirror)),
                      onSmoothOutline(name) ? &scaledNormals : nullptr);
        }
        const cv::Point2d earCanonical = earPx;
        for (const auto& cv : base.sideContour) {
            const glm::dvec3 p = scaled.positions[cv.vertex];
            const glm::dvec2 earHead = sideCanonical.toHead(earCanonical);
            const cv::Point2d dir(p.z - earHead.x, -(p.y - earHead.y));
            const cv::Point2d hit = outlineCrossing(sideMask, earCanonical, dir, "side");
            if (onBigHair(sideHair, hit, sideCanonical.toPixel(projectToView(p, View::Side)), earCanonical, sideCanonical.mmPerPixel))
                continue;
            fit.sideRays.emplace_back(mirrorPoint(earCanonical, sideWidth, mirror), mirrorPoint(hit, sideWidth, mirror));
            addSideContour("side_contour_" + std::to_string(static_cast<int>(cv.angleDeg)), cv.vertex, sideCanonical.toHead(hit));
        }

        if (options.faceProfile) {
            for (const auto v : profileVertices) {
                const glm::dvec2 n = projectToView(scaledNormals[v], View::Side);
                if (glm::length(n) < 1e-6) continue;
                const glm::dvec2 n2 = glm::normalize(n);
                const cv::Point2d at = sideCanonical.toPixel(projectToView(scaled.positions[v], View::Side));
                const auto hit = outlineAlongNormal(sideMask, at, cv::Point2d(n2.x, -n2.y),
                                                    options.faceProfileSearchMm / sideCanonical.mmPerPixel);
                if (!hit) continue;
                fit.sideRays.emplace_back(mirrorPoint(at, sideWidth, mirror), mirrorPoint(*hit, sideWidth, mirror));
                addSideContour(std::string(kFaceProfilePrefix) + std::to_string(v), v, sideCanonical.toHead(*hit));
            }
        }

        if (!base.modifiers || round == options.modifierRounds) break;
        std::vector<ModifierTarget> targets;
        for (const ViewTargets* view : {&frontT, &sideT})
            for (std::size_t k = 0; k < view->vertices.size(); ++k) {
                // The outline rays meet hair as often as skin: they shape the head less than the landmarks do.
                const bool profile = isFaceProfileTarget(view->targets[k].first);
                const bool contour = profile || isContourTarget(view->targets[k].first);
                const bool onOutline = glm::dot(view->outlineNormals[k], view->outlineNormals[k]) > 0.0;
                const double weight = profile ? options.faceProfileWeight : contour ? options.contourWeight : 1.0;
                // A ray's crossing says nothing about where along the outline the vertex lies; a profile landmark
                // says a little (outlineTangentWeight).
                const double along = !onOutline ? weight : contour ? 0.0 : options.outlineTangentWeight * weight;
                targets.push_back({view->vertices[k], view->view, view->measured[k], glm::dvec2(weight, along),
                                   view->outlineNormals[k]});
            }
        const ModifierFit m = fitModifiers(*base.modifiers, base.mesh.positions, fit.axisScale, base.earHoleCentre, targets,
                                           options.modifiers);
        shaped.positions = base.modifiers->apply(base.mesh.positions, m.weights);
        frameShift += m.translation;
        fit.axisScale *= 1.0 + m.scaleChange;
        fit.modifierWeights.clear();
        for (std::size_t k = 0; k < m.weights.size(); ++k)
            if (m.weights[k] > 1e-4) fit.modifierWeights.emplace_back(base.modifiers->modifiers[k].name, m.weights[k]);
        fit.modifierRmsMm = {m.rmsBeforeMm, m.rmsAfterMm};
    }
    const Mesh& s = fit.scaledBase;

    // --- Step 5: the RBF warps, (x, y) from the front and (z, y) from the side, merged.
    // After the modifiers the warp takes a residual, and the landmarks give way by landmarkRidge; the outline rays
    // are interpolated exactly. A base head without modifiers is warped as the paper does, through every point.
    const double landmarkRidge = base.modifiers ? options.landmarkRidge : 0.0;
    const auto ridgeOf = [&](const ViewTargets& view) {
        std::vector<double> ridge;
        for (const auto& [name, target] : view.targets)
            ridge.push_back(isContourTarget(name) ? 0.0 : landmarkRidge);
        return ridge;
    };
    const RbfWarp frontWarp(frontT.centres, frontT.displacements, options.rbf, ridgeOf(frontT));
    const RbfWarp sideWarp(sideT.centres, sideT.displacements, options.rbf, ridgeOf(sideT));
    const auto normals = s.vertexNormals();
    fit.mesh = s;
    for (std::size_t i = 0; i < s.positions.size(); ++i) {
        const glm::dvec3 p = s.positions[i];
        const auto df = frontWarp.evaluate(p);
        const auto ds = sideWarp.evaluate(p);
        // y comes from both views: each weighs in by how squarely it sees the surface there (|n_z| for the
        // front, |n_x| for the side), half and half where neither does (the top of the head).
        const double nz = std::abs(normals[i].z), nx = std::abs(normals[i].x);
        const double wFront = (nz + 0.01) / (nz + nx + 0.02);
        fit.mesh.positions[i] = p + glm::dvec3(df[0], wFront * df[1] + (1.0 - wFront) * ds[1], ds[0]);
    }
    // The blend leaves feature vertices a little off their measured y. A last warp over all feature vertices (with
    // the same kernel and ridge) moves each onto its y; a vertex measured in both photos takes the mean of the two.
    struct YTarget {
        double sum = 0.0;
        int count = 0;
        double ridge = 0.0;
    };
    std::map<std::uint32_t, YTarget> yTargets;
    for (const ViewTargets* view : {&frontT, &sideT}) {
        const std::vector<double> ridge = ridgeOf(*view);
        for (std::size_t k = 0; k < view->vertices.size(); ++k) {
            auto& t = yTargets[view->vertices[k]];
            t.sum += view->targets[k].second.y;
            ++t.count;
            t.ridge = std::max(t.ridge, ridge[k]);
        }
    }
    std::vector<glm::dvec3> yCentres;
    std::vector<std::vector<double>> yDisp;
    std::vector<double> yRidge;
    for (const auto& [v, t] : yTargets) {
        yCentres.push_back(fit.mesh.positions[v]);
        yDisp.push_back({t.sum / t.count - fit.mesh.positions[v].y});
        yRidge.push_back(t.ridge);
    }
    const RbfWarp yWarp(yCentres, yDisp, options.rbf, yRidge);
    for (auto& p : fit.mesh.positions) p.y += yWarp.evaluate(p)[0];
    // Where features lie close together with conflicting pulls (eyelids, lips) the warp can turn the surface over;
    // those places take their neighbours' displacement instead.
    for (const auto& part : base.rigidParts) {
        glm::dvec3 mean(0.0);
        for (const auto v : part) mean += fit.mesh.positions[v] - fit.scaledBase.positions[v];
        mean /= static_cast<double>(std::max<std::size_t>(part.size(), 1));
        for (const auto v : part) fit.mesh.positions[v] = fit.scaledBase.positions[v] + mean;
    }
    // --- The ears, last: moved to where the side photo shows the ear. After the warp, so that they move nothing else
    // (the warp's targets, and so the face, are as they would be without them); before the folds are smoothed out.
    EarPlacement ears;
    if (options.placeEars && photos.sideEar && base.modifiers) {
        ears = placeEars(*base.modifiers, fit.mesh, fit.axisScale, fit.side.toHead(*photos.sideEar));
        if (ears.placed) {
            for (const auto& [v, d] : earDisplacements(*base.modifiers, ears, fit.axisScale)) {
                fit.mesh.positions[v] += d;
                fit.scaledBase.positions[v] += d;
            }
            for (std::size_t k = 0; k < ears.weights.size(); ++k)
                if (ears.weights[k] > 0.0) fit.modifierWeights.emplace_back(base.modifiers->modifiers[k].name, ears.weights[k]);
            fit.earShiftMm = ears.shiftMm;
            fit.earOffsetMm = ears.offsetMm;
            fit.earsPlaced = true;
        }
    }
    fit.foldsRemoved = unfold(fit.scaledBase, fit.mesh);
    if (fit.earsPlaced) {  // where the ear ended up (the fold repair may have moved it a little)
        for (const auto v : ears.earVertices) fit.earMiddleMm += fit.mesh.positions[v] / static_cast<double>(ears.earVertices.size());
        fit.earLeftMm = fit.side.toHead(*photos.sideEar) - glm::dvec2(fit.earMiddleMm.z, fit.earMiddleMm.y);
    }
    if (photos.sideEye) {
        const glm::dvec3 eye = meanVertex(fit.mesh, base, 36, 41);
        const glm::dvec2 left = fit.side.toHead(*photos.sideEye) - glm::dvec2(eye.z, eye.y);
        // The photos share the eye's height (the side photo's rows are tied to the front's): a dark spot found
        // further above or below is a shadow or hair, not the eye.
        if (std::abs(left.y) <= kSideEyeHeightToleranceMm) {
            fit.eyeMiddleMm = eye;
            fit.eyeLeftMm = left;
            fit.sideEyeFound = true;
        }
    }


    for (const ViewTargets* view : {&frontT, &sideT})
        for (std::size_t k = 0; k < view->vertices.size(); ++k) {
            const glm::dvec2 q = projectToView(fit.mesh.positions[view->vertices[k]], view->view);
            const glm::dvec2 t = view->targets[k].second;
            fit.residuals.push_back({view->targets[k].first, view->view == View::Front ? "front" : "side", t, q, glm::distance(t, q)});
        }
    return fit;
}

}  // namespace avatarbooth
