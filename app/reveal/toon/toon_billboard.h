// Kitamura's two-view toon character, second half: contour correspondence, billboard rendering, turntable strip.
#pragma once

#include "reveal/toon/toon_regions.h"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth::toon {

// Corresponding outline points of one matched pair, as offsets (pixels) from each region's centroid: point i of
// `a` corresponds to point i of `b`; the billboard's outline is interpolated segment by segment between them.
struct ContourCorrespondence {
    std::vector<cv::Point2d> a, b;
};
// Automatic correspondence: both outlines resampled to `points` points by arc length, b's offsets rotated so the
// regions' principal axes align, then the cyclic start of b chosen that puts each point nearest its partner.
ContourCorrespondence correspondContours(const Region& a, const Region& b, int points = 64);

// Everything needed to draw the toon head at any yaw between the two views.
struct ToonModel {
    DrawingView viewA, viewB;  // viewA at theta 0 (front), viewB at theta 90 (side): the renderer interpolates
    Regions regionsA, regionsB;
    std::vector<PlacedPair> pairs;
    std::vector<ContourCorrespondence> contours;  // one per pair
    // The first `backdropPairs` pairs are drawn first whatever their depth (toonFromPhotos: the whole head's
    // silhouette, so regions left unmatched leave no holes).
    std::size_t backdropPairs = 0;
    // The face parts the drawings were guided by (toonFromPhotos with landmarks), in each drawing's pixels.
    DrawingGuide guideA, guideB;
};
// Splits both drawings (regions under `minRegionArea` pixels join their neighbours), matches A's regions to B's, places every matched pair and corresponds its outlines.
ToonModel buildToonModel(const cv::Mat& drawingA, const cv::Mat& maskA, const DrawingView& viewA,
                         const cv::Mat& drawingB, const cv::Mat& maskB, const DrawingView& viewB,
                         const cv::Mat& outlineA = cv::Mat(), const cv::Mat& outlineB = cv::Mat(),
                         int minRegionArea = 30);

// Renders the billboards orthographically at `yawDeg` in [-90, 90] (0 = front, 90 = view B's side, negative =
// the other side, drawn mirrored), far regions first, each filled with its colour and outlined dark.
// `unitsPerPixel` is the render's scale in character units; the origin lands on the image centre.
// `coverage` (optional) receives a CV_8U mask of what was drawn (255 inside, anti-aliased edges), so the head can be
// laid over any background.
cv::Mat renderToon(const ToonModel& model, double yawDeg, cv::Size size, double unitsPerPixel,
                   int outlineWidth = 2, cv::Mat* coverage = nullptr);

// The radius (character units) of a sphere round the origin that holds every billboard at every yaw: positions and
// outline reaches at both views (the renderer interpolates between them linearly).
double toonRadius(const ToonModel& model);
// One frame for the kiosk: the toon head at `yawDeg` as BGRA (straight alpha = coverage, transparent around the head,
// as Screens::avatar takes it), scaled so a sphere of `radius` (toonRadius(model) when <= 0; pass it in per frame
// to skip that pass) fills the smaller side of `size`, so the head keeps its size and stays in frame while it turns.
cv::Mat renderToonBgra(const ToonModel& model, double yawDeg, cv::Size size, double radius = 0.0, int outlineWidth = 2);

// Builds a toon model from a front photo and a side photo with their head masks. The side photo may face either
// way: `sideNoseImageRight` (SideAnalysis::noseImageRight) says which, and such a photo is mirrored so it looks at
// the character's left side (theta 90). Both are cropped to their masks and scaled to `headHeightPx` pixels of
// mask height, so heights agree; the origin is the front mask's box centre and the side mask's box centre.
// Throws BoothError(NoFace) when a mask is empty.
// `landmarks` (optional) guide the drawings: the face parts become regions of their own in both views
// (frontDrawingGuide, sideDrawingGuide; the side's parts take the front's colours, so they match) and the skin's
// colour is taken from the cheeks.
struct ToonLandmarks {
    std::optional<std::array<cv::Point2d, 68>> front;  // dlib's 68 points, front photo pixels
    std::map<std::string, cv::Point2d> side;           // profile points (kProfileLandmarkNames), side photo pixels
};
ToonModel toonFromPhotos(const cv::Mat& frontBgr, const cv::Mat& frontMask, const cv::Mat& sideBgr,
                         const cv::Mat& sideMask, bool sideNoseImageRight, int colours = 6,
                         int headHeightPx = 320, const ToonLandmarks& landmarks = {});

// The whole recipe from two photos (what `avatarbooth toon` and the kiosk use): the person's silhouette in each photo
// (segmentPerson; the side one from analyseSidePhoto, which also says which way it faces), both cut at the side
// photo's chin row (same camera, same height) so the masks hold the head, then toonFromPhotos. `plate` (the empty
// booth, optional) improves the silhouettes. Throws BoothError(NoFace) when the side profile or a mask is missing.
// `frontLandmarks` (dlib's 68 points of the front photo, optional) guide the drawing with the side's profile points.
ToonModel toonFromPhotoPair(const cv::Mat& frontBgr, const cv::Mat& sideBgr, const cv::Mat& plate = cv::Mat(),
                            int colours = 6,
                            const std::optional<std::array<cv::Point2d, 68>>& frontLandmarks = std::nullopt);


// The turntable strip in memory: `frames` (file name, PNG bytes) sweeping the yaw from -90 to 90 degrees.
std::vector<std::pair<std::string, std::string>> turntableFrames(const ToonModel& model, int frames, cv::Size size,
                                                                 double unitsPerPixel);
// Writes `frames` PNGs (turntable_000.png …) sweeping the yaw from -90 to 90 degrees into `directory`
// (created if missing), each file atomically; returns the paths.
std::vector<std::filesystem::path> writeTurntable(const ToonModel& model, const std::filesystem::path& directory,
                                                  int frames, cv::Size size, double unitsPerPixel);

}  // namespace avatarbooth::toon
