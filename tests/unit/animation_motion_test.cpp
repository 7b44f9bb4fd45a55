// The avatar's keyframed motion: easing between keys, the rig's kinematics, the reveal and attract clips played
// full and limited, the settings' checks.
#include "reveal/animation/avatar_motion.h"
#include "common/error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <set>

namespace avatarbooth {
namespace {

void expectNear(const glm::dvec3& a, const glm::dvec3& b, double tol = 1e-9) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

MotionClip twoKeys() {
    MotionClip clip{"test", {}};
    clip.keys = {{1.0, {}}, {3.0, {{}, {40.0, -8.0, 4.0}, {}}}};
    return clip;
}

TEST(AvatarMotion, EasesBetweenKeysAndClampsOutside) {
    const MotionClip clip = twoKeys();
    EXPECT_DOUBLE_EQ(samplePose(clip, 0.0).head.yawDeg, 0.0);
    EXPECT_DOUBLE_EQ(samplePose(clip, 2.0).head.yawDeg, 20.0);           // smoothstep(1/2) = 1/2
    EXPECT_DOUBLE_EQ(samplePose(clip, 1.5).head.yawDeg, 40.0 * 0.15625);  // smoothstep(1/4) = 5/32
    EXPECT_DOUBLE_EQ(samplePose(clip, 1.5).head.pitchDeg, -8.0 * 0.15625);
    EXPECT_DOUBLE_EQ(samplePose(clip, 9.0).head.rollDeg, 4.0);
    MotionClip bad = clip;
    std::swap(bad.keys[0], bad.keys[1]);
    EXPECT_THROW(samplePose(bad, 1.0), std::invalid_argument);
    EXPECT_THROW(samplePose(MotionClip{}, 0.0), std::invalid_argument);
}

TEST(AvatarMotion, SamplesBothEndsAt24Fps) {
    EXPECT_EQ(sampleMotion(twoKeys(), 24.0).size(), 73u);  // 3 s * 24 + 1
    EXPECT_EQ(sampleMotion(revealMotion(), 24.0).size(), 123u);
    EXPECT_EQ(sampleMotion(attractMotion(), 24.0).size(), 97u);
}

TEST(AvatarMotion, HeadTurnsAboutItsPivots) {
    const AvatarRig rig;
    Pose p;
    p.head.yawDeg = 90.0;  // the face turns to the subject's left (+x)
    // Nose tip (0, -33, 98) about the head pivot (0, -35, -10): (0, 2, 108) -> (108, 2, 0).
    expectNear(glm::dvec3(headModelMatrix(p, rig) * glm::dvec4(rig.noseTip, 1.0)), {108.0, -33.0, -10.0});
    const JointPositions turned = rigPoints(p, rig);
    expectNear(turned[0], rig.headPivot);  // the neck did not move
    expectNear(turned[1], {108.0, -33.0, -10.0});

    Pose nod;
    nod.neck.pitchDeg = 90.0;  // positive pitch tips the face down: +z goes to -y
    // Head pivot (0, -35, -10) about the neck pivot (0, -110, -15): (0, 75, 5) -> (0, -5, 75).
    expectNear(rigPoints(nod, rig)[0], {0.0, -115.0, 60.0});

    Pose look;
    look.eyes.yawDeg = 90.0;  // the gaze points swing to +x, 40 mm from each eye
    const JointPositions eyes = rigPoints(look, rig);
    expectNear(eyes[3], rig.rightEye + glm::dvec3(40.0, 0.0, 0.0));
    expectNear(eyes[4], rig.leftEye + glm::dvec3(40.0, 0.0, 0.0));
    const JointPositions rest = rigPoints(Pose{}, rig);
    expectNear(rest[2], rig.topOfHead);
    expectNear(rest[3], rig.rightEye + glm::dvec3(0.0, 0.0, 40.0));
}

TEST(AvatarMotion, FullPlaybackShowsEveryFrame) {
    AnimationSettings settings;
    settings.style = AnimationStyle::Full;
    const auto frames = playAnimation(revealMotion(), settings);
    ASSERT_EQ(frames.size(), 123u);
    for (std::size_t k = 0; k < frames.size(); ++k) EXPECT_EQ(frames[k].sourceFrame, static_cast<int>(k));
    // Frame 31 (t = 1.2917 s) is on the way to the first side; its head rotation is the pose's.
    const Pose at = samplePose(revealMotion(), 31.0 / 24.0);
    EXPECT_DOUBLE_EQ(frames[31].pose.head.yawDeg, at.head.yawDeg);
    const glm::dquat expected = jointRotation(at.neck) * jointRotation(at.head);
    EXPECT_NEAR(std::abs(glm::dot(frames[31].headWorld, expected)), 1.0, 1e-12);
}

TEST(AvatarMotion, LimitedPlaybackKeepsTheLengthOmitsTheFastestAndHolds) {
    const AnimationSettings settings;  // limited, N_io 4, N_hf = round(123 / 3) = 41
    const auto limited = playAnimation(revealMotion(), settings);
    ASSERT_EQ(limited.size(), 123u);
    std::set<int> shown;
    int repeats = 0;
    for (std::size_t k = 0; k < limited.size(); ++k) {
        shown.insert(limited[k].sourceFrame);
        if (k > 0) {
            EXPECT_LE(limited[k - 1].sourceFrame, limited[k].sourceFrame);
            repeats += limited[k].sourceFrame == limited[k - 1].sourceFrame ? 1 : 0;
        }
    }
    EXPECT_GE(repeats, 41);
    EXPECT_LE(shown.size(), 123u - 41u);
    // The fastest frame of the full motion is one of those omitted.
    const std::vector<Pose> poses = sampleMotion(revealMotion(), 24.0);
    std::vector<JointPositions> points;
    for (const Pose& p : poses) points.push_back(rigPoints(p));
    const std::vector<double> speeds = frameSpeeds(points, fullTiming(points.size()));
    const int fastest = static_cast<int>(std::max_element(speeds.begin(), speeds.end()) - speeds.begin());
    EXPECT_EQ(shown.count(fastest), 0u) << "frame " << fastest;
    // Holds show the same pose as the frame they repeat.
    for (const auto& f : limited) EXPECT_DOUBLE_EQ(f.pose.head.yawDeg, poses[static_cast<std::size_t>(f.sourceFrame)].head.yawDeg);
}

TEST(AvatarMotion, StyleNamesAndSettingChecks) {
    EXPECT_EQ(parseAnimationStyle("limited"), AnimationStyle::Limited);
    EXPECT_EQ(parseAnimationStyle("full"), AnimationStyle::Full);
    EXPECT_EQ(animationStyleName(AnimationStyle::Full), "full");
    try {
        parseAnimationStyle("Limited");
        FAIL() << "accepted a wrong style";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), "animation.style");
    }
    AnimationSettings s;
    s.holdFraction = 1.5;
    EXPECT_THROW(checkAnimationSettings(s), BoothError);
    s = {};
    s.inbetweenOmissions = -1;
    EXPECT_THROW(checkAnimationSettings(s), BoothError);
    s = {};
    s.fps = 0.0;
    EXPECT_THROW(checkAnimationSettings(s), BoothError);
    EXPECT_NO_THROW(checkAnimationSettings(AnimationSettings{}));
}

}  // namespace
}  // namespace avatarbooth
