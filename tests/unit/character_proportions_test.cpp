// Narita's ratios on hand-made point sets whose every length was worked out by hand, and on rotated, translated
// and scaled copies of them (the ratios and tilts must not change); the sliders and character.json.
#include "reveal/character/proportions.h"
#include "common/error.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

namespace avatarbooth {
namespace {

// The face line runs along +x from Pf0 = (0, 0) to Pf1 = (100, 0); image y points down, the chin at +y.
//   l_f0 = 100, l_f1 = 2 * 60 = 120, r0 = 1.2
//   eye centres (30, -0.2) and (70, -0.2): l_e0 = 30, l_e1 = 70, r1 = 100 / 200 = 0.5
//   eye widths along the line 20 and 20: r2 = 40 / 200 = 0.2
//   ear tops 10 and 12 above the line: r3 = 22 / 200 = 0.11; ear heights 35 and 39: r4 = 74 / 200 = 0.37
//   brow inner ends 15 and 17 above: r5 = 32 / 200 = 0.16; nose tip 22 below: r6 = 0.22; mouth 38 below: r7 = 0.38
//   eye spacing 40 / 100 = 0.4; each eye's outer corner 2 above its inner corner over 20: tilt atan(0.1);
//   each brow's outer end 3 below its inner end over 22: tilt -atan(3/22)
NaritaPoints handMade() {
    NaritaPoints p;
    p.f = {cv::Point2d(0, 0), cv::Point2d(100, 0), cv::Point2d(50, 60)};
    p.e = {cv::Point2d(20, -2), cv::Point2d(40, 0), cv::Point2d(30, -5), cv::Point2d(24, 3), cv::Point2d(36, 3),
           cv::Point2d(80, -2), cv::Point2d(60, 0), cv::Point2d(70, -5), cv::Point2d(76, 3), cv::Point2d(64, 3)};
    p.a = {cv::Point2d(-5, -10), cv::Point2d(-4, 25), cv::Point2d(105, -12), cv::Point2d(104, 27)};
    p.b = {cv::Point2d(42, -15), cv::Point2d(58, -17)};
    p.browOuter = {cv::Point2d(20, -12), cv::Point2d(80, -14)};
    p.n = {50, 22};
    p.m = {50, 38};
    return p;
}

NaritaPoints transformed(NaritaPoints p, const std::function<cv::Point2d(cv::Point2d)>& t) {
    for (auto& q : p.f) q = t(q);
    for (auto& q : p.e) q = t(q);
    for (auto& q : p.a) q = t(q);
    for (auto& q : p.b) q = t(q);
    for (auto& q : p.browOuter) q = t(q);
    p.n = t(p.n);
    p.m = t(p.m);
    return p;
}

const double kEyeTilt = std::atan(0.1) * 180.0 / 3.14159265358979323846;
const double kBrowTilt = -std::atan(3.0 / 22.0) * 180.0 / 3.14159265358979323846;

void expectHandMadeRatios(const CharacterProportions& r, double scale) {
    EXPECT_NEAR(r.lf0, 100.0 * scale, 1e-9 * scale);
    EXPECT_NEAR(r.lf1, 120.0 * scale, 1e-9 * scale);
    const std::array<double, 8> expected = {1.2, 0.5, 0.2, 0.11, 0.37, 0.16, 0.22, 0.38};
    for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(r.r[i], expected[i], 1e-12) << "r" << i;
    EXPECT_NEAR(r.eyeSpacing, 0.4, 1e-12);
    EXPECT_NEAR(r.eyeTiltDeg, kEyeTilt, 1e-9);
    EXPECT_NEAR(r.browTiltDeg, kBrowTilt, 1e-9);
}

TEST(CharacterProportions, HandComputedRatios) {
    const CharacterProportions r = computeProportions(handMade());
    EXPECT_DOUBLE_EQ(r.lf0, 100.0);
    EXPECT_DOUBLE_EQ(r.lf1, 120.0);
    EXPECT_DOUBLE_EQ(r.r[0], 1.2);
    EXPECT_DOUBLE_EQ(r.r[1], 0.5);
    EXPECT_DOUBLE_EQ(r.r[2], 0.2);
    EXPECT_DOUBLE_EQ(r.r[3], 0.11);
    EXPECT_DOUBLE_EQ(r.r[4], 0.37);
    EXPECT_DOUBLE_EQ(r.r[5], 0.16);
    EXPECT_DOUBLE_EQ(r.r[6], 0.22);
    EXPECT_DOUBLE_EQ(r.r[7], 0.38);
    EXPECT_DOUBLE_EQ(r.eyeSpacing, 0.4);
    EXPECT_NEAR(r.eyeTiltDeg, 5.710593137499643, 1e-12);
    EXPECT_NEAR(r.browTiltDeg, -7.765166018425308, 1e-12);
}

TEST(CharacterProportions, RotatedTranslatedAndScaledCopiesGiveTheSameRatios) {
    for (const double degrees : {0.0, 17.0, -90.0, 143.0}) {
        for (const double scale : {0.25, 1.0, 7.5}) {
            const double a = degrees * 3.14159265358979323846 / 180.0;
            const auto t = [&](cv::Point2d q) {
                return cv::Point2d(scale * (std::cos(a) * q.x - std::sin(a) * q.y) + 412.5,
                                   scale * (std::sin(a) * q.x + std::cos(a) * q.y) - 37.25);
            };
            SCOPED_TRACE(testing::Message() << degrees << " deg, x" << scale);
            expectHandMadeRatios(computeProportions(transformed(handMade(), t)), scale);
        }
    }
}

// The formulas take absolute values: a point on the far side of Pf0 or of the face line counts by its distance.
// Here the right eye's centre is 10 left of Pf0 (l_e0 = 10, not -10) and the left brow 4 below the line.
TEST(CharacterProportions, AbsoluteValuesAsInTheFormulas) {
    NaritaPoints p = handMade();
    for (std::size_t i = 0; i < 5; ++i) p.e[i].x -= 40.0;  // right eye centre at x = -10
    p.b[1] = {58, 4};
    const CharacterProportions r = computeProportions(p);
    EXPECT_DOUBLE_EQ(r.r[1], (10.0 + 70.0) / 200.0);
    EXPECT_DOUBLE_EQ(r.r[5], (15.0 + 4.0) / 200.0);
    EXPECT_DOUBLE_EQ(r.eyeSpacing, 0.8);
    EXPECT_DOUBLE_EQ(r.r[2], 0.2);  // the eye's width did not change
}

// A second set off the axes: the face line from (10, 20) along (0.6, 0.8) (an image rotated by 53.13 degrees),
// every point placed by its along/across coordinates (a, c): chin (50, 70) -> r0 = 140 / 100.
TEST(CharacterProportions, HandComputedOnATiltedFaceLine) {
    const cv::Point2d o(10, 20), u(0.6, 0.8), n(-0.8, 0.6);  // n: across, towards the chin
    const auto at = [&](double a, double c) { return o + a * u + c * n; };
    NaritaPoints p;
    p.f = {at(0, 0), at(100, 0), at(50, 70)};
    // Eyes: centres at a = 28 and 72 (widths 24 and 20), on the line.
    p.e = {at(16, 0), at(40, 0), at(28, -4), at(22, 2), at(34, 2), at(82, 0), at(62, 0), at(72, -4), at(77, 2), at(67, 2)};
    p.a = {at(-6, -20), at(-5, 14), at(106, -18), at(105, 20)};  // ear tops 20 and 18 above; heights 34 and 38
    p.b = {at(41, -18), at(59, -18)};
    p.browOuter = {at(15, -18), at(85, -18)};  // level brows: tilt 0
    p.n = at(50, 25);
    p.m = at(50, 45);
    const CharacterProportions r = computeProportions(p);
    EXPECT_NEAR(r.lf0, 100.0, 1e-9);
    EXPECT_NEAR(r.r[0], 1.4, 1e-12);
    EXPECT_NEAR(r.r[1], (28.0 + 72.0) / 200.0, 1e-12);
    EXPECT_NEAR(r.r[2], (24.0 + 20.0) / 200.0, 1e-12);
    EXPECT_NEAR(r.r[3], (20.0 + 18.0) / 200.0, 1e-12);
    EXPECT_NEAR(r.r[4], (34.0 + 38.0) / 200.0, 1e-12);
    EXPECT_NEAR(r.r[5], 36.0 / 200.0, 1e-12);
    EXPECT_NEAR(r.r[6], 0.25, 1e-12);
    EXPECT_NEAR(r.r[7], 0.45, 1e-12);
    EXPECT_NEAR(r.eyeSpacing, 0.44, 1e-12);
    EXPECT_NEAR(r.eyeTiltDeg, 0.0, 1e-9);
    EXPECT_NEAR(r.browTiltDeg, 0.0, 1e-9);
}

TEST(CharacterProportions, CoincidingTemplesAreAnError) {
    NaritaPoints p = handMade();
    p.f[1] = p.f[0];
    EXPECT_THROW(computeProportions(p), BoothError);
}

TEST(CharacterProportions, SlidersMapTheDocumentedRanges) {
    const SliderRange& aspect = sliderRanges()[0];
    EXPECT_EQ(aspect.key, "face_aspect");
    EXPECT_DOUBLE_EQ(sliderFromValue(aspect, 1.2), (1.2 - 0.8) / (1.8 - 0.8));
    EXPECT_DOUBLE_EQ(sliderFromValue(aspect, 0.1), 0.0);
    EXPECT_DOUBLE_EQ(sliderFromValue(aspect, 9.0), 1.0);
    EXPECT_DOUBLE_EQ(valueFromSlider(aspect, 0.25), 0.8 + 0.25);
    const auto sliders = slidersOf(computeProportions(handMade()));
    EXPECT_EQ(sliders.size(), 11u);
    EXPECT_DOUBLE_EQ(sliders.at("eye_size"), (0.2 - 0.06) / (0.22 - 0.06));
    EXPECT_DOUBLE_EQ(sliders.at("eye_tilt"), (kEyeTilt + 15.0) / 30.0);
    for (const auto& [key, value] : sliders) {
        EXPECT_GE(value, 0.0) << key;
        EXPECT_LE(value, 1.0) << key;
    }
    CharacterProportions wild = computeProportions(handMade());
    wild.r[2] = 5.0;
    wild.browTiltDeg = -80.0;
    const CharacterProportions clamped = clampToSliderRanges(wild);
    EXPECT_DOUBLE_EQ(clamped.r[2], 0.22);
    EXPECT_DOUBLE_EQ(clamped.browTiltDeg, -30.0);
    EXPECT_DOUBLE_EQ(clamped.r[0], 1.2);
}

TEST(CharacterProportions, JsonHoldsPointsRatiosAndSliders) {
    NaritaMapping mapping;
    mapping.points = handMade();
    mapping.earSource = {"silhouette", "canon"};
    mapping.earPointSource = {"silhouette", "silhouette", "silhouette", "face contour"};
    mapping.earHoleSource = "side photo";
    mapping.warnings = {"the left ear was not found"};
    const nlohmann::json j = characterJson(mapping, computeProportions(mapping.points));
    EXPECT_EQ(j["points"]["Pf1"], nlohmann::json({100.0, 0.0}));
    EXPECT_EQ(j["points"]["Pm"], nlohmann::json({50.0, 38.0}));
    EXPECT_EQ(j["points"].size(), 23u);  // the 21 and the two brow ends
    EXPECT_DOUBLE_EQ(j["lengths_px"]["l_f1"].get<double>(), 120.0);
    EXPECT_DOUBLE_EQ(j["ratios"]["r4"].get<double>(), 0.37);
    EXPECT_DOUBLE_EQ(j["extras"]["eye_spacing"].get<double>(), 0.4);
    EXPECT_DOUBLE_EQ(j["narita_sliders"]["face_aspect"]["value"].get<double>(), 0.4);
    EXPECT_EQ(j["narita_sliders"]["face_aspect"]["range"], nlohmann::json({0.8, 1.8}));
    EXPECT_EQ(j["narita_sliders"].size(), 11u);
    EXPECT_EQ(j["point_sources"]["Pa2, Pa3"], "left ear top and bottom: canon (points on the silhouette, face contour)");
    EXPECT_EQ(j["warnings"].size(), 1u);
}

}  // namespace
}  // namespace avatarbooth
