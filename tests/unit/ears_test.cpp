// Moving the base head's ears to where the side photo shows the ear: MakeHuman's ear translations, both ears alike,
// within their sliders' ranges (fit/head/ears.h). Exact values on a small head with a basis of known offsets.
#include "fit/head/ears.h"

#include <gtest/gtest.h>

namespace {

using namespace avatarbooth;

// Ten vertices: the right ear (0-3, x < 0), the left ear (4-7), a vertex of the right ear's rim that the
// translation moves by half (8), and one of the skull (9).
struct SmallHead {
    Mesh mesh;
    ModifierBasis basis;
    SmallHead() {
        mesh.positions = {{-70, 10, 0}, {-72, 30, 4}, {-71, 20, -12}, {-73, 14, 8}, {70, 10, 0}, {72, 30, 4},
                          {71, 20, -12}, {73, 14, 8}, {-74, 40, -20}, {0, 100, 0}};
        basis.vertexCount = mesh.positions.size();
        const auto add = [&](const std::string& name, std::vector<std::uint32_t> vertices, glm::vec3 offset,
                             float rimShare = 0.0f) {
            Modifier m{name, "ears", vertices, std::vector<glm::vec3>(vertices.size(), offset)};
            if (rimShare > 0.0f) {
                m.vertices.push_back(8);
                m.offsets.push_back(rimShare * offset);
            }
            basis.modifiers.push_back(m);
        };
        for (const char* side : {"r", "l"}) {
            const std::vector<std::uint32_t> ear = side[0] == 'r' ? std::vector<std::uint32_t>{0, 1, 2, 3}
                                                                  : std::vector<std::uint32_t>{4, 5, 6, 7};
            const float rim = side[0] == 'r' ? 0.5f : 0.0f;
            add(std::string("ears/") + side + "-ear-trans-depth-forward", ear, {0, 0, 12.5f}, rim);
            add(std::string("ears/") + side + "-ear-trans-depth-backward", ear, {0, 0, -10.0f}, rim);
            add(std::string("ears/") + side + "-ear-trans-vert-up", ear, {0, 20.0f, 0}, rim);
            add(std::string("ears/") + side + "-ear-trans-vert-down", ear, {0, -20.0f, 0}, rim);
        }
        basis.modifiers.push_back({"nose/nose-trans-up", "nose", {9}, {{0, 5, 0}}});
    }
    Mesh scaled(const std::vector<double>& weights, const glm::dvec3& axisScale) const {
        Mesh m = mesh;
        m.positions = basis.apply(mesh.positions, weights);
        for (auto& p : m.positions) p *= axisScale;  // about the ear holes, at the origin
        return m;
    }
    static glm::dvec2 rightEarMiddle(const Mesh& m) {
        glm::dvec2 sum(0.0);
        for (int v = 0; v < 4; ++v) sum += glm::dvec2(m.positions[v].z, m.positions[v].y);
        return sum / 4.0;
    }
};

TEST(Ears, TheEarIsWhatItsTranslationMovesFully) {
    const SmallHead head;
    EXPECT_EQ(rigidlyMovedVertices(head.basis, "ears/r-ear-trans-depth-backward"), (std::vector<std::uint32_t>{0, 1, 2, 3}));
    EXPECT_TRUE(rigidlyMovedVertices(head.basis, "ears/no-such-modifier").empty());
}

TEST(Ears, PlacedEarsMiddleLiesOnThePhotosEar) {
    const SmallHead head;
    const glm::dvec3 axisScale(1.1, 1.2, 0.9);
    const std::vector<double> none(head.basis.modifiers.size(), 0.0);
    const Mesh before = head.scaled(none, axisScale);
    const glm::dvec2 middle = SmallHead::rightEarMiddle(before);
    EXPECT_NEAR(middle.x, 0.0, 1e-12);  // (0 + 4 - 12 + 8) / 4
    EXPECT_DOUBLE_EQ(middle.y, 1.2 * 18.5);
    // 6 mm back and 9 mm up: within range (9 mm back, 24 mm up at this scale).
    const EarPlacement p = placeEars(head.basis, before, axisScale, middle + glm::dvec2(-6.0, 9.0));
    ASSERT_TRUE(p.placed);
    EXPECT_NEAR(p.weights[head.basis.find("ears/r-ear-trans-depth-backward")], 6.0 / 9.0, 1e-12);
    EXPECT_NEAR(p.weights[head.basis.find("ears/l-ear-trans-depth-backward")], 6.0 / 9.0, 1e-12);
    EXPECT_NEAR(p.weights[head.basis.find("ears/r-ear-trans-vert-up")], 9.0 / 24.0, 1e-12);
    EXPECT_NEAR(p.weights[head.basis.find("ears/l-ear-trans-vert-up")], 9.0 / 24.0, 1e-12);
    for (const char* unused : {"ears/r-ear-trans-depth-forward", "ears/r-ear-trans-vert-down", "nose/nose-trans-up"})
        EXPECT_EQ(p.weights[head.basis.find(unused)], 0.0) << unused;
    EXPECT_NEAR(p.shiftMm.x, -6.0, 1e-12);
    EXPECT_NEAR(p.shiftMm.y, 9.0, 1e-12);
    EXPECT_NEAR(p.offsetMm.x, -6.0, 1e-12);
    // Applied, both ears have moved by that; their rim (moved by half in the basis) by the fade's smooth step, and the
    // skull not at all.
    Mesh after = before;
    for (const auto& [v, d] : earDisplacements(head.basis, p, axisScale)) after.positions[v] += d;
    const glm::dvec2 moved = SmallHead::rightEarMiddle(after);
    EXPECT_NEAR(moved.x, middle.x - 6.0, 1e-5);
    EXPECT_NEAR(moved.y, middle.y + 9.0, 1e-5);
    for (int v = 4; v < 8; ++v) {
        EXPECT_NEAR(after.positions[v].z - before.positions[v].z, -6.0, 1e-5);
        EXPECT_NEAR(after.positions[v].y - before.positions[v].y, 9.0, 1e-5);
        EXPECT_EQ(after.positions[v].x, before.positions[v].x);
    }
    const double t = (0.5 - kEarMoveFadesTo) / (0.99 - kEarMoveFadesTo), fade = t * t * (3.0 - 2.0 * t);
    EXPECT_NEAR(after.positions[8].z - before.positions[8].z, -6.0 * fade, 1e-5);
    EXPECT_NEAR(after.positions[8].y - before.positions[8].y, 9.0 * fade, 1e-5);
    EXPECT_EQ(after.positions[9], before.positions[9]);
}

TEST(Ears, PlacementStopsAtTheSlidersEnds) {
    const SmallHead head;
    const glm::dvec3 axisScale(1.0, 1.2, 0.9);
    const Mesh before = head.scaled(std::vector<double>(head.basis.modifiers.size(), 0.0), axisScale);
    const glm::dvec2 middle = SmallHead::rightEarMiddle(before);
    const EarPlacement back = placeEars(head.basis, before, axisScale, middle + glm::dvec2(-30.0, -50.0));
    EXPECT_NEAR(back.offsetMm.x, -30.0, 1e-12);
    EXPECT_NEAR(back.offsetMm.y, -50.0, 1e-12);
    EXPECT_NEAR(back.shiftMm.x, -9.0, 1e-12);   // 10 mm at 0.9
    EXPECT_NEAR(back.shiftMm.y, -24.0, 1e-12);  // 20 mm at 1.2
    EXPECT_EQ(back.weights[head.basis.find("ears/r-ear-trans-depth-backward")], 1.0);
    EXPECT_EQ(back.weights[head.basis.find("ears/l-ear-trans-vert-down")], 1.0);
    const EarPlacement ahead = placeEars(head.basis, before, axisScale, middle + glm::dvec2(20.0, 0.0));
    EXPECT_NEAR(ahead.shiftMm.x, 12.5 * 0.9, 1e-12);
    EXPECT_EQ(ahead.weights[head.basis.find("ears/r-ear-trans-depth-forward")], 1.0);
}

TEST(Ears, WithoutTheEarsTranslationsNothingIsPlaced) {
    SmallHead head;
    head.basis.modifiers.erase(head.basis.modifiers.begin(), head.basis.modifiers.begin() + 8);
    const EarPlacement p = placeEars(head.basis, head.mesh, glm::dvec3(1.0), glm::dvec2(5.0, 5.0));
    EXPECT_FALSE(p.placed);
}

}  // namespace
