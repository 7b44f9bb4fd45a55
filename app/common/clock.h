// The time source of the button and lamp logic: the real monotonic clock, or a hand-driven one for tests.
#pragma once

#include <chrono>

namespace avatarbooth {

// Every timestamp of the buttons and lamps is on the monotonic clock, the clock libgpiod stamps edges with
// (CLOCK_MONOTONIC since Linux 5.7; see gpiod_lines.cpp for older kernels).
using SteadyTime = std::chrono::steady_clock::time_point;

// Where "now" comes from and how waiting happens; injected so that scripted timelines and debouncing can be
// tested without waiting.
class Clock {
public:
    virtual ~Clock() = default;
    // The current time.
    virtual SteadyTime now() const = 0;
    // Returns once now() >= t (at once when t has passed).
    virtual void sleepUntil(SteadyTime t) = 0;
};

// The real monotonic clock; sleepUntil really sleeps.
class SteadyClock final : public Clock {
public:
    SteadyTime now() const override { return std::chrono::steady_clock::now(); }
    void sleepUntil(SteadyTime t) override;
};

// A clock that only moves when told to: sleepUntil jumps to the wake-up time, so a 10-second script runs in
// microseconds.
class ManualClock final : public Clock {
public:
    explicit ManualClock(SteadyTime start = SteadyTime{} + std::chrono::hours(1)) : now_(start) {}
    SteadyTime now() const override { return now_; }
    void sleepUntil(SteadyTime t) override {
        if (t > now_) now_ = t;
    }
    void advance(std::chrono::nanoseconds d) { now_ += d; }

private:
    SteadyTime now_;
};

}  // namespace avatarbooth
