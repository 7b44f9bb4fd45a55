// Orthographic z-buffer rasterisation on the CPU (the texture step must work without a GL context).
#include "fit/head/view_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace avatarbooth {

cv::Mat rasteriseNearestDepth(const std::vector<ViewVertex>& vertices, const std::vector<glm::uvec3>& triangles,
                              cv::Size size) {
    cv::Mat depth(size, CV_32F, cv::Scalar(-std::numeric_limits<float>::infinity()));
    for (const auto& t : triangles) {
        const ViewVertex& a = vertices[t.x];
        const ViewVertex& b = vertices[t.y];
        const ViewVertex& c = vertices[t.z];
        const float area = (b.u - a.u) * (c.v - a.v) - (c.u - a.u) * (b.v - a.v);
        if (std::abs(area) < 1e-8f) continue;  // seen edge-on: it covers no pixel centre
        const int x0 = std::max(0, static_cast<int>(std::ceil(std::min({a.u, b.u, c.u}))));
        const int x1 = std::min(size.width - 1, static_cast<int>(std::floor(std::max({a.u, b.u, c.u}))));
        const int y0 = std::max(0, static_cast<int>(std::ceil(std::min({a.v, b.v, c.v}))));
        const int y1 = std::min(size.height - 1, static_cast<int>(std::floor(std::max({a.v, b.v, c.v}))));
        if (x0 > x1 || y0 > y1) continue;
        // Barycentric weights are affine in the pixel position: step them along the row instead of recomputing.
        const float inv = 1.0f / area;
        const float dwaX = (b.v - c.v) * inv, dwbX = (c.v - a.v) * inv;
        // A small tolerance so that pixel centres on a shared edge are covered by at least one of its triangles.
        constexpr float eps = -1e-5f;
        for (int y = y0; y <= y1; ++y) {
            float* row = depth.ptr<float>(y);
            const float py = static_cast<float>(y), px = static_cast<float>(x0);
            float wa = ((b.u - px) * (c.v - py) - (c.u - px) * (b.v - py)) * inv;
            float wb = ((c.u - px) * (a.v - py) - (a.u - px) * (c.v - py)) * inv;
            for (int x = x0; x <= x1; ++x, wa += dwaX, wb += dwbX) {
                const float wc = 1.0f - wa - wb;
                if (wa < eps || wb < eps || wc < eps) continue;
                const float d = wa * a.depth + wb * b.depth + wc * c.depth;
                if (d > row[x]) row[x] = d;
            }
        }
    }
    return depth;
}

}  // namespace avatarbooth
