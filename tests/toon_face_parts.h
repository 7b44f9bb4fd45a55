// Checks shared by the toon tests on photos (synthetic visitor, FRMDB): a toon drawn with landmarks has the face parts
// as regions of their own, one skin (maybe one shade) on the cheeks, and the parts matched between the views.
#pragma once

#include "reveal/toon/toon_billboard.h"

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <map>
#include <optional>
#include <string>

namespace avatarbooth::test {

inline cv::Point2d centreOf(const std::vector<cv::Point2d>& polygon) {
    cv::Point2d sum(0, 0);
    for (const auto& p : polygon) sum += p;
    return polygon.empty() ? sum : sum / static_cast<double>(polygon.size());
}

// The index in regions.regions of the region drawn at `p`, if any.
inline std::optional<std::size_t> regionAt(const toon::Regions& regions, cv::Point2d p) {
    const cv::Point q(cvRound(p.x), cvRound(p.y));
    if (!cv::Rect(0, 0, regions.labels.cols, regions.labels.rows).contains(q)) return std::nullopt;
    const int label = regions.labels.at<int>(q);
    for (std::size_t i = 0; i < regions.regions.size(); ++i)
        if (label > 0 && regions.regions[i].label == label) return i;
    return std::nullopt;
}

// The largest drawn region (label > 0): the skin.
inline std::size_t largestRegion(const toon::Regions& regions) {
    std::size_t best = 0;
    double area = -1.0;
    for (std::size_t i = 0; i < regions.regions.size(); ++i)
        if (regions.regions[i].label > 0 && regions.regions[i].area > area) {
            area = regions.regions[i].area;
            best = i;
        }
    return best;
}

// Per view: every iris, brow and mouth of the guide is a region of its own at its place (not the largest region,
// under 5 % of the head); the cheeks (the guide's skin samples) are at most two regions of 5 % of them or more, one
// holding 70 % or more. Across views: the front's irises and mouth are matched to the side's iris and mouth.
inline void expectFaceParts(const toon::ToonModel& model, const std::string& what) {
    auto check = [&](const toon::Regions& regions, const toon::DrawingGuide& guide, const char* view) {
        SCOPED_TRACE(what + ", " + view + " view");
        ASSERT_FALSE(guide.features.empty());
        const std::size_t skin = largestRegion(regions);
        const double head = cv::countNonZero(regions.labels != 0);
        std::map<std::string, int> seen;
        for (const toon::FeatureShape& f : guide.features) {
            if (f.name != "iris" && f.name != "brow" && f.name != "mouth") continue;
            const auto at = regionAt(regions, centreOf(f.polygon));
            ASSERT_TRUE(at.has_value()) << f.name << " has no region";
            EXPECT_NE(*at, skin) << f.name << " is drawn as skin";
            EXPECT_LT(regions.regions[*at].area, 0.05 * head) << f.name;
            ++seen[f.name];
        }
        EXPECT_GE(seen["iris"], 1);
        EXPECT_EQ(seen["mouth"], 1);
        cv::Mat cheeks = cv::Mat::zeros(regions.labels.size(), CV_8U);
        for (const auto& poly : guide.skinSamples) {
            std::vector<cv::Point> q;
            for (const auto& p : poly) q.emplace_back(cvRound(p.x), cvRound(p.y));
            cv::fillPoly(cheeks, std::vector<std::vector<cv::Point>>{q}, cv::Scalar(255));
        }
        cheeks &= regions.labels != 0;
        std::map<int, int> count;
        int total = 0;
        for (int r = 0; r < cheeks.rows; ++r)
            for (int c = 0; c < cheeks.cols; ++c)
                if (cheeks.at<uchar>(r, c)) {
                    ++count[regions.labels.at<int>(r, c)];
                    ++total;
                }
        ASSERT_GT(total, 50);
        int big = 0, most = 0;
        for (const auto& [label, n] : count) {
            if (n >= 0.05 * total) ++big;
            most = std::max(most, n);
        }
        EXPECT_LE(big, 2) << "the cheeks are cut into " << big << " regions";
        EXPECT_GE(most, 0.7 * total) << "no one skin region holds the cheeks";
    };
    check(model.regionsA, model.guideA, "front");
    check(model.regionsB, model.guideB, "side");

    auto sideRegionOf = [&](const char* name) -> std::optional<std::size_t> {
        for (const toon::FeatureShape& f : model.guideB.features)
            if (f.name == name) return regionAt(model.regionsB, centreOf(f.polygon));
        return std::nullopt;
    };
    for (const char* name : {"iris", "mouth"}) {
        const auto side = sideRegionOf(name);
        ASSERT_TRUE(side.has_value()) << what << ": the side has no " << name;
        for (const toon::FeatureShape& f : model.guideA.features) {
            if (f.name != name) continue;
            const auto front = regionAt(model.regionsA, centreOf(f.polygon));
            ASSERT_TRUE(front.has_value());
            const auto pair = std::find_if(model.pairs.begin(), model.pairs.end(),
                                           [&](const toon::PlacedPair& p) { return p.regionA == *front; });
            ASSERT_NE(pair, model.pairs.end()) << what << ": the front " << name << " is unmatched";
            EXPECT_EQ(pair->regionB, *side) << what << ": the front " << name << " is matched to another side region";
        }
    }
}

}  // namespace avatarbooth::test
