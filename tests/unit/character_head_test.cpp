// The character head without MakeHuman's modifiers (the built-in head: the base head itself, with a warning),
// exaggeration and clamping of the target, the toon texture and its tint, colours from a photo. The character on
// the MakeHuman head (its modifiers) is tests/data/character_makehuman_data_test.cpp.
#include "reveal/character/character_head.h"
#include "fit/head/surface_texels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

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

TEST(CharacterHead, WithoutAModifierBasisTheCharacterIsTheBaseHead) {
    // The built-in head has no MakeHuman modifiers: the character keeps its shape, says so, and is still painted.
    CharacterProportions target = baseProportions();
    target.r[2] = 0.19;
    const CharacterHead same = makeCharacterHead(builtinBaseHead(), target, quick());
    EXPECT_EQ(same.mesh.positions, builtinBaseHead().mesh.positions);
    EXPECT_EQ(same.mesh.triangles, builtinBaseHead().mesh.triangles);
    EXPECT_EQ(same.mesh.uvs, builtinBaseHead().mesh.uvs);
    EXPECT_TRUE(same.modifiers.empty());
    ASSERT_EQ(same.warnings.size(), 1u);
    EXPECT_NE(same.warnings[0].find("no modifier basis"), std::string::npos);
    EXPECT_DOUBLE_EQ(same.target.r[2], 0.19);
    EXPECT_DOUBLE_EQ(same.achieved.r[2], baseProportions().r[2]);
    EXPECT_EQ(same.texture.size(), cv::Size(64, 64));
}

TEST(CharacterHead, ExaggerationAndClampingOfTheTarget) {
    CharacterProportions wanted = baseProportions();
    wanted.r[6] = baseProportions().r[6] + 0.03;
    wanted.r[2] = 5.0;  // far outside the slider range
    CharacterSettings s = quick();
    s.exaggeration = 2.0;
    const CharacterHead h = makeCharacterHead(builtinBaseHead(), wanted, s);
    EXPECT_NEAR(h.target.r[6], baseProportions().r[6] + 0.06, 1e-12);
    EXPECT_DOUBLE_EQ(h.target.r[2], 0.22);  // clamped to the eye_size slider's top
    // A slider left out keeps the base head's value.
    s.sliders = std::set<std::string>{"eye_size"};
    EXPECT_DOUBLE_EQ(makeCharacterHead(builtinBaseHead(), wanted, s).target.r[6], baseProportions().r[6]);
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

TEST(CharacterHead, ToonSkinIsTintedByTheSkinColour) {
    // A toon skin of two halves: white (toon01's own colour) and mid grey. The skin colour multiplies it.
    cv::Mat toon(128, 128, CV_8UC3, cv::Scalar(255, 255, 255));
    toon.colRange(64, 128).setTo(cv::Scalar(128, 128, 128));
    CharacterLook look;
    look.skin = cv::Scalar(100, 150, 200);
    const cv::Mat tex = paintCharacterTexture(builtinBaseHead(), 128, look, toon);
    const cv::Mat plain = paintCharacterTexture(builtinBaseHead(), 128, look);
    const Mesh& mesh = builtinBaseHead().mesh;
    const cv::Mat covered = sampleSurfaceTexels(mesh, mesh.vertexNormals(), tex.size()).covered;
    int white = 0, grey = 0;
    for (int y = 0; y < tex.rows; ++y)
        for (int x = 0; x < tex.cols; ++x) {
            // Skin texels only: not the painted parts, nor the border padding (which mixes its neighbours).
            if (!covered.at<unsigned char>(y, x) || plain.at<cv::Vec3b>(y, x) != cv::Vec3b(100, 150, 200)) continue;
            const cv::Vec3b c = tex.at<cv::Vec3b>(y, x);
            if (x < 64) {
                EXPECT_EQ(c, cv::Vec3b(100, 150, 200)) << x << "," << y;
                ++white;
            } else {
                EXPECT_EQ(c, cv::Vec3b(50, 75, 100)) << x << "," << y;  // 128/255 of it, rounded
                ++grey;
            }
        }
    EXPECT_GT(white, 100);
    EXPECT_GT(grey, 100);
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
