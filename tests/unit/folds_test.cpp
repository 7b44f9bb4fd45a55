// Folds: counting triangles a warp turned over, and smoothing them out (fit/head/folds.h).
#include "fit/head/folds.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

// An n x n grid in the z = 0 plane, facing +z, with the middle column of vertices doubled (a UV seam: the same
// positions, the triangles on either side using their own copy).
Mesh grid(int n, bool seam) {
    Mesh m;
    std::vector<std::vector<std::uint32_t>> left(n, std::vector<std::uint32_t>(n)), right = left;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            left[j][i] = static_cast<std::uint32_t>(m.positions.size());
            m.positions.emplace_back(10.0 * i, 10.0 * j, 0.0);
            m.uvs.emplace_back(0.0, 0.0);
            right[j][i] = left[j][i];
            if (seam && i == n / 2) {
                right[j][i] = static_cast<std::uint32_t>(m.positions.size());
                m.positions.emplace_back(10.0 * i, 10.0 * j, 0.0);
                m.uvs.emplace_back(1.0, 0.0);
            }
        }
    for (int j = 0; j + 1 < n; ++j)
        for (int i = 0; i + 1 < n; ++i) {
            const auto& use = i < n / 2 ? left : right;
            const auto a = use[j][i], b = use[j][i + 1], c = use[j + 1][i + 1], d = use[j + 1][i];
            m.triangles.emplace_back(a, b, c);
            m.triangles.emplace_back(a, c, d);
        }
    return m;
}

TEST(Folds, CountsTrianglesTurnedOver) {
    const Mesh before = grid(9, false);
    Mesh after = before;
    EXPECT_TRUE(foldedTriangles(before, after).empty());
    // Pushing one inner vertex 25 mm to the right, past its neighbour, turns the triangles to its right over.
    after.positions[4 * 9 + 4].x += 25.0;
    const auto folded = foldedTriangles(before, after);
    EXPECT_GE(folded.size(), 2u);
    EXPECT_LE(folded.size(), 6u);
    // Moving along the normal or scaling folds nothing.
    Mesh lifted = before;
    for (auto& p : lifted.positions) p = glm::dvec3(p.x * 1.3, p.y * 0.8, p.z + 0.1 * p.x);
    EXPECT_TRUE(foldedTriangles(before, lifted).empty());
}

TEST(Folds, UnfoldLeavesNoFoldAndKeepsTheRest) {
    const Mesh before = grid(15, true);
    Mesh after = before;
    for (auto& p : after.positions) p.y += 3.0;  // a smooth warp everywhere
    for (std::size_t v = 0; v < after.positions.size(); ++v)
        if (before.positions[v] == glm::dvec3(70.0, 70.0, 0.0)) after.positions[v].x += 30.0;  // and a fold in the middle
    ASSERT_FALSE(foldedTriangles(before, after).empty());
    const std::size_t first = unfold(before, after);
    EXPECT_GT(first, 0u);
    EXPECT_TRUE(foldedTriangles(before, after).empty());
    // Far from the fold the smooth warp is untouched; the seam's two copies of a vertex are still one point.
    for (std::size_t v = 0; v < after.positions.size(); ++v) {
        const glm::dvec3 b = before.positions[v];
        if (std::abs(b.x - 70.0) > 50.0 || std::abs(b.y - 70.0) > 50.0) {
            EXPECT_DOUBLE_EQ(after.positions[v].y, b.y + 3.0);
            EXPECT_DOUBLE_EQ(after.positions[v].x, b.x);
        }
        for (std::size_t u = v + 1; u < after.positions.size(); ++u) {
            if (before.positions[u] == b) {
                EXPECT_EQ(after.positions[u], after.positions[v]);
            }
        }
    }
}

}  // namespace
}  // namespace avatarbooth
