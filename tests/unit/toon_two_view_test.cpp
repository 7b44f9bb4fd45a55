// Unit tests of the two-view toon character: regions, matching, Algorithm 1, rendering on synthetic drawings.
#include "reveal/toon/toon_billboard.h"
#include "reveal/toon/toon_regions.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <random>

namespace avatarbooth::toon {
// Named, not anonymous: the helpers share their names with toon_correspondence_test.cpp's, which a unity build
// of the tests puts in the same translation unit.
namespace two_view_test {

// A flat-coloured ball of the synthetic character: drawn as a disc with a black outline in every view.
struct Ball {
    const char* name;
    glm::dvec3 centre;  // mm
    double radius;      // mm
    cv::Vec3d rgb;      // [0, 1]
};

std::vector<Ball> character() {
    return {
        {"face", {0, 0, 0}, 100, {1.0, 0.85, 0.7}},
        {"left eye", {30, 20, 70}, 10, {0.2, 0.4, 1.0}},    // seen in both views
        {"right eye", {-30, 20, 70}, 10, {0.1, 0.8, 0.2}},  // hidden behind the face in the left side view
        {"nose", {0, -5, 85}, 12, {0.9, 0.3, 0.3}},
        {"mouth", {0, -40, 65}, 10, {0.8, 0.2, 0.6}},
    };
}

DrawingView view(double theta) {
    DrawingView v;
    v.direction = {theta, 0.0};
    v.centre = {249.5, 249.5};
    v.unitsPerPixel = 0.5;
    return v;
}

// Draws the balls far to near (at equal depth the bigger first), discs filled and outlined in black.
cv::Mat draw(const std::vector<Ball>& balls, const DrawingView& v, cv::Mat& mask) {
    cv::Mat img(500, 500, CV_8UC3, cv::Scalar(255, 255, 255));
    std::vector<Ball> order = balls;
    const glm::dvec3 towards = v.direction.towardsCamera();
    std::stable_sort(order.begin(), order.end(), [&](const Ball& a, const Ball& b) {
        const double da = glm::dot(a.centre, towards), db = glm::dot(b.centre, towards);
        return da != db ? da < db : a.radius > b.radius;
    });
    constexpr int kShift = 4;
    for (const Ball& b : order) {
        const cv::Point2d c = v.project(b.centre) * 16.0;
        const int r = cvRound(b.radius / v.unitsPerPixel * 16.0);
        const cv::Point centre(cvRound(c.x), cvRound(c.y));
        cv::circle(img, centre, r, cv::Scalar(b.rgb[2] * 255, b.rgb[1] * 255, b.rgb[0] * 255), cv::FILLED, cv::LINE_8, kShift);
        cv::circle(img, centre, r, cv::Scalar(0, 0, 0), 3, cv::LINE_8, kShift);
    }
    cv::inRange(img, cv::Scalar(255, 255, 255), cv::Scalar(255, 255, 255), mask);
    cv::bitwise_not(mask, mask);  // the character: all that is not white paper
    return img;
}

// The region whose colour is nearest the ball's.
std::optional<std::size_t> regionOf(const Regions& regions, const Ball& ball) {
    for (std::size_t i = 0; i < regions.regions.size(); ++i)
        if (cv::norm(regions.regions[i].colour - ball.rgb) < 0.05) return i;
    return std::nullopt;
}

TEST(ToonRegions, SplitsDrawingIntoClosedRegionsWithOutlinesGivenAwayAndHolesFilled) {
    cv::Mat mask;
    const cv::Mat front = draw(character(), view(0), mask);
    const Regions regions = splitRegions(front, mask);
    ASSERT_EQ(regions.regions.size(), 5u);
    const auto face = regionOf(regions, character()[0]);
    ASSERT_TRUE(face);
    // Holes filled: the face's area is the whole disc (radius 200 px plus half the outline), eyes included.
    const double discArea = CV_PI * 201.0 * 201.0;
    EXPECT_NEAR(regions.regions[*face].area, discArea, discArea * 0.02);
    // Every pixel inside the drawing's outline belongs to a region (outline pixels given away).
    cv::Mat unassigned = mask & (regions.labels == 0);
    EXPECT_EQ(cv::countNonZero(unassigned), 0);
}

TEST(ToonMatch, MatchesRegionsOfTwoViewsAndLeavesTheHiddenOneUnmatched) {
    cv::Mat maskA, maskB;
    const auto balls = character();
    const Regions a = splitRegions(draw(balls, view(0), maskA), maskA);
    const Regions b = splitRegions(draw(balls, view(90), maskB), maskB);
    ASSERT_EQ(a.regions.size(), 5u);
    ASSERT_EQ(b.regions.size(), 4u);  // the right eye is behind the face
    const auto match = matchRegions(a, b, view(0).direction, view(90).direction);
    for (const Ball& ball : balls) {
        const auto ia = regionOf(a, ball), ib = regionOf(b, ball);
        ASSERT_TRUE(ia) << ball.name;
        if (ib) {
            ASSERT_TRUE(match[*ia]) << ball.name;
            EXPECT_EQ(*match[*ia], *ib) << ball.name;
        } else {
            EXPECT_FALSE(match[*ia]) << ball.name << " should stay unmatched";
        }
    }
}

TEST(ToonMatch, SimilarityFollowsTheFormula) {
    Region a, b;
    a.colour = {0.5, 0.5, 0.5};
    b.colour = {0.6, 0.5, 0.5};
    a.bboxCentre = {10, 20};
    b.bboxCentre = {13, 24};
    a.area = 100;
    b.area = 300;
    const double expectedSame = std::exp(-3.0) * std::exp(-4.0) * std::exp(-200.0 / 200.0);
    EXPECT_NEAR(regionSimilarity(a, b, {0, 0}, {0, 0}), expectedSame, 1e-15);
    const double expectedSide = std::exp(-0.5 * 3.0) * std::exp(-4.0) * std::exp(-1.0);
    EXPECT_NEAR(regionSimilarity(a, b, {0, 0}, {90, 0}), expectedSide, 1e-15);
    const double expectedBoth = std::exp(-0.5 * 3.0) * std::exp(-0.5 * 4.0) * std::exp(-1.0);
    EXPECT_NEAR(regionSimilarity(a, b, {0, 0}, {90, 30}), expectedBoth, 1e-15);
    b.colour = {0.5 + 0.31, 0.5, 0.5};  // beyond T_c = 0.3
    EXPECT_EQ(regionSimilarity(a, b, {0, 0}, {90, 0}), 0.0);
    b.colour = {0.5 + 0.29, 0.5, 0.5};
    EXPECT_GT(regionSimilarity(a, b, {0, 0}, {90, 0}), 0.0);
}

TEST(ToonPlace, Algorithm1PutsEveryMatchedBallWithinAPixelOfItsTruePosition) {
    const auto balls = character();
    cv::Mat maskA, maskB;
    const DrawingView va = view(0), vb = view(90);
    const cv::Mat da = draw(balls, va, maskA), db = draw(balls, vb, maskB);
    const ToonModel model = buildToonModel(da, maskA, va, db, maskB, vb);
    ASSERT_EQ(model.pairs.size(), 4u);
    for (const Ball& ball : balls) {
        const auto ia = regionOf(model.regionsA, ball);
        ASSERT_TRUE(ia);
        const auto it = std::find_if(model.pairs.begin(), model.pairs.end(),
                                     [&](const PlacedPair& p) { return p.regionA == *ia; });
        if (std::string(ball.name) == "right eye") {
            EXPECT_EQ(it, model.pairs.end());
            continue;
        }
        ASSERT_NE(it, model.pairs.end()) << ball.name;
        const double errorPx = glm::length(it->position - ball.centre) / va.unitsPerPixel;
        EXPECT_LT(errorPx, 1.0) << ball.name;
        // The view-corrected positions land on the drawn centroids exactly.
        const cv::Point2d pa = va.project(it->positionA), pb = vb.project(it->positionB);
        EXPECT_LT(cv::norm(pa - model.regionsA.regions[it->regionA].centroid), 1e-9) << ball.name;
        EXPECT_LT(cv::norm(pb - model.regionsB.regions[it->regionB].centroid), 1e-9) << ball.name;
    }
}

TEST(ToonPlace, Algorithm1EqualsTheClosedFormLeastSquaresPoint) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (int trial = 0; trial < 20; ++trial) {
        std::vector<Line3> lines;
        const int count = 2 + trial % 3;
        for (int i = 0; i < count; ++i) {
            const glm::dvec3 d = glm::normalize(glm::dvec3(u(rng), u(rng), u(rng)) + glm::dvec3(i == 0, i == 1, i == 2));
            lines.push_back({glm::dvec3(u(rng), u(rng), u(rng)) * 50.0, d});
        }
        const auto exact = closestPointOfLines(lines);
        ASSERT_TRUE(exact);
        const glm::dvec3 iterated = algorithm1(lines);
        EXPECT_LT(glm::length(iterated - *exact), 1e-6) << "trial " << trial;
    }
    // Two skew perpendicular lines: the midpoint of their common perpendicular.
    const glm::dvec3 p = algorithm1({{{0, 0, 5}, {1, 0, 0}}, {{0, 2, 0}, {0, 0, 1}}});
    EXPECT_NEAR(p.x, 0.0, 1e-12);
    EXPECT_NEAR(p.y, 1.0, 1e-12);
    EXPECT_NEAR(p.z, 5.0, 1e-12);
    EXPECT_FALSE(closestPointOfLines({{{0, 0, 0}, {1, 0, 0}}, {{0, 1, 0}, {1, 0, 0}}}));
}

TEST(ToonContours, CorrespondenceFindsTheRotatedShiftedPartner) {
    Region a, b;
    // An ellipse, and the same ellipse turned 90 degrees and started elsewhere on its outline.
    for (int i = 0; i < 200; ++i) {
        const double t = 2 * CV_PI * i / 200;
        a.contour.emplace_back(cvRound(100 + 60 * std::cos(t)), cvRound(100 + 20 * std::sin(t)));
        const double s = t + 2 * CV_PI * 50 / 200;
        b.contour.emplace_back(cvRound(300 - 20 * std::sin(s)), cvRound(300 + 60 * std::cos(s)));
    }
    a.centroid = {100, 100};
    b.centroid = {300, 300};
    const ContourCorrespondence cc = correspondContours(a, b, 40);
    ASSERT_EQ(cc.a.size(), 40u);
    // Point i of a and point i of b are the same point of the shape: b's offset is a's turned 90 degrees (either way).
    double worstTurned = 0.0;
    for (std::size_t i = 0; i < cc.a.size(); ++i) {
        const cv::Point2d turnedCcw(-cc.a[i].y, cc.a[i].x), turnedCw(cc.a[i].y, -cc.a[i].x);
        worstTurned = std::max(worstTurned, std::min(cv::norm(cc.b[i] - turnedCcw), cv::norm(cc.b[i] - turnedCw)));
    }
    EXPECT_LT(worstTurned, 6.0);
}

TEST(ToonRender, FrontAndSideRendersReproduceTheDrawingsAndTheOtherSideIsMirrored) {
    const auto balls = character();
    cv::Mat maskA, maskB;
    const DrawingView va = view(0), vb = view(90);
    const cv::Mat da = draw(balls, va, maskA), db = draw(balls, vb, maskB);
    const ToonModel model = buildToonModel(da, maskA, va, db, maskB, vb);
    const ToonModel* m = &model;
    auto colourCentroid = [](const cv::Mat& img, const cv::Vec3d& rgb) {
        cv::Mat hit;
        const cv::Scalar c(rgb[2] * 255, rgb[1] * 255, rgb[0] * 255);
        cv::inRange(img, c - cv::Scalar(3, 3, 3), c + cv::Scalar(3, 3, 3), hit);
        const cv::Moments mo = cv::moments(hit, true);
        return mo.m00 > 0 ? cv::Point2d(mo.m10 / mo.m00, mo.m01 / mo.m00) : cv::Point2d(-1e9, -1e9);
    };
    const cv::Mat front = renderToon(*m, 0.0, {500, 500}, 0.5);
    const cv::Mat side = renderToon(*m, 90.0, {500, 500}, 0.5);
    for (const char* name : {"left eye", "nose", "mouth"}) {
        const Ball& ball = *std::find_if(balls.begin(), balls.end(), [&](const Ball& b) { return std::string(b.name) == name; });
        EXPECT_LT(cv::norm(colourCentroid(front, ball.rgb) - va.project(ball.centre)), 1.5) << name;
        EXPECT_LT(cv::norm(colourCentroid(side, ball.rgb) - vb.project(ball.centre)), 1.5) << name;
    }
    // Half-way the nose sits between its front and side places, in front of the face.
    const cv::Mat half = renderToon(*m, 45.0, {500, 500}, 0.5);
    const Ball& nose = balls[3];
    const DrawingView v45 = view(45);
    EXPECT_LT(cv::norm(colourCentroid(half, nose.rgb) - v45.project(nose.centre)), 2.0);
    cv::Mat mirrored;
    cv::flip(renderToon(*m, -45.0, {500, 500}, 0.5), mirrored, 1);
    EXPECT_EQ(cv::norm(mirrored, half, cv::NORM_INF), 0.0);
}

}  // namespace two_view_test
}  // namespace avatarbooth::toon
