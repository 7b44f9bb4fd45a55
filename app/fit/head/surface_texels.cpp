// UV-space rasterisation of a mesh.
#include "fit/head/surface_texels.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

namespace avatarbooth {

TexelMap mapTexels(const Mesh& mesh, cv::Size size) {
    TexelMap map;
    map.size = size;
    map.triangle = cv::Mat(size, CV_32S, cv::Scalar(-1));
    map.weights.resize(mesh.triangles.size());
    const double w = size.width, h = size.height;
    for (std::size_t ti = 0; ti < mesh.triangles.size(); ++ti) {
        const auto& t = mesh.triangles[ti];
        const std::uint32_t idx[3] = {t.x, t.y, t.z};
        glm::dvec2 p[3];
        for (int k = 0; k < 3; ++k) p[k] = glm::dvec2(mesh.uvs[idx[k]].x * w, mesh.uvs[idx[k]].y * h);
        const double area = (p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[2].x - p[0].x) * (p[1].y - p[0].y);
        if (std::abs(area) < 1e-12) continue;  // degenerate in UV (e.g. at a pole)
        // The first two corners' weights, b = (k + gx cx + gy cy) / area at the texel centre (cx, cy) = (x + 0.5, y + 0.5).
        const double k0 = p[1].x * p[2].y - p[2].x * p[1].y, gx0 = p[1].y - p[2].y, gy0 = p[2].x - p[1].x;
        const double k1 = p[2].x * p[0].y - p[0].x * p[2].y, gx1 = p[2].y - p[0].y, gy1 = p[0].x - p[2].x;
        map.weights[ti] = {(k0 + 0.5 * (gx0 + gy0)) / area, gx0 / area, gy0 / area,
                           (k1 + 0.5 * (gx1 + gy1)) / area, gx1 / area, gy1 / area};
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].x, p[1].x, p[2].x}))));
        const int x1 = std::min(size.width - 1, static_cast<int>(std::ceil(std::max({p[0].x, p[1].x, p[2].x}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({p[0].y, p[1].y, p[2].y}))));
        const int y1 = std::min(size.height - 1, static_cast<int>(std::ceil(std::max({p[0].y, p[1].y, p[2].y}))));
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                const cv::Vec2d b = map.barycentric(static_cast<int>(ti), x, y);
                const double b0 = b[0], b1 = b[1];
                constexpr double eps = -1e-9;
                if (b0 < eps || b1 < eps || 1.0 - b0 - b1 < eps) continue;
                map.triangle.at<int>(y, x) = static_cast<int>(ti);
            }
        }
    }
    return map;
}

SurfaceTexels sampleSurfaceTexels(const Mesh& mesh, const std::vector<glm::dvec3>& normals, const TexelMap& map) {
    SurfaceTexels out;
    out.position = cv::Mat(map.size, CV_32FC3, cv::Scalar::all(0));
    out.normal = cv::Mat(map.size, CV_32FC3, cv::Scalar::all(0));
    out.covered = cv::Mat(map.size, CV_8U, cv::Scalar(0));
    for (int y = 0; y < map.size.height; ++y) {
        const int* tri = map.triangle.ptr<int>(y);
        for (int x = 0; x < map.size.width; ++x) {
            if (tri[x] < 0) continue;
            const auto& t = mesh.triangles[static_cast<std::size_t>(tri[x])];
            const cv::Vec2d bary = map.barycentric(tri[x], x, y);
            const double b0 = bary[0], b1 = bary[1], b2 = 1.0 - b0 - b1;
            const glm::dvec3 pos = b0 * mesh.positions[t.x] + b1 * mesh.positions[t.y] + b2 * mesh.positions[t.z];
            const glm::dvec3 nrm = glm::normalize(b0 * normals[t.x] + b1 * normals[t.y] + b2 * normals[t.z]);
            out.position.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(pos.x), static_cast<float>(pos.y), static_cast<float>(pos.z));
            out.normal.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(nrm.x), static_cast<float>(nrm.y), static_cast<float>(nrm.z));
            out.covered.at<unsigned char>(y, x) = 255;
        }
    }
    return out;
}

SurfaceTexels sampleSurfaceTexels(const Mesh& mesh, const std::vector<glm::dvec3>& normals, cv::Size size) {
    return sampleSurfaceTexels(mesh, normals, mapTexels(mesh, size));
}

void padTextureBorders(cv::Mat& texture, const cv::Mat& covered, int texels) {
    // Each round gives every empty texel next to known ones the mean colour of its known 3x3 neighbours.
    cv::Mat known;
    covered.convertTo(known, CV_32F, 1.0 / 255.0);
    for (int i = 0; i < texels; ++i) {
        cv::Mat colour, sum, weight;
        texture.convertTo(colour, CV_32FC3);
        cv::Mat known3;
        cv::merge(std::vector<cv::Mat>{known, known, known}, known3);
        cv::boxFilter(colour.mul(known3), sum, -1, cv::Size(3, 3), cv::Point(-1, -1), false);
        cv::boxFilter(known, weight, -1, cv::Size(3, 3), cv::Point(-1, -1), false);
        for (int y = 0; y < texture.rows; ++y) {
            for (int x = 0; x < texture.cols; ++x) {
                const float wgt = weight.at<float>(y, x);
                if (known.at<float>(y, x) > 0.0f || wgt <= 0.0f) continue;
                const cv::Vec3f c = sum.at<cv::Vec3f>(y, x) / wgt;
                texture.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<unsigned char>(c[0]),
                                                        cv::saturate_cast<unsigned char>(c[1]),
                                                        cv::saturate_cast<unsigned char>(c[2]));
            }
        }
        cv::Mat grown;
        cv::threshold(weight, grown, 0.0, 1.0, cv::THRESH_BINARY);
        known = cv::max(known, grown);
    }
}

}  // namespace avatarbooth
