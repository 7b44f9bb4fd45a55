// Radial-basis-function warps: the NTT fitting step (METHODS §1 step 5) and two alternatives to compare with it.
#pragma once

#include <glm/glm.hpp>

#include <string>
#include <vector>

namespace avatarbooth {

enum class RbfKernel {
    // The paper's kernel f(r) = 1 / (r + 1), no polynomial part (Akimoto & Suenaga, eq. 2).
    InverseDistance,
    // Thin-plate spline for 3-D centres, f(r) = r (the biharmonic kernel in R^3), with an affine part.
    ThinPlate,
    // Gaussian f(r) = exp(-(r/sigma)^2), no polynomial part.
    Gaussian,
};

// Parses "ntt" / "inverse" / "paper", "tps" / "thin-plate", "gaussian"; throws std::invalid_argument otherwise.
RbfKernel parseRbfKernel(const std::string& name);
std::string rbfKernelName(RbfKernel kernel);

struct RbfOptions {
    RbfKernel kernel = RbfKernel::InverseDistance;
    // r is measured in this many millimetres (r = distance_mm / unitMm): 1/(r+1) is not scale-free, so the unit
    // fixes how far a feature's pull reaches. Default: 1/10 of the base head's height (about 23 mm).
    double unitMm = 23.0;
    // Gaussian width, in the same unit as r.
    double gaussianSigma = 2.0;
    // Ridge added to the diagonal (0 = interpolate exactly, as the paper does).
    double regularisation = 0.0;
};

// A warp R^3 -> R^D (D = number of displacement components) defined by centres and their displacements.
// Solving is exact (LU with partial pivoting on the n x n, or (n+4) x (n+4), system), not iterative.
class RbfWarp {
public:
    // centres: the feature vertices on the (scaled) base head; displacements: one row of D values per centre;
    // ridge: optional, one value per centre added to the options' regularisation on that centre's diagonal (a
    // noisy measurement gives way, an exact one does not).
    RbfWarp(std::vector<glm::dvec3> centres, const std::vector<std::vector<double>>& displacements,
            const RbfOptions& options, const std::vector<double>& ridge = {});

    // The displacement at p: v(p) = sum_j u_j f(|p - c_j|) (+ affine part for the thin-plate kernel).
    std::vector<double> evaluate(const glm::dvec3& p) const;
    double kernel(double distanceMm) const;

    std::size_t centreCount() const { return centres_.size(); }
    std::size_t dimensions() const { return dims_; }
    // The solved internal displacements u_j (one row per centre), as in the paper's eq. 3.
    const std::vector<std::vector<double>>& weights() const { return weights_; }

private:
    std::vector<glm::dvec3> centres_;
    RbfOptions options_;
    std::size_t dims_ = 0;
    std::vector<std::vector<double>> weights_;  // n rows x D
    std::vector<std::vector<double>> affine_;   // 4 rows (1, x, y, z) x D, thin-plate only
};

}  // namespace avatarbooth
