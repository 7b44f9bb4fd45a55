// The toon style (see toon_style.h).
#include "reveal/styles/toon_style.h"

#include "common/atomic_output.h"
#include "fit/fit_pipeline.h"
#include "reveal/toon/toon_billboard.h"

#include <spdlog/spdlog.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace avatarbooth {

namespace {

// The toon is drawn at the scale `avatarbooth toon` uses: toonFromPhotos makes the head 320 units high, the image
// leaves room around it for the turn.
const cv::Size kToonSize(400, 440);
constexpr double kToonUnitsPerPixel = 1.0;

cv::Mat withAlpha(const cv::Mat& bgr, const cv::Mat& mask) {
    cv::Mat channels[4];
    cv::split(bgr, channels);
    channels[3] = mask;
    cv::Mat bgra;
    cv::merge(channels, 4, bgra);
    return bgra;
}

// The head's turn as a billboard yaw: where the camera (on +z) stands in the head's own frame, in degrees around
// the vertical axis (0 front, + the character's left side; see toon::ViewDirection).
double toonYaw(const AnimationFrame& frame) {
    const glm::dvec3 c = glm::inverse(frame.headWorld) * glm::dvec3(0.0, 0.0, 1.0);
    return glm::degrees(std::atan2(c.x, c.z));
}

}  // namespace

StyleInputs styleInputsFrom(const FitOutcome& o) {
    StyleInputs in;
    in.front = o.front;
    in.frontMask = o.frontMask;
    in.side = o.side;
    in.sideMask = o.sideMask;
    in.sideNoseImageRight = o.sideNoseImageRight;
    in.frontLandmarks = o.frontLandmarks.points;
    in.sideLandmarks = o.sideLandmarks;
    if (const auto it = o.sideLandmarks.find("chin"); it != o.sideLandmarks.end())
        in.sideChinRow = static_cast<int>(it->second.y) + 1;
    return in;
}

ToonStyle::ToonStyle(const RevealSettings& settings) : settings_(settings) {}
ToonStyle::~ToonStyle() = default;

StyleWork ToonStyle::visitor(std::uint64_t id, const FitOutcome& fit) { return visitor(id, styleInputsFrom(fit)); }

StyleWork ToonStyle::visitor(std::uint64_t visitor, StyleInputs in) {
    visitor_ = visitor;
    model_.reset();  // never the previous visitor's toon on this one's reveal
    strip_.clear();
    image_.release();
    drawing_ = stripPending_ = true;
    ++version_;
    // The work captures copies only; what it posts checks that the visitor is still this one.
    return [this, visitor, in = std::move(in), colours = settings_.toonColours,
            stripFrames = settings_.toonStripFrames](const StylePost& post) {
        const auto t0 = std::chrono::steady_clock::now();
        std::shared_ptr<const toon::ToonModel> model;
        try {
            // Both photos come from one camera at one height: the side photo's chin row cuts both masks to the
            // head (as `avatarbooth toon` does).
            cv::Mat frontMask = in.frontMask.clone(), sideMask = in.sideMask.clone();
            if (in.sideChinRow >= 0) {
                frontMask.rowRange(std::clamp(in.sideChinRow, 0, frontMask.rows), frontMask.rows).setTo(0);
                sideMask.rowRange(std::clamp(in.sideChinRow, 0, sideMask.rows), sideMask.rows).setTo(0);
            }
            model = std::make_shared<toon::ToonModel>(toon::toonFromPhotos(
                in.front, frontMask, in.side, sideMask, in.sideNoseImageRight, colours, 320,
                toon::ToonLandmarks{in.frontLandmarks, in.sideLandmarks}));
        } catch (const std::exception& e) {
            spdlog::warn("the toon could not be drawn: {}", e.what());
        }
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        if (model) spdlog::info("toon drawn in {:.2f} s ({} matched regions)", seconds, model->pairs.size());
        post([this, visitor, model, seconds] {
            if (visitor != visitor_) return;  // an earlier visitor's
            drawing_ = false;
            model_ = model;
            image_.release();
            buildSeconds_ = seconds;
            ++version_;
        });
        std::vector<std::pair<std::string, std::string>> strip;
        try {
            if (model) strip = toon::turntableFrames(*model, stripFrames, kToonSize, kToonUnitsPerPixel);
        } catch (const std::exception& e) {
            spdlog::warn("the toon's turntable strip could not be made: {}", e.what());
        }
        post([this, visitor, strip = std::move(strip)]() mutable {
            if (visitor != visitor_) return;
            stripPending_ = false;
            strip_ = std::move(strip);
        });
    };
}

const cv::Mat& ToonStyle::frame(const AnimationFrame& pose, bool, int) {
    static const cv::Mat kNone;
    if (!model_) return kNone;
    const double yaw = std::round(toonYaw(pose) * 2.0) / 2.0;  // half a degree: invisible, a slow turn reuses images
    if (!image_.empty() && yaw == imageYaw_) return image_;
    const auto t0 = std::chrono::steady_clock::now();
    cv::Mat coverage;
    const cv::Mat bgr = toon::renderToon(*model_, yaw, kToonSize, kToonUnitsPerPixel, 2, &coverage);
    image_ = withAlpha(bgr, coverage);
    imageYaw_ = yaw;
    renderMs_.add(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    ++renders_;
    ++version_;
    return image_;
}

bool ToonStyle::writeInto(const std::filesystem::path& keptSession) {
    if (strip_.empty()) return false;
    StagedDirectory dir(keptSession / "toon", "turntable_000.png");
    for (const auto& [name, png] : strip_) writeFileAtomically(dir.staging() / name, png);
    dir.commit();
    return true;
}

void ToonStyle::addFigures(StyleFigures& figures) const {
    figures.toonMs = renderMs_.median();
    figures.toonRenders = renders_;
    figures.toonBuildSeconds = buildSeconds_;
}

}  // namespace avatarbooth
