// Comparing two head shapes: RMS distance after the best similarity alignment (Umeyama 1991).
#pragma once

#include "fit/head/mesh.h"

#include <vector>

namespace avatarbooth {

struct Similarity {
    double scale = 1.0;
    glm::dmat3 rotation{1.0};
    glm::dvec3 translation{0.0};
    glm::dvec3 apply(const glm::dvec3& p) const { return scale * (rotation * p) + translation; }
};

// The similarity that maps `from` onto `to` (corresponding points) with least squared error (Umeyama's closed form).
// With allowRotation false, only scale and translation are fitted.
Similarity alignSimilarity(const std::vector<glm::dvec3>& from, const std::vector<glm::dvec3>& to, bool allowRotation = true);

// RMS distance between corresponding vertices of two meshes of the same topology, after aligning `a` onto `b`,
// over the vertices where `include` is true (all when empty).
double rmsAfterSimilarity(const Mesh& a, const Mesh& b, const std::vector<bool>& include = {}, bool allowRotation = true);

}  // namespace avatarbooth
