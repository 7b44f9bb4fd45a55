// A camera that survives being unplugged: when the camera goes away it is closed, reopened with back-off, and
// the stream resumes; meanwhile status() says what is wrong, for the kiosk to show on screen.
#pragma once

#include "drivers/camera/camera.h"
#include "common/clock.h"

#include <chrono>
#include <functional>
#include <memory>
#include <mutex>
#include <string>

namespace avatarbooth {

struct ReopenPolicy {
    std::chrono::nanoseconds firstDelay = std::chrono::milliseconds(500);  // first retry after going away
    std::chrono::nanoseconds maxDelay = std::chrono::seconds(8);           // the delay doubles up to this
};

struct CameraStatus {
    bool ok = true;
    // Empty when ok, else for the screen: "camera /dev/video0 disconnected, retrying" (or "... not found,
    // retrying" when it has never opened).
    std::string message;
    std::string lastError;    // the error that made it go away or the last failed reopen
    int failedReopens = 0;    // attempts since it went away
    int recoveries = 0;       // times it came back
};

class ReopeningCamera : public Camera {
public:
    // Opens a camera, already configured (backend, device, sizes).
    using Opener = std::function<std::unique_ptr<Camera>()>;

    // Opens the camera at once. A device error (BoothError kind Device, including CameraGoneError) does not
    // throw: the camera starts out lost and is retried; other errors (bad configuration, bad sim folder) do.
    // `label` names the camera in messages (e.g. "/dev/video0").
    ReopeningCamera(Opener open, std::string label, ReopenPolicy policy = {},
                    std::shared_ptr<Clock> clock = nullptr);

    void start() override;
    // While the camera is lost, waits (up to the timeout) for the next retry and returns nullopt if it fails.
    // When it comes back the stream restarts; sequence numbers continue after the last frame delivered.
    std::optional<CameraFrame> nextFrame(std::chrono::milliseconds timeout) override;
    // Tries to reopen at once when lost. Throws CameraGoneError when the camera is (or goes) away.
    CameraFrame captureStill() override;
    void stop() override;
    // The camera's description, or the last one known (note "disconnected") while it is away.
    CameraDescription describe() const override;

    // Thread-safe: the screen may read it from another thread.
    CameraStatus status() const;
    // The camera now open, or nullptr while it is lost (for the simulation's controls, diagnostics).
    Camera* current() { return camera_.get(); }

private:
    bool tryReopen();
    void lose(const std::string& why);

    Opener open_;
    std::string label_;
    ReopenPolicy policy_;
    std::shared_ptr<Clock> clock_;
    std::unique_ptr<Camera> camera_;
    bool everOpened_ = false;
    bool wantStreaming_ = false;
    std::chrono::nanoseconds delay_;
    SteadyTime nextRetry_{};
    std::uint64_t sequenceBase_ = 0;
    std::uint64_t nextSequence_ = 0;  // one after the last frame delivered
    CameraDescription lastDescription_;
    mutable std::mutex statusMutex_;
    CameraStatus status_;
};

}  // namespace avatarbooth
