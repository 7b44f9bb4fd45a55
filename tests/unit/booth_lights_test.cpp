// The booth's lights (common/booth_lights.h).
#include "common/booth_lights.h"

#include <gtest/gtest.h>

#include <cmath>

namespace avatarbooth {
namespace {

constexpr double kPi = 3.14159265358979323846;

TEST(BoothLights, LightOnAFaceTowardsEachLight) {
    using namespace booth_lights;
    const double keyLength = std::sqrt(0.35 * 0.35 + 0.55 * 0.55 + 0.76 * 0.76);
    const double fillLength = std::sqrt(0.70 * 0.70 + 0.05 * 0.05 + 0.71 * 0.71);
    // Facing the camera: both lights at their angles, over the ambient.
    EXPECT_NEAR(lightOn({0, 0, 1}), 0.30 + 0.65 * 0.76 / keyLength + 0.20 * 0.71 / fillLength, 1e-12);
    // Facing the key light: all of it, and the fill at the angle between the two.
    const std::array<double, 3> key{0.35 / keyLength, 0.55 / keyLength, 0.76 / keyLength};
    const double between = (-0.70 * key[0] - 0.05 * key[1] + 0.71 * key[2]) / fillLength;
    EXPECT_NEAR(lightOn(key), 0.30 + 0.65 + 0.20 * between, 1e-12);
    // Facing away from both: the ambient alone.
    EXPECT_NEAR(lightOn({0, 0, -1}), 0.30, 1e-12);
}

TEST(BoothLights, MeanLightSeenOnASphereAgreesWithTheIntegralOverItsHalf) {
    // The same mean by another route: over the visible half in polar angles, each patch weighted by the area it
    // shows the camera (cos(theta) sin(theta) dtheta dphi, which sums to pi).
    constexpr int kSteps = 600;
    double sum = 0.0;
    for (int i = 0; i < kSteps; ++i)
        for (int j = 0; j < kSteps; ++j) {
            const double theta = (i + 0.5) * (kPi / 2) / kSteps, phi = (j + 0.5) * (2 * kPi) / kSteps;
            const std::array<double, 3> n{std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
            sum += booth_lights::lightOn(n) * std::cos(theta) * std::sin(theta) * (kPi / 2 / kSteps) * (2 * kPi / kSteps);
        }
    const double mean = sum / kPi;
    EXPECT_NEAR(booth_lights::meanLightSeenOnSphere(), mean, 2e-4);
    EXPECT_NEAR(mean, 0.746, 1e-3);
}

}  // namespace
}  // namespace avatarbooth
