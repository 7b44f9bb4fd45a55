// Kitamura's limited-animation filter (Algorithms 2 and 3) on small hand-made motions whose every step was
// worked out by hand: ties, the copy limit, length, where frames go, iterating against deleting all at once.
#include "reveal/animation/limited_animation.h"

#include <gtest/gtest.h>

#include <random>
#include <set>

namespace avatarbooth {
namespace {

// A one-joint motion along x: SSD(k) = (x_k - x_{k-1})^2.
std::vector<JointPositions> alongX(const std::vector<double>& xs) {
    std::vector<JointPositions> motion;
    for (const double x : xs) motion.push_back({glm::dvec3(x, 0.0, 0.0)});
    return motion;
}

// x from per-frame steps: x_0 = 0, x_k = x_{k-1} + steps[k].
std::vector<JointPositions> fromSteps(const std::vector<double>& steps) {
    std::vector<double> xs;
    double x = 0.0;
    for (std::size_t k = 0; k < steps.size(); ++k) {
        if (k > 0) x += steps[k];
        xs.push_back(x);
    }
    return alongX(xs);
}

std::set<int> omittedFrames(const std::vector<int>& timing, std::size_t frames) {
    std::set<int> missing;
    for (std::size_t k = 0; k < frames; ++k) missing.insert(static_cast<int>(k));
    for (const int f : timing) missing.erase(f);
    return missing;
}

TEST(LimitedAnimation, SpeedIsTheSumOfSquaredJointDisplacements) {
    const std::vector<JointPositions> motion = {{glm::dvec3(0, 0, 0), glm::dvec3(1, 1, 1)},
                                                {glm::dvec3(1, 2, 2), glm::dvec3(1, 1, 4)}};
    EXPECT_DOUBLE_EQ(squaredDisplacement(motion[0], motion[1]), 1.0 + 4.0 + 4.0 + 9.0);
    EXPECT_EQ(frameSpeeds(motion, {0, 1, 1, 0}), (std::vector<double>{0.0, 18.0, 0.0, 18.0}));
    EXPECT_THROW(squaredDisplacement(motion[0], {glm::dvec3(0)}), std::invalid_argument);
    EXPECT_THROW(frameSpeeds(motion, {0, 2}), std::invalid_argument);
}

TEST(LimitedAnimation, CopiesOfPictureCountsTheRun) {
    const std::vector<int> timing = {0, 0, 0, 1, 2, 2};
    EXPECT_EQ(copiesOfPicture(timing, 0), 2);
    EXPECT_EQ(copiesOfPicture(timing, 2), 2);
    EXPECT_EQ(copiesOfPicture(timing, 3), 0);
    EXPECT_EQ(copiesOfPicture(timing, 5), 1);
}

// x = 0 1 2 6 7 8: SSD 1 1 16 1 1.
//  1: delete frame 3 (16); on 0 1 2 4 5 (SSD 1 1 25 1) the slowest gap is k = 1 (tie with 2 and 4: the earliest)
//     -> copy frame 0: 0 0 1 2 4 5
//  2: SSD 0 1 1 25 1: delete frame 4; on 0 0 1 2 5 (SSD 0 1 1 36) -> copy 0 again: 0 0 0 1 2 5
//  3: SSD 0 0 1 1 36: delete frame 5 -> 0 0 0 1 2 -> copy 0: 0 0 0 0 1 2 (frame 0 now has 3 copies)
//  4: SSD 0 0 0 1 1: delete the first of the tie, frame 1 -> 0 0 0 0 2; every gap follows frame 0, which has
//     3 copies: nothing may be copied, so the iteration is undone and the algorithm stops after 3.
TEST(LimitedAnimation, OmitInbetweensStepByStep) {
    const auto motion = alongX({0, 1, 2, 6, 7, 8});
    EXPECT_EQ(omitInbetweens(motion, fullTiming(6), 1).timing, (std::vector<int>{0, 0, 1, 2, 4, 5}));
    EXPECT_EQ(omitInbetweens(motion, fullTiming(6), 2).timing, (std::vector<int>{0, 0, 0, 1, 2, 5}));
    const FilterResult three = omitInbetweens(motion, fullTiming(6), 3);
    EXPECT_EQ(three.timing, (std::vector<int>{0, 0, 0, 0, 1, 2}));
    EXPECT_EQ(three.iterations, 3);
    const FilterResult four = omitInbetweens(motion, fullTiming(6), 4);
    EXPECT_EQ(four.timing, (std::vector<int>{0, 0, 0, 0, 1, 2}));
    EXPECT_EQ(four.iterations, 3);
    EXPECT_EQ(omitInbetweens(motion, fullTiming(6), 0).timing, fullTiming(6));
}

// x = 0 1 3 6 10 15 21 28: SSD 1 4 9 16 25 36 49, the motion accelerates.
// Three iterations delete frames 7, 6, 5 and pile three copies of frame 0 into the slowest gap; the fourth
// deletes frame 4 and, frame 0 being full, copies frame 1 (the next slowest gap, SSD 4).
TEST(LimitedAnimation, OmitInbetweensRespectsTheCopyLimit) {
    const auto motion = alongX({0, 1, 3, 6, 10, 15, 21, 28});
    EXPECT_EQ(omitInbetweens(motion, fullTiming(8), 3).timing, (std::vector<int>{0, 0, 0, 0, 1, 2, 3, 4}));
    EXPECT_EQ(omitInbetweens(motion, fullTiming(8), 4).timing, (std::vector<int>{0, 0, 0, 0, 1, 1, 2, 3}));
    // With a limit of 1 copy the second copy already moves on.
    EXPECT_EQ(omitInbetweens(motion, fullTiming(8), 2, 1).timing, (std::vector<int>{0, 0, 1, 1, 2, 3, 4, 5}));
}

// x = 0 2 3 7 8 12: SSD 4 1 16 1 16.
//  1: the slowest frames are 2 and 4 (SSD 1): the earlier, 2, takes frame 1's picture: 0 1 1 3 4 5
//  2: SSD 4 0 25 1 16; frames 1 and 2 now share a picture (neither may be overwritten), the slowest other is 4:
//     0 1 1 3 3 5
//  3: SSD 4 0 25 0 25; only frame 5 still shows a picture of its own: 0 1 1 3 3 3
TEST(LimitedAnimation, HoldFramesStepByStep) {
    const auto motion = alongX({0, 2, 3, 7, 8, 12});
    EXPECT_EQ(holdFrames(motion, fullTiming(6), 1).timing, (std::vector<int>{0, 1, 1, 3, 4, 5}));
    EXPECT_EQ(holdFrames(motion, fullTiming(6), 2).timing, (std::vector<int>{0, 1, 1, 3, 3, 5}));
    const FilterResult three = holdFrames(motion, fullTiming(6), 3);
    EXPECT_EQ(three.timing, (std::vector<int>{0, 1, 1, 3, 3, 3}));
    EXPECT_EQ(holdFrames(motion, fullTiming(6), 4).iterations, 3);
}

// x = 0 8 8 8 8 8 30: SSD 64 0 0 0 0 484. The still section chains frame 1's picture forward (ties: the
// earliest) until it has 3 copies: 0 1 1 3 4 5 6 -> 0 1 1 1 4 5 6 -> 0 1 1 1 1 5 6; frame 5 (SSD 0) may not take
// a fourth copy, so the next hold is frame 6 (SSD 484): 0 1 1 1 1 5 5. Then no frame is eligible.
TEST(LimitedAnimation, HoldFramesRespectsTheCopyLimit) {
    const auto motion = alongX({0, 8, 8, 8, 8, 8, 30});
    EXPECT_EQ(holdFrames(motion, fullTiming(7), 3).timing, (std::vector<int>{0, 1, 1, 1, 1, 5, 6}));
    EXPECT_EQ(holdFrames(motion, fullTiming(7), 4).timing, (std::vector<int>{0, 1, 1, 1, 1, 5, 5}));
    const FilterResult all = holdFrames(motion, fullTiming(7), 10);
    EXPECT_EQ(all.timing, (std::vector<int>{0, 1, 1, 1, 1, 5, 5}));
    EXPECT_EQ(all.iterations, 4);
    // With a limit of 2 copies the chain stops one frame earlier.
    EXPECT_EQ(holdFrames(motion, fullTiming(7), 3, 2).timing, (std::vector<int>{0, 1, 1, 1, 4, 4, 6}));
}

// Steps of 1 mm except frames 21-25 (10 mm). Each deletion joins two frames of the fast section into a faster
// gap, so the 4 deletions are frames 21, 22, 23, 24 and nothing else; the copies go to the slow start.
TEST(LimitedAnimation, ASingleFastSectionLosesFramesExactlyThere) {
    std::vector<double> steps(48, 1.0);
    for (int k = 21; k <= 25; ++k) steps[static_cast<std::size_t>(k)] = 10.0;
    const auto motion = fromSteps(steps);
    const FilterResult r = omitInbetweens(motion, fullTiming(48), 4);
    std::vector<int> expected = {0, 0, 0, 0, 1, 1};
    for (int k = 2; k <= 20; ++k) expected.push_back(k);
    for (int k = 25; k < 48; ++k) expected.push_back(k);
    EXPECT_EQ(r.timing, expected);
    EXPECT_EQ(omittedFrames(r.timing, 48), (std::set<int>{21, 22, 23, 24}));
}

// Two fast sections, frames 10-12 (10 mm steps) and 30-32 (9.5 mm). Iterating deletes 10, 11, 12 and then 13
// (the gap left behind is the fastest every time): the omissions run together in one place, as in the thesis'
// figure 5.5. Deleting the 4 fastest at once takes 10, 11, 12 and 30: scattered, the speed-up is diluted.
TEST(LimitedAnimation, IteratingAndDeletingAllAtOnceDiffer) {
    std::vector<double> steps(44, 1.0);
    for (int k : {10, 11, 12}) steps[static_cast<std::size_t>(k)] = 10.0;
    for (int k : {30, 31, 32}) steps[static_cast<std::size_t>(k)] = 9.5;
    const auto motion = fromSteps(steps);
    const FilterResult iterated = omitInbetweens(motion, fullTiming(44), 4);
    const FilterResult atOnce = omitInbetweensAllAtOnce(motion, 4);
    EXPECT_EQ(omittedFrames(iterated.timing, 44), (std::set<int>{10, 11, 12, 13}));
    EXPECT_EQ(omittedFrames(atOnce.timing, 44), (std::set<int>{10, 11, 12, 30}));
    EXPECT_EQ(atOnce.timing.size(), 44u);
    // All at once, the copies go to the 4 slowest surviving gaps (all SSD 1: the earliest), one each.
    EXPECT_EQ(std::vector<int>(atOnce.timing.begin(), atOnce.timing.begin() + 9),
              (std::vector<int>{0, 0, 1, 1, 2, 2, 3, 3, 4}));
}

TEST(LimitedAnimation, LengthIsPreservedAndRunsStayWithinTheLimit) {
    std::mt19937 rng(11);
    std::normal_distribution<double> jitter(0.0, 1.0);
    for (const std::size_t frames : {88u, 92u, 120u, 129u}) {
        std::vector<JointPositions> motion;
        JointPositions joints(6, glm::dvec3(0.0));
        for (std::size_t k = 0; k < frames; ++k) {
            for (std::size_t i = 0; i < joints.size(); ++i)
                joints[i] += glm::dvec3(jitter(rng), jitter(rng), jitter(rng)) * (1.0 + static_cast<double>(i));
            motion.push_back(joints);
        }
        LimitedAnimationSettings settings;
        settings.inbetweenOmissions = 6;
        settings.holdFrames = static_cast<int>(frames / 3);
        const std::vector<int> timing = limitAnimation(motion, settings);
        ASSERT_EQ(timing.size(), frames);
        EXPECT_EQ(timing.front(), 0);
        for (std::size_t k = 1; k < frames; ++k) EXPECT_LE(timing[k - 1], timing[k]) << "frames never go back";
        for (std::size_t k = 0; k < frames; ++k) EXPECT_LE(copiesOfPicture(timing, k), 3);
        // Every hold repeats its predecessor (and so does every in-between copy): at least N_hf repeats.
        int repeats = 0;
        for (std::size_t k = 1; k < frames; ++k) repeats += timing[k] == timing[k - 1] ? 1 : 0;
        EXPECT_GE(repeats, settings.holdFrames);
    }
}

TEST(LimitedAnimation, NakaNashiComesBeforeHolds) {
    const auto motion = alongX({0, 1, 3, 6, 10, 15, 21, 28});
    LimitedAnimationSettings settings;
    settings.inbetweenOmissions = 4;
    settings.holdFrames = 1;
    // After Algorithm 2: 0 0 0 0 1 1 2 3 (SSD 0 0 0 1 0 4 9); the only eligible holds are frames 6 and 7 (the
    // others repeat their predecessor or follow a full picture): frame 6 (SSD 4) takes frame 1's picture, which
    // then has 2 copies.
    EXPECT_EQ(limitAnimation(motion, settings), (std::vector<int>{0, 0, 0, 0, 1, 1, 1, 3}));
}

TEST(LimitedAnimation, RejectsBadArguments) {
    const auto motion = alongX({0, 1, 2});
    EXPECT_THROW(omitInbetweens(motion, fullTiming(3), -1), std::invalid_argument);
    EXPECT_THROW(holdFrames(motion, {0, 3}, 1), std::invalid_argument);
    EXPECT_TRUE(limitAnimation({}, {}).empty());
}

}  // namespace
}  // namespace avatarbooth
