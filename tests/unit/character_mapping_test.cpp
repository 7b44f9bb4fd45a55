// The mapping from 68 landmarks + silhouette (+ ear hole) to Narita's 21 points: exact edges on a hand-made mask,
// the built-in base head seen as a photo (its ears are on its silhouette), the canon when ears are hidden, and a
// rotated and scaled copy of the same view giving the same ratios.
#include "reveal/character/character_head.h"
#include "reveal/character/narita_points.h"
#include "common/error.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>

namespace avatarbooth {
namespace {

bool inside(const cv::Mat& mask, cv::Point2d p) {
    const long x = std::lround(p.x), y = std::lround(p.y);
    return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<unsigned char>(static_cast<int>(y), static_cast<int>(x)) != 0;
}

// On the silhouette's edge: inside one pixel inwards, outside 1.5 pixels outwards.
void expectOnEdge(const cv::Mat& mask, cv::Point2d p, cv::Point2d outwards, const std::string& what) {
    EXPECT_TRUE(inside(mask, p - outwards)) << what << " at " << p;
    EXPECT_FALSE(inside(mask, p + 1.5 * outwards)) << what << " at " << p;
}

// A face whose landmarks sit on a level eye line at y = 100 inside a rectangular "head" from x = 20 to x = 180.
NaritaMappingInput boxFace() {
    NaritaMappingInput in;
    in.mask = cv::Mat::zeros(300, 200, CV_8U);
    in.mask(cv::Rect(20, 10, 161, 280)).setTo(255);
    auto& p = in.landmarks;
    for (int k = 0; k <= 16; ++k) {  // jaw from (30, 100) down to the chin (100, 200) and up to (170, 100)
        const double a = 3.14159265358979323846 * k / 16.0;
        p[static_cast<std::size_t>(k)] = {100.0 - 70.0 * std::cos(a), 100.0 + 100.0 * std::sin(a)};
    }
    for (int k = 17; k <= 26; ++k) p[static_cast<std::size_t>(k)] = {40.0 + 13.0 * (k - 17), 80.0};  // brows at y = 80
    for (int k = 27; k <= 35; ++k) p[static_cast<std::size_t>(k)] = {100.0, 100.0 + 5.0 * (k - 27)};
    p[33] = {100.0, 140.0};  // nose base: L = 140 - 80 = 60
    const double right[6][2] = {{55, 100}, {62, 96}, {70, 96}, {77, 100}, {70, 104}, {62, 104}};
    for (int i = 0; i < 6; ++i) {
        p[static_cast<std::size_t>(36 + i)] = {right[i][0], right[i][1]};
        p[static_cast<std::size_t>(42 + (i < 4 ? 3 - i : 9 - i))] = {200.0 - right[i][0], right[i][1]};
    }
    for (int k = 48; k <= 67; ++k) p[static_cast<std::size_t>(k)] = {100.0, 165.0};
    return in;
}

TEST(CharacterMapping, TemplesAreTheSilhouettesEdgeOnTheEyeLine) {
    const NaritaMapping m = mapNaritaPoints(boxFace());
    // Pixel 20 is the last inside on the left: the edge estimate lies within half a pixel of 19.5.
    EXPECT_NEAR(m.points.f[0].x, 19.5, 0.5);
    EXPECT_NEAR(m.points.f[1].x, 180.5, 0.5);
    EXPECT_DOUBLE_EQ(m.points.f[0].y, 100.0);
    EXPECT_DOUBLE_EQ(m.points.f[1].y, 100.0);
    // A box has no ears: the canon, from the brow line (y = 80) with the ear hole 0.45 L = 27 below it: the ear
    // spans the brow line to the nose base (y = 140), on the box's edge.
    EXPECT_EQ(m.earSource[0], "canon");
    EXPECT_EQ(m.earSource[1], "canon");
    EXPECT_EQ(m.earHoleSource, "canon");
    EXPECT_NEAR(m.points.a[0].y, 80.0, 1e-9);
    EXPECT_NEAR(m.points.a[1].y, 140.0, 1e-9);
    EXPECT_NEAR(m.points.a[0].x, 19.5, 0.5);
    EXPECT_NEAR(m.points.a[3].x, 180.5, 0.5);
    EXPECT_EQ(m.warnings.size(), 2u);  // both ears estimated
}

TEST(CharacterMapping, LandmarkPointsFollowTheDocumentedTable) {
    const NaritaMappingInput in = boxFace();
    const NaritaMapping m = mapNaritaPoints(in);
    const auto& p = in.landmarks;
    EXPECT_EQ(m.points.f[2], p[8]);
    EXPECT_EQ(m.points.e[0], p[36]);
    EXPECT_EQ(m.points.e[1], p[39]);
    EXPECT_EQ(m.points.e[2], 0.5 * (p[37] + p[38]));
    EXPECT_EQ(m.points.e[3], p[41]);
    EXPECT_EQ(m.points.e[4], p[40]);
    EXPECT_EQ(m.points.e[5], p[45]);
    EXPECT_EQ(m.points.e[6], p[42]);
    EXPECT_EQ(m.points.e[7], 0.5 * (p[43] + p[44]));
    EXPECT_EQ(m.points.e[8], p[46]);
    EXPECT_EQ(m.points.e[9], p[47]);
    EXPECT_EQ(m.points.b[0], p[21]);
    EXPECT_EQ(m.points.b[1], p[22]);
    EXPECT_EQ(m.points.browOuter[0], p[17]);
    EXPECT_EQ(m.points.browOuter[1], p[26]);
    EXPECT_EQ(m.points.n, p[30]);
    EXPECT_EQ(m.points.m, 0.5 * (p[62] + p[66]));
}

TEST(CharacterMapping, TheSidePhotosEarHoleMovesTheCanonsEar) {
    NaritaMappingInput in = boxFace();
    in.earHole = cv::Point2d(100.0, 110.0);  // 3 px lower than the canon's 107
    const NaritaMapping m = mapNaritaPoints(in);
    EXPECT_EQ(m.earHoleSource, "side photo");
    EXPECT_NEAR(m.points.a[0].y, 110.0 - 0.45 * 60.0, 1e-9);
    EXPECT_NEAR(m.points.a[1].y, 110.0 + 0.55 * 60.0, 1e-9);
    // An ear hole above the brows (a bad profile point) is kept to the brow line (y = 80), with a warning.
    in.earHole = cv::Point2d(100.0, 40.0);
    const NaritaMapping high = mapNaritaPoints(in);
    EXPECT_NEAR(high.points.a[0].y, 80.0 - 0.45 * 60.0, 1e-9);
    EXPECT_EQ(high.warnings.size(), m.warnings.size() + 1);
}

TEST(CharacterMapping, FindsTheBaseHeadsEarsOnItsSilhouette) {
    const BaseHead& base = builtinBaseHead();
    const MeshFrontView view = frontViewOf(base.mesh, base, base.earHoleCentre, 4.0);
    const NaritaMapping m = mapNaritaPoints(view.input);
    EXPECT_EQ(m.earSource[0], "silhouette");
    EXPECT_EQ(m.earSource[1], "silhouette");
    EXPECT_TRUE(m.warnings.empty());
    // The base head's ears are ellipsoids at x = +-78 mm from y = -36 to 26 mm (base_head_generator.cpp), joined
    // to the skull above and the jaw below: the notches lie at those ends, where the ear meets the head.
    for (std::size_t side = 0; side < 2; ++side) {
        const glm::dvec2 top = view.toMm(m.points.a[2 * side]), bottom = view.toMm(m.points.a[2 * side + 1]);
        EXPECT_NEAR(top.y, 26.0, 3.0);
        EXPECT_NEAR(bottom.y, -36.0, 3.0);
        EXPECT_GT(std::abs(top.x), 70.0);
        EXPECT_GT(std::abs(bottom.x), 60.0);
        const cv::Point2d out(side == 0 ? -1.0 : 1.0, 0.0);
        expectOnEdge(view.input.mask, m.points.a[2 * side], out, "ear top");
        expectOnEdge(view.input.mask, m.points.f[side], out, "temple");
        // At eye height the silhouette's edge is the ear's outer rim (x = 78 + 13 = 91 mm).
        EXPECT_NEAR(std::abs(view.toMm(m.points.f[side]).x), 91.0, 1.5);
    }
}

TEST(CharacterMapping, RotatedAndScaledViewGivesTheSameRatios) {
    const BaseHead& base = builtinBaseHead();
    const MeshFrontView view = frontViewOf(base.mesh, base, base.earHoleCentre, 3.0);
    const CharacterProportions upright = computeProportions(mapNaritaPoints(view.input).points);
    // 23 degrees about the image centre, 1.6 times larger, shifted.
    const cv::Point2f centre(static_cast<float>(view.input.mask.cols) / 2.0f, static_cast<float>(view.input.mask.rows) / 2.0f);
    const int side = static_cast<int>(1.7 * std::hypot(view.input.mask.cols, view.input.mask.rows));
    cv::Mat M = cv::getRotationMatrix2D(centre, 23.0, 1.6);
    M.at<double>(0, 2) += 0.5 * side - centre.x;  // the view's centre lands in the middle of the larger image
    M.at<double>(1, 2) += 0.5 * side - centre.y;
    NaritaMappingInput turned;
    cv::warpAffine(view.input.mask, turned.mask, M, cv::Size(side, side), cv::INTER_NEAREST);
    const auto move = [&](cv::Point2d p) {
        return cv::Point2d(M.at<double>(0, 0) * p.x + M.at<double>(0, 1) * p.y + M.at<double>(0, 2),
                           M.at<double>(1, 0) * p.x + M.at<double>(1, 1) * p.y + M.at<double>(1, 2));
    };
    for (std::size_t k = 0; k < 68; ++k) turned.landmarks[k] = move(view.input.landmarks[k]);
    turned.earHole = move(*view.input.earHole);
    const NaritaMapping m = mapNaritaPoints(turned);
    EXPECT_EQ(m.earSource[0], "silhouette");
    EXPECT_EQ(m.earSource[1], "silhouette");
    const CharacterProportions r = computeProportions(m.points);
    EXPECT_NEAR(r.lf0, 1.6 * upright.lf0, 0.01 * r.lf0);
    for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(r.r[i], upright.r[i], 0.01) << "r" << i;
    EXPECT_NEAR(r.eyeSpacing, upright.eyeSpacing, 0.005);
    EXPECT_NEAR(r.eyeTiltDeg, upright.eyeTiltDeg, 0.5);
    EXPECT_NEAR(r.browTiltDeg, upright.browTiltDeg, 0.5);
}

TEST(CharacterMapping, RefusesMasksThatCannotBeUsed) {
    NaritaMappingInput in = boxFace();
    in.mask = cv::Mat();
    EXPECT_THROW(mapNaritaPoints(in), BoothError);
    in = boxFace();
    for (int k = 36; k < 48; ++k) in.landmarks[static_cast<std::size_t>(k)] = in.landmarks[45];
    try {
        mapNaritaPoints(in);
        FAIL() << "coinciding eyes were accepted";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::NoFace);
    }
}

// A silhouette that misses the face (here: none at all) does not fail: the temples and ears go on the face's own
// contour (the jaw landmarks; above iBUG 0 / 16, straight up from them), with warnings.
TEST(CharacterMapping, ASilhouetteInsideTheFaceFallsBackToTheJawContour) {
    NaritaMappingInput in = boxFace();
    in.mask.setTo(0);
    const NaritaMapping m = mapNaritaPoints(in);
    EXPECT_EQ(m.templeSource[0], "face contour");
    EXPECT_EQ(m.templeSource[1], "face contour");
    EXPECT_NEAR(m.points.f[0].x, 30.0, 1e-9);  // iBUG 0 is at (30, 100), on the eye line
    EXPECT_NEAR(m.points.f[1].x, 170.0, 1e-9);
    EXPECT_NEAR(m.points.a[0].x, 30.0, 1e-9);  // the ear top (y = 80) is above iBUG 0: straight up from it
    EXPECT_NEAR(m.points.a[0].y, 80.0, 1e-9);
    // The bottom (y = 140) is on the jaw polyline, between iBUG 2 and 3.
    const auto jaw = [](double k) {
        const double a = 3.14159265358979323846 * k / 16.0;
        return cv::Point2d(100.0 - 70.0 * std::cos(a), 100.0 + 100.0 * std::sin(a));
    };
    const double f = (140.0 - jaw(2).y) / (jaw(3).y - jaw(2).y);
    EXPECT_NEAR(m.points.a[1].x, jaw(2).x + f * (jaw(3).x - jaw(2).x), 1e-9);
    EXPECT_NEAR(m.points.a[1].y, 140.0, 1e-9);
    EXPECT_EQ(m.warnings.size(), 6u);  // 2 temples, 2 ears estimated, 2 ears on the contour
    // The same happens to a silhouette that cuts into the face: a head box narrower than the jaw.
    in = boxFace();
    in.mask.setTo(0);
    in.mask(cv::Rect(50, 10, 101, 280)).setTo(255);
    EXPECT_EQ(mapNaritaPoints(in).templeSource[0], "face contour");
}

}  // namespace
}  // namespace avatarbooth
