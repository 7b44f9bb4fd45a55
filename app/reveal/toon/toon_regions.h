// Kitamura's two-view "toon" character (METHODS §3.2): drawings, closed regions, region matching, 3-D placement.
#pragma once

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth::toon {

// A view direction: theta around the vertical axis, phi around the horizontal one, in degrees. (0, 0) is the front
// view; theta = 90 looks at the character's left side (the camera stands on +x). Character frame: y up, face along
// +z, x to the character's left (DESIGN.md).
struct ViewDirection {
    double thetaDeg = 0.0;
    double phiDeg = 0.0;

    // Unit vector from the character towards the camera (the view direction, reversed).
    glm::dvec3 towardsCamera() const;
    // Image axes in the character frame: right (+u) and up (-v, image rows grow downwards).
    glm::dvec3 imageRight() const;
    glm::dvec3 imageUp() const;
};

// How a drawing's pixels map to the character frame (orthographic): pixel (u, v) (centres at integers) lies on the
// line through  origin3d + right * (u - centre.x) * unitsPerPixel + up * (centre.y - v) * unitsPerPixel  along the
// view direction.
struct DrawingView {
    ViewDirection direction;
    cv::Point2d centre{0.0, 0.0};  // the image point where the character's origin projects
    double unitsPerPixel = 1.0;

    // The 3-D point on the pixel's line closest to the origin.
    glm::dvec3 pointOnLine(cv::Point2d pixel) const;
    // Where a 3-D point lands in the drawing (the inverse of pointOnLine, along the view direction).
    cv::Point2d project(glm::dvec3 point) const;
};

// One closed, flat-coloured region of a drawing.
struct Region {
    int label = 0;               // its value in Regions::labels
    cv::Vec3d colour;            // mean RGB of its interior pixels, each in [0, 1]
    double area = 0.0;           // pixels, outline pixels given to it and holes filled included
    cv::Point2d bboxCentre;      // centre of its bounding box (pixel centres at integers)
    cv::Point2d centroid;        // mean of its pixels
    cv::Rect bbox;
    std::vector<cv::Point> contour;  // outer outline, holes filled (cv::findContours order)
};

struct Regions {
    cv::Mat labels;  // CV_32S, 0 = outside every region, else Region::label (outline pixels given to a region)
    std::vector<Region> regions;
};

// Splits a drawing of flat colours with dark outlines into closed regions (Kitamura 4.2.2): flood fill of the
// non-outline pixels (outline = darker than `outlineMaxGrey`, or marked in `outline` when given), each outline pixel
// given to the nearest region, holes left by regions inside regions filled (for shape and area: the inner region
// keeps its own label on top). Regions smaller than `minArea` pixels are treated as outline. `mask` (optional,
// CV_8U) restricts everything to the character.
Regions splitRegions(const cv::Mat& drawingBgr, const cv::Mat& mask = cv::Mat(), const cv::Mat& outline = cv::Mat(),
                     int outlineMaxGrey = 60, int minArea = 30);

// A face part drawn as its own flat region wherever the photo's colours put it (eyes and mouth vanish into the skin
// otherwise): an outline placed from landmarks, in the drawing's pixels.
struct FeatureShape {
    std::string name;                  // "eye", "iris", "brow", "mouth", "nostril"
    std::vector<cv::Point2d> polygon;  // closed outline
    // Which of the photo's pixels under the polygon give its colour: the darker (brow, iris, nostril), the lighter
    // (an eye's white) or the middle ones (lips).
    enum class Tone { Middle, Dark, Light } tone = Tone::Middle;
    std::optional<cv::Vec3b> colour;  // BGR to use instead of the photo's (the side view takes the front's)
};
// What the landmarks tell the drawing: the face parts, and where the photo shows bare skin (its colour is the skin's;
// empty: the middle of the mask).
struct DrawingGuide {
    std::vector<FeatureShape> features;
    std::vector<std::vector<cv::Point2d>> skinSamples;
};
// The guide of a front photo from dlib's 68 points (iBUG order), already in the drawing's pixels: brows, eyes with
// their irises, nostrils and mouth, sized from the eyes' distance so they stay legible when the photo shows them small.
DrawingGuide frontDrawingGuide(const std::array<cv::Point2d, 68>& points);
// The guide of a side photo from its profile points (face_profile's names, in the drawing's pixels) with the face
// pointing to image left (theta 90): the eye behind the nasion, the brow above it, the lips behind the lip points and
// a nostril, placed by fractions of the nasion-to-subnasale height. Empty when a point is missing.
DrawingGuide sideDrawingGuide(const std::map<std::string, cv::Point2d>& profile);

// A photo turned into a flat-coloured drawing with dark outlines, restricted to a mask (the head).
struct ToonDrawing {
    cv::Mat bgr;      // flat colours, outlines black, outside the mask white
    cv::Mat outline;  // CV_8U, 255 on outline pixels
    cv::Mat mask;     // CV_8U, the head
    std::vector<cv::Vec3b> featureColours;  // BGR, one per guide feature (what it was painted with)
    cv::Vec3b skinColour;                   // BGR of the skin region
};
// Colour quantisation and edges. The skin (pixels within a chroma distance of the skin's colour and not much darker:
// shading changes lightness, not hue) becomes one flat region; the rest (hair, ears' shade, what the mask holds of the
// background) is clustered by k-means in Lab with the lightness weighted down (`colours` - 1 clusters, near ones
// merged); the label map is smoothed by a majority filter and patches under 1/400 of the head's height squared go to
// their nearest-coloured neighbour; then the guide's features are painted over as regions of their own. Edges are
// the boundaries between labels and the mask's own boundary, thickened to `outlineWidth` pixels.
ToonDrawing toonDrawing(const cv::Mat& photoBgr, const cv::Mat& headMask, int colours = 6, int outlineWidth = 2,
                        const DrawingGuide& guide = {});

// Kitamura's similarity (4.1): s = J exp(-w_x |x_a - x_b|) exp(-w_y |y_a - y_b|) exp(-|S_a - S_b| / ((S_a + S_b)/2))
// with J = H(T_c - |q_a - q_b|), w_x = 1 when both views share theta else 0.5, w_y likewise for phi. Positions are
// bounding-box centres in the drawings' pixels, as the seed has them.
constexpr double kColourThreshold = 0.3;  // T_c
double regionSimilarity(const Region& a, const Region& b, const ViewDirection& viewA, const ViewDirection& viewB,
                        double colourThreshold = kColourThreshold);

// For each region of `a`, the index into `b` of its most similar region, or nullopt when none has s > 0.
std::vector<std::optional<std::size_t>> matchRegions(const Regions& a, const Regions& b, const ViewDirection& viewA,
                                                     const ViewDirection& viewB,
                                                     double colourThreshold = kColourThreshold);

// A 3-D line: a point and a unit direction.
struct Line3 {
    glm::dvec3 point;
    glm::dvec3 direction;
};
// Algorithm 1 (after Rivers et al.): from the origin, project the current point onto every line and average the
// projections, until it moves less than `tolerance` or after `maxIterations` (the seed's 10,000).
glm::dvec3 algorithm1(const std::vector<Line3>& lines, int maxIterations = 10000, double tolerance = 1e-12);
// The closed-form least-squares point of the lines: (sum (I - d d^T))^-1 sum (I - d d^T) c. nullopt when the lines
// are all parallel.
std::optional<glm::dvec3> closestPointOfLines(const std::vector<Line3>& lines);

// A matched pair placed in 3-D: the Algorithm 1 point, then for each view that point moved onto the view's line
// through the region's centroid (so the region sits exactly where it was drawn).
struct PlacedPair {
    std::size_t regionA = 0, regionB = 0;
    glm::dvec3 position;    // Algorithm 1 result (bounding-box-centre lines)
    glm::dvec3 positionA;   // on view A's centroid line
    glm::dvec3 positionB;   // on view B's centroid line
};
PlacedPair placePair(const Region& a, const Region& b, std::size_t indexA, std::size_t indexB,
                     const DrawingView& viewA, const DrawingView& viewB);

}  // namespace avatarbooth::toon
