// The avatar's parts as plain data (fit/parts): a proxy placed by its binding, its files, the tint, the head without
// what a part replaces, the drawing order.
#include "fit/parts/avatar_parts.h"
#include "fit/parts/head_proxy.h"

#include "common/error.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <unistd.h>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// Two triangles over four vertices.
Mesh square() {
    Mesh m;
    m.positions = {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}};
    m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
}

HeadProxy proxyOnSquare() {
    HeadProxy p;
    p.name = "eyebrows";
    p.binding.vertices = {{0, 1, 2}, {1, 2, 3}, {0, 2, 3}};
    p.binding.weights = {{0.5, 0.25, 0.25}, {1.0, 0.0, 0.0}, {0.2, 0.3, 0.5}};
    p.binding.offsets = {{0, 0, 1}, {0.5, -0.5, 2}, {0, 0, 0}};
    p.mesh.uvs = {{0, 0}, {1, 0}, {0, 1}};
    p.mesh.triangles = {{0, 1, 2}};
    p.alpha = AlphaMode::Blend;
    p.texture = cv::Mat(4, 4, CV_8UC4, cv::Scalar(10, 20, 30, 128));
    p.tintMask = cv::Mat(4, 4, CV_8U, cv::Scalar(255));
    p.replaces = {3};
    return p;
}

}  // namespace

TEST(ProxyBinding, PlacesEachVertexByItsWeightsAndOffset) {
    const auto placed = placeProxy(proxyOnSquare().binding, square().positions);
    ASSERT_EQ(placed.size(), 3u);
    // 0.5 (0,0,0) + 0.25 (10,0,0) + 0.25 (10,10,0) + (0,0,1)
    EXPECT_EQ(placed[0], glm::dvec3(5.0, 2.5, 1.0));
    EXPECT_EQ(placed[1], glm::dvec3(10.5, -0.5, 2.0));
    // 0.2 (0,0,0) + 0.3 (10,10,0) + 0.5 (0,10,0)
    EXPECT_NEAR(placed[2].x, 3.0, 1e-12);
    EXPECT_NEAR(placed[2].y, 8.0, 1e-12);
    // A moved head carries the proxy: translated by t, each vertex moves by t (weights sum to 1).
    std::vector<glm::dvec3> moved = square().positions;
    for (auto& p : moved) p += glm::dvec3(1, 2, 3);
    const auto again = placeProxy(proxyOnSquare().binding, moved);
    for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(glm::length(again[i] - placed[i] - glm::dvec3(1, 2, 3)), 0.0, 1e-12);
}

TEST(ProxyBinding, RefusesAVertexPastTheHead) {
    HeadProxy p = proxyOnSquare();
    p.binding.vertices[1][2] = 4;
    EXPECT_THROW(placeProxy(p.binding, square().positions), BoothError);
}

TEST(HeadProxyFiles, RoundTripAndClearErrors) {
    const fs::path dir = fs::temp_directory_path() / ("avatar_parts_" + std::to_string(getpid()));
    fs::create_directories(dir);
    const HeadProxy p = proxyOnSquare();
    const std::string file = saveHeadProxy(p, dir);
    EXPECT_EQ(file, "eyebrows.json");
    const HeadProxy back = loadHeadProxy(dir / file, square().positions);
    EXPECT_EQ(back.name, "eyebrows");
    EXPECT_EQ(back.alpha, AlphaMode::Blend);
    EXPECT_EQ(back.binding.vertices, p.binding.vertices);
    EXPECT_EQ(back.binding.weights, p.binding.weights);
    EXPECT_EQ(back.binding.offsets, p.binding.offsets);
    EXPECT_EQ(back.mesh.triangles, p.mesh.triangles);
    EXPECT_EQ(back.replaces, p.replaces);
    EXPECT_EQ(back.mesh.positions, placeProxy(p.binding, square().positions));
    ASSERT_EQ(back.texture.type(), CV_8UC4);
    EXPECT_EQ(back.texture.at<cv::Vec4b>(1, 1), cv::Vec4b(10, 20, 30, 128));
    EXPECT_EQ(cv::countNonZero(back.tintMask), 16);
    // Held encoded (a hair style waiting to be chosen), the pixels are let go and come back the same.
    HeadProxy waiting = back;
    holdEncoded(waiting);
    EXPECT_TRUE(waiting.texture.empty());
    EXPECT_TRUE(waiting.tintMask.empty());
    const auto [texture, tintMask] = proxyPixels(waiting);
    ASSERT_EQ(texture.type(), CV_8UC4);
    ASSERT_EQ(tintMask.type(), CV_8U);
    EXPECT_EQ(cv::norm(texture, back.texture, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(tintMask, back.tintMask, cv::NORM_INF), 0.0);
    // Bytes that no longer decode name the proxy.
    waiting.encodedTexture = "not a PNG";
    try {
        proxyPixels(waiting);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_NE(std::string(e.what()).find("does not decode"), std::string::npos) << e.what();
    }
    // A binding past a smaller head names the file and the field.
    try {
        loadHeadProxy(dir / file, {{0, 0, 0}, {1, 0, 0}});
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_NE(std::string(e.what()).find("eyebrows.json"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("binding.vertices"), std::string::npos) << e.what();
    }
    fs::remove_all(dir);
}

TEST(AvatarParts, TintKeepsThePatternAndAlpha) {
    cv::Mat texture(2, 2, CV_8UC4, cv::Scalar(50, 50, 50, 200));
    texture.at<cv::Vec4b>(0, 0) = {100, 100, 100, 255};  // a brighter strand
    texture.at<cv::Vec4b>(1, 1) = {7, 8, 9, 0};          // outside the mask
    cv::Mat mask(2, 2, CV_8U, cv::Scalar(255));
    mask.at<std::uint8_t>(1, 1) = 0;
    const cv::Mat out = tintTexture(texture, mask, {20, 40, 80});
    // The masked pixels' grey mean (100 + 50 + 50) / 3 becomes the colour, each keeping its brightness relative to it.
    const double mean = 200.0 / 3.0;
    EXPECT_NEAR(out.at<cv::Vec4b>(0, 0)[2], 80 * 100 / mean, 1.0);
    EXPECT_NEAR(out.at<cv::Vec4b>(0, 1)[0], 20 * 50 / mean, 1.0);
    EXPECT_EQ(out.at<cv::Vec4b>(0, 1)[3], 200);
    EXPECT_EQ(out.at<cv::Vec4b>(1, 1), cv::Vec4b(7, 8, 9, 0));
}

TEST(AvatarParts, SurfacePerTexelSharesEachTrianglesAreaAmongItsTexels) {
    // The 10 x 10 mm square over a 4 x 4 texture: each triangle's 50 mm² over the texels whose centres it holds.
    // The diagonal's texel centres lie on both triangles' edges, so each triangle holds 10 of the 16 centres.
    const cv::Mat w = surfacePerTexel(square(), {4, 4});
    ASSERT_EQ(w.type(), CV_32F);
    EXPECT_NEAR(cv::sum(w)[0], 100.0, 1e-4);
    EXPECT_NEAR(w.at<float>(0, 3), 5.0, 1e-5);   // above the diagonal: triangle (0, 1, 2) only
    EXPECT_NEAR(w.at<float>(3, 0), 5.0, 1e-5);   // below it: (0, 2, 3) only
    EXPECT_NEAR(w.at<float>(1, 1), 10.0, 1e-5);  // on it: both
    // Stretched to twice the height, the same texels cover twice the surface.
    Mesh tall = square();
    for (auto& p : tall.positions) p.y *= 2.0;
    EXPECT_NEAR(surfacePerTexel(tall, {4, 4}).at<float>(0, 3), 10.0, 1e-5);
    // A triangle smaller than a texel gives its area to the texel under its centre.
    Mesh tiny;
    tiny.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    tiny.uvs = {{0.30, 0.30}, {0.32, 0.30}, {0.30, 0.32}};
    tiny.triangles = {{0, 1, 2}};
    const cv::Mat t = surfacePerTexel(tiny, {4, 4});
    EXPECT_NEAR(t.at<float>(1, 1), 0.5, 1e-6);
    EXPECT_NEAR(cv::sum(t)[0], 0.5, 1e-6);
}

TEST(AvatarParts, TintWeightedByTheSurfaceShownAndItsOpacity) {
    // Two texels of a strand: a light one (grey 120) on 3 mm² of surface, a dark one (grey 40) on 1 mm², and a
    // third, light as can be, that no surface uses; then the dark one made half transparent.
    cv::Mat texture(1, 3, CV_8UC4);
    texture.at<cv::Vec4b>(0, 0) = {120, 120, 120, 255};
    texture.at<cv::Vec4b>(0, 1) = {40, 40, 40, 255};
    texture.at<cv::Vec4b>(0, 2) = {255, 255, 255, 255};
    const cv::Mat mask(1, 3, CV_8U, cv::Scalar(255));
    cv::Mat weights(1, 3, CV_32F, cv::Scalar(0));
    weights.at<float>(0, 0) = 3.0f;
    weights.at<float>(0, 1) = 1.0f;
    // The shown mean grey is (3 * 120 + 40) / 4 = 100: the light texel gets 1.2 of the colour, the dark one 0.4.
    cv::Mat out = tintTexture(texture, mask, {50, 100, 150}, weights);
    EXPECT_NEAR(out.at<cv::Vec4b>(0, 0)[2], 180, 1.0);
    EXPECT_NEAR(out.at<cv::Vec4b>(0, 1)[1], 40, 1.0);
    texture.at<cv::Vec4b>(0, 1)[3] = 51;  // 0.2 opaque: (3 * 120 + 0.2 * 40) / 3.2 = 115
    out = tintTexture(texture, mask, {50, 100, 150}, weights);
    EXPECT_NEAR(out.at<cv::Vec4b>(0, 0)[0], 50 * 120 / 115.0, 1.0);
    EXPECT_EQ(out.at<cv::Vec4b>(0, 1)[3], 51);
    // Without weights, the plain mean of the masked texels (415 / 3) as before.
    out = tintTexture(texture, mask, {50, 100, 150});
    EXPECT_NEAR(out.at<cv::Vec4b>(0, 0)[0], 50 * 120 / (415.0 / 3.0), 1.0);
}

TEST(AvatarParts, PlacedPartCutBelowAHeightKeepsOnlyWhatReachesAboveIt) {
    BaseHead base;
    base.mesh = square();
    HeadProxy p = proxyOnSquare();
    // A second triangle wholly under y = 3: its new vertex 3 lies at y = 0, on the square's bottom edge.
    p.binding.vertices.push_back({0, 1, 2});
    p.binding.weights.push_back({0.5, 0.5, 0.0});
    p.binding.offsets.push_back({0, 0, 0});
    p.mesh.uvs.push_back({1, 1});
    p.mesh.triangles.push_back({0, 1, 3});
    const AvatarPart all = placeProxyPart(p, base.mesh);
    EXPECT_EQ(all.mesh.triangles.size(), 2u);
    EXPECT_EQ(all.mesh.positions.size(), 4u);
    const AvatarPart cut = placeProxyPart(p, base.mesh, nullptr, 3.0);
    ASSERT_EQ(cut.mesh.triangles.size(), 1u);  // (0, 1, 2): its vertex 2 stands at y = 8
    EXPECT_EQ(cut.mesh.positions.size(), 3u);
    EXPECT_EQ(cut.mesh.uvs.size(), 3u);
}

TEST(AvatarParts, HeadWithoutReplacedVerticesAndDrawingOrder) {
    const Mesh cut = withoutVertices(square(), {3});
    ASSERT_EQ(cut.triangles.size(), 1u);  // (0, 2, 3) used vertex 3
    EXPECT_EQ(cut.positions.size(), 3u);
    EXPECT_EQ(cut.uvs.size(), 3u);
    EXPECT_EQ(cut.positions[cut.triangles[0].z], glm::dvec3(10, 10, 0));

    Mesh head = square();
    BaseHead base;
    base.mesh = head;
    base.proxies = {proxyOnSquare()};
    const auto parts = placeParts(base, head, cv::Mat(2, 2, CV_8UC3, cv::Scalar::all(90)), {{"eyebrows", {1, 2, 3}}});
    ASSERT_EQ(parts.size(), 2u);
    EXPECT_EQ(parts[0].name, "head");
    EXPECT_EQ(parts[0].mesh.triangles.size(), 1u);
    EXPECT_EQ(parts[1].name, "eyebrows");
    EXPECT_EQ(parts[1].texture.at<cv::Vec4b>(0, 0), cv::Vec4b(1, 2, 3, 128));  // tinted, alpha kept

    std::vector<AvatarPart> mixed(4);
    mixed[0].alpha = AlphaMode::Blend;
    mixed[1].alpha = AlphaMode::Opaque;
    mixed[2].alpha = AlphaMode::Mask;
    mixed[3].alpha = AlphaMode::Opaque;
    const auto order = drawOrder(mixed);
    EXPECT_EQ(order, (std::vector<const AvatarPart*>{&mixed[1], &mixed[3], &mixed[2], &mixed[0]}));
}
