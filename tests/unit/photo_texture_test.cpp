// The texture step on synthetic geometry with analytic photos: occlusion (a texel hidden from a photo does not take
// its colour), the multi-band seam (no step where the photos agree, a gradual one where they do not), the fill.
#include "fit/head/photo_texture.h"
#include "common/error.h"
#include "fit/head/surface_texels.h"
#include "fit/head/view_depth.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <functional>

using namespace avatarbooth;

namespace {

constexpr double kPi = 3.14159265358979323846;

// Appends a square grid of quads: centre c, spanning +-half along axes a and b, UVs in the rectangle uv. The
// triangles are turned to face `outward`.
void addSquare(Mesh& mesh, glm::dvec3 c, glm::dvec3 a, glm::dvec3 b, double half, cv::Rect2d uv, glm::dvec3 outward) {
    constexpr int n = 16;
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const double s = -1.0 + 2.0 * i / n, t = -1.0 + 2.0 * j / n;
            mesh.positions.push_back(c + half * s * a + half * t * b);
            mesh.uvs.push_back({uv.x + uv.width * i / n, uv.y + uv.height * (n - j) / n});
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const std::uint32_t v00 = base + static_cast<std::uint32_t>(j * (n + 1) + i), v10 = v00 + 1;
            const std::uint32_t v01 = v00 + static_cast<std::uint32_t>(n + 1), v11 = v01 + 1;
            for (glm::uvec3 t : {glm::uvec3(v00, v10, v11), glm::uvec3(v00, v11, v01)}) {
                const glm::dvec3 normal = glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
                if (glm::dot(normal, outward) < 0.0) std::swap(t.y, t.z);
                mesh.triangles.push_back(t);
            }
        }
}

// A UV sphere (longitude -> u with the seam at the back, latitude -> v), radius r, centred at the origin.
Mesh uvSphere(double r, int rows = 48, int cols = 96) {
    Mesh mesh;
    for (int j = 0; j <= rows; ++j)
        for (int i = 0; i <= cols; ++i) {
            const double u = static_cast<double>(i) / cols, v = static_cast<double>(j) / rows;
            const double lat = kPi * v, lon = 2.0 * kPi * (u - 0.5);
            mesh.positions.push_back({r * std::sin(lat) * std::sin(lon), r * std::cos(lat), r * std::sin(lat) * std::cos(lon)});
            mesh.uvs.push_back({u, v});
        }
    for (int j = 0; j < rows; ++j)
        for (int i = 0; i < cols; ++i) {
            const auto v00 = static_cast<std::uint32_t>(j * (cols + 1) + i), v10 = v00 + 1;
            const auto v01 = v00 + static_cast<std::uint32_t>(cols + 1), v11 = v01 + 1;
            for (glm::uvec3 t : {glm::uvec3(v00, v01, v11), glm::uvec3(v00, v11, v10)}) {
                const glm::dvec3 centroid = (mesh.positions[t.x] + mesh.positions[t.y] + mesh.positions[t.z]) / 3.0;
                const glm::dvec3 normal = glm::cross(mesh.positions[t.y] - mesh.positions[t.x], mesh.positions[t.z] - mesh.positions[t.x]);
                if (glm::dot(normal, centroid) < 0.0) std::swap(t.y, t.z);
                mesh.triangles.push_back(t);
            }
        }
    return mesh;
}

// Both photos 400 x 400 at 0.5 mm per pixel, centred on the origin, the side photo seen from -x (not mirrored).
HeadFit photoFrames() {
    HeadFit fit;
    fit.front = PhotoFrame{cv::Point2d(200, 200), 0.5, glm::dvec2(0.0), false, 400};
    fit.side = PhotoFrame{cv::Point2d(200, 200), 0.5, glm::dvec2(0.0), false, 400};
    return fit;
}

const cv::Vec3b kGreen(40, 200, 40), kRed(40, 40, 220), kBlue(200, 60, 40);

// An orthographic photo of flat squares: `paint` gives the colour of each photo pixel (its plane coordinates in mm).
cv::Mat paintPhoto(const HeadFit& fit, bool side, const std::function<cv::Vec3b(glm::dvec2)>& paint) {
    cv::Mat photo(400, 400, CV_8UC3);
    for (int v = 0; v < photo.rows; ++v)
        for (int u = 0; u < photo.cols; ++u)
            photo.at<cv::Vec3b>(v, u) = paint((side ? fit.side : fit.front).toHead(cv::Point2d(u, v)));
    return photo;
}

// A photo's mask (255 where `inside` holds for the pixel's plane coordinates in mm), as the hair analysis gives.
cv::Mat paintMask(const HeadFit& fit, bool side, const std::function<bool(glm::dvec2)>& inside) {
    cv::Mat mask(400, 400, CV_8U);
    for (int v = 0; v < mask.rows; ++v)
        for (int u = 0; u < mask.cols; ++u)
            mask.at<unsigned char>(v, u) = inside((side ? fit.side : fit.front).toHead(cv::Point2d(u, v))) ? 255 : 0;
    return mask;
}

cv::Vec3d meanWhere(const cv::Mat& image, const cv::Mat& mask) {
    const cv::Scalar m = cv::mean(image, mask);
    return {m[0], m[1], m[2]};
}

// Texels of the mesh's squares whose UVs fall in a rectangle (fractions of the texture).
cv::Mat uvRegion(int size, cv::Rect2d uv) {
    cv::Mat mask(size, size, CV_8U, cv::Scalar(0));
    mask(cv::Rect(static_cast<int>(uv.x * size), static_cast<int>(uv.y * size), static_cast<int>(uv.width * size),
                  static_cast<int>(uv.height * size)))
        .setTo(255);
    return mask;
}

// Within 40 levels of a colour (the bilinear reading and the blend soften edges).
bool nearColour(cv::Vec3i a, cv::Vec3b b) { return cv::norm(a - cv::Vec3i(b)) < 40.0; }

// A 200 mm square facing -x at x = -60, seen squarely by the side photo (0.6 mm a pixel: the square fills its 400
// pixels) and edge-on by the front one, which is all green.
struct SideSquare {
    static constexpr double half = 100.0;
    Mesh mesh;
    HeadFit fit = photoFrames();
    cv::Mat front{400, 400, CV_8UC3, cv::Scalar(kGreen)}, all{400, 400, CV_8U, cv::Scalar(255)};
    PhotoTextureOptions options;
    cv::Rect2d uv;
    // uv: where the square lies in the texture (the rest is texels between islands, no triangle's).
    explicit SideSquare(cv::Rect2d uvRect = {0.0, 0.0, 1.0, 1.0}) : uv(uvRect) {
        addSquare(mesh, {-60, 0, 0}, {0, 0, 1}, {0, 1, 0}, half, uv, {-1, 0, 0});
        fit.side.mmPerPixel = 0.6;
        options.size = 256;
    }
    PhotoTexture texture(const cv::Mat& side) const { return textureFromPhotos(mesh, fit, front, all, side, all, options); }
    // The colour of the texel of the square's point (z, y); past the square's edge, of a texel beside it.
    cv::Vec3i at(const PhotoTexture& t, double z, double y) const {
        const int u = static_cast<int>((uv.x + uv.width * (z / half + 1.0) / 2.0) * options.size);
        const int v = static_cast<int>((uv.y + uv.height * (1.0 - (y / half + 1.0) / 2.0)) * options.size);
        return cv::Vec3i(t.texture.at<cv::Vec3b>(v, u));
    }
};

}  // namespace

// Two parallel squares facing the front camera: a small one 20 mm in front of a large one. The front photo shows
// the small one red on the large one's green. The part of the large square behind the small one is hidden from the
// front photo: it must not take the red (before the visibility test it did), but a fill from the green around it.
TEST(PhotoTexture, TexelHiddenBehindAnotherSurfaceDoesNotTakeThatPhotosColour) {
    Mesh mesh;
    const cv::Rect2d backUv(0.0, 0.0, 0.5, 1.0), frontUv(0.5, 0.0, 0.5, 1.0);
    addSquare(mesh, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 60.0, backUv, {0, 0, 1});
    addSquare(mesh, {0, 0, 20}, {1, 0, 0}, {0, 1, 0}, 20.0, frontUv, {0, 0, 1});
    const HeadFit fit = photoFrames();
    const cv::Mat front = paintPhoto(fit, false, [](glm::dvec2 p) { return std::abs(p.x) < 20 && std::abs(p.y) < 20 ? kRed : kGreen; });
    const cv::Mat side(400, 400, CV_8UC3, cv::Scalar(kBlue));
    const cv::Mat all(400, 400, CV_8U, cv::Scalar(255));
    PhotoTextureOptions o;
    o.size = 256;
    const PhotoTexture t = textureFromPhotos(mesh, fit, front, all, side, all, o);

    // The large square spans +-60 mm over u in [0, 0.5]: +-15 mm (well inside the hidden +-20) is u 0.1875..0.3125.
    const cv::Mat hidden = uvRegion(o.size, {0.19, 0.38, 0.12, 0.24});
    const cv::Mat seenBack = uvRegion(o.size, {0.02, 0.05, 0.08, 0.9});   // x < -45 mm: seen
    const cv::Mat seenFront = uvRegion(o.size, {0.55, 0.1, 0.4, 0.8});    // the small square itself
    const cv::Vec3d hiddenColour = meanWhere(t.texture, hidden);
    std::printf("hidden texels: BGR (%.0f, %.0f, %.0f); small square (%.0f, %.0f, %.0f)\n", hiddenColour[0], hiddenColour[1],
                hiddenColour[2], meanWhere(t.texture, seenFront)[0], meanWhere(t.texture, seenFront)[1], meanWhere(t.texture, seenFront)[2]);
    EXPECT_EQ(cv::countNonZero((t.source != PhotoTexture::Filled) & hidden), 0) << "a hidden texel was taken from a photo";
    EXPECT_LT(hiddenColour[2], 90.0) << "the hidden texels took the red of the square in front of them";
    EXPECT_GT(hiddenColour[1], 150.0) << "the hidden texels should be filled from the green around them";
    EXPECT_EQ(cv::countNonZero((t.source != PhotoTexture::Front) & seenBack), 0);
    EXPECT_LT(cv::norm(meanWhere(t.texture, seenBack) - cv::Vec3d(kGreen[0], kGreen[1], kGreen[2])), 6.0);
    EXPECT_LT(cv::norm(meanWhere(t.texture, seenFront) - cv::Vec3d(kRed[0], kRed[1], kRed[2])), 6.0);
}

// The same from the side camera (-x), and from the other side (+x), which the side photo stands in for mirrored: the
// large square's part behind the small one must not take the small one's colour from the side photo.
TEST(PhotoTexture, TexelHiddenFromTheSidePhotoOnEitherSide) {
    for (const double sign : {-1.0, 1.0}) {
        Mesh mesh;
        addSquare(mesh, {0, 0, 0}, {0, 0, 1}, {0, 1, 0}, 60.0, {0.0, 0.0, 0.5, 1.0}, {sign, 0, 0});
        addSquare(mesh, {sign * 20, 0, 0}, {0, 0, 1}, {0, 1, 0}, 20.0, {0.5, 0.0, 0.5, 1.0}, {sign, 0, 0});
        const HeadFit fit = photoFrames();
        const cv::Mat front(400, 400, CV_8UC3, cv::Scalar(kBlue));
        const cv::Mat side = paintPhoto(fit, true, [](glm::dvec2 p) { return std::abs(p.x) < 20 && std::abs(p.y) < 20 ? kRed : kGreen; });
        const cv::Mat all(400, 400, CV_8U, cv::Scalar(255));
        PhotoTextureOptions o;
        o.size = 256;
        const PhotoTexture t = textureFromPhotos(mesh, fit, front, all, side, all, o);
        // The large square's u runs along z (either way, by the sign): its middle +-15 mm is hidden either way.
        const cv::Mat hidden = uvRegion(o.size, {0.19, 0.38, 0.12, 0.24});
        const cv::Vec3d hiddenColour = meanWhere(t.texture, hidden);
        EXPECT_EQ(cv::countNonZero((t.source != PhotoTexture::Filled) & hidden), 0) << "side " << sign;
        EXPECT_LT(hiddenColour[2], 90.0) << "side " << sign;
        EXPECT_GT(hiddenColour[1], 150.0) << "side " << sign;
        EXPECT_GT(cv::countNonZero(t.source == PhotoTexture::Side), o.size * o.size / 4) << "side " << sign;
    }
}

namespace {

// A smooth colour over head space, the same on both sides (x -> -x), as the mirrored side photo assumes.
cv::Vec3d sphereColour(const glm::dvec3& p) {
    return {128.0 + 50.0 * std::sin(p.y / 15.0), 128.0 + 50.0 * std::cos(p.z / 18.0), 128.0 + 40.0 * std::sin(std::abs(p.x) / 12.0)};
}

constexpr double kRadius = 80.0;

// The sphere seen by the front camera (+z) or the side camera (-x); `shade` scales the colour per visible point.
cv::Mat spherePhoto(const HeadFit& fit, bool side, cv::Mat& mask, const std::function<double(glm::dvec3)>& shade) {
    cv::Mat photo(400, 400, CV_8UC3, cv::Scalar(20, 20, 20));
    mask = cv::Mat(400, 400, CV_8U, cv::Scalar(0));
    for (int v = 0; v < 400; ++v)
        for (int u = 0; u < 400; ++u) {
            const glm::dvec2 q = (side ? fit.side : fit.front).toHead(cv::Point2d(u, v));
            const double rest = kRadius * kRadius - q.x * q.x - q.y * q.y;
            if (rest <= 0.0) continue;
            const glm::dvec3 p = side ? glm::dvec3(-std::sqrt(rest), q.y, q.x) : glm::dvec3(q.x, q.y, std::sqrt(rest));
            const cv::Vec3d c = sphereColour(p) * shade(p);
            photo.at<cv::Vec3b>(v, u) = cv::Vec3b(cv::saturate_cast<unsigned char>(c[0]), cv::saturate_cast<unsigned char>(c[1]),
                                                  cv::saturate_cast<unsigned char>(c[2]));
            mask.at<unsigned char>(v, u) = 255;
        }
    return photo;
}

struct SeamStats {
    double acrossSeam = 0.0;   // mean colour difference of neighbouring texels taken from different photos
    double withinFront = 0.0;  // the same for neighbouring texels both from the front photo
    int seamPairs = 0;
    double truthError = 0.0;   // mean |texture - true colour| over the texels a photo saw
};

SeamStats seamStats(const Mesh& mesh, const PhotoTexture& t) {
    const SurfaceTexels texels = sampleSurfaceTexels(mesh, mesh.vertexNormals(), t.texture.size());
    SeamStats s;
    double within = 0.0, truth = 0.0;
    int withinPairs = 0, seen = 0;
    for (int y = 0; y + 1 < t.texture.rows; ++y)
        for (int x = 0; x + 1 < t.texture.cols; ++x) {
            const unsigned char a = t.source.at<unsigned char>(y, x);
            if (a == PhotoTexture::Filled) continue;
            const cv::Vec3d ca = t.texture.at<cv::Vec3b>(y, x);
            const cv::Vec3f p = texels.position.at<cv::Vec3f>(y, x);
            truth += cv::norm(ca - sphereColour({p[0], p[1], p[2]})) / std::sqrt(3.0);
            ++seen;
            for (const cv::Point n : {cv::Point(x + 1, y), cv::Point(x, y + 1)}) {
                const unsigned char b = t.source.at<unsigned char>(n);
                if (b == PhotoTexture::Filled) continue;
                const double d = cv::norm(ca - cv::Vec3d(t.texture.at<cv::Vec3b>(n))) / std::sqrt(3.0);
                if (a != b) {
                    s.acrossSeam += d;
                    ++s.seamPairs;
                } else if (a == PhotoTexture::Front) {
                    within += d;
                    ++withinPairs;
                }
            }
        }
    s.acrossSeam /= std::max(s.seamPairs, 1);
    s.withinFront = within / std::max(withinPairs, 1);
    s.truthError = truth / std::max(seen, 1);
    return s;
}

}  // namespace

// Both photos show the same colours (the sphere's own): the texture reproduces them, and the seam between the
// front and the side photo's texels is no step: neighbours across it differ no more than neighbours elsewhere.
TEST(PhotoTexture, SeamHasNoStepWherePhotosAgree) {
    const Mesh sphere = uvSphere(kRadius);
    const HeadFit fit = photoFrames();
    cv::Mat frontMask, sideMask;
    const auto same = [](const glm::dvec3&) { return 1.0; };
    const cv::Mat front = spherePhoto(fit, false, frontMask, same), side = spherePhoto(fit, true, sideMask, same);
    PhotoTextureOptions o;
    o.size = 512;
    const PhotoTexture t = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o);
    const SeamStats s = seamStats(sphere, t);
    std::printf("agreeing photos: %d seam pairs, step across the seam %.2f, between front texels %.2f, error vs truth %.2f\n",
                s.seamPairs, s.acrossSeam, s.withinFront, s.truthError);
    ASSERT_GT(s.seamPairs, 500) << "the sphere should have a front/side seam";
    EXPECT_LT(s.acrossSeam, 2.0 * s.withinFront + 1.0);
    EXPECT_LT(s.truthError, 1.5);
    EXPECT_GT(t.seenFraction, 0.7);  // a sphere: neither photo sees the back, nor the top and bottom beyond 80 degrees
}

// The side photo is lit differently, brighter and darker in bands from top to bottom (no single gain can match it).
// A hard switch between the photos would step by the whole difference at the seam; the multi-band blend spreads the
// low frequencies over a wide band, so neighbours across the seam differ far less than the photos do.
TEST(PhotoTexture, SeamIsBlendedWherePhotosDisagree) {
    const Mesh sphere = uvSphere(kRadius);
    const HeadFit fit = photoFrames();
    cv::Mat frontMask, sideMask;
    const auto same = [](const glm::dvec3&) { return 1.0; };
    const auto banded = [](const glm::dvec3& p) { return 1.0 + 0.3 * std::sin(p.y / 20.0); };
    const cv::Mat front = spherePhoto(fit, false, frontMask, same), side = spherePhoto(fit, true, sideMask, banded);
    PhotoTextureOptions o;
    o.size = 512;
    const PhotoTexture t = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o);
    const SeamStats s = seamStats(sphere, t);

    // The step a hard switch would make: the two photos' difference at the seam texels.
    const SurfaceTexels texels = sampleSurfaceTexels(sphere, sphere.vertexNormals(), t.texture.size());
    double raw = 0.0;
    int n = 0;
    for (int y = 0; y + 1 < t.texture.rows; ++y)
        for (int x = 0; x + 1 < t.texture.cols; ++x) {
            const unsigned char a = t.source.at<unsigned char>(y, x), b = t.source.at<unsigned char>(y, x + 1);
            if (a == PhotoTexture::Filled || b == PhotoTexture::Filled || a == b) continue;
            const cv::Vec3f q = texels.position.at<cv::Vec3f>(y, x);
            const glm::dvec3 p(q[0], q[1], q[2]);
            raw += cv::norm(sphereColour(p) * (banded(p) - 1.0)) / std::sqrt(3.0);
            ++n;
        }
    raw /= std::max(n, 1);
    std::printf("disagreeing photos: photos differ by %.1f at the seam; step across the seam %.2f, between front texels %.2f\n",
                raw, s.acrossSeam, s.withinFront);
    ASSERT_GT(n, 100);
    EXPECT_GT(raw, 12.0) << "the test's photos should disagree at the seam";
    EXPECT_LT(s.acrossSeam, 0.15 * raw);
    EXPECT_LT(s.acrossSeam, 2.0 * s.withinFront + 1.0);
}

// The side photo is taken at another exposure and white balance (its channels at 0.8, 0.9 and 1.1 of the front's),
// and in the front photo dark hair falls over the upper half of the band both photos see (as long hair falls over
// the temples and cheeks and lies behind them in the profile). The gain is measured on the skin both photos see, the
// hair left out by the not-skin mask: it undoes the exposure. Compared with the hair, it would not.
TEST(PhotoTexture, SidePhotosExposureIsMatchedOnSkinNotOnHair) {
    const Mesh sphere = uvSphere(kRadius);
    const HeadFit fit = photoFrames();
    cv::Mat frontMask, sideMask;
    const auto same = [](const glm::dvec3&) { return 1.0; };
    cv::Mat front = spherePhoto(fit, false, frontMask, same), side = spherePhoto(fit, true, sideMask, same);
    const cv::Vec3d exposure(0.8, 0.9, 1.1);
    cv::multiply(side, cv::Scalar(exposure[0], exposure[1], exposure[2]), side);
    cv::Mat frontHair(front.size(), CV_8U, cv::Scalar(0));
    for (int v = 0; v < front.rows; ++v)
        for (int u = 0; u < front.cols; ++u) {
            const glm::dvec2 q = fit.front.toHead(cv::Point2d(u, v));
            // The side camera looks from -x: the band both see lies at x < -0.4 r on the front photo; the hair reaches
            // a little further in, as it does over a cheek.
            if (frontMask.at<unsigned char>(v, u) && q.x < -0.3 * kRadius && q.y > 0.0) {
                front.at<cv::Vec3b>(v, u) = cv::Vec3b(25, 30, 40);
                frontHair.at<unsigned char>(v, u) = 255;
            }
        }
    PhotoTextureOptions o;
    o.size = 512;
    const PhotoTexture masked = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o, ColourMatchMasks{frontHair, {}});
    const PhotoTexture unmasked = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o);
    std::printf("side gain on skin %.3f %.3f %.3f (%d texels), with the hair %.3f %.3f %.3f; exposure undone by %.3f %.3f %.3f\n",
                masked.sideGain[0], masked.sideGain[1], masked.sideGain[2], masked.sideGainTexels, unmasked.sideGain[0],
                unmasked.sideGain[1], unmasked.sideGain[2], 1.0 / exposure[0], 1.0 / exposure[1], 1.0 / exposure[2]);
    ASSERT_GT(masked.sideGainTexels, 500);
    EXPECT_LT(masked.sideGainTexels, unmasked.sideGainTexels);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(masked.sideGain[c], 1.0 / exposure[c], 0.02) << "channel " << c;
        EXPECT_GT(std::abs(unmasked.sideGain[c] - 1.0 / exposure[c]), 0.1) << "the hair should mislead an unmasked match, channel " << c;
    }
    // And the side photo's texels show the sphere's own colours again: no step at the seam.
    const SeamStats s = seamStats(sphere, masked);
    EXPECT_LT(s.acrossSeam, 2.0 * s.withinFront + 1.0);
}

// The side photo's exposure differs from the front's by more on the top of the head than under it (the lights
// fall differently on the two photos: FRMDB 005's side-photo cheek read pale, 008's a light band beside the seam).
// One gain for the whole photo leaves the top too dark and the bottom too light; the gain measured near each texel
// gives the side photo's texels beside the seam the sphere's own colours.
TEST(PhotoTexture, SidePhotosExposureIsMatchedWhereItDiffers) {
    const Mesh sphere = uvSphere(kRadius);
    const HeadFit fit = photoFrames();
    cv::Mat frontMask, sideMask;
    const cv::Mat front = spherePhoto(fit, false, frontMask, [](const glm::dvec3&) { return 1.0; });
    const cv::Mat side = spherePhoto(fit, true, sideMask, [](const glm::dvec3& p) { return std::exp(-0.3 * p.y / kRadius); });
    const auto sideError = [&](const PhotoTexture& t) {
        const SurfaceTexels texels = sampleSurfaceTexels(sphere, sphere.vertexNormals(), t.texture.size());
        double error = 0.0;
        int n = 0;
        for (int y = 0; y < t.texture.rows; ++y)
            for (int x = 0; x < t.texture.cols; ++x) {
                if (t.source.at<unsigned char>(y, x) != PhotoTexture::Side) continue;
                const cv::Vec3f p = texels.position.at<cv::Vec3f>(y, x);
                // Near the seam, where the skin both photos see is: further round, the gain eases into the whole's.
                if (std::abs(p[1]) > 0.8 * kRadius || p[2] < 0.3 * kRadius) continue;
                error += cv::norm(cv::Vec3d(t.texture.at<cv::Vec3b>(y, x)) - sphereColour({p[0], p[1], p[2]})) / std::sqrt(3.0);
                ++n;
            }
        return error / std::max(n, 1);
    };
    PhotoTextureOptions o;
    o.size = 512;
    const PhotoTexture local = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o);
    o.exposureSmoothing = 0.0;
    const PhotoTexture whole = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o);
    const double localError = sideError(local), wholeError = sideError(whole);
    std::printf("side photo's texels off the sphere's colours: %.1f levels with the local gain, %.1f with one gain\n",
                localError, wholeError);
    EXPECT_LT(localError, 0.5 * wholeError);
    EXPECT_LT(localError, 8.0);
}

// The side photo shows a dark mark where the surface turns 55 degrees from the front (as a brow's tail lands on the
// temple when the fitted depth there is a few millimetres off); the front photo shows the sphere's own colour. By
// default the side photo takes that surface (beyond about 51 degrees). With a front feature vertex beside it, the
// front photo is preferred there (up to about 63 degrees) and the mark is gone.
TEST(PhotoTexture, FrontPhotoIsPreferredRoundFrontFeatures) {
    const Mesh sphere = uvSphere(kRadius);
    const HeadFit fit = photoFrames();
    cv::Mat frontMask, sideMask;
    const auto same = [](const glm::dvec3&) { return 1.0; };
    const double yaw = 55.0 * kPi / 180.0;
    const glm::dvec3 spot(-kRadius * std::sin(yaw), 0.0, kRadius * std::cos(yaw));
    const auto marked = [&](const glm::dvec3& p) { return glm::distance(p, spot) < 8.0 ? 0.15 : 1.0; };
    const cv::Mat front = spherePhoto(fit, false, frontMask, same), side = spherePhoto(fit, true, sideMask, marked);
    PhotoTextureOptions o;
    o.size = 512;
    std::uint32_t nearest = 0;
    for (std::uint32_t v = 0; v < sphere.positions.size(); ++v)
        if (glm::distance(sphere.positions[v], spot) < glm::distance(sphere.positions[nearest], spot)) nearest = v;
    const PhotoTexture plain = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o, TextureTables(sphere, o));
    const PhotoTexture preferred =
        textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o, TextureTables(sphere, o, {}, {nearest}));

    // The texture round the spot against the sphere's own colours there.
    const SurfaceTexels texels = sampleSurfaceTexels(sphere, sphere.vertexNormals(), cv::Size(o.size, o.size));
    const auto errorAtSpot = [&](const PhotoTexture& t, int& source) {
        double error = 0.0;
        int n = 0, fromFront = 0;
        for (int y = 0; y < o.size; ++y)
            for (int x = 0; x < o.size; ++x) {
                if (!texels.covered.at<unsigned char>(y, x)) continue;
                const cv::Vec3f q = texels.position.at<cv::Vec3f>(y, x);
                const glm::dvec3 p(q[0], q[1], q[2]);
                if (glm::distance(p, spot) > 4.0) continue;
                error += cv::norm(cv::Vec3d(t.texture.at<cv::Vec3b>(y, x)) - sphereColour(p)) / std::sqrt(3.0);
                fromFront += t.source.at<unsigned char>(y, x) == PhotoTexture::Front ? 1 : 0;
                ++n;
            }
        source = n > 0 ? 100 * fromFront / n : 0;
        return error / std::max(n, 1);
    };
    int plainFront = 0, preferredFront = 0;
    const double plainError = errorAtSpot(plain, plainFront), preferredError = errorAtSpot(preferred, preferredFront);
    std::printf("at 55 degrees: %d %% from the front photo, error %.1f; with a front feature beside it %d %%, error %.1f\n",
                plainFront, plainError, preferredFront, preferredError);
    EXPECT_EQ(plainFront, 0);
    EXPECT_GT(plainError, 40.0) << "the side photo's mark should show without the preference";
    EXPECT_EQ(preferredFront, 100);
    EXPECT_LT(preferredError, 6.0);
}

// The side photo's ear lies 25 mm behind where the ears' sliders could take the head's (HeadFit::earLeftMm): round
// the head's ear the side photo is read shifted by that, so that the photo's ear (a red disc) lands on the head's ear
// (the side-facing square's middle) and not beside it; far from the ear the photo is read where it lies (a blue disc).
TEST(PhotoTexture, SidePhotosEarLandsOnTheHeadsEar) {
    SideSquare square;
    const cv::Mat side = paintPhoto(square.fit, true, [](glm::dvec2 p) {
        if (glm::distance(p, glm::dvec2(-25.0, 0.0)) < 10.0) return kRed;
        if (glm::distance(p, glm::dvec2(90.0, 80.0)) < 8.0) return kBlue;
        return kGreen;
    });
    const PhotoTexture unplaced = square.texture(side);
    EXPECT_TRUE(nearColour(square.at(unplaced, -25.0, 0.0), kRed)) << "without a placement the photo is read where it lies";
    EXPECT_TRUE(nearColour(square.at(unplaced, 0.0, 0.0), kGreen));

    square.fit.earsPlaced = true;
    square.fit.earMiddleMm = {-60.0, 0.0, 0.0};
    square.fit.earLeftMm = {-25.0, 0.0};
    const PhotoTexture placed = square.texture(side);
    EXPECT_TRUE(nearColour(square.at(placed, 0.0, 0.0), kRed)) << "the photo's ear on the head's ear";
    EXPECT_TRUE(nearColour(square.at(placed, 0.0, 6.0), kRed));
    EXPECT_TRUE(nearColour(square.at(placed, -25.0, 0.0), kGreen)) << "no second ear beside it";
    EXPECT_TRUE(nearColour(square.at(placed, 90.0, 80.0), kBlue)) << "far from the ear the photo is read where it lies";
}

// A visitor turned short of the profile: the side photo shows the eye 25 mm further back (and 5 mm lower, where its
// darkest part lies) than the head's. Read shifted, the photo's eye lands on the head's, and the whole side of the
// head is read that much further back; up and down only round the eye. Near the midline (the outline, which the fit
// matched) the photo is read where it lies.
TEST(PhotoTexture, SidePhotosEyeLandsOnTheHeadsEye) {
    SideSquare square;
    const cv::Mat side = paintPhoto(square.fit, true, [](glm::dvec2 p) {
        if (glm::distance(p, glm::dvec2(25.0, -5.0)) < 8.0) return kRed;
        if (glm::distance(p, glm::dvec2(40.0, 80.0)) < 8.0) return kBlue;
        return kGreen;
    });
    square.fit.sideEyeFound = true;
    square.fit.eyeMiddleMm = {-60.0, 0.0, 50.0};  // as far off the midline as the square: the whole shift
    square.fit.eyeLeftMm = {-25.0, -5.0};
    const PhotoTexture shifted = square.texture(side);
    EXPECT_TRUE(nearColour(square.at(shifted, 50.0, 0.0), kRed)) << "the photo's eye on the head's";
    EXPECT_TRUE(nearColour(square.at(shifted, 25.0, -5.0), kGreen)) << "no second eye behind it";
    EXPECT_TRUE(nearColour(square.at(shifted, 65.0, 80.0), kBlue)) << "away from the eye, read as far back, at the same height";

    square.fit.eyeMiddleMm.x = -600.0;  // the square ten times nearer the midline than the eye: read almost where it lies
    const PhotoTexture nearMidline = square.texture(side);
    EXPECT_TRUE(nearColour(square.at(nearMidline, 40.0, 80.0), kBlue));
    EXPECT_TRUE(nearColour(square.at(nearMidline, 65.0, 80.0), kGreen));
}

// Hair the front photo shows over the face's sides (blue, marked not-skin) is repainted with the skin round it (green)
// where the sides are (outward of 40 mm, between 50 mm down and up); inside them (the brows and eyes, which count as
// hair too) and above them (the hairline) it stays, after a fade.
TEST(PhotoTexture, HairBesideTheFaceIsRepaintedWithSkin) {
    Mesh mesh;
    constexpr double half = 90.0;
    addSquare(mesh, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, half, {0.0, 0.0, 1.0, 1.0}, {0, 0, 1});
    const HeadFit fit = photoFrames();
    const auto hairAt = [](glm::dvec2 p) { return std::abs(p.x) > 60.0 || std::abs(p.x) < 10.0; };
    const cv::Mat front = paintPhoto(fit, false, [&](glm::dvec2 p) { return hairAt(p) ? kBlue : kGreen; });
    const cv::Mat frontHair = paintMask(fit, false, hairAt);
    const cv::Mat side(400, 400, CV_8UC3, cv::Scalar(kRed));
    const cv::Mat all(400, 400, CV_8U, cv::Scalar(255));
    PhotoTextureOptions o;
    o.size = 256;
    const TextureTables tables(mesh, o);
    PhotoTexture t = textureFromPhotos(mesh, fit, front, all, side, all, o, tables);
    const auto at = [&](double x, double y) {
        const int u = static_cast<int>((x / half + 1.0) / 2.0 * o.size), v = static_cast<int>((1.0 - (y / half + 1.0) / 2.0) * o.size);
        return cv::Vec3i(t.texture.at<cv::Vec3b>(v, u));
    };
    ASSERT_TRUE(nearColour(at(75.0, 0.0), kBlue)) << "the photo's hair, before";

    FaceSides sides;
    sides.innerX = 40.0;
    sides.bottomY = -50.0;
    sides.topY = 50.0;
    const int repainted = skinOverHairBesideFace(t, mesh, fit, ColourMatchMasks{frontHair, {}}, sides, o, tables);
    EXPECT_GT(repainted, 0);
    for (const double x : {-80.0, -70.0, 70.0, 80.0})
        for (const double y : {-40.0, 0.0, 40.0}) EXPECT_TRUE(nearColour(at(x, y), kGreen)) << "skin at " << x << ", " << y;
    EXPECT_TRUE(nearColour(at(0.0, 0.0), kBlue)) << "inside the sides it stays";
    EXPECT_TRUE(nearColour(at(75.0, 75.0), kBlue)) << "above them, past FaceSides::fadeMm, it stays";
    // In between the repaint fades out: cut at the brows' top, the photo's hair ended in a straight edge across the
    // temples (FRMDB 008). Half-way up the fade, about half of each (green's blue channel 40, blue's 200).
    const cv::Vec3i mid = at(75.0, 50.0 + 0.5 * sides.fadeMm);
    EXPECT_GT(mid[0], 40 + 40) << "some of the photo's hair is left: " << mid;
    EXPECT_LT(mid[0], 200 - 40) << "some skin is painted over it: " << mid;
    EXPECT_TRUE(nearColour(at(30.0, 0.0), kGreen));
    EXPECT_EQ(skinOverHairBesideFace(t, mesh, fit, ColourMatchMasks{}, sides, o, tables), 0) << "no hair known, nothing repainted";
}

// The same where the side photo shows the hair over the cheek (a texel that took the side photo): repainted ahead of the
// ear's front, kept behind it (the hair's own place) and above the brows.
TEST(PhotoTexture, HairOverTheCheekInTheSidePhotoIsRepaintedWithSkin) {
    SideSquare square;
    const auto hairAt = [](glm::dvec2 p) { return (p.x > 20.0 && p.x < 60.0) || p.x < -20.0; };  // p: (z, y)
    const cv::Mat side = paintPhoto(square.fit, true, [&](glm::dvec2 p) { return hairAt(p) ? kBlue : kGreen; });
    const cv::Mat sideHair = paintMask(square.fit, true, hairAt);
    const TextureTables tables(square.mesh, square.options);
    PhotoTexture t = textureFromPhotos(square.mesh, square.fit, square.front, square.all, side, square.all, square.options, tables);
    ASSERT_TRUE(nearColour(square.at(t, 40.0, 0.0), kBlue)) << "the photo's hair, before";

    FaceSides sides;
    sides.innerX = 10.0;
    sides.frontOfZ = 0.0;
    sides.bottomY = -50.0;
    sides.topY = 50.0;
    EXPECT_GT(skinOverHairBesideFace(t, square.mesh, square.fit, ColourMatchMasks{{}, sideHair}, sides, square.options, tables), 0);
    for (const double y : {-40.0, 0.0, 40.0}) EXPECT_TRUE(nearColour(square.at(t, 40.0, y), kGreen)) << "skin at 40, " << y;
    EXPECT_TRUE(nearColour(square.at(t, -50.0, 0.0), kBlue)) << "behind the ear's front it stays";
    EXPECT_TRUE(nearColour(square.at(t, 40.0, 75.0), kBlue)) << "above the brows it stays";
}

// A hood (yellow) round the bottom of the neck in the side photo, rising behind the ear as a hood does at the nape,
// is repainted with the skin round it; skin in shadow (darker, the same hue) is skin and keeps its own colour; hair
// (marked) under the neck's top stays, and so does what is not skin above the neck's top (a blue mark).
TEST(PhotoTexture, ClothesOnTheNeckAreRepaintedWithSkin) {
    SideSquare square({0.0, 0.0, 0.75, 1.0});
    const cv::Vec3b skin(120, 150, 205), shadow(75, 95, 130), hood(30, 200, 230), hairColour(25, 25, 30);
    const auto hairAt = [](glm::dvec2 p) { return p.x < -75.0; };  // p: (z, y)
    const auto paint = [&](glm::dvec2 p) {
        if (hairAt(p)) return hairColour;
        if (p.y < (p.x > 0.0 ? -60.0 : -10.0)) return hood;
        if (p.x > 50.0 && p.x < 70.0 && p.y < -40.0) return shadow;
        if (p.x > 40.0 && p.x < 70.0 && p.y > 40.0 && p.y < 70.0) return kBlue;
        return skin;
    };
    const cv::Mat side = paintPhoto(square.fit, true, paint);
    const cv::Mat sideHair = paintMask(square.fit, true, hairAt);
    const TextureTables tables(square.mesh, square.options);
    PhotoTexture t = textureFromPhotos(square.mesh, square.fit, square.front, square.all, side, square.all, square.options, tables);
    ASSERT_TRUE(nearColour(square.at(t, 40.0, -80.0), hood)) << "the photo's hood, before";
    ASSERT_TRUE(nearColour(square.at(t, -40.0, -30.0), hood)) << "the photo's hood behind the ear, before";
    // The texels beside the square's edge (no triangle's) hold the fill's bleed of the hood, which a renderer's
    // filtering reads at the edge (FRMDB 002: a thin yellow line along a seam of the neck).
    ASSERT_TRUE(nearColour(square.at(t, 104.0, -80.0), hood)) << "the hood's bleed beside the edge, before";

    NeckClothes neck;
    neck.topY = -30.0;
    neck.frontZ = 20.0;
    neck.backZ = -20.0;
    neck.backTopY = 10.0;
    cv::Mat lab;
    cv::cvtColor(cv::Mat(1, 1, CV_32FC3, cv::Scalar(skin[0] / 255.0, skin[1] / 255.0, skin[2] / 255.0)), lab, cv::COLOR_BGR2Lab);
    neck.skinLab = lab.at<cv::Vec3f>(0, 0);
    EXPECT_GT(skinOverClothesOnNeck(t, square.mesh, square.fit, ColourMatchMasks{{}, sideHair}, neck, square.options, tables), 0);
    for (const double z : {20.0, 40.0}) EXPECT_TRUE(nearColour(square.at(t, z, -80.0), skin)) << "skin at " << z << ", -80";
    EXPECT_FALSE(nearColour(square.at(t, 104.0, -80.0), hood)) << "the hood's bleed beside the edge is left";
    for (const double z : {-60.0, -40.0}) EXPECT_TRUE(nearColour(square.at(t, z, -30.0), skin)) << "skin at " << z << ", -30, behind the ear";
    EXPECT_TRUE(nearColour(square.at(t, 60.0, -50.0), shadow)) << "skin in shadow keeps its colour";
    EXPECT_TRUE(nearColour(square.at(t, -90.0, -30.0), hairColour)) << "hair stays";
    EXPECT_TRUE(nearColour(square.at(t, 55.0, 55.0), kBlue)) << "above the neck's top it stays";
}

// No photo sees the back of the sphere: it is filled from the colours around it, not left black.
TEST(PhotoTexture, UnseenTexelsAreFilledWithSurroundingColours) {
    const Mesh sphere = uvSphere(kRadius);
    const HeadFit fit = photoFrames();
    cv::Mat frontMask, sideMask;
    const auto same = [](const glm::dvec3&) { return 1.0; };
    const cv::Mat front = spherePhoto(fit, false, frontMask, same), side = spherePhoto(fit, true, sideMask, same);
    PhotoTextureOptions o;
    o.size = 256;
    const PhotoTexture t = textureFromPhotos(sphere, fit, front, frontMask, side, sideMask, o);
    const cv::Mat filled = t.source == PhotoTexture::Filled;
    ASSERT_GT(cv::countNonZero(filled), 1000) << "the back of the sphere is seen by neither photo";
    cv::Mat grey;
    cv::cvtColor(t.texture, grey, cv::COLOR_BGR2GRAY);
    double lo = 0, hi = 0;
    cv::minMaxLoc(grey, &lo, &hi, nullptr, nullptr, filled);
    // The sphere's colours run from about 40 to 215 per channel; the fill stays among them.
    EXPECT_GT(lo, 50.0);
    EXPECT_LT(hi, 215.0);
}

TEST(PhotoTexture, PullPushFillsHolesFromTheirSurroundings) {
    cv::Mat colour(64, 64, CV_32FC3, cv::Scalar(10, 100, 200)), weight(64, 64, CV_32F, cv::Scalar(1));
    colour(cv::Rect(20, 20, 24, 24)).setTo(cv::Scalar::all(0));
    weight(cv::Rect(20, 20, 24, 24)).setTo(0.0f);
    pullPushFill(colour, weight);
    const cv::Scalar m = cv::mean(colour(cv::Rect(20, 20, 24, 24)));
    EXPECT_NEAR(m[0], 10.0, 0.5);
    EXPECT_NEAR(m[1], 100.0, 0.5);
    EXPECT_NEAR(m[2], 200.0, 0.5);
    EXPECT_EQ(cv::countNonZero(weight != 1.0f), 0);
}

// A cut-out texture: an opaque strand of one colour, a partly clear fringe darker than it, black where clear. After
// the bleed the clear texels carry the strand's colour, the opaque ones keep theirs, and alpha is untouched.
TEST(PhotoTexture, ClearTexelsOfACutOutTakeTheOpaqueTexelsColour) {
    cv::Mat t(64, 64, CV_8UC4, cv::Scalar(0, 0, 0, 0));
    t(cv::Rect(24, 0, 16, 64)).setTo(cv::Scalar(40, 80, 120, 255));
    t(cv::Rect(22, 0, 2, 64)).setTo(cv::Scalar(10, 20, 30, 128));
    t(cv::Rect(40, 0, 2, 64)).setTo(cv::Scalar(10, 20, 30, 128));
    const cv::Mat before = t.clone();
    bleedIntoClearTexels(t);
    std::vector<cv::Mat> was, now;
    cv::split(before, was);
    cv::split(t, now);
    EXPECT_EQ(cv::countNonZero(was[3] != now[3]), 0) << "alpha changed";
    const cv::Scalar strand = cv::mean(t(cv::Rect(24, 0, 16, 64)));
    EXPECT_EQ(strand, cv::Scalar(40, 80, 120, 255));
    for (const int x : {0, 10, 21, 42, 50, 63}) {
        const cv::Vec4b c = t.at<cv::Vec4b>(32, x);
        EXPECT_NEAR(c[0], 40, 2) << x;
        EXPECT_NEAR(c[1], 80, 2) << x;
        EXPECT_NEAR(c[2], 120, 2) << x;
    }
    // The fringe, at alpha 128, keeps (128 - 112) / 112 of its own colour (opacity 224 and up keeps all of it, half
    // of that and under none).
    const double keep = (128.0 - 112.0) / 112.0;
    for (const int x : {22, 41}) {
        const cv::Vec4b c = t.at<cv::Vec4b>(32, x);
        EXPECT_NEAR(c[0], keep * 10 + (1 - keep) * 40, 1.5) << x;
        EXPECT_NEAR(c[1], keep * 20 + (1 - keep) * 80, 1.5) << x;
        EXPECT_NEAR(c[2], keep * 30 + (1 - keep) * 120, 1.5) << x;
    }
    cv::Mat opaque(4, 4, CV_8UC3);
    EXPECT_THROW(bleedIntoClearTexels(opaque), BoothError);
}

// The z-buffer: the nearer of two overlapping triangles wins, and pixels no triangle covers stay at -infinity.
TEST(ViewDepth, NearestTriangleWins) {
    const std::vector<ViewVertex> v = {{10, 10, 1}, {90, 10, 1}, {10, 90, 1}, {10, 10, 5}, {90, 10, 5}, {10, 90, 5}};
    const std::vector<glm::uvec3> t = {{0, 1, 2}, {3, 5, 4}};  // either winding
    const cv::Mat z = rasteriseNearestDepth(v, t, cv::Size(100, 100));
    EXPECT_FLOAT_EQ(z.at<float>(20, 20), 5.0f);
    EXPECT_TRUE(std::isinf(z.at<float>(95, 95)) && z.at<float>(95, 95) < 0);
}
