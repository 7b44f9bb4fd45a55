// Narita's 21 character-maker feature points (METHODS §2) found on a front photo: from dlib's 68 landmarks, the
// person's silhouette and, when there is a side photo, its ear hole.
//
// Names follow the thesis. "Right" and "left" are the subject's: the subject's right is on the image's left, and
// index 0 of every pair is on the image's left (as iBUG's point 0 is). The mapping, point by point:
//   Pf0, Pf1  temples: where the eye line (through the two eye centres, the means of iBUG 36-41 and 42-47) leaves
//             the silhouette, going outwards from each eye centre: "the head contour at eye height". Hair or an
//             ear that stands out at eye height is part of that contour (see the note on ears below).
//   Pf2       chin tip: iBUG 8.
//   Pe0..Pe4  the subject's right eye: Pe0 outer corner (iBUG 36), Pe1 inner corner (39), Pe2 middle of the upper
//             lid (midpoint of 37 and 38), Pe3 and Pe4 the ends of the lower lid, outer and inner (41, 40).
//   Pe5..Pe9  the left eye likewise: 45, 42, midpoint of 43 and 44, 46, 47.
//   Pb0, Pb1  inner ends of the brows, near the glabella: iBUG 21, 22.
//   Pn        nose tip: iBUG 30.
//   Pm        mouth centre: the midpoint of the inner lips' middles, iBUG 62 and 66.
//   Pa0..Pa3  ear tops and bottoms (Pa0 right top, Pa1 right bottom, Pa2 left top, Pa3 left bottom). No landmark
//             model here finds ears, so they are found on the silhouette: along the face's vertical axis, a band
//             around the ear hole is scanned for the half-width of the silhouette (midline to edge, along the eye
//             line) on each side; an ear shows as a bump between two notches, the notches being the deepest
//             points below the band's upper convex hull above and below the ear hole, and the bump must reach
//             beyond the face's own contour (the jaw landmarks 0-8 / 16-8) at its height. The notches are the
//             ear's top and bottom. Where hair hides the ears (no notch deep enough, or an implausible ear), the ear
//             spans the classical canon instead: top at ear-hole height + 0.45 L, bottom at - 0.55 L, with
//             L = the height from the brow line (mean of iBUG 17-26) to the nose base (iBUG 33), on the
//             silhouette's edge at those heights. The ear hole's height comes from the side photo (carried into
//             the front photo through the fit's shared heights, and kept within the brow-to-nose-base band);
//             without one it is brow line - 0.45 L, which puts
//             the canon's ear exactly from the brow line to the nose base (METHODS §5).
//   Guard: the head's outline is never inside the face. Where the silhouette's edge (for a temple or an ear
//   point) is missing or lies inside the face's own contour (the jaw landmarks 0-8 / 16-8, extended straight up
//   from iBUG 0 / 16 above it), the silhouette cut into the face; the point is put on that contour instead, with
//   a warning. So a bad silhouette never fails the session, it only makes those points estimates.
//   Extra (not among the 21, for the tilts the thesis found missing): the brows' outer ends, iBUG 17 and 26.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct NaritaPoints {
    std::array<cv::Point2d, 3> f{};    // Pf0 right temple, Pf1 left temple, Pf2 chin tip
    std::array<cv::Point2d, 10> e{};   // Pe0..Pe9
    std::array<cv::Point2d, 4> a{};    // Pa0 right ear top, Pa1 right ear bottom, Pa2 left top, Pa3 left bottom
    std::array<cv::Point2d, 2> b{};    // Pb0 right brow inner end, Pb1 left
    cv::Point2d n, m;                  // Pn nose tip, Pm mouth centre
    std::array<cv::Point2d, 2> browOuter{};  // extra: outer ends of the right and left brows

    // ("Pf0", point), ... in the thesis' order, then "brow_outer_right", "brow_outer_left".
    std::vector<std::pair<std::string, cv::Point2d>> named() const;
};

// Tuning of the silhouette part of the mapping; lengths are fractions of the distance between the eye centres.
struct NaritaMappingSettings {
    double maxReach = 3.0;      // how far from the eye centre / midline an edge is looked for
    double gapBridge = 0.06;    // background runs shorter than this (a gap between lobe and jaw) are bridged
    double minNotchDepth = 0.035;  // an ear's notches must be at least this deep below the hull (about 2 mm)
    double minEarProtrusion = 0.08;  // and the ear must reach this far beyond the jaw contour (about 5 mm)
    double contourTolerance = 0.03;  // a silhouette edge this far inside the jaw contour still counts as on it
};

struct NaritaMappingInput {
    std::array<cv::Point2d, 68> landmarks{};  // front photo, iBUG order, pixels
    cv::Mat mask;                             // CV_8U silhouette of the person, the photo's size (non-zero inside)
    std::optional<cv::Point2d> earHole;       // the side photo's ear hole carried into the front photo, if known
};

struct NaritaMapping {
    NaritaPoints points;
    // Per ear (right, left): "silhouette" (notches found) or "canon" (estimated from the ear hole and L).
    std::array<std::string, 2> earSource;
    // Per temple (right, left) and per ear point (Pa0..Pa3): "silhouette" (on its edge), or "face contour" where
    // the silhouette fell short (see the guard above).
    std::array<std::string, 2> templeSource;
    std::array<std::string, 4> earPointSource;
    std::string earHoleSource;  // "side photo" or "canon"
    std::vector<std::string> warnings;
};

// Throws BoothError(NoFace) when the eyes coincide or the brows are not above the nose base; BoothError(BadInput)
// when there is no 8-bit mask.
NaritaMapping mapNaritaPoints(const NaritaMappingInput& input, const NaritaMappingSettings& settings = {});

// Draws the 21 points (and the extras) with their names on a BGR canvas.
void drawNaritaPoints(cv::Mat& canvas, const NaritaMapping& mapping);

}  // namespace avatarbooth
