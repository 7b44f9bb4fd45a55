// The guides on rendered images: the synthetic visitor's front photo says "hold still", its profiles (either way)
// are seen as profiles and its front is not, the empty booth has nobody, and the preview analyses' rates are
// printed (the real photos' test is tests/data/booth_guidance_data_test.cpp).
#include "booth/guidance.h"
#include "fit/face/landmarks68.h"
#include "sim/synthetic_visitor.h"

#include <opencv2/imgproc.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>

using namespace avatarbooth;

namespace {

const LandmarkDetector& detector() {
    static const LandmarkDetector d(AVATARBOOTH_DEFAULT_DLIB_MODEL);
    return d;
}

const SyntheticVisitor& visitor(bool noseRight) {
    static MeshRenderer renderer;
    static std::map<bool, SyntheticVisitor> cache;
    auto it = cache.find(noseRight);
    if (it == cache.end()) {
        SyntheticVisitorOptions o;
        o.seed = 3;
        o.sideNoseImageRight = noseRight;
        o.textureSize = 512;
        it = cache.emplace(noseRight, makeSyntheticVisitor(builtinBaseHead(), renderer, o)).first;
    }
    return it->second;
}

// A 640-px-wide copy, as a preview stream delivers it.
cv::Mat preview(const cv::Mat& photo) {
    cv::Mat out;
    const double s = 640.0 / photo.cols;
    cv::resize(photo, out, {}, s, s, cv::INTER_AREA);
    return out;
}

double medianMs(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

}  // namespace

TEST(GuidanceImages, SyntheticFrontSaysHoldStill) {
    PreviewAnalyser analyser(&detector(), {});
    const FrontObservation obs = analyser.observeFront(preview(visitor(true).front));
    ASSERT_TRUE(obs.face.has_value());
    const cv::Rect2d oval = ovalBox(GuidanceSettings{}.oval, obs.frame);
    const auto& p = *obs.landmarks;
    std::printf("synthetic front: face/oval %.2f, centre off (%.2f, %.2f) oval heights, yaw %.2f\n",
                obs.face->height / oval.height,
                (obs.face->x + obs.face->width / 2 - oval.x - oval.width / 2) / oval.height,
                (obs.face->y + obs.face->height / 2 - oval.y - oval.height / 2) / oval.height,
                (p[30].x - 0.5 * (p[36].x + p[45].x)) / cv::norm(p[45] - p[36]));
    EXPECT_EQ(frontHint(obs, {}), Hint::HoldStill);
}

TEST(GuidanceImages, SyntheticProfilesAreSeenAndTheFrontIsNot) {
    PreviewAnalyser analyser(&detector(), {});
    for (bool noseRight : {true, false}) {
        const SideObservation side = analyser.observeSide(preview(visitor(noseRight).side));
        EXPECT_TRUE(side.personSeen);
        EXPECT_FALSE(side.frontalFace);
        EXPECT_TRUE(side.profileSeen) << "nose right " << noseRight;
        EXPECT_EQ(side.noseImageRight, noseRight);
        EXPECT_EQ(sideHint(side), Hint::HoldStill);
    }
    const SideObservation front = analyser.observeSide(preview(visitor(true).front));
    EXPECT_TRUE(front.personSeen);
    EXPECT_FALSE(front.profileSeen && !front.frontalFace);
    EXPECT_EQ(sideHint(front), Hint::TurnRight);
}

TEST(GuidanceImages, EmptyBoothHasNobody) {
    PreviewAnalyser analyser(&detector(), {});
    const cv::Mat empty = preview(visitor(true).background);
    EXPECT_EQ(frontHint(analyser.observeFront(empty), {}), Hint::NoFace);
    const SideObservation side = analyser.observeSide(empty);
    EXPECT_FALSE(side.profileSeen);
    EXPECT_EQ(sideHint(side), Hint::TurnRight);
}

TEST(GuidanceImages, PreviewAnalysisRateIsPrinted) {
    PreviewAnalyser analyser(&detector(), {});
    PreviewAnalyser cascadeOnly(nullptr, {});
    const cv::Mat front = preview(visitor(true).front), side = preview(visitor(true).side);
    std::vector<double> frontMs, cascadeMs, sideMs;
    auto time = [](auto&& f) {
        const auto t0 = std::chrono::steady_clock::now();
        f();
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    };
    for (int i = 0; i < 15; ++i) {
        frontMs.push_back(time([&] { analyser.observeFront(front); }));
        cascadeMs.push_back(time([&] { cascadeOnly.observeFront(front); }));
        sideMs.push_back(time([&] { analyser.observeSide(side); }));
    }
    std::printf("preview analysis on %dx%d, median of 15: front (cascade + 68 points) %.1f ms = %.0f Hz, front "
                "(cascade only) %.1f ms = %.0f Hz, side (cascade + silhouette + profile) %.1f ms = %.0f Hz\n",
                front.cols, front.rows, medianMs(frontMs), 1000.0 / medianMs(frontMs), medianMs(cascadeMs),
                1000.0 / medianMs(cascadeMs), medianMs(sideMs), 1000.0 / medianMs(sideMs));
    SUCCEED();
}
