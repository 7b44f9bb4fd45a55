// The fit's first step: bounded, regularised least squares for the modifier weights (fit/head/modifier_fit.h).
#include "fit/head/modifier_fit.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace avatarbooth {
namespace {

// A cloud of vertices and four modifiers, each moving a different set of them in a different direction.
struct Problem {
    std::vector<glm::dvec3> base;
    ModifierBasis basis;
};

Problem makeProblem() {
    Problem p;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-80.0, 80.0);
    for (int i = 0; i < 40; ++i) p.base.emplace_back(u(rng), u(rng), u(rng));
    p.basis.vertexCount = p.base.size();
    const glm::vec3 dirs[] = {{6, 0, 0}, {0, 5, 0}, {0, 0, 7}, {3, -4, 2}};
    for (int k = 0; k < 4; ++k) {
        Modifier m;
        m.name = "m" + std::to_string(k);
        for (std::uint32_t v = static_cast<std::uint32_t>(k); v < p.base.size(); v += 2) {
            m.vertices.push_back(v);
            m.offsets.push_back(dirs[k] * (1.0f + 0.02f * static_cast<float>(v)));
        }
        p.basis.modifiers.push_back(m);
    }
    return p;
}

// The targets a head shaped by `weights`, scaled by `scale` about `centre` and shifted by `shift`, shows in both views.
std::vector<ModifierTarget> targetsFor(const Problem& p, const std::vector<double>& weights, const glm::dvec3& scale,
                                       const glm::dvec3& centre, const glm::dvec3& shift) {
    const auto shaped = p.basis.apply(p.base, weights);
    std::vector<ModifierTarget> t;
    for (std::uint32_t v = 0; v < shaped.size(); ++v) {
        const glm::dvec3 q = centre + scale * (shaped[v] - centre) + shift;
        t.push_back({v, View::Front, projectToView(q, View::Front)});
        t.push_back({v, View::Side, projectToView(q, View::Side)});
    }
    return t;
}

TEST(ModifierFit, RecoversKnownWeightsScaleAndShift) {
    const Problem p = makeProblem();
    const std::vector<double> truth = {0.3, 0.0, 0.85, 0.5};
    const glm::dvec3 scale(1.1, 0.95, 1.05), centre(0.0, 2.0, -3.0), shift(4.0, -2.5, 1.5);
    ModifierFitOptions o;
    o.regularisation = 1e-9;
    const ModifierFit f = fitModifiers(p.basis, p.base, scale, centre, targetsFor(p, truth, scale, centre, shift), o);
    ASSERT_EQ(f.weights.size(), truth.size());
    for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_NEAR(f.weights[k], truth[k], 1e-5) << k;
    EXPECT_NEAR(f.translation.x, shift.x, 1e-4);
    EXPECT_NEAR(f.translation.y, shift.y, 1e-4);
    EXPECT_NEAR(f.translation.z, shift.z, 1e-4);
    EXPECT_GT(f.rmsBeforeMm, 1.0);
    EXPECT_LT(f.rmsAfterMm, 1e-4);
}

TEST(ModifierFit, RecoversTheHeadsSizeWhenItIsLeftFree) {
    const Problem p = makeProblem();
    const std::vector<double> truth = {0.3, 0.0, 0.85, 0.5};
    const glm::dvec3 scale(1.0), centre(0.0, 2.0, -3.0), shift(4.0, -2.5, 1.5);
    // The targets come from a head 4 % larger than the scaling the fit is given.
    const auto targets = targetsFor(p, truth, 1.04 * scale, centre, shift);
    ModifierFitOptions o;
    o.regularisation = 1e-9;
    o.scaleRegularisation = 1e-9;
    const ModifierFit free = fitModifiers(p.basis, p.base, scale, centre, targets, o);
    // sigma enters linearly: its product with the weights' offsets (4 % of up to 7 mm) is what remains.
    EXPECT_NEAR(free.scaleChange, 0.04, 0.002);
    EXPECT_NEAR(free.translation.x, shift.x, 0.3);
    EXPECT_LT(free.rmsAfterMm, 0.2);
    for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_NEAR(free.weights[k], truth[k], 0.05) << k;
    // Held (range 0), the size cannot follow, and the weights and the shift take the difference.
    o.scaleRange = 0.0;
    const ModifierFit held = fitModifiers(p.basis, p.base, scale, centre, targets, o);
    EXPECT_EQ(held.scaleChange, 0.0);
    EXPECT_GT(held.rmsAfterMm, 5.0 * free.rmsAfterMm);
    // Within its range: asked for 4 %, allowed 2 %, it stops at 2 %.
    o.scaleRange = 0.02;
    EXPECT_DOUBLE_EQ(fitModifiers(p.basis, p.base, scale, centre, targets, o).scaleChange, 0.02);
}

TEST(ModifierFit, WeightsStayWithinTheirRange) {
    const Problem p = makeProblem();
    // Asked for 2.5 of the first modifier and "-1" of the second: the bounds hold them at 1 and 0.
    const std::vector<double> beyond = {2.5, 0.0, 0.4, 0.0};
    auto targets = targetsFor(p, beyond, glm::dvec3(1.0), glm::dvec3(0.0), glm::dvec3(0.0));
    const auto moved = p.basis.apply(p.base, {0.0, 1.0, 0.0, 0.0});
    for (std::size_t i = 0; i < targets.size(); ++i)  // the second modifier's vertices pulled the opposite way
        targets[i].target -= projectToView(moved[targets[i].vertex] - p.base[targets[i].vertex], targets[i].view);
    ModifierFitOptions o;
    o.regularisation = 1e-9;
    const ModifierFit f = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
    EXPECT_DOUBLE_EQ(f.weights[0], 1.0);
    EXPECT_DOUBLE_EQ(f.weights[1], 0.0);
    for (const double w : f.weights) {
        EXPECT_GE(w, 0.0);
        EXPECT_LE(w, 1.0);
    }
}

TEST(ModifierFit, RegularisationPullsTowardsTheAverage) {
    const Problem p = makeProblem();
    const std::vector<double> truth = {0.6, 0.6, 0.6, 0.6};
    const auto targets = targetsFor(p, truth, glm::dvec3(1.0), glm::dvec3(0.0), glm::dvec3(0.0));
    double previous = 1e9;
    for (const double lambda : {1e-6, 100.0, 10000.0, 1e7}) {
        ModifierFitOptions o;
        o.regularisation = lambda;
        const ModifierFit f = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
        double sum = 0.0;
        for (const double w : f.weights) sum += w;
        EXPECT_LT(sum, previous + 1e-9) << lambda;
        previous = sum;
    }
    EXPECT_LT(previous, 0.05);  // at a huge lambda the head stays the average one
}

// The subject's right and left modifiers of one slider are held together by mirrorRegularisation: one side measured
// 1.2 mm off (as dlib's scatter puts one eye's points) reads 0.2 of a weight more on that side alone; held together,
// both sides take the mean of what they measure.
TEST(ModifierFit, MirroredModifiersAreHeldTogether) {
    Problem p;
    for (int i = 0; i < 20; ++i) p.base.emplace_back(-30.0 - i, 0.5 * i, 10.0);  // the subject's right (-x) ...
    for (int i = 0; i < 20; ++i) p.base.emplace_back(30.0 + i, 0.5 * i, 10.0);   // ... and left
    for (int i = 0; i < 20; ++i) p.base.emplace_back(0.0, 0.5 * i, 40.0);        // the midline: the frame's shift
    p.basis.vertexCount = p.base.size();
    for (const char* side : {"r", "l"}) {
        Modifier m;
        m.name = std::string("eyes/") + side + "-eye-move-out";
        m.group = "eyes";
        for (std::uint32_t v = side[0] == 'r' ? 0 : 20, end = v + 20; v < end; ++v) {
            m.vertices.push_back(v);
            m.offsets.emplace_back(side[0] == 'r' ? -6.0f : 6.0f, 0.0f, 0.0f);
        }
        p.basis.modifiers.push_back(m);
    }
    Modifier unpaired;  // a name with no side is nobody's mirror
    unpaired.name = "nose/nose-trans-up";
    p.basis.modifiers.push_back(unpaired);
    const auto pairs = mirroredModifiers(p.basis);
    ASSERT_EQ(pairs.size(), 1u);
    EXPECT_EQ(pairs[0], (std::pair<std::size_t, std::size_t>(0, 1)));

    auto targets = targetsFor(p, {0.5, 0.5, 0.0}, glm::dvec3(1.0), glm::dvec3(0.0), glm::dvec3(0.0));
    for (ModifierTarget& t : targets)
        if (t.vertex < 20 && t.view == View::Front) t.target.x -= 1.2;  // 0.2 of the right modifier's 6 mm
    ModifierFitOptions o;
    o.regularisation = 1e-9;
    o.scaleRange = 0.0;
    o.mirrorRegularisation = 0.0;
    const ModifierFit apart = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
    EXPECT_GT(apart.weights[0] - apart.weights[1], 0.15);
    o.mirrorRegularisation = 1e9;
    const ModifierFit together = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
    EXPECT_NEAR(together.weights[0], together.weights[1], 1e-6);
    EXPECT_NEAR(together.weights[0], 0.6, 1e-4);
    // What the symmetric shape leaves (0.6 mm towards the right on either side) the frame's shift shares with the
    // midline's 20 exact points: 40 x 0.6 / 60.
    EXPECT_NEAR(together.translation.x, -0.4, 1e-4);
}

// An outline target counts along its normal only: moved along the outline (here the front view's y), it still gives
// the true weights, and the modifier is free to move the vertex along the outline.
TEST(ModifierFit, OutlineTargetsCountAlongTheirNormalOnly) {
    const Problem p = makeProblem();
    const std::vector<double> truth = {0.3, 0.7, 0.2, 0.5};
    auto targets = targetsFor(p, truth, glm::dvec3(1.0), glm::dvec3(0.0), glm::dvec3(0.0));
    for (auto& t : targets)
        if (t.view == View::Front) {
            t.normal = {1.0, 0.0};
            t.weight = {1.0, 0.0};
            t.target.y += 9.0;  // anywhere along the outline
        }
    ModifierFitOptions o;
    o.regularisation = 1e-9;
    o.robustMm = 0.0;
    const ModifierFit f = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
    for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_NEAR(f.weights[k], truth[k], 1e-5) << k;
    // The same targets as points pull the front y by 9 mm: the weights go wrong.
    for (auto& t : targets) {
        t.normal = glm::dvec2(0.0);
        t.weight = glm::dvec2(1.0);
    }
    const ModifierFit g = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
    EXPECT_GT(std::abs(g.weights[1] - truth[1]) + std::abs(g.translation.y), 1.0);
}

// One misplaced point (30 mm off) among exact ones: the Huber weights leave the modifiers near the truth, where plain
// least squares lets it bend them.
TEST(ModifierFit, RobustWeightsKeepAMisplacedPointFromBendingTheHead) {
    const Problem p = makeProblem();
    const std::vector<double> truth = {0.3, 0.7, 0.2, 0.5};
    auto targets = targetsFor(p, truth, glm::dvec3(1.0), glm::dvec3(0.0), glm::dvec3(0.0));
    targets[6].target += glm::dvec2(30.0, -30.0);
    const auto error = [&](double robustMm) {
        ModifierFitOptions o;
        o.regularisation = 1e-9;
        o.robustMm = robustMm;
        o.robustIterations = 10;
        const ModifierFit f = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
        double sum = 0.0;
        for (std::size_t k = 0; k < truth.size(); ++k) sum += std::abs(f.weights[k] - truth[k]);
        return sum;
    };
    const double plain = error(0.0), robust = error(1.0);
    EXPECT_GT(plain, 0.05);
    EXPECT_LT(robust, 0.25 * plain);
}

// Many overlapping modifiers (correlated, as MakeHuman's are) asked for weights partly beyond their range, with noise:
// the result is the exact optimum of the bounded problem. No single weight can be moved within its range, nor the
// translation, to lower the objective (the sum of squared target errors plus lambda times the squared weights).
TEST(ModifierFit, ReachesTheBoundedOptimum) {
    Problem p = makeProblem();
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-4.0f, 4.0f);
    for (int k = 4; k < 30; ++k) {
        Modifier m;
        m.name = "extra" + std::to_string(k);
        for (std::uint32_t v = 0; v < p.base.size(); ++v)
            if ((v + static_cast<std::uint32_t>(k)) % 3 != 0) {
                m.vertices.push_back(v);
                m.offsets.emplace_back(u(rng), u(rng), u(rng));
            }
        p.basis.modifiers.push_back(m);
    }
    std::vector<double> asked(p.basis.modifiers.size());
    std::uniform_real_distribution<double> w(-0.6, 1.6);
    for (double& a : asked) a = w(rng);
    auto targets = targetsFor(p, asked, glm::dvec3(1.0), glm::dvec3(0.0), glm::dvec3(2.0, -1.0, 3.0));
    std::normal_distribution<double> noise(0.0, 0.5);
    for (auto& t : targets) t.target += glm::dvec2(noise(rng), noise(rng));
    ModifierFitOptions o;
    o.regularisation = 2.0;
    o.robustMm = 0.0;
    o.fixedGroups.clear();
    o.scaleRange = 0.0;  // the size held: the objective below has no sigma
    const ModifierFit f = fitModifiers(p.basis, p.base, glm::dvec3(1.0), glm::dvec3(0.0), targets, o);
    const auto objective = [&](const std::vector<double>& weights, const glm::dvec3& shift) {
        const auto shaped = p.basis.apply(p.base, weights);
        double e = 0.0;
        for (const auto& t : targets) {
            const glm::dvec2 d = projectToView(shaped[t.vertex] + shift, t.view) - t.target;
            e += glm::dot(d, d);
        }
        for (const double x : weights) e += o.regularisation * x * x;
        return e;
    };
    const double best = objective(f.weights, f.translation);
    int atBound = 0;
    for (std::size_t k = 0; k < f.weights.size(); ++k) {
        atBound += f.weights[k] == 0.0 || f.weights[k] == 1.0;
        for (const double step : {-1e-4, 1e-4}) {
            std::vector<double> moved = f.weights;
            moved[k] = std::clamp(moved[k] + step, 0.0, 1.0);
            EXPECT_GE(objective(moved, f.translation), best - 1e-9) << k << " " << step;
        }
    }
    EXPECT_GT(atBound, 3);  // the bounds matter in this problem
    for (int axis = 0; axis < 3; ++axis)
        for (const double step : {-1e-4, 1e-4}) {
            glm::dvec3 shift = f.translation;
            shift[axis] += step;
            EXPECT_GE(objective(f.weights, shift), best - 1e-9) << axis;
        }
}

}  // namespace
}  // namespace avatarbooth
