// The booth's one time source for drivers and their tests: the real monotonic clock, or a hand-driven one.
#pragma once

#include <chrono>
#include <mutex>
#include <thread>

namespace avatarbooth {

// Every timestamp of the buttons, lamps and cameras is on the monotonic clock, the clock libgpiod stamps edges
// with (CLOCK_MONOTONIC since Linux 5.7; see gpiod_lines.cpp for older kernels) and V4L2 stamps frames with.
using SteadyTime = std::chrono::steady_clock::time_point;

// Where "now" comes from and how waiting happens; injected so that scripted timelines, debouncing, the simulated
// camera's pacing and the camera's reopen back-off can be tested without waiting.
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
    void sleepUntil(SteadyTime t) override { std::this_thread::sleep_until(t); }
};

// A clock that only moves when told to: sleepUntil jumps to the wake-up time, so a 10-second script runs in
// microseconds, and a camera paced by it delivers frames as fast as they are asked for while its timestamps still
// advance at the frame rate. Thread-safe, so a test may advance it while a camera waits on another thread.
class ManualClock final : public Clock {
public:
    explicit ManualClock(SteadyTime start = SteadyTime{} + std::chrono::hours(1)) : now_(start) {}
    SteadyTime now() const override {
        std::lock_guard lock(mutex_);
        return now_;
    }
    void sleepUntil(SteadyTime t) override {
        std::lock_guard lock(mutex_);
        if (t > now_) now_ = t;
    }
    void advance(std::chrono::nanoseconds d) {
        std::lock_guard lock(mutex_);
        now_ += d;
    }

private:
    mutable std::mutex mutex_;
    SteadyTime now_;
};

}  // namespace avatarbooth
