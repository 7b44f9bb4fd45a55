// Fitting the base head to a front and a side photo's measurements (METHODS §1 steps 2-5): per-axis scaling from
// the measured extents, contour points by rays, and the RBF warp of (x, y) from the front and (z, y) from the side.
#pragma once

#include "fit/head/base_head.h"
#include "fit/head/modifier_fit.h"
#include "fit/head/rbf.h"

#include <opencv2/core.hpp>

#include <map>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

// What the photos say, in pixels (pixel centres at integer coordinates, as OpenCV and dlib).
struct PhotoMeasurements {
    std::map<std::string, cv::Point2d> frontPoints;  // ibug_00 .. ibug_67
    cv::Mat frontMask;                                // CV_8U silhouette of the person in the front photo
    std::map<std::string, cv::Point2d> sidePoints;   // profile landmarks (nose_tip, ...), in the side photo as taken
    cv::Mat sideMask;                                 // CV_8U silhouette in the side photo as taken
    bool sideNoseImageRight = true;                   // false: the side photo is mirrored before use
    // Hair pixels of each photo as taken (CV_8U, 255 on hair; empty: not known), for hairOutlineSlackMm.
    cv::Mat frontHair, sideHair;
    // The middle of the ear in the side photo as taken (fit/face/ear_locator.h), when it was found.
    std::optional<cv::Point2d> sideEar;
    // The middle of the near eye in the side photo as taken (fit/face/side_eye.h), when it was found.
    std::optional<cv::Point2d> sideEye;
};

struct HeadFitOptions {
    RbfOptions rbf;
    // Which front landmarks pull the head (default: see defaultHeadFitOptions()).
    std::vector<int> frontLandmarks;
    // Of those, the points between a brow's ends and between a lip's corners and its middle: where along the line
    // the detector puts them is its convention (dlib's middle brow points lie up to 4.6 mm nearer the nose than the
    // base head's feature vertices on the synthetic people, the lips' up to 2.6 mm off along the lip); their height
    // is what the photo measures. They are fitted in height with full weight, sideways with outlineTangentWeight,
    // and the warp moves them in height only (with a modifier basis; without one they pull both ways, as in the
    // paper). Ground-truth landmarks, which are exact, take none.
    std::vector<int> frontLandmarksByHeight;
    // Accepted ratio between the two photos' scales before they are called a mismatch.
    double maxScaleRatio = 1.35;
    // The first step, with a base head that has a modifier basis: the weights' fit, and how many times it is done
    // again with the shape it found (0: the modifiers are not fitted).
    ModifierFitOptions modifiers;
    int modifierRounds = 2;
    // Weight of an outline point against a landmark's in the modifier fit.
    double contourWeight = 0.3;
    // A profile landmark on a smooth stretch of outline (chin, brow, lips, ...) is measured along the outline's
    // normal with full weight and along the outline with this weight in the modifier fit: the detector's idea of
    // where along the curve the point lies is a convention, but not worthless (the ground truth's too). The same
    // weight holds the front's points measured by their height (frontLandmarksByHeight) sideways.
    double outlineTangentWeight = 0.3;
    // Ridge of the warp for the landmarks (added to rbf.regularisation on their diagonal; the outline rays keep the
    // exact interpolation) when the base head has a modifier basis: a detected landmark is a few pixels off, and the
    // warp that passes through each one exactly carries that noise into the face the modifiers had already shaped.
    double landmarkRidge = 3.0;
    // The face's own profile in the side photo: the midline vertices on the base head's side outline between the
    // glabella and the throat, each pushed onto the photo's outline along its normal (searched this far either way).
    // The profile landmarks alone leave the nose's bridge and underside, the lips and the under-chin unmeasured.
    bool faceProfile = true;
    double faceProfileWeight = 0.3;
    double faceProfileSearchMm = 12.0;
    // Big hair (a bob, long hair, a bun): an outline ray or a profile point that ends on hair (the photos' hair
    // masks) more than this far outside the shaped head measures the hair, not the skull, and is left out, so that
    // the skull stays where the modifiers put it under a separate hair part. 0: every crossing counts (the hair
    // analysis sets it when the hair is big).
    double hairOutlineSlackMm = 0.0;
    // With a modifier basis and the side photo's ear found: the fitted head's ears are moved last (MakeHuman's ear
    // translations, both ears alike) so that the ear's middle lies where the side photo shows it, within the
    // sliders' ranges. The base head's ear sits where proportions put it, and the side photo's ear was painted on
    // the scalp or the neck beside it.
    bool placeEars = true;
};

HeadFitOptions defaultHeadFitOptions();

// One feature point: where the fitted head put it against where the photo measured it (millimetres).
struct FeatureResidual {
    std::string name;
    std::string view;  // "front" or "side"
    glm::dvec2 measured{0.0};
    glm::dvec2 fitted{0.0};
    double errorMm = 0.0;
};

// How a photo pixel maps to head space: front (x, y) = ((u - centre.x) * mmPerPixel + offset.x,
// -(v - centre.y) * mmPerPixel + offset.y); side likewise for (z, y), after mirroring when needed.
struct PhotoFrame {
    cv::Point2d centrePx;
    double mmPerPixel = 1.0;
    glm::dvec2 offsetMm{0.0};
    bool mirrored = false;   // side photo: u is mirrored (u' = width - 1 - u) first
    int imageWidth = 0;

    glm::dvec2 toHead(const cv::Point2d& px) const;
    cv::Point2d toPixel(const glm::dvec2& head) const;
};

// Whether the pixel nearest `p` lies on `mask` (CV_8U, nonzero on it; outside the image: no).
bool inMask(const cv::Mat& mask, const cv::Point2d& p);

struct HeadFit {
    Mesh mesh;                   // the fitted head (base head topology)
    Mesh scaledBase;             // the base head after steps 1-2 (modifiers, scaling), before the warp
    glm::dvec3 axisScale{1.0};   // sx, sy, sz of step 2, as applied
    // The photos' head width, height and depth over the base head's (height and depth include the hair).
    glm::dvec3 measuredExtents{1.0};
    PhotoFrame front, side;
    std::vector<FeatureResidual> residuals;
    // Contour rays for the overlays: from the view's centre to the measured outline point (pixels).
    std::vector<std::pair<cv::Point2d, cv::Point2d>> frontRays, sideRays;
    std::vector<std::string> warnings;
    // The first step's result: the modifiers it used (name, weight in (0, 1]) and the targets' RMS error before and
    // after it (millimetres).
    std::vector<std::pair<std::string, double>> modifierWeights;
    std::pair<double, double> modifierRmsMm{0.0, 0.0};
    std::size_t foldsRemoved = 0;  // triangles the warp had turned over, before they were smoothed out
    // How far the ears were moved to the side photo's ear (millimetres, forward and up; 0 when they were not), and
    // how far that ear lay from the shaped head's before (the same, unclamped).
    glm::dvec2 earShiftMm{0.0}, earOffsetMm{0.0};
    bool earsPlaced = false;
    // When they were placed: the right ear's middle on the fitted head (its vertices' mean), and what the sliders'
    // ranges left between it and the side photo's ear (side view: forward, up), which the texture takes up
    // (PhotoTextureOptions::earReachMm).
    glm::dvec3 earMiddleMm{0.0};
    glm::dvec2 earLeftMm{0.0};
    // When the side photo's eye was found (and lies within kSideEyeHeightToleranceMm of the head's eye's height):
    // the right eye's middle on the fitted head (the mean of its six landmark vertices), and how far the side photo's
    // eye lies from it (side view: forward, up). A visitor turned short of the profile shows the eye further behind
    // the nose than a profile would, turned past it nearer; the texture reads the side photo shifted by that much
    // (textureFromPhotos).
    bool sideEyeFound = false;
    glm::dvec3 eyeMiddleMm{0.0};
    glm::dvec2 eyeLeftMm{0.0};
};

// On FRMDB's profiles the side photo's eye lies 0-16 mm under the head's (its darkest part, the lashes and the iris
// under the lid, against the six landmarks' middle); further off it was a shadow or hair on synthetic visitors
// turned 100-110 degrees (18-29 mm).
inline constexpr double kSideEyeHeightToleranceMm = 17.0;

// Throws BoothError(Mismatch) when the photos disagree (scale ratio, shared heights), NoFace when a needed
// landmark or outline is missing.
HeadFit fitHead(const BaseHead& base, const PhotoMeasurements& photos, const HeadFitOptions& options);

}  // namespace avatarbooth
