// Scripted button timelines for the simulated booth: a text file of presses, releases, taps and holds.
//
//   # a visitor's session; times count from the start of the script
//   at 2s tap start              press, then release 100 ms later (tap DURATION to change it)
//   at 10.5s press retake        press and keep it down ...
//   after 300ms release retake   ... until released ("after": relative to the previous line's time)
//   at 20s hold start+retake 5s  several buttons together, held 5 s (the operator's lock)
//   at 30s tap start bounce 3    each edge bounces: 3 extra off/on pairs 1 ms apart before it settles
//
// One event per line; blank lines and everything after '#' are ignored. Times are a number with a unit: "ms",
// "s" or "min". Lines must not go back in time; a press of a button that is down, or a release of one that is up,
// is an error. Errors name the file, the line and what is wrong (BoothError BadConfig).
#pragma once

#include "common/clock.h"
#include "drivers/gpio/raw_lines.h"

#include <chrono>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace avatarbooth {

struct TimelineEdge {
    std::chrono::nanoseconds at{0};  // since the start of the script
    std::size_t button = 0;          // index into ButtonTimeline::buttons
    bool pressed = false;            // the level after this edge (bounces included)
    int sourceLine = 0;              // the script line that made it

    bool operator==(const TimelineEdge&) const = default;
};

struct ButtonTimeline {
    std::vector<std::string> buttons;  // the button names the script may use
    std::vector<TimelineEdge> edges;   // in time order (script order for equal times)
};

// Every edge of the script; `source` names it in errors ("session.timeline"). `buttons`: the names it may use.
ButtonTimeline parseButtonTimeline(std::string_view text, const std::string& source,
                                   const std::vector<std::string>& buttons);
// Reads and parses a timeline file; a missing or unreadable file is BadConfig naming it.
ButtonTimeline loadButtonTimeline(const std::filesystem::path& path, const std::vector<std::string>& buttons);

// The script as input lines (high = pressed), on the given clock from `start` on: waitEdges sleeps on the clock
// until the next edge, so a ManualClock runs a script instantly and the SteadyClock in real time.
class ScriptedLines final : public RawInputLines {
public:
    ScriptedLines(ButtonTimeline timeline, Clock& clock, SteadyTime start, std::string source);
    std::vector<bool> levels() override;
    std::vector<RawEdge> waitEdges(SteadyTime deadline) override;
    SteadyTime now() const override { return clock_.now(); }
    std::string describe() const override;
    bool exhausted() const override { return next_ >= timeline_.edges.size(); }

private:
    ButtonTimeline timeline_;
    Clock& clock_;
    SteadyTime start_;
    std::string source_;
    std::size_t next_ = 0;
    std::vector<bool> levels_;
};

}  // namespace avatarbooth
