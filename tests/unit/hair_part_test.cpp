// The hair part (fit/parts/hair_part.h). It keeps the face clear: hair under the brows and ahead of the plane through
// the jaw's top goes back to within FaceClearance::depth of it, keeping its order; over the brows it fades out; nothing
// else moves. Big hair meets the photos' outlines beside and behind the head, and nothing within the head's moves.
#include "fit/parts/hair_part.h"

#include "common/error.h"
#include "common/landmark_names.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <functional>
#include <utility>
#include <vector>

using namespace avatarbooth;

namespace {

// A "fitted head" whose only vertices are its landmarks: the jaw's top (ibug 0 and 16) at z 10 and 14 (the plane at
// z 12), the brows (17-26) with their lowest point at y 40, every other landmark at the origin.
struct Face {
    BaseHead base;
    Mesh head;
};

Face face() {
    Face f;
    f.head.positions.assign(68, glm::dvec3(0.0));
    for (int k = 0; k < 68; ++k) f.base.frontFeatures[landmarkName(k)] = static_cast<std::uint32_t>(k);
    f.head.positions[0] = {-70.0, 20.0, 10.0};
    f.head.positions[16] = {70.0, 20.0, 14.0};
    for (int k = 17; k <= 26; ++k) f.head.positions[static_cast<std::size_t>(k)] = {-50.0 + 10.0 * (k - 17), k == 21 ? 40.0 : 45.0, 80.0};
    return f;
}

}  // namespace

TEST(HairPart, HairUnderTheBrowsGoesBehindTheFacesFrontKeepingItsOrder) {
    const Face f = face();
    Mesh hair;
    // Under the brows: a fringe strand over an eye (z 90, 100) and hair beside the cheek (z 40); one behind the
    // plane (z 0).
    hair.positions = {{-30.0, 30.0, 90.0}, {-30.0, 25.0, 100.0}, {-80.0, 0.0, 40.0}, {-80.0, 0.0, 0.0}};
    FaceClearance c;
    keepFaceClear(hair, f.base, f.head, c);
    const double plane = 12.0;
    // Within `depth` of the plane, by 10 (1 - exp(-d / 10)) for what was d ahead.
    EXPECT_NEAR(hair.positions[0].z, plane + 10.0 * (1.0 - std::exp(-78.0 / 10.0)), 1e-9);
    EXPECT_NEAR(hair.positions[1].z, plane + 10.0 * (1.0 - std::exp(-88.0 / 10.0)), 1e-9);
    EXPECT_LT(hair.positions[0].z, hair.positions[1].z);  // the strands stay layered
    EXPECT_NEAR(hair.positions[2].z, plane + 10.0 * (1.0 - std::exp(-28.0 / 10.0)), 1e-9);
    EXPECT_EQ(hair.positions[3].z, 0.0);
    // Only depth changes.
    EXPECT_EQ(hair.positions[0].x, -30.0);
    EXPECT_EQ(hair.positions[0].y, 30.0);
    EXPECT_EQ(hair.positions[2].x, -80.0);
}

TEST(HairPart, OverTheBrowsThePushFadesOut) {
    const Face f = face();
    Mesh hair;
    // At the brows' lowest point (y 40), a third of the way up the 15 mm ramp, and over it.
    hair.positions = {{0.0, 40.0, 62.0}, {0.0, 45.0, 62.0}, {0.0, 55.0, 62.0}, {0.0, 80.0, 62.0}};
    keepFaceClear(hair, f.base, f.head);
    const double kept = 12.0 + 10.0 * (1.0 - std::exp(-5.0));
    EXPECT_NEAR(hair.positions[0].z, kept, 1e-9);
    // t = 2/3: smoothstep 20/27 of the push.
    EXPECT_NEAR(hair.positions[1].z, 62.0 - 20.0 / 27.0 * (62.0 - kept), 1e-9);
    EXPECT_EQ(hair.positions[2].z, 62.0);
    EXPECT_EQ(hair.positions[3].z, 62.0);
}

TEST(HairPart, AHeadWithoutTheFeatureVerticesIsAnInternalError) {
    Face f = face();
    f.base.frontFeatures.erase(landmarkName(16));
    Mesh hair;
    hair.positions = {{0.0, 0.0, 50.0}};
    try {
        keepFaceClear(hair, f.base, f.head);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Internal);
        EXPECT_NE(std::string(e.what()).find("ibug_16"), std::string::npos) << e.what();
    }
}

namespace {

// The four side walls of a box (x from xMinus to xPlus, z from zBack to zFront) through rings of vertices at the given
// heights, as triangles: what the silhouette fit slices.
Mesh walls(double xMinus, double xPlus, double zBack, double zFront, const std::vector<double>& rings) {
    Mesh m;
    for (const double y : rings)
        for (const auto& [x, z] : {std::pair{xMinus, zBack}, std::pair{xPlus, zBack}, std::pair{xPlus, zFront}, std::pair{xMinus, zFront}})
            m.positions.emplace_back(x, y, z);
    for (std::uint32_t r = 0; r + 1 < rings.size(); ++r)
        for (std::uint32_t c = 0; c < 4; ++c) {
            const std::uint32_t a = 4 * r + c, b = 4 * r + (c + 1) % 4;
            m.triangles.emplace_back(a, b, b + 4);
            m.triangles.emplace_back(a, b + 4, a + 4);
        }
    return m;
}

// A photo frame at 1 mm per pixel with the head's origin at pixel (200, 200), and a mask filled over [from, to] in
// the frame's horizontal coordinate, for every row.
PhotoFrame frame() {
    PhotoFrame f;
    f.centrePx = {200.0, 200.0};
    f.imageWidth = 400;
    return f;
}

cv::Mat mask(double from, double to) {
    cv::Mat m = cv::Mat::zeros(400, 400, CV_8U);
    m.colRange(static_cast<int>(from) + 200, static_cast<int>(to) + 201).setTo(255);
    return m;
}

}  // namespace

TEST(HairPart, BigHairMeetsThePhotosOutlineBesideAndBehindTheHead) {
    // The head a box 120 mm wide and 160 deep; the hair 30 mm out to each side and behind it, down to the chin (y
    // -100). The photos: the hair reaches 15 mm out on the +x side, 60 on the -x side, 15 behind.
    const Mesh head = walls(-60.0, 60.0, -80.0, 80.0, {-100.0, 100.0});
    Mesh hair = walls(-90.0, 90.0, -110.0, 50.0, {-100.0, 0.0, 50.0});
    const auto stretches = fitHairToSilhouettes(hair, head, frame(), mask(-120.0, 75.0), frame(), mask(-95.0, 90.0), -100.0);
    for (std::size_t i = 4; i < 8; ++i) {  // the ring at y 0
        const glm::dvec3& p = hair.positions[i];
        EXPECT_NEAR(std::abs(p.x), p.x > 0 ? 75.0 : 120.0, 1e-6) << i;
        EXPECT_NEAR(p.z, p.z < 0 ? -95.0 : 50.0, 1e-6) << i;  // the front (z 50, inside the head's depth) stays
        EXPECT_EQ(p.y, 0.0);
    }
    // The stretches the bands report: (75 - 60) / 30, (120 - 60) / 30, (95 - 80) / 30.
    const auto at = std::find_if(stretches.begin(), stretches.end(), [](const HairStretch& s) { return s.y > 0.0; });
    ASSERT_NE(at, stretches.end());
    EXPECT_NEAR(at->plusX, 0.5, 1e-9);
    EXPECT_NEAR(at->minusX, 2.0, 1e-9);
    EXPECT_NEAR(at->back, 0.5, 1e-9);
}

TEST(HairPart, HairWithinTheHeadsOutlineAndAPonytailsBackStayPut) {
    const Mesh head = walls(-60.0, 60.0, -80.0, 80.0, {-100.0, 100.0});
    // A cap inside the head's width and depth, and a tail 40 mm behind the head.
    Mesh cap = walls(-50.0, 50.0, -70.0, 40.0, {-50.0, 0.0, 50.0});
    const Mesh capBefore = cap;
    fitHairToSilhouettes(cap, head, frame(), mask(-100.0, 100.0), frame(), mask(-100.0, 90.0), -100.0);
    EXPECT_EQ(cap.positions, capBefore.positions);
    Mesh tail = walls(-20.0, 20.0, -120.0, -90.0, {-100.0, 0.0, 50.0});
    HairSilhouetteFit options;
    options.behind = false;
    fitHairToSilhouettes(tail, head, frame(), mask(-100.0, 100.0), frame(), mask(-90.0, 90.0), -100.0, options);
    for (const glm::dvec3& p : tail.positions) EXPECT_TRUE(p.z == -120.0 || p.z == -90.0) << p.z;
}

namespace {

// A side photo's hair over the band behind the head (z -110 to -10 at 1 mm a pixel, frame()), from y 50 down to
// `bottom`, and a few stray hair pixels 30 mm under it (a lone curl, noise).
cv::Mat hairBehindDownTo(double bottom) {
    cv::Mat m = cv::Mat::zeros(400, 400, CV_8U);
    m(cv::Range(200 - 50, 200 - static_cast<int>(bottom) + 1), cv::Range(200 - 110, 200 - 10 + 1)).setTo(255);
    m(cv::Range(200 - static_cast<int>(bottom) + 30, 200 - static_cast<int>(bottom) + 33), cv::Range(140, 146)).setTo(255);
    return m;
}

}  // namespace

TEST(HairPart, ABobHangsBehindTheHeadAsFarDownAsTheSidePhotoShowsItsHair) {
    // The head down to the bust's cut at y -130; the bob's back (z -110) and front (z 50, beside the face) down to
    // y -60; the jaw's top at z 20. The photo's hair behind the head ends at y -85.
    const Mesh head = walls(-60.0, 60.0, -80.0, 80.0, {-130.0, 100.0});
    Mesh hair = walls(-90.0, 90.0, -110.0, 50.0, {-60.0, 0.0, 50.0});
    const Mesh before = hair;
    const HairLength length = fitHairLengthBehind(hair, head, frame(), hairBehindDownTo(-85.0), 20.0);
    ASSERT_TRUE(length.measured);
    EXPECT_NEAR(length.photoBottom, -85.0, 1.0);
    EXPECT_NEAR(length.avatarBottom, -60.0, 1e-9);
    EXPECT_NEAR(length.factor, 85.0 / 60.0, 0.02);
    for (std::size_t i = 0; i < hair.positions.size(); ++i) {
        const glm::dvec3& p = hair.positions[i];
        const glm::dvec3& q = before.positions[i];
        EXPECT_EQ(p.x, q.x) << i;
        EXPECT_EQ(p.z, q.z) << i;
        if (q.y >= 0.0 || q.z >= 20.0) EXPECT_EQ(p.y, q.y) << i;  // over the ear holes, and the locks beside the face
        else EXPECT_NEAR(p.y, -85.0, 1.0) << i;                    // the back's ends, to the photo's
    }

    // Shorter in the photo: measured, but the hair is only ever lengthened (HairLengthFit::minFactor); far longer:
    // no further than the factor's limit.
    Mesh shorter = before;
    const HairLength up = fitHairLengthBehind(shorter, head, frame(), hairBehindDownTo(-50.0), 20.0);
    EXPECT_NEAR(up.photoBottom, -50.0, 1.0);
    EXPECT_EQ(up.factor, 1.0);
    EXPECT_EQ(shorter.positions, before.positions);
    Mesh longer = before;
    const HairLength capped = fitHairLengthBehind(longer, head, frame(), hairBehindDownTo(-125.0), 20.0);
    EXPECT_EQ(capped.factor, HairLengthFit{}.maxFactor);
    EXPECT_NEAR(longer.positions[0].y, -60.0 * HairLengthFit{}.maxFactor, 1e-9);

    // No hair behind the head in the photo (or no mask): nothing is measured and nothing moves.
    Mesh untouched = before;
    EXPECT_FALSE(fitHairLengthBehind(untouched, head, frame(), cv::Mat::zeros(400, 400, CV_8U), 20.0).measured);
    EXPECT_FALSE(fitHairLengthBehind(untouched, head, frame(), cv::Mat(), 20.0).measured);
    EXPECT_EQ(untouched.positions, before.positions);
}

namespace {

// Two layers of hair beside the head on the +x side, flat sheets at x 80 (inner) and 84 (outer) over y -20..30 and
// z -25..20; on the -x side none.
Mesh hairSheetsOverTheLeftEar() {
    Mesh m;
    for (const double x : {80.0, 84.0}) {
        const auto first = static_cast<std::uint32_t>(m.positions.size());
        m.positions.insert(m.positions.end(), {{x, -20.0, -25.0}, {x, -20.0, 20.0}, {x, 30.0, 20.0}, {x, 30.0, -25.0}});
        m.triangles.emplace_back(first, first + 1, first + 2);
        m.triangles.emplace_back(first, first + 2, first + 3);
    }
    return m;
}

}  // namespace

TEST(HairPart, AnEarStandingOutThroughTheHairIsTuckedUnderItsInnermostLayer) {
    const Mesh hair = hairSheetsOverTheLeftEar();
    Mesh head;
    head.positions = {
        {86.0, 0.0, -5.0},   // the ear's rim, out through both layers
        {81.0, 10.0, 5.0},   // just through the inner layer
        {78.0, 10.0, 5.0},   // 2 mm under it: already under the hair
        {86.0, 0.0, 25.0},   // beyond the sheets (and ahead of the jaw's top, at z 22): no hair over it
        {86.0, 40.0, -5.0},  // over the sheets
        {-86.0, 0.0, -5.0},  // the other ear: no hair on that side
        {86.0, 60.0, -5.0},  // out of the ears' window (45 mm over the ear holes)
    };
    const Mesh before = head;
    EXPECT_EQ(tuckEarsUnderHair(head, hair, 22.0), 2);
    EXPECT_DOUBLE_EQ(head.positions[0].x, 80.0 - 1.5);
    EXPECT_DOUBLE_EQ(head.positions[1].x, 80.0 - 1.5);
    // Only sideways.
    EXPECT_EQ(head.positions[0].y, before.positions[0].y);
    EXPECT_EQ(head.positions[0].z, before.positions[0].z);
    for (const std::size_t k : {2u, 3u, 4u, 5u, 6u}) EXPECT_EQ(head.positions[k], before.positions[k]) << k;
}

TEST(HairPart, NothingAheadOfTheJawsTopIsTucked) {
    const Mesh hair = hairSheetsOverTheLeftEar();
    Mesh head;
    // Over the sheets, but ahead of a jaw's top at z 0 (a cheek beside hair that keepFaceClear put under the skin).
    head.positions = {{86.0, 0.0, 5.0}, {86.0, 0.0, -5.0}};
    EXPECT_EQ(tuckEarsUnderHair(head, hair, 0.0), 1);
    EXPECT_EQ(head.positions[0].x, 86.0);
    EXPECT_DOUBLE_EQ(head.positions[1].x, 78.5);
    // The same on the -x side, mirrored.
    Mesh mirrored = hair;
    for (glm::dvec3& p : mirrored.positions) p.x = -p.x;
    Mesh other;
    other.positions = {{-86.0, 0.0, -5.0}};
    EXPECT_EQ(tuckEarsUnderHair(other, mirrored, 0.0), 1);
    EXPECT_DOUBLE_EQ(other.positions[0].x, -78.5);
}

namespace {

// A flat sheet at x = `x` over z0..z1, y0..y1, a vertex every `step` mm, triangulated (facing either way: the tuck
// looks at it from the side it is on).
void addSheet(Mesh& m, double x, double z0, double z1, double y0, double y1, double step) {
    const auto first = static_cast<std::uint32_t>(m.positions.size());
    const int cols = static_cast<int>(std::lround((z1 - z0) / step)) + 1, rows = static_cast<int>(std::lround((y1 - y0) / step)) + 1;
    for (int r = 0; r < rows; ++r)
        for (int c = 0; c < cols; ++c) m.positions.emplace_back(x, y0 + r * step, z0 + c * step);
    for (int r = 0; r + 1 < rows; ++r)
        for (int c = 0; c + 1 < cols; ++c) {
            const auto a = first + static_cast<std::uint32_t>(r * cols + c);
            const auto cols32 = static_cast<std::uint32_t>(cols);
            m.triangles.emplace_back(a, a + 1, a + cols32 + 1);
            m.triangles.emplace_back(a, a + cols32 + 1, a + cols32);
        }
}

}  // namespace

TEST(HairPart, HairUnderTheSkinDoesNotCountAndTheHeadsSideKeepsItsShape) {
    // The head's left side a wall at x 75 round the ears' window, with an ear standing out 11 mm from it (z -10..10,
    // y -10..20); bob02 on the fitted head of FRMDB 008 had a layer 20-30 mm under the skin beside the ear, and the
    // head pressed in under it showed as a dent down the cheek.
    Mesh head;
    addSheet(head, 75.0, -70.0, 40.0, -70.0, 70.0, 5.0);
    const auto earFirst = head.positions.size();
    addSheet(head, 86.0, -10.0, 10.0, -10.0, 20.0, 5.0);
    const auto earEnd = head.positions.size();
    // Hair: a layer deep under the skin (x 50) and the visible one outside it (x 84).
    Mesh hair;
    addSheet(hair, 50.0, -40.0, 40.0, -45.0, 50.0, 10.0);
    addSheet(hair, 84.0, -40.0, 40.0, -45.0, 50.0, 10.0);
    const Mesh before = head;
    EXPECT_EQ(tuckEarsUnderHair(head, hair, 30.0), static_cast<int>(earEnd - earFirst));
    for (std::size_t k = 0; k < head.positions.size(); ++k) {
        if (k >= earFirst && k < earEnd) EXPECT_DOUBLE_EQ(head.positions[k].x, 84.0 - 1.5) << "the ear goes under the visible hair";
        else EXPECT_EQ(head.positions[k], before.positions[k]) << "the head's side stays, vertex " << k;
    }
    // Hair lying 1 mm under the head's side (within EarTuck::hiddenDepth) counts: the ear goes down to the side, no
    // further, and the side stays.
    Mesh close;
    addSheet(close, 74.0, -40.0, 40.0, -45.0, 50.0, 10.0);
    head = before;
    tuckEarsUnderHair(head, close, 30.0);
    for (std::size_t k = 0; k < head.positions.size(); ++k)
        EXPECT_DOUBLE_EQ(head.positions[k].x, 75.0) << "vertex " << k;
}

namespace {

// A front photo at 0.5 mm a pixel with its middle brow points 19 and 24 at row 200, columns 100 and 140.
std::array<cv::Point2d, 68> browsAtRow200() {
    std::array<cv::Point2d, 68> points{};
    points[19] = {100.0, 200.0};
    points[24] = {140.0, 200.0};
    return points;
}

PhotoFrame halfMillimetrePixels() {
    PhotoFrame f;
    f.mmPerPixel = 0.5;
    return f;
}

}  // namespace

TEST(HairPart, TheForeheadShownIsMeasuredFromTheBrowsToTheHairline) {
    cv::Mat hair(400, 300, CV_8U, cv::Scalar(0));
    hair.rowRange(0, 151).setTo(255);  // hair down to row 150: 50 rows, 25 mm over the brows
    EXPECT_DOUBLE_EQ(foreheadShownMm(hair, browsAtRow200(), halfMillimetrePixels()), 25.0 - 3.0);
    EXPECT_DOUBLE_EQ(foreheadShownMm(hair, browsAtRow200(), halfMillimetrePixels(), 0.0), 25.0);
    // A stray hair pixel (under 2 mm of hair) on the forehead is no hairline.
    hair.at<std::uint8_t>(180, 120) = 255;
    hair.at<std::uint8_t>(179, 120) = 255;
    EXPECT_DOUBLE_EQ(foreheadShownMm(hair, browsAtRow200(), halfMillimetrePixels(), 0.0), 25.0);
}

TEST(HairPart, AFringeOnTheBrowsOrNoHairlineShowsNoForehead) {
    cv::Mat fringe(400, 300, CV_8U, cv::Scalar(0));
    fringe.rowRange(0, 201).setTo(255);
    EXPECT_DOUBLE_EQ(foreheadShownMm(fringe, browsAtRow200(), halfMillimetrePixels()), 0.0);
    // No hair over most of the forehead's columns (a bald crown): nothing is said.
    cv::Mat bald(400, 300, CV_8U, cv::Scalar(0));
    bald(cv::Rect(100, 0, 10, 150)).setTo(255);
    EXPECT_DOUBLE_EQ(foreheadShownMm(bald, browsAtRow200(), halfMillimetrePixels()), 0.0);
    EXPECT_DOUBLE_EQ(foreheadShownMm(cv::Mat(), browsAtRow200(), halfMillimetrePixels()), 0.0);
}

TEST(HairPart, OverTheForeheadShownTheFaceIsKeptClearToo) {
    const Face f = face();  // brows' lowest point at y 40, the jaw's plane at z 12
    Mesh hair;
    hair.positions = {{0.0, 60.0, 62.0}};  // a fringe 20 mm over the brows
    FaceClearance clear;
    clear.above = 30.0;
    keepFaceClear(hair, f.base, f.head, clear);
    EXPECT_NEAR(hair.positions[0].z, 12.0 + 10.0 * (1.0 - std::exp(-5.0)), 1e-9);
}

namespace {

// A latitude-longitude sphere of the given radius about the origin (y up), its rings from the top down to `lowestY`.
Mesh sphere(double radius, double lowestY, int rings = 36, int segments = 72) {
    Mesh m;
    std::vector<int> kept;
    for (int r = 1; r < rings; ++r) {
        const double polar = M_PI * r / rings;
        if (radius * std::cos(polar) < lowestY) break;
        for (int s = 0; s < segments; ++s) {
            const double az = 2.0 * M_PI * s / segments;
            m.positions.emplace_back(radius * std::sin(polar) * std::sin(az), radius * std::cos(polar),
                                     radius * std::sin(polar) * std::cos(az));
        }
        kept.push_back(r);
    }
    const auto at = [&](int ring, int s) { return static_cast<std::uint32_t>(ring * segments + (s % segments)); };
    for (int ring = 0; ring + 1 < static_cast<int>(kept.size()); ++ring)
        for (int s = 0; s < segments; ++s) {
            m.triangles.emplace_back(at(ring, s), at(ring + 1, s), at(ring + 1, s + 1));
            m.triangles.emplace_back(at(ring, s), at(ring + 1, s + 1), at(ring, s + 1));
        }
    return m;
}

// Photos of a round head of radius 90 at 1 mm per pixel (frame()): the person a disc, hair over head height `hairFromY`.
HairPhotoMasks roundHeadPhotos(double hairFromY) {
    HairPhotoMasks p;
    p.front = p.side = frame();
    p.frontPerson = cv::Mat::zeros(400, 400, CV_8U);
    cv::circle(p.frontPerson, {200, 200}, 90, cv::Scalar(255), cv::FILLED);
    p.sidePerson = p.frontPerson.clone();
    p.frontHair = p.frontPerson.clone();
    p.frontHair.rowRange(static_cast<int>(200 - hairFromY), 400).setTo(0);
    p.sideHair = p.frontHair.clone();
    return p;
}

}  // namespace

TEST(HairPart, ShortHairGoesWhereThePhotosShowSkinAndStaysWhereTheyShowHair) {
    const Mesh head = sphere(90.0, -200.0);
    Mesh hair = sphere(91.5, -60.0);
    const std::size_t before = hair.positions.size();
    std::size_t over40 = 0;
    for (const auto& p : hair.positions) over40 += p.y > 40.0;
    const int gone = trimShortHairToPhotos(hair, head, roundHeadPhotos(20.0));
    EXPECT_EQ(static_cast<std::size_t>(gone) + hair.positions.size(), before);
    std::size_t kept40 = 0;
    for (const auto& p : hair.positions) {
        // Below the photos' hair, with the share's spread and the strands' smoothing, no hair is left.
        EXPECT_GT(p.y, 5.0) << p.x << " " << p.y << " " << p.z;
        kept40 += p.y > 40.0;
    }
    EXPECT_EQ(kept40, over40) << "the hair the photos show stays";
    for (const auto& t : hair.triangles)
        for (int k = 0; k < 3; ++k) EXPECT_LT(t[k], hair.positions.size());
}

TEST(HairPart, AStrandCardCutInPartGoesWhole) {
    const Mesh head = sphere(90.0, -200.0);
    // A card of 3 x 4 vertices hanging down the back from y 40 to -20, 2 mm off the scalp: its lower end is on skin.
    Mesh card;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 3; ++c) {
            const double y = 40.0 - 20.0 * r, x = -5.0 + 5.0 * c;
            card.positions.emplace_back(x, y, -std::sqrt(92.0 * 92.0 - x * x - y * y));
        }
    for (std::uint32_t r = 0; r < 3; ++r)
        for (std::uint32_t c = 0; c < 2; ++c) {
            const std::uint32_t a = 3 * r + c;
            card.triangles.emplace_back(a, a + 3, a + 4);
            card.triangles.emplace_back(a, a + 4, a + 1);
        }
    EXPECT_EQ(trimShortHairToPhotos(card, head, roundHeadPhotos(20.0)), 12);
    EXPECT_TRUE(card.positions.empty());
    EXPECT_TRUE(card.triangles.empty());
}

// Photos showing hair all over the head: no spot reads as skin. Of two strand cards down the back, the one lying
// 1 mm off the scalp stays; the one hanging straight down from 5 mm behind the head reaches out of the side
// photo's outline (the head's disc) and goes whole.
TEST(HairPart, AStrandCardReachingOutOfThePhotosOutlineGoesWhole) {
    const Mesh head = sphere(90.0, -200.0);
    Mesh cards;
    const auto addCard = [&](const std::function<glm::dvec3(double x, int row)>& at) {
        const auto base = static_cast<std::uint32_t>(cards.positions.size());
        for (int r = 0; r < 4; ++r)
            for (int c = 0; c < 3; ++c) cards.positions.push_back(at(-5.0 + 5.0 * c, r));
        for (std::uint32_t r = 0; r < 3; ++r)
            for (std::uint32_t c = 0; c < 2; ++c) {
                const std::uint32_t a = base + 3 * r + c;
                cards.triangles.emplace_back(a, a + 3, a + 4);
                cards.triangles.emplace_back(a, a + 4, a + 1);
            }
    };
    addCard([](double x, int row) {  // on the scalp: y 40 to -20
        const double y = 40.0 - 20.0 * row;
        return glm::dvec3(x, y, -std::sqrt(91.0 * 91.0 - x * x - y * y));
    });
    addCard([](double x, int row) { return glm::dvec3(x, -25.0 * row, -95.0); });  // hanging free: y 0 to -75
    Mesh withoutTheRule = cards;
    HairTrim anywhere;
    anywhere.outside = 1e9;
    EXPECT_EQ(trimShortHairToPhotos(withoutTheRule, head, roundHeadPhotos(-100.0), anywhere), 0)
        << "only the outline should take the hanging card";
    EXPECT_EQ(trimShortHairToPhotos(cards, head, roundHeadPhotos(-100.0)), 12);
    ASSERT_EQ(cards.positions.size(), 12u);
    for (const auto& p : cards.positions) EXPECT_GT(p.y, -25.0) << "the card on the scalp stays";
    EXPECT_EQ(cards.triangles.size(), 12u);
}

// A haircut of two layers, 5 and 10 mm off a round head of radius 90, in photos whose outline is a disc of radius
// 92: where a photo sees a layer's edge, it comes in to the outline (within the margin and a pixel); where neither
// photo sees it edge-on (between the views) it stays; the layers keep their order without meeting, and nothing goes
// nearer the scalp than the least offset.
TEST(HairPart, ShortHairStandingOutOfThePhotosOutlinesComesInKeepingItsLayers) {
    const Mesh head = sphere(90.0, -200.0);
    Mesh hair = sphere(95.0, -60.0);
    const Mesh outer = sphere(100.0, -60.0);
    const auto innerCount = static_cast<std::uint32_t>(hair.positions.size());
    for (const auto& p : outer.positions) hair.positions.push_back(p);
    for (const auto& t : outer.triangles) hair.triangles.push_back(t + glm::uvec3(innerCount));
    HairPhotoMasks photos = roundHeadPhotos(-100.0);
    photos.frontPerson.setTo(0);
    cv::circle(photos.frontPerson, {200, 200}, 92, cv::Scalar(255), cv::FILLED);
    photos.sidePerson = photos.frontPerson.clone();
    const Mesh before = hair;
    const int moved = pullShortHairIntoOutlines(hair, head, photos);
    EXPECT_GT(moved, 100);
    ASSERT_EQ(hair.positions.size(), before.positions.size());
    int keptBetween = 0;
    for (std::size_t i = 0; i < hair.positions.size(); ++i) {
        const glm::dvec3& p = hair.positions[i];
        const glm::dvec3& was = before.positions[i];
        EXPECT_LE(glm::length(glm::dvec2(p.x, p.y)), 92.0 + 1.0 + 1.5) << "out of the front photo's outline: " << i;
        EXPECT_LE(glm::length(glm::dvec2(p.z, p.y)), 92.0 + 1.0 + 1.5) << "out of the side photo's outline: " << i;
        EXPECT_GE(glm::length(p), 90.5 - 1e-6) << "under the least offset: " << i;
        EXPECT_NEAR(glm::length(glm::cross(glm::normalize(p), glm::normalize(was))), 0.0, 0.02) << "not along the normal";
        // Half-way between the front and the side view, at the equator, neither photo sees the hair's edge.
        if (std::abs(p.y) < 10.0 && std::abs(std::abs(was.x) - std::abs(was.z)) < 5.0) {
            EXPECT_EQ(p, was) << i;
            ++keptBetween;
        }
    }
    EXPECT_GT(keptBetween, 0);
    for (std::uint32_t i = 0; i < innerCount; ++i)
        EXPECT_GT(glm::length(hair.positions[innerCount + i]), glm::length(hair.positions[i]) + 0.1)
            << "the outer layer met or went under the inner one at " << i;
    Mesh unchanged = before;
    HairPhotoMasks none = photos;
    none.sidePerson = cv::Mat();
    EXPECT_EQ(pullShortHairIntoOutlines(unchanged, head, none), 0);
    EXPECT_EQ(unchanged.positions, before.positions);
}

TEST(HairPart, WithoutThePhotosMasksTheShortHairIsKeptAndBadMasksAreAnInternalError) {
    const Mesh head = sphere(90.0, -200.0);
    Mesh hair = sphere(91.5, -60.0);
    const Mesh original = hair;
    HairPhotoMasks none = roundHeadPhotos(20.0);
    none.sideHair = cv::Mat();
    EXPECT_EQ(trimShortHairToPhotos(hair, head, none), 0);
    EXPECT_EQ(hair.positions.size(), original.positions.size());
    HairPhotoMasks wrong = roundHeadPhotos(20.0);
    wrong.frontHair.convertTo(wrong.frontHair, CV_32F);
    try {
        trimShortHairToPhotos(hair, head, wrong);
        FAIL() << "a float mask was taken";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Internal);
    }
}

namespace {

// The side photo's hair (in the frame of frame(), face to the right): hair behind z `edge` from y -40 up, none ahead
// of it (the bare cheek and ear); nothing at all under y -40 (the shoulders' clothes).
cv::Mat hairBehind(double edge) {
    cv::Mat m = cv::Mat::zeros(400, 400, CV_8U);
    m(cv::Rect(0, 0, static_cast<int>(edge) + 200, 241)).setTo(255);
    return m;
}

SideFaceClearance cheeks() {
    SideFaceClearance c;
    c.topY = 40.0;
    c.bottomY = -60.0;
    c.frontZ = 60.0;
    c.innerX = 40.0;
    return c;
}

}  // namespace

TEST(HairPart, HairOverTheBareSideOfTheFaceGoesBehindTheSidePhotosHairKeepingItsOrder) {
    // Locks on both sides of the face (x +-75, beyond innerX + sideRamp) from z -40 to 40 at every height from -80 to
    // 70, and a fringe's strand at x 10; the photo's hair begins 10 mm behind the ear holes.
    Mesh hair;
    for (const double x : {-75.0, 10.0, 75.0})
        for (double y = -80.0; y <= 70.0; y += 5.0)
            for (double z = -40.0; z <= 40.0; z += 5.0) hair.positions.emplace_back(x, y, z);
    const Mesh before = hair;
    const SideFaceClearance o = cheeks();
    const int moved = tuckHairBehindTheFace(hair, frame(), hairBehind(-10.0), o);
    EXPECT_GT(moved, 0);
    const double edge = -10.0 - o.margin;  // where the tucked hair ends (the photo's pixels: within 1 mm)
    for (std::size_t i = 0; i < hair.positions.size(); ++i) {
        const glm::dvec3& p = hair.positions[i];
        const glm::dvec3& q = before.positions[i];
        EXPECT_EQ(p.x, q.x) << i;
        EXPECT_EQ(p.y, q.y) << i;
        EXPECT_LE(p.z, q.z) << i;  // only ever back
        const bool tucked = std::abs(q.x) > o.innerX + o.sideRamp && q.y >= -40.0 && q.y <= o.topY - o.ramp && q.z > edge - o.band + 1.0;
        if (std::abs(q.x) < o.innerX || q.y > o.topY || q.y < -40.0 || q.z <= edge - 3.0 * o.band) {
            // The fringe, over the heights read, where the photo shows no hair (no edge), and far enough behind it.
            EXPECT_NEAR(p.z, q.z, q.z <= edge - 3.0 * o.band ? 0.2 : 0.0) << i;
        } else if (tucked) {
            EXPECT_LE(p.z, edge + 1.0) << i;  // behind the photo's hair edge
            EXPECT_GT(p.z, edge - o.band - 1.0) << i;
        }
    }
    // The strands keep their order along each row: z' rises with z (no triangle turns over).
    for (std::size_t i = 1; i < hair.positions.size(); ++i) {
        if (before.positions[i].x == before.positions[i - 1].x && before.positions[i].y == before.positions[i - 1].y) {
            EXPECT_GT(hair.positions[i].z, hair.positions[i - 1].z) << i;
        }
    }

    // No photo, or one that shows hair ahead of the face's side (hair over the ears): nothing moves.
    Mesh untouched = before;
    EXPECT_EQ(tuckHairBehindTheFace(untouched, frame(), cv::Mat(), o), 0);
    EXPECT_EQ(tuckHairBehindTheFace(untouched, frame(), hairBehind(60.0), o), 0);
    EXPECT_EQ(untouched.positions, before.positions);
}
