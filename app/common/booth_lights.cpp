// The booth's lights (booth_lights.h).
#include "common/booth_lights.h"

#include <algorithm>
#include <cmath>

namespace avatarbooth::booth_lights {
namespace {

double dotUnit(const std::array<double, 3>& n, const std::array<double, 3>& towards) {
    const double length = std::sqrt(towards[0] * towards[0] + towards[1] * towards[1] + towards[2] * towards[2]);
    return (n[0] * towards[0] + n[1] * towards[1] + n[2] * towards[2]) / length;
}

}  // namespace

double lightOn(const std::array<double, 3>& n) {
    return kAmbient + kKey * std::max(0.0, dotUnit(n, kKeyEye)) + kFill * std::max(0.0, dotUnit(n, kFillEye));
}

double meanLightSeenOnSphere() {
    // The disc sampled at the centres of a 256 x 256 grid: within 1e-4 of the integral.
    static const double mean = [] {
        constexpr int kSteps = 256;
        double sum = 0.0;
        int count = 0;
        for (int i = 0; i < kSteps; ++i)
            for (int j = 0; j < kSteps; ++j) {
                const double x = -1.0 + (2.0 * i + 1.0) / kSteps, y = -1.0 + (2.0 * j + 1.0) / kSteps;
                const double zz = 1.0 - x * x - y * y;
                if (zz <= 0.0) continue;
                sum += lightOn({x, y, std::sqrt(zz)});
                ++count;
            }
        return sum / count;
    }();
    return mean;
}

}  // namespace avatarbooth::booth_lights
