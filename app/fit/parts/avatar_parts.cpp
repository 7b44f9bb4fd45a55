// The avatar's parts on a fitted head (avatar_parts.h).
#include "fit/parts/avatar_parts.h"

#include "common/error.h"
#include "fit/parts/hair_part.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

namespace avatarbooth {

namespace {

// The triangles `keepTriangle` holds for, and only the vertices they use (UVs kept with them), in first-use order.
template <typename KeepTriangle>
Mesh trianglesWhere(const Mesh& mesh, KeepTriangle keepTriangle) {
    constexpr std::uint32_t kUnused = ~0u;
    std::vector<std::uint32_t> newIndex(mesh.positions.size(), kUnused);
    Mesh out;
    const bool withUvs = mesh.uvs.size() == mesh.positions.size();
    const auto keep = [&](std::uint32_t v) {
        if (newIndex[v] == kUnused) {
            newIndex[v] = static_cast<std::uint32_t>(out.positions.size());
            out.positions.push_back(mesh.positions[v]);
            if (withUvs) out.uvs.push_back(mesh.uvs[v]);
        }
        return newIndex[v];
    };
    for (const glm::uvec3& t : mesh.triangles)
        if (keepTriangle(t)) out.triangles.emplace_back(keep(t.x), keep(t.y), keep(t.z));
    return out;
}

}  // namespace

Mesh withoutVertices(const Mesh& mesh, const std::vector<std::uint32_t>& vertices) {
    std::vector<bool> dropped(mesh.positions.size(), false);
    for (const auto v : vertices)
        if (v < dropped.size()) dropped[v] = true;
    return trianglesWhere(mesh, [&](const glm::uvec3& t) { return !dropped[t.x] && !dropped[t.y] && !dropped[t.z]; });
}

cv::Mat surfacePerTexel(const Mesh& mesh, cv::Size size) {
    cv::Mat weights(size, CV_32F, cv::Scalar(0));
    if (mesh.uvs.size() != mesh.positions.size() || size.area() <= 0) return weights;
    for (const glm::uvec3& t : mesh.triangles) {
        const glm::dvec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
        const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
        std::array<glm::dvec2, 3> q;
        for (int k = 0; k < 3; ++k) q[static_cast<std::size_t>(k)] = mesh.uvs[t[k]] * glm::dvec2(size.width, size.height);
        const double twice = (q[1].x - q[0].x) * (q[2].y - q[0].y) - (q[2].x - q[0].x) * (q[1].y - q[0].y);
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].x, q[1].x, q[2].x}))));
        const int x1 = std::min(size.width - 1, static_cast<int>(std::ceil(std::max({q[0].x, q[1].x, q[2].x}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({q[0].y, q[1].y, q[2].y}))));
        const int y1 = std::min(size.height - 1, static_cast<int>(std::ceil(std::max({q[0].y, q[1].y, q[2].y}))));
        std::vector<cv::Point> inside;
        if (std::abs(twice) > 1e-12)
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) {
                    const glm::dvec2 p(x + 0.5, y + 0.5);
                    const auto edge = [&](const glm::dvec2& u, const glm::dvec2& v) {
                        return ((v.x - u.x) * (p.y - u.y) - (p.x - u.x) * (v.y - u.y)) / twice;
                    };
                    if (edge(q[0], q[1]) >= 0 && edge(q[1], q[2]) >= 0 && edge(q[2], q[0]) >= 0) inside.emplace_back(x, y);
                }
        if (inside.empty()) {
            const glm::dvec2 m = (q[0] + q[1] + q[2]) / 3.0;
            inside.emplace_back(std::clamp(static_cast<int>(m.x), 0, size.width - 1), std::clamp(static_cast<int>(m.y), 0, size.height - 1));
        }
        const float share = static_cast<float>(area / static_cast<double>(inside.size()));
        for (const cv::Point& p : inside) weights.at<float>(p) += share;
    }
    return weights;
}

cv::Mat tintTexture(const cv::Mat& texture, const cv::Mat& mask, const cv::Vec3d& bgr, const cv::Mat& weights) {
    if (texture.size() != mask.size() || mask.type() != CV_8U || (texture.type() != CV_8UC3 && texture.type() != CV_8UC4))
        throw BoothError(ErrorKind::Internal, "tint", "needs an 8-bit BGR(A) texture and an 8-bit mask of its size");
    if (!weights.empty() && (weights.size() != texture.size() || weights.type() != CV_32F))
        throw BoothError(ErrorKind::Internal, "tint", "its weights must be CV_32F and of the texture's size");
    cv::Mat grey;
    cv::cvtColor(texture, grey, texture.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    const int channels = texture.channels();
    double meanGrey = -1.0;
    if (!weights.empty()) {
        double sum = 0.0, total = 0.0;
        for (int r = 0; r < texture.rows; ++r) {
            const auto* m = mask.ptr<std::uint8_t>(r);
            const auto* g = grey.ptr<std::uint8_t>(r);
            const auto* w = weights.ptr<float>(r);
            const auto* t = texture.ptr<std::uint8_t>(r);
            for (int c = 0; c < texture.cols; ++c) {
                if (m[c] == 0) continue;
                const double seen = w[c] * (channels == 4 ? t[c * 4 + 3] / 255.0 : 1.0);
                sum += seen * g[c];
                total += seen;
            }
        }
        if (total > 0.0) meanGrey = sum / total;
    }
    if (meanGrey < 0.0) meanGrey = cv::mean(grey, mask)[0];  // no weights, or no surface over the mask
    meanGrey = std::max(1.0, meanGrey);
    cv::Mat out = texture.clone();
    for (int r = 0; r < out.rows; ++r) {
        const auto* m = mask.ptr<std::uint8_t>(r);
        const auto* g = grey.ptr<std::uint8_t>(r);
        auto* o = out.ptr<std::uint8_t>(r);
        for (int c = 0; c < out.cols; ++c) {
            if (m[c] == 0) continue;
            const double w = m[c] / 255.0, relative = g[c] / meanGrey;
            for (int k = 0; k < 3; ++k) {
                std::uint8_t& px = o[c * channels + k];
                px = cv::saturate_cast<std::uint8_t>((1.0 - w) * px + w * bgr[k] * relative);
            }
        }
    }
    return out;
}

void alignToPoints(AvatarPart& part, const Mesh& head, const std::vector<glm::dvec2>& points, double below) {
    for (const double side : {-1.0, 1.0}) {
        double shift = 0.0;
        int count = 0;
        for (const auto& q : points) {
            if (q.x * side <= 0) continue;
            double y = 0.0;
            int near = 0;
            for (const auto& p : part.mesh.positions)
                if (p.x * side > 0 && std::abs(p.x - q.x) < 4.0) y += p.y, ++near;
            if (near == 0) continue;
            shift += (q.y - below) - y / near;
            ++count;
        }
        if (count == 0) continue;
        shift /= count;
        for (auto& p : part.mesh.positions) {
            if (p.x * side <= 0) continue;
            const double from = head.frontZ(p.x, p.y), to = head.frontZ(p.x, p.y + shift);
            p.y += shift;
            if (std::isfinite(from) && std::isfinite(to)) p.z += to - from;
        }
    }
}

AvatarPart placeProxyPart(const HeadProxy& proxy, const Mesh& fittedHead, const cv::Vec3d* colour, double keepAbove) {
    AvatarPart part;
    part.name = proxy.name;
    part.mesh.positions = placeProxy(proxy.binding, fittedHead.positions);
    part.mesh.uvs = proxy.mesh.uvs;
    part.mesh.triangles = proxy.mesh.triangles;
    if (std::isfinite(keepAbove)) {
        const auto& p = part.mesh.positions;
        part.mesh = trianglesWhere(part.mesh, [&](const glm::uvec3& t) {
            return p[t.x].y >= keepAbove || p[t.y].y >= keepAbove || p[t.z].y >= keepAbove;
        });
    }
    const auto [texture, tintMask] = proxyPixels(proxy);
    part.texture = colour != nullptr && !tintMask.empty()
                       ? tintTexture(texture, tintMask, *colour, surfacePerTexel(part.mesh, texture.size()))
                       : texture;
    part.alpha = proxy.alpha;
    part.alphaCutoff = proxy.alphaCutoff;
    return part;
}

std::vector<AvatarPart> placeParts(const BaseHead& base, const Mesh& fittedHead, const cv::Mat& headTexture,
                                   const PartColours& colours) {
    if (fittedHead.positions.size() != base.mesh.positions.size())
        throw BoothError(ErrorKind::Internal, "avatar parts",
                         "the fitted head has " + std::to_string(fittedHead.positions.size()) + " vertices, its base head " +
                             std::to_string(base.mesh.positions.size()));
    std::vector<AvatarPart> parts;
    AvatarPart head;
    head.name = "head";
    std::vector<std::uint32_t> replaced;
    for (const HeadProxy& p : base.proxies) replaced.insert(replaced.end(), p.replaces.begin(), p.replaces.end());
    head.mesh = replaced.empty() ? fittedHead : withoutVertices(fittedHead, replaced);
    head.texture = headTexture;
    parts.push_back(std::move(head));
    for (const HeadProxy& p : base.proxies) {
        if (isHairStyleProxy(p)) continue;  // alternatives: the fit places the one it chose (hair_part.h)
        const auto c = colours.find(p.name);
        parts.push_back(placeProxyPart(p, fittedHead, c == colours.end() ? nullptr : &c->second));
    }
    return parts;
}

}  // namespace avatarbooth
