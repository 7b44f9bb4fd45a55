// Umeyama's least-squares similarity between point sets.
#include "fit/head/shape_compare.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <stdexcept>

namespace avatarbooth {

Similarity alignSimilarity(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to, bool allowRotation) {
    if (from.size() != to.size() || from.empty()) throw std::invalid_argument("alignSimilarity: point sets differ in size");
    const double n = static_cast<double>(from.size());
    glm::dvec3 mf(0.0), mt(0.0);
    for (std::size_t i = 0; i < from.size(); ++i) {
        mf += from[i];
        mt += to[i];
    }
    mf /= n;
    mt /= n;
    double varFrom = 0.0;
    cv::Matx33d cov = cv::Matx33d::zeros();
    for (std::size_t i = 0; i < from.size(); ++i) {
        const glm::dvec3 a = from[i] - mf, b = to[i] - mt;
        varFrom += glm::dot(a, a);
        for (int r = 0; r < 3; ++r)
            for (int c = 0; c < 3; ++c) cov(r, c) += b[r] * a[c];
    }
    varFrom /= n;
    cov *= 1.0 / n;
    Similarity s;
    if (allowRotation) {
        cv::Mat w, u, vt;
        cv::SVD::compute(cv::Mat(cov), w, u, vt);
        cv::Matx33d d = cv::Matx33d::eye();
        if (cv::determinant(u) * cv::determinant(vt) < 0) d(2, 2) = -1.0;
        const cv::Matx33d r = cv::Matx33d(u) * d * cv::Matx33d(vt);
        for (int row = 0; row < 3; ++row)
            for (int col = 0; col < 3; ++col) s.rotation[col][row] = r(row, col);  // glm is column-major
        double trace = 0.0;
        for (int k = 0; k < 3; ++k) trace += w.at<double>(k) * d(k, k);
        s.scale = trace / varFrom;
    } else {
        double dot = 0.0;
        for (int k = 0; k < 3; ++k) dot += cov(k, k);
        s.scale = dot / varFrom;
    }
    s.translation = mt - s.scale * (s.rotation * mf);
    return s;
}

double rmsAfterSimilarity(const Mesh& a, const Mesh& b, const std::vector<bool>& include, bool allowRotation) {
    if (a.positions.size() != b.positions.size()) throw std::invalid_argument("rmsAfterSimilarity: different topologies");
    std::vector<glm::dvec3> from, to;
    for (std::size_t i = 0; i < a.positions.size(); ++i)
        if (include.empty() || include[i]) {
            from.push_back(a.positions[i]);
            to.push_back(b.positions[i]);
        }
    const Similarity s = alignSimilarity(from, to, allowRotation);
    double sum = 0.0;
    for (std::size_t i = 0; i < from.size(); ++i) {
        const glm::dvec3 d = s.apply(from[i]) - to[i];
        sum += glm::dot(d, d);
    }
    return std::sqrt(sum / static_cast<double>(from.size()));
}

}  // namespace avatarbooth
