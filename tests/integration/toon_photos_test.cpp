// Integration test of the toon character from photos: the synthetic visitor's pair to a turntable strip of PNGs.
#include "fit/face/silhouette.h"
#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"
#include "sim/synthetic_visitor.h"
#include "test_paths.h"
#include "reveal/toon/toon_billboard.h"
#include "toon_face_parts.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace avatarbooth::toon {
namespace {

// The person's silhouette cut below the chin: the head the toon is drawn from.
cv::Mat headMask(const cv::Mat& photo, const cv::Mat& background, double chinRow) {
    cv::Mat mask = segmentPerson(photo, background);
    const int cut = std::clamp(static_cast<int>(chinRow) + 1, 0, mask.rows);
    mask.rowRange(cut, mask.rows).setTo(0);
    return mask;
}

// The synthetic visitor's two photos with their head masks (cut under the chin), as the kiosk hands them over.
struct VisitorPhotos {
    SyntheticVisitorOptions options;
    SyntheticVisitor visitor;
    cv::Mat frontMask, sideMask;
};
VisitorPhotos visitorPhotos() {
    MeshRenderer renderer;
    VisitorPhotos p;
    p.options.textureSize = 512;
    p.visitor = makeSyntheticVisitor(builtinBaseHead(), renderer, p.options);
    p.frontMask = headMask(p.visitor.front, p.visitor.background, p.visitor.frontLandmarks.at("ibug_08").y);
    p.sideMask = headMask(p.visitor.side, p.visitor.background, p.visitor.sideLandmarks.at("chin").y);
    return p;
}

TEST(ToonPhotos, SyntheticVisitorBecomesAToonTurntable) {
    const VisitorPhotos photos = visitorPhotos();
    const SyntheticVisitor& visitor = photos.visitor;
    const SyntheticVisitorOptions& options = photos.options;
    const cv::Mat &frontMask = photos.frontMask, &sideMask = photos.sideMask;
    const ToonModel model = toonFromPhotos(visitor.front, frontMask, visitor.side, sideMask, options.sideNoseImageRight);

    ASSERT_GE(model.regionsA.regions.size(), 3u);
    ASSERT_GE(model.regionsB.regions.size(), 3u);
    ASSERT_GE(model.pairs.size(), 3u);
    // The whole-head backdrop pair comes first; of the drawn regions (label > 0) the biggest of each view (the
    // skin) is matched with the other view's biggest.
    ASSERT_EQ(model.backdropPairs, 1u);
    EXPECT_EQ(model.regionsA.regions[model.pairs[0].regionA].label, -1);
    auto biggest = [](const Regions& r) {
        std::size_t best = 0;
        for (std::size_t i = 0; i < r.regions.size(); ++i)
            if (r.regions[i].label > 0 && (r.regions[best].label <= 0 || r.regions[i].area > r.regions[best].area)) best = i;
        return best;
    };
    const std::size_t bigA = biggest(model.regionsA), bigB = biggest(model.regionsB);
    const auto pair = std::find_if(model.pairs.begin(), model.pairs.end(), [&](const PlacedPair& p) { return p.regionA == bigA; });
    ASSERT_NE(pair, model.pairs.end());
    EXPECT_EQ(pair->regionB, bigB);

    // At the front the toon covers about the head's area (the drawing was scaled to 320 px of head height).
    const cv::Mat front = renderToon(model, 0.0, {400, 400}, 1.0);
    cv::Mat paper;
    cv::inRange(front, cv::Scalar(255, 255, 255), cv::Scalar(255, 255, 255), paper);
    const double covered = static_cast<double>(front.total()) - cv::countNonZero(paper);
    double drawn = 0.0;
    for (const PlacedPair& p : model.pairs) drawn = std::max(drawn, model.regionsA.regions[p.regionA].area);
    EXPECT_GT(covered, 0.8 * drawn);
    EXPECT_LT(covered, 1.6 * cv::countNonZero(cv::Mat(model.regionsA.labels != 0)));

    const auto dir = test::scratchDir("toon_turntable");
    const auto frames = writeTurntable(model, dir, 9, {320, 360}, 1.2);
    ASSERT_EQ(frames.size(), 9u);
    const cv::Mat first = cv::imread(frames.front().string()), middle = cv::imread(frames[4].string()),
                  last = cv::imread(frames.back().string());
    ASSERT_FALSE(first.empty());
    EXPECT_EQ(first.size(), cv::Size(320, 360));
    // -90 and +90 are mirror images; the front differs from both.
    cv::Mat mirrored;
    cv::flip(last, mirrored, 1);
    EXPECT_EQ(cv::norm(first, mirrored, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::norm(first, middle, cv::NORM_L1), 0.0);
}

// With the visitor's landmarks (what the fit hands the kiosk) the drawing has the eyes, brows and mouth as regions
// at their places in both views, matched front to side, and the cheeks are one skin.
TEST(ToonPhotos, LandmarksGiveTheSyntheticVisitorFacePartsAndOneSkin) {
    const VisitorPhotos photos = visitorPhotos();
    const SyntheticVisitor& visitor = photos.visitor;
    const SyntheticVisitorOptions& options = photos.options;
    const cv::Mat &frontMask = photos.frontMask, &sideMask = photos.sideMask;
    ToonLandmarks landmarks;
    landmarks.front.emplace();
    for (std::size_t i = 0; i < 68; ++i) (*landmarks.front)[i] = visitor.frontLandmarks.at(cv::format("ibug_%02zu", i));
    landmarks.side = visitor.sideLandmarks;
    const ToonModel model = toonFromPhotos(visitor.front, frontMask, visitor.side, sideMask, options.sideNoseImageRight,
                                           6, 320, landmarks);
    test::expectFaceParts(model, "synthetic visitor");
    cv::imwrite((test::scratchDir("toon_face_parts") / "front.png").string(), renderToon(model, 0.0, {400, 440}, 1.0));
}

}  // namespace
}  // namespace avatarbooth::toon
