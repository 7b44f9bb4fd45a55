// A triangle mesh in head space (millimetres, y up, face along +z, x to the subject's left; DESIGN.md).
#pragma once

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace avatarbooth {

struct Mesh {
    std::vector<glm::dvec3> positions;
    // Texture coordinates in the glTF convention: (0,0) is the top-left corner of the texture image.
    std::vector<glm::dvec2> uvs;
    std::vector<glm::uvec3> triangles;  // counter-clockwise seen from outside

    std::size_t vertexCount() const { return positions.size(); }
    // Area-weighted vertex normals, pointing outwards for counter-clockwise triangles.
    std::vector<glm::dvec3> vertexNormals() const;
    // Axis-aligned bounds of the positions.
    void bounds(glm::dvec3& lo, glm::dvec3& hi) const;
    // The front-most z of the surface over (x, y), seen along z, or NaN where that line misses it.
    double frontZ(double x, double y) const;
};

}  // namespace avatarbooth
