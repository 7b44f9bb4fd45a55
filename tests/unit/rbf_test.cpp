// RBF warps: exact interpolation, known values per kernel, solved rather than approximated.
#include "fit/head/rbf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace avatarbooth;

namespace {

RbfOptions options(RbfKernel kernel, double unit = 10.0) {
    RbfOptions o;
    o.kernel = kernel;
    o.unitMm = unit;
    return o;
}

}  // namespace

TEST(Rbf, PaperKernelTwoCentresKnownValues) {
    // Centres one unit apart: f(0) = 1, f(1) = 1/2, so [[1, 1/2], [1/2, 1]] u = w. With w = (1, 0):
    // u = (4/3, -2/3); at the midpoint (r = 1/2 from both) f = 2/3 and v = (4/3 - 2/3) * 2/3 = 4/9.
    const RbfWarp warp({{0, 0, 0}, {10, 0, 0}}, {{1.0}, {0.0}}, options(RbfKernel::InverseDistance));
    EXPECT_NEAR(warp.weights()[0][0], 4.0 / 3.0, 1e-12);
    EXPECT_NEAR(warp.weights()[1][0], -2.0 / 3.0, 1e-12);
    EXPECT_NEAR(warp.evaluate({5, 0, 0})[0], 4.0 / 9.0, 1e-12);
    // Far away the paper's kernel decays like 1/r: at 3 units from c0 and 2 from c1, v = 4/3 * 1/4 - 2/3 * 1/3.
    EXPECT_NEAR(warp.evaluate({30, 0, 0})[0], 4.0 / 3.0 / 4.0 - 2.0 / 3.0 / 3.0, 1e-12);
    EXPECT_DOUBLE_EQ(warp.kernel(0.0), 1.0);
    EXPECT_DOUBLE_EQ(warp.kernel(10.0), 0.5);
}

TEST(Rbf, PerCentreRidgeLetsThatCentreGiveWay) {
    // Ridge 1 on the first centre only: [[2, 1/2], [1/2, 1]] u = (1, 0), so u = (4/7, -2/7); the first centre moves
    // 4/7 - 1/7 = 3/7 of its displacement, the second still exactly 0.
    const RbfWarp warp({{0, 0, 0}, {10, 0, 0}}, {{1.0}, {0.0}}, options(RbfKernel::InverseDistance), {1.0, 0.0});
    EXPECT_NEAR(warp.weights()[0][0], 4.0 / 7.0, 1e-12);
    EXPECT_NEAR(warp.weights()[1][0], -2.0 / 7.0, 1e-12);
    EXPECT_NEAR(warp.evaluate({0, 0, 0})[0], 3.0 / 7.0, 1e-12);
    EXPECT_NEAR(warp.evaluate({10, 0, 0})[0], 0.0, 1e-12);
    EXPECT_THROW(RbfWarp({{0, 0, 0}, {10, 0, 0}}, {{1.0}, {0.0}}, options(RbfKernel::InverseDistance), {1.0}),
                 std::invalid_argument);
}

TEST(Rbf, GaussianKernelKnownValues) {
    RbfOptions o = options(RbfKernel::Gaussian);
    o.gaussianSigma = 2.0;
    const RbfWarp warp({{0, 0, 0}, {20, 0, 0}}, {{2.0}, {2.0}}, o);
    // f(2 units) = exp(-(2/2)^2) = e^-1; symmetric system [[1, e^-1], [e^-1, 1]] u = (2, 2): u = 2 / (1 + e^-1).
    const double e1 = std::exp(-1.0);
    EXPECT_NEAR(warp.weights()[0][0], 2.0 / (1.0 + e1), 1e-12);
    EXPECT_NEAR(warp.kernel(10.0), std::exp(-0.25), 1e-15);
    EXPECT_NEAR(warp.evaluate({10, 0, 0})[0], 2.0 * 2.0 / (1.0 + e1) * std::exp(-0.25), 1e-12);
}

TEST(Rbf, ThinPlateReproducesAffineDisplacementsEverywhere) {
    // With an affine part, an affine displacement field is reproduced exactly, with zero RBF weights.
    const std::vector<glm::dvec3> centres = {{0, 0, 0}, {50, 0, 0}, {0, 40, 0}, {0, 0, 30}, {20, 25, 10}, {-30, 5, 12}};
    const auto field = [](const glm::dvec3& p) { return std::vector<double>{1.5 + 0.1 * p.x - 0.2 * p.z, -3.0 + 0.05 * p.y}; };
    std::vector<std::vector<double>> w;
    for (const auto& c : centres) w.push_back(field(c));
    const RbfWarp warp(centres, w, options(RbfKernel::ThinPlate));
    for (const auto& u : warp.weights()) {
        EXPECT_NEAR(u[0], 0.0, 1e-10);
        EXPECT_NEAR(u[1], 0.0, 1e-10);
    }
    const glm::dvec3 far(123, -77, 45);
    EXPECT_NEAR(warp.evaluate(far)[0], field(far)[0], 1e-9);
    EXPECT_NEAR(warp.evaluate(far)[1], field(far)[1], 1e-9);
    EXPECT_DOUBLE_EQ(warp.kernel(25.0), 2.5);
}

TEST(Rbf, ThinPlateKnownValueWithTwoDisplacedCentres) {
    // Five centres, one displaced by 1: a non-trivial solution. Check the system's defining equations directly:
    // sum_j u_j = 0 and sum_j u_j c_j = 0 (the side conditions) and interpolation at every centre.
    const std::vector<glm::dvec3> centres = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}, {10, 10, 10}};
    const RbfWarp warp(centres, {{0}, {0}, {0}, {0}, {1}}, options(RbfKernel::ThinPlate));
    double sum = 0;
    glm::dvec3 moment(0.0);
    for (std::size_t j = 0; j < centres.size(); ++j) {
        sum += warp.weights()[j][0];
        moment += warp.weights()[j][0] * centres[j];
    }
    EXPECT_NEAR(sum, 0.0, 1e-12);
    EXPECT_NEAR(glm::length(moment), 0.0, 1e-10);
    for (std::size_t j = 0; j < centres.size(); ++j) EXPECT_NEAR(warp.evaluate(centres[j])[0], j == 4 ? 1.0 : 0.0, 1e-12);
}

class RbfInterpolation : public ::testing::TestWithParam<RbfKernel> {};

TEST_P(RbfInterpolation, ReproducesEveryFeatureDisplacementTo1e9) {
    // 80 feature points spread over a head-sized box, random displacements: the warp must hit each exactly.
    std::mt19937 rng(42);
    std::uniform_real_distribution<double> pos(-110.0, 110.0), disp(-15.0, 15.0);
    std::vector<glm::dvec3> centres;
    std::vector<std::vector<double>> w;
    for (int i = 0; i < 80; ++i) {
        centres.emplace_back(pos(rng), pos(rng), pos(rng));
        w.push_back({disp(rng), disp(rng)});
    }
    RbfOptions o = options(GetParam(), 23.0);
    o.gaussianSigma = 1.0;
    const RbfWarp warp(centres, w, o);
    for (std::size_t k = 0; k < centres.size(); ++k) {
        const auto v = warp.evaluate(centres[k]);
        EXPECT_NEAR(v[0], w[k][0], 1e-9) << "centre " << k;
        EXPECT_NEAR(v[1], w[k][1], 1e-9) << "centre " << k;
    }
}

INSTANTIATE_TEST_SUITE_P(AllKernels, RbfInterpolation,
                         ::testing::Values(RbfKernel::InverseDistance, RbfKernel::ThinPlate, RbfKernel::Gaussian),
                         [](const ::testing::TestParamInfo<RbfKernel>& p) { return rbfKernelName(p.param); });

TEST(Rbf, CoincidentCentresAreRejected) {
    EXPECT_THROW(RbfWarp({{1, 2, 3}, {1, 2, 3}}, {{0.0}, {1.0}}, options(RbfKernel::InverseDistance)), std::runtime_error);
}

TEST(Rbf, KernelNamesRoundTrip) {
    for (const auto k : {RbfKernel::InverseDistance, RbfKernel::ThinPlate, RbfKernel::Gaussian})
        EXPECT_EQ(parseRbfKernel(rbfKernelName(k)), k);
    EXPECT_THROW(parseRbfKernel("cubic"), std::invalid_argument);
}

// All centres on one plane (a view's profile points on the head's mid-plane): the thin-plate system is singular
// along the plane's normal, and the warp still interpolates every centre exactly, with no tilt out of the plane.
TEST(Rbf, ThinPlateWithCoplanarCentresStillInterpolatesExactly) {
    const std::vector<glm::dvec3> centres = {{0, 0, 0}, {0, 40, 10}, {0, -30, 25}, {0, 15, -35}, {0, 60, 60}, {0, -50, -20}};
    const std::vector<std::vector<double>> w = {{1.0}, {-2.0}, {0.5}, {3.0}, {0.0}, {-1.5}};
    const RbfWarp warp(centres, w, options(RbfKernel::ThinPlate));
    for (std::size_t k = 0; k < centres.size(); ++k) EXPECT_NEAR(warp.evaluate(centres[k])[0], w[k][0], 1e-9);
    // Symmetric about the plane: nothing in the data says which side is which.
    EXPECT_NEAR(warp.evaluate({20, 10, 5})[0], warp.evaluate({-20, 10, 5})[0], 1e-9);
}
