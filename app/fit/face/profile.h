// Side-photo analysis: the head's profile outline, which way it faces, and the profile landmarks (METHODS.md §1, §4).
#pragma once

#include <opencv2/core.hpp>
#include <opencv2/objdetect.hpp>

#include <array>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace avatarbooth {

class LandmarkDetector;

// A named 2-D point of a profile, in the frame of the outline it was found on.
struct ProfilePoint {
    std::string name;
    cv::Point2d px;
};

// The names findProfileLandmarks returns, top to bottom, then the back of the head and the ear hole estimate.
// (Soft-tissue anthropometric points: vertex, a forehead point, glabella, nasion, pronasale, subnasale, labrale
// superius, labrale inferius, pogonion, cervical point, opisthocranion, porion estimate.)
inline constexpr std::string_view kProfileLandmarkNames[] = {
    "top_of_head", "forehead", "glabella", "nasion", "nose_tip", "subnasale", "upper_lip",
    "lower_lip",   "chin",     "throat",   "back_of_head", "ear_hole"};

// The result of fitting the landmark model to an outline, with how sure it is.
struct ProfileFit {
    bool ok = false;
    std::string failure;                  // why not, when !ok
    std::vector<ProfilePoint> landmarks;  // in kProfileLandmarkNames order when ok
    // min(nose depth above, nose depth below) / (nose tip height below the top of head): about 0.1 for a real
    // profile (a 2 cm nose on a 14.5 cm vertex-to-nose-tip height), near 0 for a front view's silhouette.
    double noseProminence = 0.0;
    std::vector<std::string> warnings;    // points that were estimated rather than found
    // The outline ended at the collar (clothes left out of the silhouette) and the throat was sought above it: a
    // weaker profile (the back of big hair can pass as one), which loses to one found without (profileFacesRight).
    bool throatAtCollar = false;
};

// Which way a side photo's outline faces, from its fits both ways (at least one ok): the ok one; of two, the one
// whose throat was found without the collar's help, then the more prominent nose.
bool profileFacesRight(const ProfileFit& right, const ProfileFit& left);

// Finds the profile landmarks on a head's closed silhouette outline (METHODS §4: extrema and concavities of the
// profile). The outline is in an image-like frame: y points down, the face points +x (image right), or -x when
// noseRight is false (the outline is then mirrored, fitted, and the answers mirrored back); any start point,
// either winding, any unit (image pixels, or millimetres of a base head's mid-sagittal line); it may carry the
// neck, shoulders and the image's bottom edge. Pure function. See profile.cpp for each point's definition and
// every constant.
ProfileFit fitProfile(const std::vector<cv::Point2d>& outline, bool noseRight = true);

// The ear hole (porion) placed by proportions from the nasion and chin of a profile facing image-right (pixels, y
// down) and V, the nose tip's height below the top of the head; the base head places its own ear hole by the same
// rule, so that the side photo's centre and the base head's agree.
cv::Point2d estimateEarHole(const cv::Point2d& nasion, const cv::Point2d& chin, double V);

// As fitProfile, returning the landmarks; throws BoothError(NoFace) with the reason when no profile is found.
// Warnings (estimated points) are appended to *warnings when given.
std::vector<ProfilePoint> findProfileLandmarks(const std::vector<cv::Point2d>& outline, bool noseRight = true,
                                               std::vector<std::string>* warnings = nullptr);

// The point called `name`; throws BoothError(Internal) when it is missing.
cv::Point2d profilePoint(const std::vector<ProfilePoint>& points, std::string_view name);

// Where the ear shows behind the cheek of a side photo, in V behind the nose tip (horizontally): where its skin's
// folds begin (the front of the ear: the tragus and the helix's root) and where they are strongest. Unlike the
// outline, it tells a head turned past the profile from one turned short of it: the ear comes towards the face.
// Heads differ in length, and their ears with them: the front's share of the head's length (headLength: glabella
// to the back of the head, in V; the same 20 degrees either side of the profile) is what says the turn.
struct EarPlace {
    bool found = false;
    double front = 0.0;
    double fold = 0.0;
    double headLength = 0.0;
};

// Reads the ear from the skin's folds per column behind the nasion (columns[i]: the mean gradient of cheek-coloured
// skin 0.01*i to 0.01*(i+1) V behind it; at least 30 columns), the nose tip lying noseAhead V in front of the
// nasion. The columns are smoothed over 0.05 V; the cheek's level is the smallest 0.12-0.26 V behind the nasion;
// the ear's front is the first column past 0.2 V more than kEarOverCheek times that, its fold the strongest
// column past 0.15 V. Not found when the strongest is not kEarOverCheek times the cheek's level (a textured
// cheek: stubble, hair over it). Pure function.
EarPlace readEarColumns(const std::vector<double>& columns, double noseAhead, double headLength);
inline constexpr double kEarOverCheek = 4.0;

// How far a side photo is turned from a true profile, from what the photo shows inside the outline: the outline
// alone cannot tell (orthographically, a symmetric head turned 20 degrees short of the profile and one turned 20
// degrees past it have the same outline). The cues: profile.cpp; their calibration and limits: README, issue 22.
struct ProfileTurn {
    bool known = false;
    // Degrees off the profile by the eye: < 0 not turned far enough (more of the face shows), > 0 turned past it
    // (more of the back of the head shows).
    double degrees = 0.0;
    double eyeBehind = 0.0;  // the visible eye's distance behind the face's outline, in V
    EarPlace ear;
    bool pastProfile = false;  // turnedPastProfile(degrees, ear): the visitor should turn a little back
};

// The turn of a side photo whose profile landmarks are known (facing as noseImageRight says).
ProfileTurn estimateProfileTurn(const cv::Mat& bgr, const cv::Mat& mask, const std::vector<ProfilePoint>& landmarks,
                                bool noseImageRight);

// Whether the two cues agree that the head is turned clearly past the profile (about 120 degrees from the front):
// the ear's front lies within kEarShareTurnBack of the head's length behind the nose tip, its strongest folds
// within kEarFoldTurnBack (a second reading of the same ear, against the hair or skin texture taken for it), and
// the eye (eyeDegrees, ProfileTurn::degrees) says past as well. Pure function. Calibration: README, issue 22.
bool turnedPastProfile(double eyeDegrees, const EarPlace& ear);
inline constexpr double kEarShareTurnBack = 0.318;
inline constexpr double kEarFoldTurnBack = 0.60;  // V behind the nose tip
inline constexpr double kEyeTurnBackDegrees = 8.0;
// How far past the profile an ear's share says a head is turned, for the words told to the visitor: the share is
// 0.49-0.56 at a profile on the synthetic visitors and falls 0.08-0.09 per 10 degrees (README, issue 22).
inline constexpr double kEarShareAtProfile = 0.525;
inline constexpr double kEarSharePerDegree = 0.0085;
double degreesPastProfile(const EarPlace& ear);

// Whether the eye and the ear both say the head is turned well short of the profile (about 60 degrees from the
// front): the eye kEyeTurnMoreDegrees or more short, and the ear's front at kEarShareTurnMore of the head's length
// or more behind the nose tip; or, where no ear was found (a dark or textured cheek, hair), the eye
// kEyeTurnMoreNoEarDegrees or more short (a dark-skinned synthetic visitor at 60 degrees reads -22; none of those
// without an ear at 70-110 degrees reads under -15). On its own it is not enough (a visitor at 70 degrees reads -24
// by the eye, 0.69 by the ear): the caller then looks for the face with dlib's detector, whose filters for faces
// looking aside find it at 55-66 degrees and not past the profile (README, issue 22). Pure.
bool turnedShortCues(const ProfileTurn& turn);
inline constexpr double kEyeTurnMoreDegrees = -25.0;
inline constexpr double kEyeTurnMoreNoEarDegrees = -20.0;
inline constexpr double kEarShareTurnMore = 0.67;

struct SideAnalysis {
    cv::Mat mask;                        // CV_8U, 255 on the person (see segmentPerson)
    bool noseImageRight = true;          // the subject faces image-right
    std::vector<cv::Point2d> outline;    // the silhouette's outline, original image coordinates
    std::vector<ProfilePoint> landmarks; // kProfileLandmarkNames, original image coordinates
    std::vector<std::string> warnings;
    ProfileTurn turn;
};

// OpenCV's frontal-face cascade, which refuses a side photo that shows a front view. LBP "improved" is preferred:
// on the sample photos it is as reliable as the Haar cascade (every frmdb front found, none of the profiles;
// tests/data) and several times faster. Thread-safe (one detection at a time).
class FrontalFaceCheck {
public:
    // `dir`: the folder of OpenCV's haarcascades (the LBP cascades are looked for in ../lbpcascades beside it).
    explicit FrontalFaceCheck(const std::filesystem::path& dir = AVATARBOOTH_DEFAULT_CASCADE_DIR);
    // False when no cascade was found there: front views are then recognised by their silhouette only.
    bool available() const { return !source_.empty(); }
    // Frontal faces in a grey image (boxes in its pixels).
    std::vector<cv::Rect> detect(const cv::Mat& grey, int minSize, int maxSize);

private:
    std::mutex mutex_;
    cv::CascadeClassifier cascade_;
    std::string source_;
};

struct SideOptions {
    // Folder of OpenCV's haarcascades, for a check loaded for this call; empty: the build's default
    // (/usr/share/opencv4/haarcascades from opencv-data).
    std::filesystem::path cascadeDir;
    // The check to use (a pipeline loads one and keeps it); null: one is loaded from cascadeDir for this call.
    FrontalFaceCheck* frontalCheck = nullptr;
    // Run the frontal-face detector on the head and refuse a front view.
    bool rejectFrontViews = true;
    // With it, a frontal face found on the head gets dlib's 68 points: turned more than kHalfTurnedYaw it is a
    // visitor half-way round (told to turn more), else a front view. Null: every frontal face is a front view.
    const LandmarkDetector* landmarkDetector = nullptr;
    // Refuse a side photo turned past the profile (ProfileTurn::pastProfile, the cue on which the kiosk's side
    // guide says "turn a little back"): the same photo taken 20 degrees nearer the profile fits better.
    bool refusePastProfile = true;
    // With landmarkDetector: refuse a side photo turned well short of the profile (turnedShortCues, and dlib's
    // detector finds the face looking aside; the side guide's "turn more" on the same cues), fault TurnMore.
    bool refuseShortOfProfile = true;
};

// The face's front edge on row y of a side photo facing image-right (mask: CV_8U, non-zero on the person): the last
// person pixel at or before the nose tip's column (tipX, and 2 pixels for the tip's rounding); -1 where there is none.
int faceFrontEdge(const cv::Mat& mask, double tipX, int y);

// A face's turn from the front by its 68 points: the nose tip's offset from the middle of the eyes' outer corners,
// along the eye line, in eye widths (positive: the nose towards image-right). The front guide's measure.
double noseOffsetYaw(const std::array<cv::Point2d, 68>& points);
// The largest face dlib's detector (LandmarkDetector::detectFaces, whose filters also find faces looking aside) finds
// in `bgr` whose box's centre lies on the person (personMask: CV_8U, non-zero on the person, of the photo's size);
// a face on a poster behind the visitor does not count.
std::optional<cv::Rect> faceOnPerson(const LandmarkDetector& detector, const cv::Mat& bgr, const cv::Mat& personMask);

// Beyond this |noseOffsetYaw| a face is half-turned (the front guide's maxYaw: frmdb's fronts -0.23 to 0.15, its
// 45-degree views 0.28-0.38 where the frontal cascade still finds them).
inline constexpr double kHalfTurnedYaw = 0.26;

// Analyses a side photo: silhouette (with the empty-booth plate when not empty), facing direction (either way
// works: the outline is fitted both ways, a nose pointing left is fitted mirrored and the points mapped back),
// profile landmarks.
// Throws BoothError: BadInput (empty/odd image), NoFace (nothing stands out from the background),
// FitError (Mismatch) when the photo is no profile, its fault saying which way to turn: NotProfile "this looks like
// a front view" (a frontal face looks at the camera), TurnMore (a face turned aside shows: the cascade's with dlib's
// points, or, when neither side of the outline has a nose, dlib's detector's), FaceHidden (no nose on the outline
// and no face: turned well past the profile, or hair over the face; needs options.landmarkDetector, else such a
// photo is NotProfile), TurnBack (a profile turned past, with options.refusePastProfile).
SideAnalysis analyseSidePhoto(const cv::Mat& bgr, const cv::Mat& backgroundPlate = cv::Mat(),
                              const SideOptions& options = {});

// Draws the outline and the named landmarks (and warnings) on a BGR canvas of the photo's size.
void drawSideOverlay(cv::Mat& canvas, const SideAnalysis& analysis);

}  // namespace avatarbooth
