// Small geometric helpers on Mesh.
#include "fit/head/mesh.h"

#include <algorithm>
#include <cmath>
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

double Mesh::frontZ(double x, double y) const {
    double best = std::numeric_limits<double>::quiet_NaN();
    for (const auto& t : triangles) {
        const glm::dvec3 &a = positions[t.x], &b = positions[t.y], &c = positions[t.z];
        if (x < std::min({a.x, b.x, c.x}) || x > std::max({a.x, b.x, c.x}) || y < std::min({a.y, b.y, c.y}) ||
            y > std::max({a.y, b.y, c.y}))
            continue;
        const double det = (b.y - c.y) * (a.x - c.x) + (c.x - b.x) * (a.y - c.y);
        if (std::abs(det) < 1e-12) continue;
        const double l0 = ((b.y - c.y) * (x - c.x) + (c.x - b.x) * (y - c.y)) / det;
        const double l1 = ((c.y - a.y) * (x - c.x) + (a.x - c.x) * (y - c.y)) / det;
        const double l2 = 1.0 - l0 - l1;
        if (l0 < 0 || l1 < 0 || l2 < 0) continue;
        const double z = l0 * a.z + l1 * b.z + l2 * c.z;
        if (!(z <= best)) best = z;
    }
    return best;
}

}  // namespace avatarbooth
