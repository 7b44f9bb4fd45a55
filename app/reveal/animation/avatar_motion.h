// Keyframed motion of the avatar for the reveal and attract screens (head turn, nod, looking around), sampled at
// 24 fps and played either in full or through the limited-animation filter (limited_animation.h).
//
// The rig has three joints, each a rotation: the neck (turns everything above it about the base of the neck),
// the head (about the top of the neck) and the eyes (both the same way, about each eyeball's centre, relative to
// the head). Head space as everywhere: millimetres, y up, the face looks along +z, x to the subject's left.
// Angles: yaw about +y (positive turns the face towards the subject's left, +x), pitch about +x (positive tips
// the face down, a nod), roll about +z (positive tilts the top of the head towards -x); applied yaw, then pitch,
// then roll in the joint's own frame (q = yaw * pitch * roll).
#pragma once

#include "reveal/animation/limited_animation.h"

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <string>
#include <vector>

namespace avatarbooth {

struct JointAngles {
    double yawDeg = 0.0;
    double pitchDeg = 0.0;
    double rollDeg = 0.0;
};

struct Pose {
    JointAngles neck, head, eyes;
};

struct Keyframe {
    double timeSeconds = 0.0;
    Pose pose;
};

// Keys in time order; between two keys every angle eases in and out (smoothstep, zero speed at each key, so a
// key is also where the motion rests).
struct MotionClip {
    std::string name;
    std::vector<Keyframe> keys;
    double durationSeconds() const { return keys.empty() ? 0.0 : keys.back().timeSeconds; }
};

// The reveal: the eyes lead, the head turns to one side, through the front to the other side and back (showing
// the avatar from both sides), then a nod. About 5 s: 123 frames at 24 fps.
MotionClip revealMotion();
// Attract loop: looking around the room (eyes first, then the head), a glance up, back to rest. 4 s.
MotionClip attractMotion();

// The pose at time t (clamped to the clip); throws std::invalid_argument for a clip without keys or keys out of
// time order.
Pose samplePose(const MotionClip& clip, double tSeconds);
// Frames at t = k / fps, k = 0 .. round(duration * fps) (both ends included).
std::vector<Pose> sampleMotion(const MotionClip& clip, double fps);

// Pivots and the points whose motion the limited-animation filter measures (millimetres, rest pose).
struct AvatarRig {
    glm::dvec3 neckPivot{0.0, -110.0, -15.0};  // base of the neck
    glm::dvec3 headPivot{0.0, -35.0, -10.0};   // top of the neck, below the ear holes
    glm::dvec3 rightEye{-32.0, 6.0, 70.0};     // eyeball centres (the built-in base head's)
    glm::dvec3 leftEye{32.0, 6.0, 70.0};
    glm::dvec3 noseTip{0.0, -33.0, 98.0};
    glm::dvec3 topOfHead{0.0, 122.0, -5.0};
    double gazeLengthMm = 40.0;  // the eyes are measured by a point this far along each line of sight
};

glm::dquat jointRotation(const JointAngles& angles);
// Head space -> turned head space for the pose (neck and head rotations about their pivots): the matrix the
// kiosk's renderer applies to the avatar mesh.
glm::dmat4 headModelMatrix(const Pose& pose, const AvatarRig& rig = {});
// The measured points of a pose, in this order: top of the neck (moved by the neck), nose tip and top of the head
// (moved by neck and head), the right and left gaze points (moved by all three).
JointPositions rigPoints(const Pose& pose, const AvatarRig& rig = {});

enum class AnimationStyle { Limited, Full };

// "limited" or "full"; throws BoothError(BadConfig) naming animation.style otherwise.
AnimationStyle parseAnimationStyle(const std::string& name);
std::string animationStyleName(AnimationStyle style);

// The avatar animation's settings (the config's [animation] table).
struct AnimationSettings {
    AnimationStyle style = AnimationStyle::Limited;  // "limited" (Kitamura's filter) or "full" (every frame)
    double fps = 24.0;                               // sampling rate of the keyframed motion, frames per second
    int inbetweenOmissions = 4;                      // N_io: in-betweens omitted where the motion is fastest (4-6)
    double holdFraction = 1.0 / 3.0;                 // N_hf = round(holdFraction * frames): frames held (about 1/3)
};

// Throws BoothError(BadConfig) naming the key (animation.fps, ...) for a value out of range.
void checkAnimationSettings(const AnimationSettings& settings);

// One displayed frame.
struct AnimationFrame {
    int sourceFrame = 0;     // which sampled frame of the motion it shows (equal for held frames)
    Pose pose;
    glm::dquat neck{1.0, 0.0, 0.0, 0.0}, head{1.0, 0.0, 0.0, 0.0}, leftEye{1.0, 0.0, 0.0, 0.0},
        rightEye{1.0, 0.0, 0.0, 0.0};
    glm::dquat headWorld{1.0, 0.0, 0.0, 0.0};  // neck * head: how the whole head is turned
    glm::dmat4 headModel{1.0};                 // headModelMatrix(pose)
};

// The clip sampled at settings.fps and, for the limited style, timed by limitAnimation (N_io, then N_hf holds).
// Same number of frames in both styles.
std::vector<AnimationFrame> playAnimation(const MotionClip& clip, const AnimationSettings& settings,
                                          const AvatarRig& rig = {});

}  // namespace avatarbooth
