// Unit tests of the toon's editable correspondence file: round trip, edits changing the 3-D result, errors.
#include "common/error.h"
#include "reveal/toon/toon_correspondence.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <regex>

namespace avatarbooth::toon {
namespace {

// Coloured balls at known 3-D places (mm), drawn as outlined discs from the front (theta 0) and the side (theta 90).
struct Ball {
    glm::dvec3 centre;
    double radius;
    cv::Vec3d rgb;
};
const std::vector<Ball>& balls() {
    static const std::vector<Ball> b{
        {{0, 0, 0}, 100, {1.0, 0.85, 0.7}},    // 0 face
        {{30, 20, 70}, 10, {0.2, 0.4, 1.0}},   // 1 left eye: in both views
        {{-30, 20, 70}, 10, {0.1, 0.8, 0.2}},  // 2 right eye: hidden from the side
        {{0, -5, 85}, 12, {0.9, 0.3, 0.3}},    // 3 nose
        {{0, -40, 65}, 10, {0.8, 0.2, 0.6}},   // 4 mouth
    };
    return b;
}

DrawingView view(double theta) {
    DrawingView v;
    v.direction = {theta, 0.0};
    v.centre = {249.5, 249.5};
    v.unitsPerPixel = 0.5;
    return v;
}

cv::Mat draw(const DrawingView& v, cv::Mat& mask) {
    cv::Mat img(500, 500, CV_8UC3, cv::Scalar(255, 255, 255));
    std::vector<Ball> order = balls();
    const glm::dvec3 towards = v.direction.towardsCamera();
    std::stable_sort(order.begin(), order.end(), [&](const Ball& a, const Ball& b) {
        return glm::dot(a.centre, towards) < glm::dot(b.centre, towards);
    });
    for (const Ball& b : order) {
        const cv::Point2d c = v.project(b.centre) * 16.0;
        const int r = cvRound(b.radius / v.unitsPerPixel * 16.0);
        const cv::Point centre(cvRound(c.x), cvRound(c.y));
        cv::circle(img, centre, r, cv::Scalar(b.rgb[2] * 255, b.rgb[1] * 255, b.rgb[0] * 255), cv::FILLED, cv::LINE_8, 4);
        cv::circle(img, centre, r, cv::Scalar(0, 0, 0), 3, cv::LINE_8, 4);
    }
    cv::inRange(img, cv::Scalar(255, 255, 255), cv::Scalar(255, 255, 255), mask);
    cv::bitwise_not(mask, mask);
    return img;
}

ToonModel model() {
    cv::Mat maskA, maskB;
    const cv::Mat a = draw(view(0), maskA), b = draw(view(90), maskB);
    return buildToonModel(a, maskA, view(0), b, maskB, view(90));
}

std::size_t regionOf(const Regions& regions, int ball) {
    for (std::size_t i = 0; i < regions.regions.size(); ++i)
        if (cv::norm(regions.regions[i].colour - balls()[static_cast<std::size_t>(ball)].rgb) < 0.05) return i;
    ADD_FAILURE() << "no region for ball " << ball;
    return 0;
}

const PlacedPair* pairOf(const ToonModel& m, std::size_t a) {
    const auto it = std::find_if(m.pairs.begin(), m.pairs.end(), [a](const PlacedPair& p) { return p.regionA == a; });
    return it == m.pairs.end() ? nullptr : &*it;
}

int pixelsOfColour(const cv::Mat& img, const cv::Vec3d& rgb) {
    cv::Mat hit;
    const cv::Scalar c(rgb[2] * 255, rgb[1] * 255, rgb[0] * 255);
    cv::inRange(img, c - cv::Scalar(3, 3, 3), c + cv::Scalar(3, 3, 3), hit);
    return cv::countNonZero(hit);
}

// Replaces the block of a front region (its match/unmatched line and its points) with `replacement`.
std::string replaceBlock(const std::string& text, std::size_t a, const std::string& replacement) {
    const std::regex block("(match|unmatched) " + std::to_string(a) + "( [0-9]+)?\n(point [^\n]*\n)*");
    return std::regex_replace(text, block, replacement, std::regex_constants::format_first_only);
}

TEST(ToonCorrespondence, WrittenFileReadsBackToTheSameModel) {
    const ToonModel original = model();
    ASSERT_EQ(original.regionsA.regions.size(), 5u);
    ASSERT_EQ(original.pairs.size(), 4u);
    const std::string text = formatCorrespondence(original);
    const CorrespondenceFile file = parseCorrespondence(text, "c.txt");
    EXPECT_EQ(file.regionsA, 5u);
    EXPECT_EQ(file.regionsB, 4u);
    EXPECT_EQ(file.entries.size(), 5u);  // four matches and the hidden right eye unmatched
    ToonModel back = original;
    applyCorrespondence(back, file, "c.txt");
    ASSERT_EQ(back.pairs.size(), original.pairs.size());
    for (std::size_t k = 0; k < back.pairs.size(); ++k) {
        EXPECT_EQ(back.pairs[k].regionA, original.pairs[k].regionA);
        EXPECT_EQ(back.pairs[k].regionB, original.pairs[k].regionB);
        EXPECT_EQ(back.pairs[k].position, original.pairs[k].position);
        EXPECT_EQ(back.contours[k].a, original.contours[k].a);  // exact: the file keeps every digit
        EXPECT_EQ(back.contours[k].b, original.contours[k].b);
    }
    EXPECT_EQ(formatCorrespondence(back), text);
    EXPECT_EQ(cv::norm(renderToon(back, 30.0, {300, 300}, 1.0), renderToon(original, 30.0, {300, 300}, 1.0),
                       cv::NORM_INF),
              0.0);
}

TEST(ToonCorrespondence, ForcingAMatchPlacesTheRegionWhereBothLinesMeet) {
    const ToonModel original = model();
    const std::size_t rightEye = regionOf(original.regionsA, 2), sideEye = regionOf(original.regionsB, 1);
    ASSERT_EQ(pairOf(original, rightEye), nullptr);  // hidden from the side: unmatched automatically
    // The operator pairs the right eye with the side view's eye (the drawing shows one eye there): the front line
    // through x = -30, y = 20 and the side line through y = 20, z = 70 meet at the right eye's true place.
    std::string text = replaceBlock(formatCorrespondence(original), rightEye,
                                    "match " + std::to_string(rightEye) + " " + std::to_string(sideEye) + "\n");
    ToonModel edited = original;
    applyCorrespondence(edited, parseCorrespondence(text), "c");
    const PlacedPair* p = pairOf(edited, rightEye);
    ASSERT_NE(p, nullptr);
    EXPECT_EQ(p->regionB, sideEye);
    EXPECT_LT(glm::length(p->position - balls()[2].centre), 0.5 * 1.0) << "within a pixel (0.5 mm)";
    EXPECT_EQ(edited.pairs.size(), 5u);
}

TEST(ToonCorrespondence, UnmatchedAndForbidRemovePairsAndEditedPointsReshapeTheOutline) {
    const ToonModel original = model();
    const std::size_t nose = regionOf(original.regionsA, 3), mouth = regionOf(original.regionsA, 4);
    const std::size_t sideMouth = regionOf(original.regionsB, 4);
    const cv::Vec3d noseRgb = balls()[3].rgb, mouthRgb = balls()[4].rgb;
    const int noseBefore = pixelsOfColour(renderToon(original, 0.0, {500, 500}, 0.5), noseRgb);
    ASSERT_GT(noseBefore, 1000);  // a 24 px disc

    // The nose unmatched: it is no longer drawn.
    {
        ToonModel edited = original;
        applyCorrespondence(edited, parseCorrespondence(replaceBlock(formatCorrespondence(original), nose,
                                                                     "unmatched " + std::to_string(nose) + "\n")));
        EXPECT_EQ(pairOf(edited, nose), nullptr);
        EXPECT_EQ(pixelsOfColour(renderToon(edited, 0.0, {500, 500}, 0.5), noseRgb), 0);
    }
    // The mouth left to the automatic match but forbidden its side counterpart: no other side region is near its
    // colour, so it stays unmatched.
    {
        std::string text = replaceBlock(formatCorrespondence(original), mouth, "");
        text += "forbid " + std::to_string(mouth) + " " + std::to_string(sideMouth) + "\n";
        ToonModel edited = original;
        applyCorrespondence(edited, parseCorrespondence(text));
        EXPECT_EQ(pairOf(edited, mouth), nullptr);
        EXPECT_EQ(pixelsOfColour(renderToon(edited, 0.0, {500, 500}, 0.5), mouthRgb), 0);
        // Without the forbid the automatic match comes back.
        ToonModel automatic = original;
        applyCorrespondence(automatic, parseCorrespondence(replaceBlock(formatCorrespondence(original), mouth, "")));
        ASSERT_NE(pairOf(automatic, mouth), nullptr);
        EXPECT_EQ(pairOf(automatic, mouth)->regionB, sideMouth);
    }
    // The nose's points halved: the billboard is half as wide, a quarter of the area, same place.
    {
        const PlacedPair* p = pairOf(original, nose);
        ASSERT_NE(p, nullptr);
        const ContourCorrespondence& cc = original.contours[static_cast<std::size_t>(p - original.pairs.data())];
        std::string block = "match " + std::to_string(nose) + " " + std::to_string(p->regionB) + "\n";
        for (std::size_t k = 0; k < cc.a.size(); ++k)
            block += "point " + std::to_string(cc.a[k].x / 2) + " " + std::to_string(cc.a[k].y / 2) + " " +
                     std::to_string(cc.b[k].x / 2) + " " + std::to_string(cc.b[k].y / 2) + "\n";
        ToonModel edited = original;
        applyCorrespondence(edited, parseCorrespondence(replaceBlock(formatCorrespondence(original), nose, block)));
        const int after = pixelsOfColour(renderToon(edited, 0.0, {500, 500}, 0.5), noseRgb);
        EXPECT_NEAR(after, noseBefore / 4.0, noseBefore * 0.08);
        const int side = pixelsOfColour(renderToon(edited, 90.0, {500, 500}, 0.5), noseRgb);
        EXPECT_NEAR(side, pixelsOfColour(renderToon(original, 90.0, {500, 500}, 0.5), noseRgb) / 4.0, noseBefore * 0.08);
    }
}

TEST(ToonCorrespondence, BadLinesNameFileLineAndField) {
    auto where = [](const std::string& text) {
        try {
            parseCorrespondence(text, "c.txt");
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
            return e.where() + " " + e.what();
        }
        return std::string("no error");
    };
    const std::string head = "toon-correspondence 1\nregions 3 2\n";
    EXPECT_EQ(where("regions 3 2\n").substr(0, 9), "c.txt:1:1");                     // no header
    EXPECT_EQ(where("toon-correspondence 2\n").substr(0, 9), "c.txt:1:2");            // unknown version
    EXPECT_EQ(where(head + "match 0 1\nmatch 0 0\n").substr(0, 9), "c.txt:4:2");      // listed twice
    EXPECT_EQ(where(head + "match 0 x\n").substr(0, 9), "c.txt:3:3");                 // not a number
    EXPECT_EQ(where(head + "match 0 2\n").substr(0, 9), "c.txt:3:3");                 // side region out of range
    EXPECT_EQ(where(head + "unmatched 3\n").substr(0, 9), "c.txt:3:2");               // front region out of range
    EXPECT_EQ(where(head + "match 0\n").substr(0, 9), "c.txt:3:3");                   // missing field B
    EXPECT_EQ(where(head + "match 0 1 1\n").substr(0, 9), "c.txt:3:4");               // extra field
    EXPECT_EQ(where(head + "point 1 2 3 4\n").substr(0, 9), "c.txt:3:1");             // point with no match
    EXPECT_EQ(where(head + "match 0 1\npoint 1 2 3 nan\n").substr(0, 9), "c.txt:4:5");  // not finite
    EXPECT_EQ(where(head + "match 0 1\npoint 1 2 3 4\npoint 2 3 4 5\n\n").substr(0, 9), "c.txt:3:1");  // 2 points
    EXPECT_EQ(where(head + "pair 0 1\n").substr(0, 9), "c.txt:3:1");                  // unknown record
    EXPECT_EQ(where(head + "match 0 1\nforbid 0 1\n").substr(0, 9), "c.txt:4:1");     // matched and forbidden
    EXPECT_NE(where(head + "match 0 1\npoint 1 2 3 4\n").find("at least 3"), std::string::npos);
    EXPECT_EQ(where(head + "match 0 1  # a comment\nunmatched 1\nforbid 2 0\n\n"), "no error");
    // A file for other drawings: the region counts disagree with the model.
    ToonModel m = model();
    try {
        applyCorrespondence(m, parseCorrespondence(head, "c.txt"), "c.txt");
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.where(), "c.txt:2");
    }
}

}  // namespace
}  // namespace avatarbooth::toon
