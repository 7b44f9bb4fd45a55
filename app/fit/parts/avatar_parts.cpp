// The avatar's parts on a fitted head (avatar_parts.h).
#include "fit/parts/avatar_parts.h"

#include "common/error.h"
#include "fit/parts/hair_part.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace avatarbooth {

Mesh withoutVertices(const Mesh& mesh, const std::vector<std::uint32_t>& vertices) {
    std::vector<bool> dropped(mesh.positions.size(), false);
    for (const auto v : vertices)
        if (v < dropped.size()) dropped[v] = true;
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
    for (const auto& t : mesh.triangles) {
        if (dropped[t.x] || dropped[t.y] || dropped[t.z]) continue;
        out.triangles.emplace_back(keep(t.x), keep(t.y), keep(t.z));
    }
    return out;
}

cv::Mat tintTexture(const cv::Mat& texture, const cv::Mat& mask, const cv::Vec3d& bgr) {
    if (texture.size() != mask.size() || mask.type() != CV_8U || (texture.type() != CV_8UC3 && texture.type() != CV_8UC4))
        throw BoothError(ErrorKind::Internal, "tint", "needs an 8-bit BGR(A) texture and an 8-bit mask of its size");
    cv::Mat grey;
    cv::cvtColor(texture, grey, texture.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
    const double meanGrey = std::max(1.0, cv::mean(grey, mask)[0]);
    cv::Mat out = texture.clone();
    const int channels = texture.channels();
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

AvatarPart placeProxyPart(const HeadProxy& proxy, const Mesh& fittedHead, const cv::Vec3d* colour) {
    AvatarPart part;
    part.name = proxy.name;
    part.mesh.positions = placeProxy(proxy.binding, fittedHead.positions);
    part.mesh.uvs = proxy.mesh.uvs;
    part.mesh.triangles = proxy.mesh.triangles;
    const auto [texture, tintMask] = proxyPixels(proxy);
    part.texture = colour != nullptr && !tintMask.empty() ? tintTexture(texture, tintMask, *colour) : texture;
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
