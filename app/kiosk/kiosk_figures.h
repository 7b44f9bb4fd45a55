// The kiosk's speed and memory figures (`avatarbooth run` prints them; the README's targets are for these), and
// where a slow main-loop step spent its time.
#pragma once

#include "booth/flow_types.h"
#include "common/recent_timings.h"
#include "kiosk/kiosk.h"

#include <chrono>
#include <optional>
#include <utility>
#include <vector>

namespace avatarbooth {

class RevealStyles;

class KioskFigures {
public:
    using Time = std::chrono::steady_clock::time_point;

    // A frame presented: its screen, when its drawing started, when the styles were rendered (and whether any
    // rendered), when the screen was composed, when it was presented.
    struct Frame {
        ScreenId screen;
        Time drawStart, renderEnd, composeEnd, presented;
        bool rendered = false;
        bool avatarShown = false;
    };
    void frame(const Frame& f);
    void analysed(ScreenId screen);   // a preview analysis arrived while `screen` was shown
    void sidePhotoTaken(Time t);

    // Fills the report's figures (and peak RSS) at the run's end.
    void report(KioskReport& report, const RevealStyles& styles) const;

private:
    int guideFrames_ = 0, analyses_ = 0;
    double guideSeconds_ = 0.0;
    bool inGuide_ = false;
    Time lastGuideFrame_{};
    std::optional<Time> sideTakenAt_;
    // (The most recent frames' times: the booth runs for weeks, and a list of every frame grew without end.)
    RecentTimings revealFrame_, captureToReveal_, revealRender_, revealCompose_, revealPresent_;
};

// Where one main-loop step spent its time: logged when the step took long enough for the visitor to see the screen
// stand still (the screen runs at 30 fps), so that an operator's log says which part stalled it.
class StepTimer {
public:
    void mark(const char* part);
    void reportIfSlow(const char* screen) const;

private:
    static constexpr double kSlowStep = 0.5;  // seconds
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_ = start_;
    std::vector<std::pair<const char*, double>> parts_;
};

}  // namespace avatarbooth
