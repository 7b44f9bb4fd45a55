// The avatar styles shown side by side on the reveal and attract screens ([reveal] styles: RevealStyle each), the
// head motion they all turn with, and the tile stage under them, as the kiosk's main loop uses them.
//
// The kiosk hands each finished fit to visitor() (and runs the work it returns off the screen's thread), and the
// character to visitorCharacter() when the fitter has made it. Each frame, fill() hands out every style's picture
// at the size it is shown, and the stage; every picture is kept and reused while the animation holds a pose or the
// stage camera holds its angle.
#pragma once

#include "reveal/styles/photo_style.h"
#include "reveal/styles/reveal_style.h"
#include "reveal/styles/style_settings.h"

#include <opencv2/core.hpp>

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

struct BaseHead;
class HeadlessEglContext;

// One style's picture (reveal and attract show several side by side).
struct StyledAvatar {
    std::string style;  // "photo", "character", "toon": its label is the string "style.<style>"
    cv::Mat image;      // BGR or BGRA; empty: still being made (the place shows "style.making")
};

// What fill() hands the screen: the styles in order of importance, and the stage band.
struct StyleImages {
    std::vector<StyledAvatar> avatars;
    cv::Mat stage;  // BGRA, at half the band's resolution; empty without a stage
};

// The styles a configuration lists, in its order, made by name (the one place that knows every style).
std::vector<std::unique_ptr<RevealStyle>> makeRevealStyles(const RevealSettings& reveal, const BaseHead& base,
                                                           HeadlessEglContext* context, PhotoStyleOptions photo = {});

class RevealStyles {
public:
    // `base` shows before the first visitor. Throws BoothError (BadConfig) when the stage map cannot be read or
    // parsed (file:line:column). `context`: the GL context the styles and the stage render through (the kiosk's
    // one offscreen context for its main thread; it must outlive this); their own when null.
    RevealStyles(const RevealSettings& reveal, const StageSettings& stage, const AnimationSettings& animation,
                 const BaseHead& base, HeadlessEglContext* context = nullptr, PhotoStyleOptions photo = {});
    ~RevealStyles();

    // A new visitor's fit: each style drops the last visitor's picture and starts on this one's. Returns the work
    // to run off the screen's thread, in order; what it posts is run on the screen's thread.
    std::vector<StyleWork> visitor(const FitOutcome& fit);
    // The current visitor's character, once made; null when none comes (its making failed or it is off).
    void visitorCharacter(const CharacterOutputs* character);

    // Every style's picture in order, each `sizes[i]` pixels square (the size its place is shown at; the last size
    // for the rest), and the stage for a band of `stageBand` pixels (none when empty), for the reveal (`reveal`)
    // or attract screen `since` it was entered. A style without a picture has an empty place on the reveal while
    // it is being made, and no place otherwise.
    void fill(StyleImages& out, bool reveal, std::chrono::milliseconds since, const std::vector<int>& sizes,
              cv::Size stageBand);
    // Changes whenever a picture fill() hands out changes (a new render, a style appearing or going); for the
    // screen, which does not compose an unchanged reveal again.
    std::uint64_t version() const;
    // Whether the last fill() had a picture for every style it listed (the toon may still be drawing).
    bool complete() const { return complete_; }
    // A picture that comes for sure and soon (the character) is still awaited.
    bool awaitingSoon() const;
    // No style's work is running for the current visitor.
    bool settled() const;
    // Whether a kept session gets extras of some style (the toon strip).
    bool hasExtras() const;
    // Writes every style's extras for a kept session (the toon strip). Returns whether any wrote.
    bool writeInto(const std::filesystem::path& keptSession);
    // Whether the last fill() had the photo style's picture.
    bool photoShown() const { return photoShown_; }
    std::size_t photoTriangles() const;
    int photoSamples() const;

    StyleFigures figures() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    bool complete_ = true;
    bool photoShown_ = false;
};

}  // namespace avatarbooth
