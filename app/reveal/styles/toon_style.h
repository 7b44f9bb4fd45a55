// The toon style (Kitamura): the two-view billboard character drawn from the visitor's two photos, turned with
// the head motion and mirrored for the other side; a kept session gets its turntable strip.
#pragma once

#include "common/recent_timings.h"
#include "reveal/styles/reveal_style.h"

#include <array>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

namespace toon {
struct ToonModel;
}

// What the toon is drawn from: the photos with their head masks.
struct StyleInputs {
    cv::Mat front, frontMask, side, sideMask;
    bool sideNoseImageRight = true;
    int sideChinRow = -1;  // the side photo's chin row: both masks are cut there (head only); -1: not cut
    // The fit's landmarks (optional): the toon draws the eyes, brows, nostrils and mouth as regions of their own.
    std::optional<std::array<cv::Point2d, 68>> frontLandmarks;
    std::map<std::string, cv::Point2d> sideLandmarks;
};
// Takes what the toon needs from a fit (the photos and masks are shared, not copied).
StyleInputs styleInputsFrom(const FitOutcome& outcome);

class ToonStyle final : public RevealStyle {
public:
    explicit ToonStyle(const RevealSettings& settings);
    ~ToonStyle() override;

    AvatarStyle kind() const override { return AvatarStyle::Toon; }
    // The drawing (a second or more) and then its strip are the work handed out.
    StyleWork visitor(std::uint64_t visitor, const FitOutcome& fit) override;
    bool pending() const override { return drawing_; }
    const cv::Mat& frame(const AnimationFrame& pose, bool reveal, int size) override;
    std::uint64_t version() const override { return version_; }
    bool settled() const override { return !drawing_ && !stripPending_; }
    bool hasExtras() const override { return true; }
    bool writeInto(const std::filesystem::path& keptSession) override;
    void addFigures(StyleFigures& figures) const override;

private:
    StyleWork visitor(std::uint64_t visitor, StyleInputs inputs);

    RevealSettings settings_;
    std::uint64_t visitor_ = 0;
    bool drawing_ = false;       // the model is being made (its place shows "drawing you")
    bool stripPending_ = false;  // its strip is being made
    std::shared_ptr<const toon::ToonModel> model_;
    std::vector<std::pair<std::string, std::string>> strip_;
    cv::Mat image_;
    double imageYaw_ = 1000.0;
    std::uint64_t version_ = 0;
    int renders_ = 0;
    double buildSeconds_ = 0.0;
    RecentTimings renderMs_;
};

}  // namespace avatarbooth
