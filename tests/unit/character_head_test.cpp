// The character head: its parts follow the proportions it is given (measured back the way a photo is), a bigger
// eye ratio gives measurably bigger eyes, exaggeration and clamping, the toon texture, colours from a photo.
#include "reveal/character/character_head.h"
#include "common/landmark_names.h"

#include <gtest/gtest.h>

#include <cmath>

namespace avatarbooth {
namespace {

CharacterSettings quick() {
    CharacterSettings s;
    s.textureSize = 64;  // the texture does not matter here
    return s;
}

const CharacterProportions& baseProportions() {
    static const CharacterProportions p = [] {
        const BaseHead& base = builtinBaseHead();
        return measureHead(base.mesh, base, base.earHoleCentre).proportions;
    }();
    return p;
}

glm::dvec3 featureOf(const Mesh& mesh, int k) {
    return mesh.positions[builtinBaseHead().frontFeatures.at(landmarkName(k))];
}

void expectMeasures(const CharacterProportions& achieved, const CharacterProportions& target) {
    for (std::size_t i = 0; i < 8; ++i) EXPECT_NEAR(achieved.r[i], target.r[i], 0.004) << "r" << i;
    EXPECT_NEAR(achieved.eyeSpacing, target.eyeSpacing, 0.004);
    EXPECT_NEAR(achieved.eyeTiltDeg, target.eyeTiltDeg, 0.5);
    EXPECT_NEAR(achieved.browTiltDeg, target.browTiltDeg, 0.5);
}

TEST(CharacterHead, EveryPartFollowsItsParameter) {
    CharacterProportions target = baseProportions();
    target.r[0] = 1.45;
    target.r[2] = 0.19;
    target.r[3] = 0.16;
    target.r[4] = 0.30;
    target.r[5] = 0.17;
    target.r[6] = 0.25;
    target.r[7] = 0.42;
    target.eyeSpacing = 0.40;
    target.eyeTiltDeg = 8.0;
    target.browTiltDeg = 10.0;
    const CharacterHead up = makeCharacterHead(builtinBaseHead(), target, quick());
    expectMeasures(up.target, target);
    expectMeasures(up.achieved, target);

    target = baseProportions();
    target.r[0] = 1.15;
    target.r[2] = 0.11;
    target.r[3] = 0.08;
    target.r[4] = 0.38;
    target.r[5] = 0.10;
    target.r[6] = 0.19;
    target.r[7] = 0.33;
    target.eyeSpacing = 0.32;
    target.eyeTiltDeg = -6.0;
    target.browTiltDeg = -15.0;
    expectMeasures(makeCharacterHead(builtinBaseHead(), target, quick()).achieved, target);
}

TEST(CharacterHead, ABiggerEyeRatioGivesBiggerEyes) {
    CharacterProportions small = baseProportions(), big = baseProportions();
    small.r[2] = 0.8 * baseProportions().r[2];
    big.r[2] = 1.3 * baseProportions().r[2];
    const CharacterHead a = makeCharacterHead(builtinBaseHead(), small, quick());
    const CharacterHead b = makeCharacterHead(builtinBaseHead(), big, quick());
    const auto eyeWidth = [](const Mesh& m) {
        return 0.5 * (glm::distance(glm::dvec2(featureOf(m, 36)), glm::dvec2(featureOf(m, 39))) +
                      glm::distance(glm::dvec2(featureOf(m, 42)), glm::dvec2(featureOf(m, 45))));
    };
    const auto eyeHeight = [](const Mesh& m) { return featureOf(m, 37).y - featureOf(m, 41).y; };
    // The face width barely changes, so the eyes' width grows by about 1.3 / 0.8.
    EXPECT_NEAR(eyeWidth(b.mesh) / eyeWidth(a.mesh), 1.3 / 0.8, 0.05);
    EXPECT_GT(eyeHeight(b.mesh), 1.4 * eyeHeight(a.mesh));
    EXPECT_NEAR(b.achieved.r[2] / a.achieved.r[2], 1.3 / 0.8, 0.02);
}

TEST(CharacterHead, TheBaseHeadsOwnProportionsLeaveItAsItIs) {
    const CharacterHead same = makeCharacterHead(builtinBaseHead(), baseProportions(), quick());
    double worst = 0.0;
    for (std::size_t v = 0; v < same.mesh.positions.size(); ++v)
        worst = std::max(worst, glm::distance(same.mesh.positions[v], builtinBaseHead().mesh.positions[v]));
    EXPECT_LT(worst, 0.5);  // millimetres
    EXPECT_EQ(same.mesh.triangles, builtinBaseHead().mesh.triangles);
    EXPECT_EQ(same.mesh.uvs, builtinBaseHead().mesh.uvs);
}

TEST(CharacterHead, ExaggerationAndClamping) {
    CharacterProportions wanted = baseProportions();
    wanted.r[6] = baseProportions().r[6] + 0.03;
    wanted.r[2] = 5.0;  // far outside the slider range
    CharacterSettings s = quick();
    s.exaggeration = 2.0;
    const CharacterHead h = makeCharacterHead(builtinBaseHead(), wanted, s);
    EXPECT_NEAR(h.target.r[6], baseProportions().r[6] + 0.06, 1e-12);
    EXPECT_DOUBLE_EQ(h.target.r[2], 0.22);  // clamped to the eye_size slider's top
    EXPECT_NEAR(h.achieved.r[6], h.target.r[6], 0.004);
}

TEST(CharacterHead, ToonTextureUsesTheLooksFlatColours) {
    CharacterLook look;
    look.skin = cv::Scalar(100, 150, 200);
    look.hair = cv::Scalar(20, 60, 140);
    const cv::Mat tex = paintCharacterTexture(builtinBaseHead(), 256, look);
    ASSERT_EQ(tex.size(), cv::Size(256, 256));
    int skin = 0, hair = 0, other = 0;
    for (int y = 0; y < tex.rows; ++y)
        for (int x = 0; x < tex.cols; ++x) {
            const cv::Vec3b c = tex.at<cv::Vec3b>(y, x);
            if (c == cv::Vec3b(100, 150, 200)) ++skin;
            else if (c == cv::Vec3b(20, 60, 140)) ++hair;
            else ++other;
        }
    const double n = static_cast<double>(tex.total());
    EXPECT_GT(skin / n, 0.3);
    EXPECT_GT(hair / n, 0.15);
    EXPECT_GT(other, 0);  // eyes, brows, lips, blush
}

TEST(CharacterHead, ColoursFromAPhoto) {
    // A front photo of flat colours: skin everywhere, hair over the top rows.
    cv::Mat photo(300, 200, CV_8UC3, cv::Scalar(90, 120, 200));
    photo.rowRange(0, 80).setTo(cv::Scalar(30, 40, 50));
    cv::Mat mask = cv::Mat::zeros(300, 200, CV_8U);
    mask(cv::Rect(20, 0, 161, 300)).setTo(255);
    std::array<cv::Point2d, 68> p{};
    for (int k = 0; k < 68; ++k) p[static_cast<std::size_t>(k)] = {100.0, 160.0};
    for (int k = 17; k <= 26; ++k) p[static_cast<std::size_t>(k)] = {40.0 + 13.0 * (k - 17), 100.0};  // brows
    p[33] = {100.0, 130.0};                                                                           // nose base
    p[36] = {55, 110}; p[39] = {77, 110}; p[42] = {123, 110}; p[45] = {145, 110};
    p[41] = {62, 114}; p[46] = {138, 114}; p[48] = {80, 170}; p[54] = {120, 170};
    const CharacterLook look = lookFromPhoto(photo, p, mask);
    EXPECT_EQ(look.skin, cv::Scalar(90, 120, 200));
    EXPECT_EQ(look.hair, cv::Scalar(30, 40, 50));  // brow line 100, up 30 px per unit: samples at y 55..64 +- 10
    // Nothing to sample (no mask): the default hair colour stays.
    EXPECT_EQ(lookFromPhoto(photo, p, cv::Mat()).hair, CharacterLook{}.hair);
}

}  // namespace
}  // namespace avatarbooth
