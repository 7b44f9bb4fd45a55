// RBF warps: build the interpolation system, solve it exactly, evaluate.
#include "fit/head/rbf.h"

#include <opencv2/core.hpp>

#include <cmath>
#include <stdexcept>

namespace avatarbooth {

RbfKernel parseRbfKernel(const std::string& name) {
    if (name == "ntt" || name == "inverse" || name == "paper") return RbfKernel::InverseDistance;
    if (name == "tps" || name == "thin-plate") return RbfKernel::ThinPlate;
    if (name == "gaussian") return RbfKernel::Gaussian;
    throw std::invalid_argument("unknown RBF kernel '" + name + "' (expected ntt, tps or gaussian)");
}

std::string rbfKernelName(RbfKernel kernel) {
    switch (kernel) {
        case RbfKernel::InverseDistance: return "ntt";
        case RbfKernel::ThinPlate: return "tps";
        case RbfKernel::Gaussian: return "gaussian";
    }
    return "?";
}

double RbfWarp::kernel(double distanceMm) const {
    const double r = distanceMm / options_.unitMm;
    switch (options_.kernel) {
        case RbfKernel::InverseDistance: return 1.0 / (r + 1.0);
        case RbfKernel::ThinPlate: return r;
        case RbfKernel::Gaussian: {
            const double s = r / options_.gaussianSigma;
            return std::exp(-s * s);
        }
    }
    return 0.0;
}

RbfWarp::RbfWarp(std::vector<glm::dvec3> centres, const std::vector<std::vector<double>>& displacements,
                 const RbfOptions& options, const std::vector<double>& ridge)
    : centres_(std::move(centres)), options_(options) {
    const std::size_t n = centres_.size();
    if (n == 0) throw std::invalid_argument("RBF warp needs at least one centre");
    if (displacements.size() != n) throw std::invalid_argument("RBF warp: one displacement per centre expected");
    if (!ridge.empty() && ridge.size() != n) throw std::invalid_argument("RBF warp: one ridge value per centre expected");
    if (!(options_.unitMm > 0.0)) throw std::invalid_argument("RBF warp: unit must be positive");
    dims_ = displacements.front().size();
    const bool affine = options_.kernel == RbfKernel::ThinPlate;
    const int size = static_cast<int>(n + (affine ? 4 : 0));

    // [ K  P ] [u]   [w]
    // [ P' 0 ] [a] = [0]    (P only for the thin-plate kernel: rows (1, x, y, z) in units of r)
    cv::Mat a = cv::Mat::zeros(size, size, CV_64F);
    cv::Mat b = cv::Mat::zeros(size, static_cast<int>(dims_), CV_64F);
    for (std::size_t k = 0; k < n; ++k) {
        if (displacements[k].size() != dims_) throw std::invalid_argument("RBF warp: ragged displacements");
        for (std::size_t j = 0; j < n; ++j)
            a.at<double>(static_cast<int>(k), static_cast<int>(j)) = kernel(glm::distance(centres_[k], centres_[j]));
        a.at<double>(static_cast<int>(k), static_cast<int>(k)) += options_.regularisation + (ridge.empty() ? 0.0 : ridge[k]);
        for (std::size_t d = 0; d < dims_; ++d) b.at<double>(static_cast<int>(k), static_cast<int>(d)) = displacements[k][d];
        if (affine) {
            const glm::dvec3 q = centres_[k] / options_.unitMm;
            const double row[4] = {1.0, q.x, q.y, q.z};
            for (int c = 0; c < 4; ++c) {
                a.at<double>(static_cast<int>(k), static_cast<int>(n) + c) = row[c];
                a.at<double>(static_cast<int>(n) + c, static_cast<int>(k)) = row[c];
            }
        }
    }
    cv::Mat x;
    if (!cv::solve(a, b, x, cv::DECOMP_LU)) {
        // Singular. With the thin-plate kernel that happens when every centre lies on one plane (one view's
        // profile points all sit on the head's mid-plane): the affine part along the plane's normal is then free,
        // and the minimum-norm solution (SVD) leaves it at zero while still interpolating every centre exactly.
        // Coincident centres stay an error: no solution interpolates two different displacements at one point.
        if (!affine || !cv::solve(a, b, x, cv::DECOMP_SVD))
            throw std::runtime_error("RBF system is singular: feature vertices coincide or are degenerate");
        const double residual = cv::norm(a * x - b, cv::NORM_INF);
        if (!(residual <= 1e-6 * std::max(1.0, cv::norm(b, cv::NORM_INF))))
            throw std::runtime_error("RBF system is singular: feature vertices coincide or are degenerate");
    }
    weights_.assign(n, std::vector<double>(dims_));
    for (std::size_t j = 0; j < n; ++j)
        for (std::size_t d = 0; d < dims_; ++d) weights_[j][d] = x.at<double>(static_cast<int>(j), static_cast<int>(d));
    if (affine) {
        affine_.assign(4, std::vector<double>(dims_));
        for (int c = 0; c < 4; ++c)
            for (std::size_t d = 0; d < dims_; ++d)
                affine_[static_cast<std::size_t>(c)][d] = x.at<double>(static_cast<int>(n) + c, static_cast<int>(d));
    }
}

std::vector<double> RbfWarp::evaluate(const glm::dvec3& p) const {
    std::vector<double> v(dims_, 0.0);
    for (std::size_t j = 0; j < centres_.size(); ++j) {
        const double f = kernel(glm::distance(p, centres_[j]));
        for (std::size_t d = 0; d < dims_; ++d) v[d] += weights_[j][d] * f;
    }
    if (!affine_.empty()) {
        const glm::dvec3 q = p / options_.unitMm;
        const double row[4] = {1.0, q.x, q.y, q.z};
        for (int c = 0; c < 4; ++c)
            for (std::size_t d = 0; d < dims_; ++d) v[d] += affine_[static_cast<std::size_t>(c)][d] * row[c];
    }
    return v;
}

}  // namespace avatarbooth
