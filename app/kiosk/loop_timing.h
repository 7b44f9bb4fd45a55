// Where the kiosk's main loop spends its time, summed per part over a few seconds and logged at debug level
// (`avatarbooth -v run`): how to find what makes the screen slow on a slow board or under emulation.
#pragma once

#include <spdlog/spdlog.h>

#include <array>
#include <chrono>

namespace avatarbooth {

class LoopTiming {
public:
    using Clock = std::chrono::steady_clock;
    // The parts of one iteration, in order; each ends at the time point given for it.
    enum Part { Input, Work, Render, Compose, Present, After, kParts };

    explicit LoopTiming(Clock::duration every = std::chrono::seconds(5)) : every_(every) {}

    // One iteration: it started at `start`, and part i ended at ends[i] (non-decreasing).
    void frame(Clock::time_point start, const std::array<Clock::time_point, kParts>& ends) {
        if (windowStart_ == Clock::time_point{}) windowStart_ = start;
        Clock::time_point from = start;
        for (int i = 0; i < kParts; ++i) {
            sums_[i] += ends[i] - from;
            from = ends[i];
        }
        ++frames_;
        if (from - windowStart_ < every_) return;
        if (spdlog::should_log(spdlog::level::debug)) log(from);
        reset(from);
    }

private:
    void log(Clock::time_point end) const {
        const double window = seconds(end - windowStart_);
        const auto ms = [&](Part p) { return 1000.0 * seconds(sums_[p]) / frames_; };
        // The rest of the window is the loop sleeping until its next frame (or waiting for the CPU).
        spdlog::debug("main loop: {} frames in {:.1f} s ({:.1f}/s); per frame: input+camera {:.1f} ms, flow+workers "
                      "{:.1f} ms, avatars {:.1f} ms, screens.draw {:.1f} ms, present {:.1f} ms, screenshots+rest {:.1f} ms",
                      frames_, window, frames_ / window, ms(Input), ms(Work), ms(Render), ms(Compose), ms(Present),
                      ms(After));
    }
    static double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }
    void reset(Clock::time_point at) {
        windowStart_ = at;
        sums_.fill(Clock::duration::zero());
        frames_ = 0;
    }

    Clock::duration every_;
    Clock::time_point windowStart_{};
    std::array<Clock::duration, kParts> sums_{};
    int frames_ = 0;
};

}  // namespace avatarbooth
