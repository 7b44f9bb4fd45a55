// Time as the cameras see it, injectable so that the simulated camera and the reopen back-off can be tested
// without waiting.
#pragma once

#include <chrono>
#include <mutex>

namespace avatarbooth {

class CameraClock {
public:
    virtual ~CameraClock() = default;
    // Time since the clock's epoch (CLOCK_MONOTONIC for the real clock).
    virtual std::chrono::nanoseconds now() = 0;
    // Returns once now() >= t (at once when t has passed).
    virtual void sleepUntil(std::chrono::nanoseconds t) = 0;
};

// The real steady clock; sleeps for real.
class SteadyCameraClock : public CameraClock {
public:
    std::chrono::nanoseconds now() override;
    void sleepUntil(std::chrono::nanoseconds t) override;
};

// A clock that only moves when told to: sleepUntil() jumps straight to the wanted time, so a camera paced by it
// delivers frames as fast as they are asked for while its timestamps still advance at the frame rate.
// Thread-safe, so a test may advance it while a camera waits on another thread.
class ManualCameraClock : public CameraClock {
public:
    explicit ManualCameraClock(std::chrono::nanoseconds start = std::chrono::nanoseconds{0}) : now_(start) {}
    std::chrono::nanoseconds now() override;
    void sleepUntil(std::chrono::nanoseconds t) override;
    void advance(std::chrono::nanoseconds by);

private:
    std::mutex mutex_;
    std::chrono::nanoseconds now_;
};

}  // namespace avatarbooth
