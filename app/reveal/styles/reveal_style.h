// One way of showing the visitor's head on the reveal and attract screens (photo, character, toon): the interface
// each style implements, so that a new style is one new file and the kiosk knows none of them by name.
#pragma once

#include "reveal/animation/avatar_motion.h"
#include "reveal/styles/style_settings.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <filesystem>
#include <functional>

namespace avatarbooth {

struct FitOutcome;
struct CharacterOutputs;

// Per-style cost of the recent frames, for the benchmark figures (milliseconds, medians over the frames that drew).
struct StyleFigures {
    double characterMs = 0.0, toonMs = 0.0, stageMs = 0.0;
    double toonBuildSeconds = 0.0;  // the last toon drawn from photos
    int stageRenders = 0, characterRenders = 0, toonRenders = 0, frames = 0;
};

// Work a style hands out for a visitor, to run off the screen's thread (drawing the toon takes a second or more).
// It may call `post` several times, each with what to do on the screen's thread with a result (the toon first, its
// strip later); it touches nothing of the style itself, only what it captured.
using StylePost = std::function<void(std::function<void()> onScreenThread)>;
using StyleWork = std::function<void(const StylePost& post)>;

class RevealStyle {
public:
    virtual ~RevealStyle() = default;

    virtual AvatarStyle kind() const = 0;
    // A new visitor's fit: the previous visitor's picture is dropped (never shown on this one's reveal). Returns
    // the work to do for it off the screen's thread; empty when there is none.
    virtual StyleWork visitor(std::uint64_t visitor, const FitOutcome& fit) = 0;
    // The current visitor's character (null: none will come).
    virtual void character(const CharacterOutputs* character) { (void)character; }
    // Its picture for the current visitor is still being made: its place on the reveal says so.
    virtual bool pending() const = 0;
    // Whether a pending picture comes for sure, and soon (made right after the fit): a reveal is pictured only
    // once it is there.
    virtual bool comesSoon() const { return false; }
    // Its picture at `pose` (BGRA, coverage as alpha, `size` pixels square: rendered at the size shown); empty when
    // it has none. A pose it drew already gives the same image again without rendering.
    virtual const cv::Mat& frame(const AnimationFrame& pose, bool reveal, int size) = 0;
    // Changes whenever frame() hands out a new picture.
    virtual std::uint64_t version() const = 0;
    // No work of its own is running for the current visitor.
    virtual bool settled() const { return true; }
    // Whether a kept session gets something of it besides the session folder (writeInto).
    virtual bool hasExtras() const { return false; }
    // Writes what a kept session gets of it besides the session folder (the toon's turntable strip) into
    // `keptSession`; false when there is nothing.
    virtual bool writeInto(const std::filesystem::path& keptSession) { (void)keptSession; return false; }
    virtual void addFigures(StyleFigures& figures) const { (void)figures; }
};

}  // namespace avatarbooth
