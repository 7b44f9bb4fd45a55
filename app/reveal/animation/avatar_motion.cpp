// The avatar's keyframed motions, their sampling, the rig's kinematics and playback (full or limited).
#include "reveal/animation/avatar_motion.h"

#include "common/error.h"

#include <glm/gtc/matrix_transform.hpp>

#include <cmath>
#include <stdexcept>

namespace avatarbooth {
namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;

Pose pose(JointAngles neck, JointAngles head, JointAngles eyes) { return Pose{neck, head, eyes}; }

double ease(double s) { return s * s * (3.0 - 2.0 * s); }

JointAngles mix(const JointAngles& a, const JointAngles& b, double w) {
    return {a.yawDeg + (b.yawDeg - a.yawDeg) * w, a.pitchDeg + (b.pitchDeg - a.pitchDeg) * w,
            a.rollDeg + (b.rollDeg - a.rollDeg) * w};
}

glm::dvec3 transformPoint(const glm::dmat4& m, const glm::dvec3& p) { return glm::dvec3(m * glm::dvec4(p, 1.0)); }

glm::dmat4 rotationAbout(const glm::dvec3& pivot, const glm::dquat& q) {
    return glm::translate(glm::dmat4(1.0), pivot) * glm::mat4_cast(q) * glm::translate(glm::dmat4(1.0), -pivot);
}

}  // namespace

MotionClip revealMotion() {
    // Times chosen so each turn takes about a second (fast in its middle, easing at both ends) with short rests
    // on each side: the shape the limited filter is made for.
    MotionClip clip{"reveal", {}};
    clip.keys = {
        {0.0, pose({}, {}, {})},
        {0.4, pose({}, {}, {15, 0, 0})},                      // the eyes lead towards the subject's left
        {1.3, pose({15, 0, 0}, {45, 0, 3}, {5, 0, 0})},       // the head follows: three-quarter to profile
        {1.7, pose({15, 0, 0}, {45, 0, 3}, {-10, 0, 0})},     // eyes start back
        {2.9, pose({-15, 0, 0}, {-45, 0, -3}, {-5, 0, 0})},   // through the front to the other side
        {3.3, pose({-15, 0, 0}, {-45, 0, -3}, {0, 0, 0})},
        {4.2, pose({}, {}, {})},                              // back to the front
        {4.5, pose({}, {0, 12, 0}, {0, -6, 0})},              // a nod: down ...
        {4.8, pose({}, {0, -3, 0}, {})},                      // ... up ...
        {5.1, pose({}, {}, {})},                              // ... rest
    };
    return clip;
}

MotionClip attractMotion() {
    MotionClip clip{"attract", {}};
    clip.keys = {
        {0.0, pose({}, {}, {})},
        {0.5, pose({}, {}, {-20, 0, 0})},                     // glance to the subject's right
        {1.0, pose({-5, 0, 0}, {-25, 0, 0}, {-8, 0, 0})},     // the head follows
        {1.2, pose({-5, 0, 0}, {-25, 0, 0}, {20, 0, 0})},     // a quick glance across (a saccade)
        {2.1, pose({5, 0, 0}, {25, 2, 0}, {8, 0, 0})},        // the head turns after the eyes
        {2.8, pose({5, 0, 0}, {10, -10, 0}, {0, -10, 0})},    // a look up
        {3.4, pose({}, {}, {})},
        {4.0, pose({}, {}, {})},                              // rest before the loop starts again
    };
    return clip;
}

Pose samplePose(const MotionClip& clip, double t) {
    if (clip.keys.empty()) throw std::invalid_argument("motion '" + clip.name + "' has no keys");
    for (std::size_t i = 1; i < clip.keys.size(); ++i)
        if (!(clip.keys[i].timeSeconds > clip.keys[i - 1].timeSeconds))
            throw std::invalid_argument("motion '" + clip.name + "': key " + std::to_string(i) + " is not after key " +
                                        std::to_string(i - 1));
    if (t <= clip.keys.front().timeSeconds) return clip.keys.front().pose;
    if (t >= clip.keys.back().timeSeconds) return clip.keys.back().pose;
    std::size_t i = 1;
    while (clip.keys[i].timeSeconds < t) ++i;
    const Keyframe& a = clip.keys[i - 1];
    const Keyframe& b = clip.keys[i];
    const double w = ease((t - a.timeSeconds) / (b.timeSeconds - a.timeSeconds));
    return {mix(a.pose.neck, b.pose.neck, w), mix(a.pose.head, b.pose.head, w), mix(a.pose.eyes, b.pose.eyes, w)};
}

std::vector<Pose> sampleMotion(const MotionClip& clip, double fps) {
    if (!(fps > 0.0)) throw std::invalid_argument("sampleMotion: fps must be positive");
    const auto frames = static_cast<std::size_t>(std::lround(clip.durationSeconds() * fps)) + 1;
    std::vector<Pose> poses;
    poses.reserve(frames);
    for (std::size_t k = 0; k < frames; ++k) poses.push_back(samplePose(clip, static_cast<double>(k) / fps));
    return poses;
}

glm::dquat jointRotation(const JointAngles& a) {
    return glm::angleAxis(a.yawDeg * kDegToRad, glm::dvec3(0, 1, 0)) *
           glm::angleAxis(a.pitchDeg * kDegToRad, glm::dvec3(1, 0, 0)) *
           glm::angleAxis(a.rollDeg * kDegToRad, glm::dvec3(0, 0, 1));
}

glm::dmat4 headModelMatrix(const Pose& p, const AvatarRig& rig) {
    return rotationAbout(rig.neckPivot, jointRotation(p.neck)) * rotationAbout(rig.headPivot, jointRotation(p.head));
}

JointPositions rigPoints(const Pose& p, const AvatarRig& rig) {
    const glm::dmat4 neck = rotationAbout(rig.neckPivot, jointRotation(p.neck));
    const glm::dmat4 head = neck * rotationAbout(rig.headPivot, jointRotation(p.head));
    const glm::dquat eye = jointRotation(p.eyes);
    const glm::dvec3 gaze = eye * glm::dvec3(0.0, 0.0, rig.gazeLengthMm);
    return {transformPoint(neck, rig.headPivot), transformPoint(head, rig.noseTip), transformPoint(head, rig.topOfHead),
            transformPoint(head, rig.rightEye + gaze), transformPoint(head, rig.leftEye + gaze)};
}

AnimationStyle parseAnimationStyle(const std::string& name) {
    if (name == "limited") return AnimationStyle::Limited;
    if (name == "full") return AnimationStyle::Full;
    throw BoothError(ErrorKind::BadConfig, "animation.style", "'" + name + "' is not \"limited\" or \"full\"");
}

std::string animationStyleName(AnimationStyle style) { return style == AnimationStyle::Limited ? "limited" : "full"; }

void checkAnimationSettings(const AnimationSettings& s) {
    if (!(s.fps >= 1.0 && s.fps <= 240.0))
        throw BoothError(ErrorKind::BadConfig, "animation.fps", std::to_string(s.fps) + " is outside 1 .. 240");
    if (s.inbetweenOmissions < 0 || s.inbetweenOmissions > 100)
        throw BoothError(ErrorKind::BadConfig, "animation.inbetween_omissions",
                         std::to_string(s.inbetweenOmissions) + " is outside 0 .. 100");
    if (!(s.holdFraction >= 0.0 && s.holdFraction <= 1.0))
        throw BoothError(ErrorKind::BadConfig, "animation.hold_fraction",
                         std::to_string(s.holdFraction) + " is outside 0 .. 1");
}

std::vector<AnimationFrame> playAnimation(const MotionClip& clip, const AnimationSettings& settings,
                                          const AvatarRig& rig) {
    checkAnimationSettings(settings);
    const std::vector<Pose> poses = sampleMotion(clip, settings.fps);
    std::vector<int> timing = fullTiming(poses.size());
    if (settings.style == AnimationStyle::Limited) {
        std::vector<JointPositions> points;
        points.reserve(poses.size());
        for (const Pose& p : poses) points.push_back(rigPoints(p, rig));
        LimitedAnimationSettings limits;
        limits.inbetweenOmissions = settings.inbetweenOmissions;
        limits.holdFrames = static_cast<int>(std::lround(settings.holdFraction * static_cast<double>(poses.size())));
        timing = limitAnimation(points, limits);
    }
    std::vector<AnimationFrame> frames;
    frames.reserve(timing.size());
    for (const int source : timing) {
        AnimationFrame f;
        f.sourceFrame = source;
        f.pose = poses[static_cast<std::size_t>(source)];
        f.neck = jointRotation(f.pose.neck);
        f.head = jointRotation(f.pose.head);
        f.leftEye = f.rightEye = jointRotation(f.pose.eyes);
        f.headWorld = f.neck * f.head;
        f.headModel = headModelMatrix(f.pose, rig);
        frames.push_back(f);
    }
    return frames;
}

}  // namespace avatarbooth
