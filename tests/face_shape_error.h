// The fitted face's shape error against a synthetic visitor's true head (same topology, vertex to vertex): the
// measure of tests/data's MakeHuman population and turned-profile tests.
#pragma once

#include "fit/head/base_head.h"
#include "fit/head/mesh.h"

#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>
#include <vector>

namespace avatarbooth::test {

// The face: the base head's vertices between the chin and the forehead point, in front of the ears (z > 40 mm, the
// ear hole at 0 and the nose tip at 120) and inside the outer brows' width (|x| < 60 mm); not the eyeballs, which
// move as rigid parts. Chosen on the base head, so the same vertices on every person.
inline std::vector<bool> faceRegion(const BaseHead& base) {
    const double chinY = base.mesh.positions[base.frontFeatures.at("ibug_08")].y;
    const double foreheadY = base.mesh.positions[base.sideFeatures.at("forehead")].y;
    std::vector<bool> face(base.mesh.positions.size(), false);
    for (std::size_t v = 0; v < face.size(); ++v) {
        const glm::dvec3& p = base.mesh.positions[v];
        face[v] = p.y >= chinY && p.y <= foreheadY && p.z > 40.0 && std::abs(p.x) < 60.0;
    }
    for (const auto& part : base.rigidParts)
        for (const auto v : part) face[v] = false;
    return face;
}

// The shape error over the face: RMS of the per-vertex distance between the fitted and the true head, after taking
// away the mean offset over the face (the fit places the head in the photos' frames, which the truth does not
// share to the millimetre). `scale` multiplies the fitted head first: the photos cannot give the head's size (the
// fit takes the eye distance to be the base head's), so the shape is compared at the true scale, the fitted head
// scaled by true mm per pixel / the fit's mm per pixel.
inline double faceRms(const Mesh& fitted, const Mesh& truth, const std::vector<bool>& face, double scale = 1.0) {
    glm::dvec3 offset(0.0);
    std::size_t n = 0;
    for (std::size_t v = 0; v < face.size(); ++v)
        if (face[v]) {
            offset += truth.positions[v] - scale * fitted.positions[v];
            ++n;
        }
    offset /= static_cast<double>(n);
    double sum = 0.0;
    for (std::size_t v = 0; v < face.size(); ++v)
        if (face[v]) {
            const glm::dvec3 d = scale * fitted.positions[v] + offset - truth.positions[v];
            sum += glm::dot(d, d);
        }
    return std::sqrt(sum / static_cast<double>(n));
}

inline double median(std::vector<double> values) {
    if (values.empty()) return std::nan("");
    std::sort(values.begin(), values.end());
    const std::size_t m = values.size() / 2;
    return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

}  // namespace avatarbooth::test
