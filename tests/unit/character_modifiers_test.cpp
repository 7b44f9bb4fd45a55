// The character's solve over modifier weights on a model with a known Jacobian (exact answers), its bounds, the
// chord step from weights already set, and MakeHuman's two-sided slider names.
#include "reveal/character/character_modifiers.h"

#include <gtest/gtest.h>

namespace avatarbooth {
namespace {

// Three controls: the two ends of a face-aspect slider (r0 +-0.5 per unit weight) and an eye-size one (r2 +0.1).
CharacterModel linearModel() {
    CharacterModel m;
    m.base.r = {1.3, 0.5, 0.14, 0.12, 0.34, 0.13, 0.22, 0.38};
    m.base.eyeSpacing = 0.36;
    QuantityVector up{}, down{}, eyes{};
    up[0] = 0.5;
    down[0] = -0.5;
    eyes[2] = 0.1;
    m.jacobian = {up, down, eyes};
    m.controlModifiers = {{0}, {1}, {2, 3}};
    m.earHoleShift.assign(3, glm::dvec3(0.0));
    return m;
}

TEST(CharacterModifiers, LeastSquaresWeightsOnAKnownJacobian) {
    const CharacterModel m = linearModel();
    CharacterProportions target = m.base;
    target.r[0] += 0.2;
    target.r[2] -= 0.05;  // the eye control only enlarges: it stays at 0
    const double lambda = 1e-4;
    const std::vector<double> w = solveCharacterStep(m, {0.0, 0.0, 0.0}, m.base, target, lambda);
    // r0's range is 1.0 wide: minimise (0.5 w - 0.2)^2 + lambda w^2.
    EXPECT_NEAR(w[0], 0.5 * 0.2 / (0.25 + lambda), 1e-7);
    EXPECT_DOUBLE_EQ(w[1], 0.0);
    EXPECT_DOUBLE_EQ(w[2], 0.0);

    target = m.base;
    target.r[0] -= 0.1;
    target.r[2] += 0.5;  // five times what the eye control gives at full weight
    const std::vector<double> v = solveCharacterStep(m, {0.0, 0.0, 0.0}, m.base, target, lambda);
    EXPECT_DOUBLE_EQ(v[0], 0.0);
    EXPECT_NEAR(v[1], 0.5 * 0.1 / (0.25 + lambda), 1e-7);
    EXPECT_DOUBLE_EQ(v[2], 1.0);
}

TEST(CharacterModifiers, AChordStepFromWeightsAlreadySet) {
    // The head at weights (0.4, 0, 0) measures 0.01 short of the target in r0 (the model is not quite linear):
    // the step adds what that residual needs on top of the weights it had.
    const CharacterModel m = linearModel();
    CharacterProportions target = m.base, now = m.base;
    target.r[0] += 0.2;
    now.r[0] += 0.19;
    const std::vector<double> w = solveCharacterStep(m, {0.4, 0.0, 0.0}, now, target, 0.0);
    EXPECT_NEAR(w[0], 0.4 + 0.01 / 0.5, 1e-9);
    EXPECT_DOUBLE_EQ(w[1], 0.0);
}

TEST(CharacterModifiers, BasisWeightsShareAControlsWeight) {
    const CharacterModel m = linearModel();
    EXPECT_EQ(basisWeights(m, 5, {0.25, 0.0, 0.5}), (std::vector<double>{0.25, 0.0, 0.5, 0.5, 0.0}));
}

TEST(CharacterModifiers, MakeHumanSlidersPairTheEnds) {
    const std::vector<std::pair<std::string, double>> ends = {
        {"nose/nose-trans-vert-down", 0.25}, {"nose/nose-trans-vert-up", 0.0},
        {"eyes/r-eye-size-small", 0.0},      {"eyes/l-eye-size-small", 0.0},
        {"eyes/r-eye-size-big", 0.5},        {"eyes/l-eye-size-big", 0.5},
        {"eyebrows/eyebrows-angle-up", 0.1}, {"eyebrows/eyebrows-angle-down", 0.3}};
    const auto sliders = makeHumanSliders(ends);
    ASSERT_EQ(sliders.size(), 4u);
    EXPECT_EQ(sliders[0].first, "nose/nose-trans-vert-down|up");
    EXPECT_DOUBLE_EQ(sliders[0].second, -0.25);
    EXPECT_EQ(sliders[1].first, "eyes/r-eye-size-small|big");
    EXPECT_DOUBLE_EQ(sliders[1].second, 0.5);
    EXPECT_EQ(sliders[2].first, "eyes/l-eye-size-small|big");
    EXPECT_DOUBLE_EQ(sliders[2].second, 0.5);
    EXPECT_EQ(sliders[3].first, "eyebrows/eyebrows-angle-up|down");
    EXPECT_NEAR(sliders[3].second, 0.2, 1e-12);
}

TEST(CharacterModifiers, EveryControlIsOneEndOfAMakeHumanSlider) {
    // The controls' names pair up into MakeHuman's two-sided sliders, every one of them.
    std::vector<std::pair<std::string, double>> all;
    for (const CharacterControl& c : characterControls())
        for (const std::string_view name : c.modifiers) all.emplace_back(std::string(name), 0.0);
    EXPECT_EQ(makeHumanSliders(all).size() * 2, all.size());
}

}  // namespace
}  // namespace avatarbooth
