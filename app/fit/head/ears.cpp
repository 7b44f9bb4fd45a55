#include "fit/head/ears.h"

#include "common/smoothstep.h"
#include "fit/head/view_depth.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>

namespace avatarbooth {

EarTemplate makeEarTemplate(const Mesh& head, const std::vector<std::uint32_t>& earVertices, double noseTipToTop,
                            const glm::dvec3& noseTip, double mmPerPixel) {
    EarTemplate t;
    if (earVertices.empty() || !(mmPerPixel > 0.0)) return t;
    const std::set<std::uint32_t> ear(earVertices.begin(), earVertices.end());
    // The ear's box in the side view (z, y), with 8 mm round it.
    double z0 = std::numeric_limits<double>::infinity(), z1 = -z0, y0 = z0, y1 = -z0;
    glm::dvec3 mean(0.0);
    for (const auto v : earVertices) {
        const glm::dvec3& p = head.positions[v];
        z0 = std::min(z0, p.z), z1 = std::max(z1, p.z), y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
        mean += p / static_cast<double>(earVertices.size());
    }
    constexpr double kMarginMm = 8.0;
    z0 -= kMarginMm, z1 += kMarginMm, y0 -= kMarginMm, y1 += kMarginMm;
    const cv::Size size(static_cast<int>(std::ceil((z1 - z0) / mmPerPixel)) + 1,
                        static_cast<int>(std::ceil((y1 - y0) / mmPerPixel)) + 1);
    // Seen from the subject's right (x < 0): depth grows towards the camera, along -x.
    std::vector<ViewVertex> view(head.positions.size());
    for (std::size_t i = 0; i < view.size(); ++i) {
        const glm::dvec3& p = head.positions[i];
        view[i] = {static_cast<float>((p.z - z0) / mmPerPixel), static_cast<float>((y1 - p.y) / mmPerPixel),
                   static_cast<float>(-p.x)};
    }
    const cv::Mat all = rasteriseNearestDepth(view, head.triangles, size);
    float lowest = std::numeric_limits<float>::infinity();
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c)
            if (std::isfinite(all.at<float>(r, c))) lowest = std::min(lowest, all.at<float>(r, c));
    if (!std::isfinite(lowest)) return t;
    cv::Mat depth(size, CV_32F);
    for (int r = 0; r < size.height; ++r)
        for (int c = 0; c < size.width; ++c)
            depth.at<float>(r, c) = std::isfinite(all.at<float>(r, c)) ? all.at<float>(r, c) : lowest;
    // The ear itself: where its own triangles are the nearest surface, grown by 4 mm (the helix's rim moves a
    // little less than the rest with the ear's translations, and is not among earVertices).
    {
        std::vector<glm::uvec3> earTriangles;
        for (const auto& tri : head.triangles)
            if (ear.count(tri.x) && ear.count(tri.y) && ear.count(tri.z)) earTriangles.push_back(tri);
        const cv::Mat own = rasteriseNearestDepth(view, earTriangles, size);
        t.mask = cv::Mat(size, CV_8U, cv::Scalar(0));
        for (int r = 0; r < size.height; ++r)
            for (int c = 0; c < size.width; ++c)
                if (std::isfinite(own.at<float>(r, c)) && own.at<float>(r, c) >= all.at<float>(r, c) - 1e-3f)
                    t.mask.at<unsigned char>(r, c) = 255;
        const int g = std::max(1, static_cast<int>(std::lround(4.0 / mmPerPixel)));
        cv::dilate(t.mask, t.mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * g + 1, 2 * g + 1}));
    }
    // Shading under a light from the camera and a little above (the booth's lights), darkened in the ear's hollows
    // (the concha, the scapha), which the light reaches less: a photo's ear is its folds' light and shade.
    cv::Mat smooth;
    cv::GaussianBlur(depth, smooth, {0, 0}, 0.6 / mmPerPixel);
    cv::Mat du, dv;
    cv::Sobel(smooth, du, CV_32F, 1, 0, 3, 1.0 / (8.0 * mmPerPixel));
    cv::Sobel(smooth, dv, CV_32F, 0, 1, 3, 1.0 / (8.0 * mmPerPixel));
    cv::Mat rim;
    const int r = std::max(1, static_cast<int>(std::lround(5.0 / mmPerPixel)));
    cv::dilate(smooth, rim, cv::getStructuringElement(cv::MORPH_ELLIPSE, {2 * r + 1, 2 * r + 1}));
    const glm::dvec3 light = glm::normalize(glm::dvec3(0.0, -0.4, 1.0));  // (u right, v down, towards the camera)
    t.shade = cv::Mat(size, CV_32F, cv::Scalar(0.0f));
    for (int y = 0; y < size.height; ++y)
        for (int x = 0; x < size.width; ++x) {
            const glm::dvec3 n = glm::normalize(glm::dvec3(-du.at<float>(y, x), -dv.at<float>(y, x), 1.0));
            const double lambert = std::max(0.0, glm::dot(n, light));
            const double hollow = std::exp(-(rim.at<float>(y, x) - smooth.at<float>(y, x)) / 6.0);
            t.shade.at<float>(y, x) = static_cast<float>((0.3 + 0.7 * lambert) * (0.5 + 0.5 * hollow));
        }
    t.mmPerPixel = mmPerPixel;
    t.centre = {(mean.z - z0) / mmPerPixel, (y1 - mean.y) / mmPerPixel};
    t.noseTipToTop = noseTipToTop;
    t.behindNoseTip = (noseTip.z - mean.z) / noseTipToTop;
    t.aboveNoseTip = (mean.y - noseTip.y) / noseTipToTop;
    return t;
}

std::vector<std::uint32_t> rigidlyMovedVertices(const ModifierBasis& basis, const std::string& modifier) {
    const std::size_t k = basis.find(modifier);
    if (k >= basis.modifiers.size()) return {};
    const Modifier& m = basis.modifiers[k];
    double longest = 0.0;
    for (const auto& d : m.offsets) longest = std::max(longest, glm::length(glm::dvec3(d)));
    std::vector<std::uint32_t> out;
    for (std::size_t i = 0; i < m.vertices.size(); ++i)
        if (glm::length(glm::dvec3(m.offsets[i])) > 0.99 * longest) out.push_back(m.vertices[i]);
    return out;
}

EarTemplate makeEarTemplate(const BaseHead& base) {
    if (!base.modifiers || !base.sideFeatures.count("nose_tip") || !base.sideFeatures.count("top_of_head")) return {};
    const glm::dvec3 tip = base.mesh.positions[base.sideFeatures.at("nose_tip")];
    const double V = base.mesh.positions[base.sideFeatures.at("top_of_head")].y - tip.y;
    return makeEarTemplate(base.mesh, rigidlyMovedVertices(*base.modifiers, kRightEarTranslation), V, tip);
}

EarPlacement placeEars(const ModifierBasis& basis, const Mesh& head, const glm::dvec3& axisScale,
                       const glm::dvec2& photoEar) {
    EarPlacement out;
    out.earVertices = rigidlyMovedVertices(basis, kRightEarTranslation);
    if (out.earVertices.empty()) return out;
    glm::dvec2 middle(0.0);
    for (const auto v : out.earVertices)
        middle += glm::dvec2(head.positions[v].z, head.positions[v].y) / static_cast<double>(out.earVertices.size());
    out.offsetMm = photoEar - middle;
    out.weights.assign(basis.modifiers.size(), 0.0);
    // One axis: the modifier each way and how far it moves the ear at weight 1 (scaled as the head is).
    const auto along = [&](double wanted, const char* forward, const char* backward, int axis, double scale) {
        const bool ahead = wanted >= 0.0;
        double moved = 0.0;
        for (const char* side : {"r", "l"}) {
            const std::string name = std::string("ears/") + side + (ahead ? forward : backward);
            const std::size_t k = basis.find(name);
            if (k >= basis.modifiers.size()) return 0.0;
            const Modifier& m = basis.modifiers[k];
            double reach = 0.0;
            for (const auto& d : m.offsets) reach = std::max(reach, std::abs(static_cast<double>(d[axis])));
            reach *= scale;
            if (reach <= 0.0) return 0.0;
            const double w = std::min(1.0, std::abs(wanted) / reach);
            out.weights[k] = w;
            moved = (ahead ? 1.0 : -1.0) * w * reach;
        }
        return moved;
    };
    out.shiftMm.x = along(out.offsetMm.x, "-ear-trans-depth-forward", "-ear-trans-depth-backward", 2, axisScale.z);
    out.shiftMm.y = along(out.offsetMm.y, "-ear-trans-vert-up", "-ear-trans-vert-down", 1, axisScale.y);
    out.placed = true;
    return out;
}

std::vector<std::pair<std::uint32_t, glm::dvec3>> earDisplacements(const ModifierBasis& basis, const EarPlacement& placement,
                                                                   const glm::dvec3& axisScale) {
    std::map<std::uint32_t, glm::dvec3> moved;
    for (std::size_t k = 0; k < placement.weights.size() && k < basis.modifiers.size(); ++k) {
        if (placement.weights[k] <= 0.0) continue;
        const Modifier& m = basis.modifiers[k];
        double longest = 0.0;
        for (const auto& o : m.offsets) longest = std::max(longest, glm::length(glm::dvec3(o)));
        if (longest <= 0.0) continue;
        for (std::size_t i = 0; i < m.vertices.size(); ++i) {
            const glm::dvec3 offset(m.offsets[i]);
            const double share = glm::length(offset) / longest;
            const double t = std::clamp((share - kEarMoveFadesTo) / (0.99 - kEarMoveFadesTo), 0.0, 1.0);
            if (t <= 0.0) continue;
            // The offset's direction at the ear's full length, by the smooth step of its share.
            const double along = smoothstep(t) * longest / glm::length(offset);
            moved[m.vertices[i]] += placement.weights[k] * along * offset * axisScale;
        }
    }
    return {moved.begin(), moved.end()};
}

}  // namespace avatarbooth
