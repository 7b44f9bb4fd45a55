// The smooth step the fit's fades share (the texture's shifts, gains and repaints; the hair part's pushes, stretches
// and lengths; the ears' move).
#pragma once

#include <algorithm>

namespace avatarbooth {

// 0 at t <= 0 rising smoothly (no kink at either end) to 1 at t >= 1.
inline double smoothstep(double t) {
    t = std::clamp(t, 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

}  // namespace avatarbooth
