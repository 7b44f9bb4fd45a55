// Small geometric helpers on Mesh.
#include "fit/head/mesh.h"

#include <limits>

namespace avatarbooth {

std::vector<glm::dvec3> Mesh::vertexNormals() const {
    std::vector<glm::dvec3> normals(positions.size(), glm::dvec3(0.0));
    for (const auto& t : triangles) {
        const glm::dvec3 a = positions[t.x], b = positions[t.y], c = positions[t.z];
        const glm::dvec3 n = glm::cross(b - a, c - a);  // length = twice the area: area weighting for free
        normals[t.x] += n;
        normals[t.y] += n;
        normals[t.z] += n;
    }
    for (auto& n : normals) {
        const double len = glm::length(n);
        n = len > 0.0 ? n / len : glm::dvec3(0.0, 0.0, 1.0);
    }
    return normals;
}

void Mesh::bounds(glm::dvec3& lo, glm::dvec3& hi) const {
    lo = glm::dvec3(std::numeric_limits<double>::max());
    hi = glm::dvec3(std::numeric_limits<double>::lowest());
    for (const auto& p : positions) {
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
    }
}

}  // namespace avatarbooth
