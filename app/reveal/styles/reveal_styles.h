// The avatar styles besides the photo-fitted head on the reveal and attract screens — the character (issue 6) and
// the two-view toon (issue 7) — and the tile stage under them, as the kiosk's main loop uses them.
//
// The kiosk hands each finished fit to visitor(), and the character head to visitorCharacter() when the fitter has
// made it (a moment later: the reveal does not wait for it); the toon is drawn from the two photos on a
// worker thread of its own so the screen never waits. Each frame, fill() adds the styles' images (and the stage) to
// the screen's inputs; every image is kept and reused while the animation holds a pose or the stage camera holds
// its angle.
#pragma once

#include "reveal/animation/avatar_motion.h"
#include "fit/head/base_head.h"
#include "fit/head/mesh.h"
#include "reveal/styles/style_settings.h"
#include "booth/screens/screens.h"

#include <opencv2/core.hpp>

#include <array>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>

namespace avatarbooth {

struct FitOutcome;
class HeadlessEglContext;

// What the toon needs of one fit: the photos with their head masks.
struct StyleInputs {
    cv::Mat front, frontMask, side, sideMask;
    bool sideNoseImageRight = true;
    int sideChinRow = -1;  // the side photo's chin row: both masks are cut there (head only); -1: not cut
    // The fit's landmarks (optional): the toon draws the eyes, brows, nostrils and mouth as regions of their own.
    std::optional<std::array<cv::Point2d, 68>> frontLandmarks;
    std::map<std::string, cv::Point2d> sideLandmarks;
};
// Takes what the styles need from a fit (the photos and masks are shared, not copied).
StyleInputs styleInputsFrom(const FitOutcome& outcome);

// Per-style cost of the last frames, for the benchmark figures (milliseconds, medians over the frames that drew).
struct StyleFigures {
    double characterMs = 0.0, toonMs = 0.0, stageMs = 0.0;
    double toonBuildSeconds = 0.0;  // the last toon drawn from photos
    int stageRenders = 0, characterRenders = 0, toonRenders = 0, frames = 0;
};

class RevealStyles {
public:
    // `base` shows as the character (painted, neutral proportions) before the first visitor. Throws BoothError
    // (BadConfig) when the stage map cannot be read or parsed (file:line:column).
    // `context`: the GL context the character and the stage render through (the kiosk's one offscreen context for
    // its main thread; it must outlive this); their own when null.
    RevealStyles(const RevealSettings& reveal, const StageSettings& stage, const AnimationSettings& animation,
                 const BaseHead& base, int avatarSize, HeadlessEglContext* context = nullptr);
    ~RevealStyles();

    // A new visitor's fit: starts drawing their toon (an earlier toon still being drawn is dropped); their character
    // is awaited (its place says so on the reveal; never the previous visitor's).
    void visitor(StyleInputs inputs);
    // The current visitor's character head, once made; or none (its making or the session's write failed): the
    // character's place is then left out.
    void visitorCharacter(const Mesh& mesh, const cv::Mat& texture);
    void visitorWithoutCharacter();
    // Changes whenever an image fill() hands out changes (a new render, a style appearing or going); for the screen,
    // which does not compose an unchanged reveal again.
    std::uint64_t version() const;

    // Adds to `in` the image of every configured style in order (the photo style is `in.avatar`, which the kiosk
    // rendered) and the stage, for the reveal (`reveal`) or attract screen `since` it was entered.
    void fill(ScreenInputs& in, bool reveal, std::chrono::milliseconds since, const ScreenLayout& layout);

    // The visitor's character is still being made (it comes, or visitorWithoutCharacter() says it will not).
    bool characterPending() const;
    // Whether the toon style is on (drawn for every visitor).
    bool showsToon() const;
    // Whether the last fill() had an image for every style it listed (the toon may still be drawing).
    bool complete() const { return complete_; }
    // No toon is being drawn for the current visitor (drawn, failed, or none asked for).
    bool toonSettled() const;
    // Writes the current visitor's toon turntable strip into `sessionFolder`/toon (atomically) when there is one.
    // Returns whether it wrote.
    bool writeToonStrip(const std::filesystem::path& sessionFolder);

    StyleFigures figures() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    bool complete_ = true;
};

}  // namespace avatarbooth
