// The two orthographic views of NTT fitting, as plane coordinates (a, b) with b up:
// front view (a, b) = (x, y), seen from +z, the subject's left on the image's right;
// side view  (a, b) = (z, y), seen from the subject's right (-x), the face pointing right (+a).
#pragma once

#include <glm/glm.hpp>

namespace avatarbooth {

enum class View { Front = 0, Side = 1 };

inline glm::dvec2 projectToView(const glm::dvec3& p, View view) {
    return view == View::Front ? glm::dvec2(p.x, p.y) : glm::dvec2(p.z, p.y);
}

// Angle of a view-plane vector in degrees, counter-clockwise from +a, in [-90, 270) so that rays over the top of
// the head (0..180) and down the sides stay continuous.
double viewAngleDeg(const glm::dvec2& d);

}  // namespace avatarbooth
