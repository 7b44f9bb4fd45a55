// The guides' hint rules with exact inputs: the oval's box, each front hint at and around its threshold, the
// order of the checks, and the side hint table.
#include "booth/guidance.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace avatarbooth;

namespace {

// 640x480 frame, default settings: the oval is 336 px tall (0.7 x 480), 248.64 wide, centred at (320, 240); the
// right face box is 0.42 x 336 = 141.12 px tall, centred 0.1 x 336 = 33.6 px below the oval's centre (y 273.6).
const cv::Size kFrame(640, 480);
constexpr double kOvalH = 336.0;
constexpr double kFaceH = 0.42 * kOvalH;
const cv::Point2d kFaceCentre(320.0, 240.0 + 0.1 * kOvalH);

FrontObservation face(double height, cv::Point2d centre = kFaceCentre) {
    FrontObservation o;
    o.frame = kFrame;
    o.face = cv::Rect2d(centre.x - height / 2, centre.y - height / 2, height, height);
    return o;
}

// Landmarks with the eyes' outer corners 80 px apart, rolled by `rollDeg`, the nose tip `yaw` eye widths off.
FrontObservation withLandmarks(double yaw, double rollDeg) {
    FrontObservation o = face(kFaceH);
    std::array<cv::Point2d, 68> p{};
    const double r = rollDeg * CV_PI / 180.0;
    const cv::Point2d axis(std::cos(r), std::sin(r)), down(-std::sin(r), std::cos(r));
    const cv::Point2d mid(320.0, 250.0);
    p[36] = mid - 40.0 * axis;
    p[45] = mid + 40.0 * axis;
    p[30] = mid + yaw * 80.0 * axis + 30.0 * down;
    o.landmarks = p;
    return o;
}

}  // namespace

TEST(Guidance, OvalBox) {
    const cv::Rect2d box = ovalBox(FaceOval{}, kFrame);
    EXPECT_DOUBLE_EQ(box.height, 336.0);
    EXPECT_DOUBLE_EQ(box.width, 0.74 * 336.0);
    EXPECT_DOUBLE_EQ(box.x, 320.0 - 0.5 * 0.74 * 336.0);
    EXPECT_DOUBLE_EQ(box.y, 72.0);
    FaceOval o;
    o.centreX = 0.25;
    o.centreY = 0.75;
    o.height = 0.5;
    o.aspect = 1.0;
    EXPECT_EQ(ovalBox(o, {1000, 800}), cv::Rect2d(250.0 - 200.0, 600.0 - 200.0, 400.0, 400.0));
}

TEST(Guidance, FrontNoFace) {
    FrontObservation o;
    o.frame = kFrame;
    EXPECT_EQ(frontHint(o, {}), Hint::NoFace);
    o.face = cv::Rect2d(10, 10, 0, 0);
    EXPECT_EQ(frontHint(o, {}), Hint::NoFace);
}

TEST(Guidance, FrontCentredRightSizeHoldsStill) { EXPECT_EQ(frontHint(face(kFaceH), {}), Hint::HoldStill); }

TEST(Guidance, FrontSizeThresholds) {
    EXPECT_EQ(frontHint(face(kFaceH * 0.69), {}), Hint::StepCloser);
    EXPECT_EQ(frontHint(face(kFaceH * 0.71), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(face(kFaceH * 1.29), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(face(kFaceH * 1.31), {}), Hint::StepBack);
}

TEST(Guidance, FrontCentreThresholds) {
    // Horizontal: 0.12 oval heights = 40.32 px; vertical: 0.2 oval heights = 67.2 px.
    for (double dx : {-40.0, 40.0}) EXPECT_EQ(frontHint(face(kFaceH, kFaceCentre + cv::Point2d(dx, 0)), {}), Hint::HoldStill);
    for (double dx : {-41.0, 41.0})
        EXPECT_EQ(frontHint(face(kFaceH, kFaceCentre + cv::Point2d(dx, 0)), {}), Hint::MoveToCentre);
    for (double dy : {-67.0, 67.0}) EXPECT_EQ(frontHint(face(kFaceH, kFaceCentre + cv::Point2d(0, dy)), {}), Hint::HoldStill);
    for (double dy : {-68.0, 68.0})
        EXPECT_EQ(frontHint(face(kFaceH, kFaceCentre + cv::Point2d(0, dy)), {}), Hint::MoveToCentre);
}

TEST(Guidance, FrontSizeIsCheckedBeforeTheCentre) {
    EXPECT_EQ(frontHint(face(kFaceH * 0.5, kFaceCentre + cv::Point2d(200, 0)), {}), Hint::StepCloser);
    EXPECT_EQ(frontHint(face(kFaceH * 1.5, kFaceCentre + cv::Point2d(200, 0)), {}), Hint::StepBack);
}

TEST(Guidance, FrontTurnedOrTilted) {
    EXPECT_EQ(frontHint(withLandmarks(0.0, 0.0), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(withLandmarks(0.25, 0.0), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(withLandmarks(-0.25, 0.0), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(withLandmarks(0.27, 0.0), {}), Hint::LookAtCamera);
    EXPECT_EQ(frontHint(withLandmarks(-0.27, 0.0), {}), Hint::LookAtCamera);
    EXPECT_EQ(frontHint(withLandmarks(0.0, 14.0), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(withLandmarks(0.0, -14.0), {}), Hint::HoldStill);
    EXPECT_EQ(frontHint(withLandmarks(0.0, 16.0), {}), Hint::LookAtCamera);
    EXPECT_EQ(frontHint(withLandmarks(0.0, -16.0), {}), Hint::LookAtCamera);
    // Yaw is measured along the eye line: a tilted head looking straight on is not "turned".
    EXPECT_EQ(frontHint(withLandmarks(0.2, 12.0), {}), Hint::HoldStill);
}

TEST(Guidance, FrontSettingsMoveTheThresholds) {
    GuidanceSettings s;
    s.faceToOval = 0.5;
    EXPECT_EQ(frontHint(face(kFaceH), s), Hint::HoldStill);  // 0.84 of the new target
    s.sizeTolerance = 0.1;
    EXPECT_EQ(frontHint(face(kFaceH), s), Hint::StepCloser);
    GuidanceSettings t;
    t.maxYaw = 0.1;
    EXPECT_EQ(frontHint(withLandmarks(0.15, 0.0), t), Hint::LookAtCamera);
}

TEST(Guidance, SideHintTable) {
    struct Row {
        bool person, frontal, profile;
        Hint hint;
    };
    const Row rows[] = {
        {false, false, false, Hint::TurnRight}, {true, true, false, Hint::TurnRight},
        {true, true, true, Hint::TurnRight},    {true, false, false, Hint::TurnMore},
        {true, false, true, Hint::HoldStill},
    };
    for (const Row& r : rows) {
        SideObservation o;
        o.personSeen = r.person;
        o.frontalFace = r.frontal;
        o.profileSeen = r.profile;
        EXPECT_EQ(sideHint(o), r.hint) << r.person << r.frontal << r.profile;
        o.noseImageRight = true;
        EXPECT_EQ(sideHint(o), r.hint) << "either facing direction";
    }
}

TEST(Guidance, SideHintSaysWhichWayToTurn) {
    SideObservation o;
    o.personSeen = o.frontalFace = true;
    o.frontalYaw = 0.25;  // within kHalfTurnedYaw: looking at the camera
    EXPECT_EQ(sideHint(o), Hint::TurnRight);
    o.frontalYaw = -0.27;  // half-way round, either way
    EXPECT_EQ(sideHint(o), Hint::TurnMore);
    o.frontalYaw = 0.27;
    EXPECT_EQ(sideHint(o), Hint::TurnMore);
    o = {};
    o.personSeen = o.profileSeen = true;
    o.turnDegrees = 30.0;  // the eye alone, however far past: it saturates and misreads past 110 degrees
    EXPECT_EQ(sideHint(o), Hint::HoldStill);
    o.turnDegrees = -40.0;  // short of the profile: the outline's own test says "turn more" when it fails
    EXPECT_EQ(sideHint(o), Hint::HoldStill);
    o.turnedBack = true;  // the ear and the eye agree
    EXPECT_EQ(sideHint(o), Hint::TurnBack);
    o.turnedBack = false;
    o.turnedShort = true;  // the eye, the ear and dlib's face agree: well short of the profile
    EXPECT_EQ(sideHint(o), Hint::TurnMore);
}

TEST(Guidance, SideHintWithoutAProfileFollowsTheFace) {
    SideObservation o;
    o.personSeen = true;  // no frontal face, no nose on the outline
    EXPECT_EQ(sideHint(o), Hint::TurnMore) << "no detector looked: as before";
    o.faceLooked = true;
    o.faceShows = true;  // a face looking aside: turned short of the profile
    EXPECT_EQ(sideHint(o), Hint::TurnMore);
    o.faceShows = false;  // turned well past the profile, or hair over the face
    EXPECT_EQ(sideHint(o), Hint::FaceHidden);
    o.profileSeen = true;  // a profile: the face check does not count
    EXPECT_EQ(sideHint(o), Hint::HoldStill);
}
