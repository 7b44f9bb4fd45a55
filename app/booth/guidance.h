// The guides' hints: what the visitor should do, from one preview frame. The hint rules are pure functions of small
// observations (a face box, landmarks, "a profile was seen"), so they are tested with exact numbers; the
// observations come from cheap analyses of a downscaled preview (PreviewAnalyser), fast enough for 10 Hz or more
// on two cores (measured in tests/integration/booth_guidance_test.cpp).
#pragma once

#include "booth/flow_types.h"

#include <opencv2/core.hpp>
#include <opencv2/objdetect.hpp>

#include <array>
#include <filesystem>
#include <memory>
#include <optional>

namespace avatarbooth {

class LandmarkDetector;

// The oval the visitor puts their head in, in the camera's frame (not mirrored). The screens draw the same oval
// through the same mapping (screens.h), so what the guide checks is what the visitor sees.
struct FaceOval {
    double centreX = 0.5;   // centre, fraction of the frame's width
    double centreY = 0.5;   // centre, fraction of the frame's height
    double height = 0.70;   // the head's outline (hair to chin), fraction of the frame's height
    double aspect = 0.74;   // width / height (an adult head seen from the front is about 0.75 as wide as tall)
};

// The oval's bounding box in a frame of `frame` pixels.
cv::Rect2d ovalBox(const FaceOval& oval, cv::Size frame);

struct GuidanceSettings {
    FaceOval oval;
    // The face detector's box (about brows to chin) should be this fraction of the oval's height; within
    // [1 - sizeTolerance, 1 + sizeTolerance] times it the size is right.
    double faceToOval = 0.42;
    double sizeTolerance = 0.3;
    // Where the face box's centre sits in a head that fills the oval: this many oval heights below its centre
    // (the box centres on the nose, the head's outline on the eyes).
    double faceBelowCentre = 0.1;
    // The face box's centre may be this far from there, horizontally, in oval heights ...
    double centreToleranceX = 0.12;
    // ... and vertically (people are of different heights; the camera is not).
    double centreToleranceY = 0.2;
    // Head turned: the nose tip off the middle of the eyes' outer corners by more than this many eye widths.
    // Measured on frmdb's 8 frontal photos: -0.23 to 0.15; on its 45-degree views where a face is still found:
    // 0.28 to 0.30 (the predictor, trained on near-frontal faces, understates large turns).
    double maxYaw = 0.26;
    // Head tilted: the line through the eyes' outer corners more than this many degrees off horizontal.
    double maxRollDegrees = 15.0;
};

struct FrontObservation {
    cv::Size frame;                                        // the analysed frame's size
    std::optional<cv::Rect2d> face;                        // the largest face, in frame pixels
    std::optional<std::array<cv::Point2d, 68>> landmarks;  // iBUG 68 points of that face, when computed
};

// The front guide's hint. Order of checks: no face, size (closer/back), centre, turned or tilted; else hold still.
Hint frontHint(const FrontObservation& observation, const GuidanceSettings& settings);

struct SideObservation {
    bool personSeen = false;     // something stands out from the background
    bool frontalFace = false;    // a frontal face was found on the head
    bool profileSeen = false;    // the head's outline has a nose and a profile's proportions (face/profile.h)
    bool noseImageRight = false; // with profileSeen: which way the nose points in the (unmirrored) frame
    double noseProminence = 0.0; // of the outline's best nose (ProfileFit::noseProminence), 0 when none
    double frontalYaw = 0.0;     // with frontalFace and a landmark detector: noseOffsetYaw of that face
    double turnDegrees = 0.0;    // with profileSeen: ProfileTurn::degrees (0 when unknown)
    bool turnedBack = false;     // with profileSeen: ProfileTurn::pastProfile
    // With profileSeen and a landmark detector: the eye and the ear say turned well short (turnedShortCues) and
    // dlib's detector finds the face on the person: "turn more" (about 60 degrees from the front).
    bool turnedShort = false;
    // Without a profile and without the cascade's frontal face, with a landmark detector: whether dlib's detector
    // (whose filters also find faces looking aside) found a face on the person. None: turned well past the
    // profile, or hair hides the face.
    bool faceLooked = false;
    bool faceShows = false;
};

// The side guide's hint: "turn to your right" while nobody or a frontal face looking at the camera is seen, "turn
// more" while half-turned (a frontal face turned more than kHalfTurnedYaw, or an outline without a profile whose
// face still shows), "we can't see your face" when the outline has no profile and no face shows (turned well past
// it, or hair over the face), "turn a little back" when the profile is seen turned clearly past it
// (ProfileTurn::pastProfile: the ear and the eye agree), "turn more" when it is seen turned well short of it (the
// eye, the ear and the face agree), else "hold still" (either way: the fit takes both).
Hint sideHint(const SideObservation& observation);

// Runs the observations on preview frames. Holds the detectors; not thread-safe (one analyser per thread).
class PreviewAnalyser {
public:
    struct Options {
        // Side frames are analysed on a copy this many pixels tall (the outline test needs about 100 px of head).
        int sideHeight = 240;
        // Folder of OpenCV's cascades (lbpcascades is looked for beside it); empty: the build's default.
        std::filesystem::path cascadeDir;
    };

    // Faces are found by OpenCV's LBP frontal-face cascade (the fit's dlib HOG detector costs 4x more on a preview).
    // detector: the 68-point predictor, run in that face box for the "turned or tilted" check (loaded once by the
    // kiosk, 1-2 s; may be null: no landmarks, no such check). Throws BoothError(BadConfig) naming the folder when
    // no frontal-face cascade is found there.
    PreviewAnalyser(const LandmarkDetector* detector, Options options);
    ~PreviewAnalyser();

    FrontObservation observeFront(const cv::Mat& bgr);
    // backgroundPlate: the empty booth at the frame's size, or empty.
    SideObservation observeSide(const cv::Mat& bgr, const cv::Mat& backgroundPlate = cv::Mat());

    // The event for the flow: the hint for `photo` and whether someone is there.
    PreviewAnalysed analyse(Photo photo, const cv::Mat& bgr, const GuidanceSettings& settings, FlowTime t);

private:
    std::vector<cv::Rect> frontalFaces(const cv::Mat& grey, int minSize, int maxSize);

    const LandmarkDetector* detector_;
    Options options_;
    cv::CascadeClassifier cascade_;
};

}  // namespace avatarbooth
