// The built-in base head: closed, UV-covered, with distinct feature vertices where an adult head has them.
#include "fit/head/base_head.h"
#include "fit/head/head_views.h"

#include <gtest/gtest.h>

#include <cmath>

#include <map>
#include <set>
#include <tuple>

using namespace avatarbooth;

TEST(BaseHead, SizeIsAFewThousandToTwentyThousandTriangles) {
    const Mesh& mesh = builtinBaseHead().mesh;
    EXPECT_GE(mesh.triangles.size(), 3000u);
    EXPECT_LE(mesh.triangles.size(), 20000u);
    EXPECT_EQ(mesh.uvs.size(), mesh.positions.size());
}

TEST(BaseHead, IsClosedOnceSeamAndPoleDuplicatesAreWelded) {
    const Mesh& mesh = builtinBaseHead().mesh;
    // Weld vertices that share a position (UV seam and poles), then every edge must have exactly two triangles,
    // used once in each direction (consistent orientation).
    std::map<std::tuple<long, long, long>, std::uint32_t> ids;
    std::vector<std::uint32_t> weld(mesh.positions.size());
    for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
        const auto& p = mesh.positions[i];
        const auto key = std::make_tuple(std::lround(p.x * 1e4), std::lround(p.y * 1e4), std::lround(p.z * 1e4));
        weld[i] = ids.emplace(key, static_cast<std::uint32_t>(ids.size())).first->second;
    }
    std::map<std::pair<std::uint32_t, std::uint32_t>, int> directed;
    for (const auto& t : mesh.triangles) {
        const std::uint32_t v[3] = {weld[t.x], weld[t.y], weld[t.z]};
        ASSERT_TRUE(v[0] != v[1] && v[1] != v[2] && v[0] != v[2]) << "degenerate triangle";
        for (int k = 0; k < 3; ++k) ++directed[{v[k], v[(k + 1) % 3]}];
    }
    for (const auto& [edge, count] : directed) {
        EXPECT_EQ(count, 1) << "edge used twice in one direction";
        EXPECT_EQ(directed.count({edge.second, edge.first}), 1u) << "boundary edge: mesh not closed";
    }
}

TEST(BaseHead, NormalsPointOutwards) {
    const Mesh& mesh = builtinBaseHead().mesh;
    const auto normals = mesh.vertexNormals();
    int outward = 0;
    for (std::size_t i = 0; i < mesh.positions.size(); ++i)
        if (glm::dot(normals[i], mesh.positions[i] - glm::dvec3(0, -20, 0)) > 0) ++outward;
    EXPECT_GT(outward, static_cast<int>(0.97 * static_cast<double>(mesh.positions.size())));
}

TEST(BaseHead, UvsCoverTheWholeUnitSquare) {
    const Mesh& mesh = builtinBaseHead().mesh;
    double area = 0;
    for (const auto& t : mesh.triangles) {
        const glm::dvec2 a = mesh.uvs[t.x], b = mesh.uvs[t.y], c = mesh.uvs[t.z];
        area += 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
    }
    // The polar rows are triangles in UV (half of a quad row each): all but 2 * (1/76) / 2 of the square.
    EXPECT_GT(area, 0.98);
    EXPECT_LE(area, 1.0 + 1e-9);
}

TEST(BaseHead, ProportionsAreThoseOfAnAdultHead) {
    // METHODS §5: head height 22-23 cm, breadth about 15 cm, length 19-20 cm, pupils 62-64 mm apart,
    // eyes about half-way down.
    const BaseHead& head = builtinBaseHead();
    const auto pos = [&](const std::string& name) { return head.mesh.positions[head.sideFeatures.at(name)]; };
    const double height = pos("top_of_head").y - pos("chin").y;
    EXPECT_NEAR(height, 225.0, 10.0);
    const double length = pos("glabella").z - pos("back_of_head").z;
    EXPECT_NEAR(length, 195.0, 10.0);
    double breadth = 0;
    for (const auto& p : head.mesh.positions)
        if (p.y > 40 && p.y < 60) breadth = std::max(breadth, 2.0 * std::abs(p.x));
    EXPECT_NEAR(breadth, 150.0, 8.0);
    glm::dvec3 right(0.0), left(0.0);
    for (int k = 36; k < 42; ++k) right += head.mesh.positions[head.frontFeatures.at("ibug_" + std::to_string(k))];
    for (int k = 42; k < 48; ++k) left += head.mesh.positions[head.frontFeatures.at("ibug_" + std::to_string(k))];
    EXPECT_NEAR(glm::distance(right / 6.0, left / 6.0), 63.0, 3.0);
    const double eyeFromTop = (pos("top_of_head").y - head.eyeMidpoint().y) / height;
    EXPECT_NEAR(eyeFromTop, 0.5, 0.04);
}

TEST(BaseHead, FeatureVerticesAreDistinctAndInAnatomicalOrder) {
    const BaseHead& head = builtinBaseHead();
    std::set<std::uint32_t> used;
    for (const auto& [name, v] : head.frontFeatures) EXPECT_TRUE(used.insert(v).second) << name << " shares a vertex";
    EXPECT_EQ(head.frontFeatures.size(), 68u);
    const auto y = [&](const std::string& n) { return head.mesh.positions[head.sideFeatures.at(n)].y; };
    const char* order[] = {"top_of_head", "forehead", "glabella", "nasion", "nose_tip", "subnasale",
                           "upper_lip", "lower_lip", "chin", "throat"};
    for (int i = 0; i + 1 < 10; ++i) EXPECT_GT(y(order[i]), y(order[i + 1])) << order[i] << " vs " << order[i + 1];
    // The nose tip is the most forward point of the head.
    const double noseZ = head.mesh.positions[head.sideFeatures.at("nose_tip")].z;
    for (const auto& p : head.mesh.positions) EXPECT_LE(p.z, noseZ + 1.0);
}

TEST(BaseHead, ContourVerticesLieOnTheOutline) {
    const BaseHead& head = builtinBaseHead();
    ASSERT_FALSE(head.frontContour.empty());
    const glm::dvec2 c = projectToView(head.eyeMidpoint(), View::Front);
    for (const auto& cv : head.frontContour) {
        const glm::dvec2 d = projectToView(head.mesh.positions[cv.vertex], View::Front) - c;
        // Angles compared on the circle (the jaw rays' 300 degrees is viewAngleDeg's -60).
        EXPECT_NEAR(std::remainder(viewAngleDeg(d) - cv.angleDeg, 360.0), 0.0, 3.0) << "ray at " << cv.angleDeg;
        // Nothing in the mesh projects further out along this ray (within the same narrow wedge).
        EXPECT_GT(glm::length(d), 60.0);
    }
    for (const auto& cv : head.sideContour) {
        const glm::dvec2 d = projectToView(head.mesh.positions[cv.vertex], View::Side) -
                             projectToView(head.earHoleCentre, View::Side);
        EXPECT_NEAR(viewAngleDeg(d), cv.angleDeg, 3.0);
    }
}
