// The simulated camera: replays a recorded session folder as a live preview and stills, with a scene set by the
// simulation (empty booth, visitor facing the camera, visitor in profile) and faults injected on demand.
#pragma once

#include "drivers/camera/camera.h"
#include "common/clock.h"

#include <opencv2/core.hpp>

#include <array>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <vector>

namespace avatarbooth {

// What stands in front of the simulated camera.
enum class SimScene {
    Empty,  // the empty booth: the folder's background.* plate, or a neutral grey backdrop when there is none
    Front,  // the visitor facing the camera: front.*
    Side,   // the visitor in profile: side.*
};

const char* simSceneName(SimScene scene);

// The simulated world around the camera: the scene, and the faults a reliability test injects. Outlives the
// cameras that read it (a reopened camera sees the same world), and is safe to change from any thread.
class SimCameraControls {
public:
    void setScene(SimScene scene);
    SimScene scene() const;

    // Unplugs the camera: every call on an open simulated camera throws CameraGoneError, and opening one fails,
    // until comeBack(). A camera that saw the unplug stays dead (like a V4L2 file descriptor after ENODEV):
    // after comeBack() a new one must be opened (ReopeningCamera does).
    void vanish();
    void comeBack();
    bool vanished() const;

    // The next `count` preview frames arrive torn: the lower half is what a broken USB transfer of zeroed YUYV
    // bytes shows (flat green, BGR 0,135,0). They are delivered as ordinary frames, for the consumers to cope.
    void corruptNextFrames(int count);
    // The stream stalls: the next frame arrives `by` late and later ones keep the rate from there.
    void delayNextFrame(std::chrono::nanoseconds by);

    // Used by the camera: consume one pending corruption / the pending delay.
    bool takeCorruption();
    std::chrono::nanoseconds takeDelay();

private:
    mutable std::mutex mutex_;
    SimScene scene_ = SimScene::Empty;
    bool vanished_ = false;
    int corruptFrames_ = 0;
    std::chrono::nanoseconds delay_{0};
};

// Sensor noise for preview frames: +-amplitude grey levels on every byte, different for every frame and
// reproducible from a seed. A noise field slightly larger than a quarter of a frame is drawn once; each quarter of
// each frame takes it from an offset of its own and applies it with two saturating SIMD passes (add the positive
// part, subtract the negative part), about a millisecond at 1280x720 here.
class SensorNoise {
public:
    SensorNoise() = default;
    // For frames of `frameBytes` bytes; amplitude 0 adds nothing.
    SensorNoise(std::size_t frameBytes, std::uint64_t seed, int amplitude);
    // Adds the noise of frame `frameSeed` to a continuous 8-bit image of frameBytes bytes.
    void apply(cv::Mat& image, std::uint64_t frameSeed) const;

private:
    std::size_t frameBytes_ = 0;
    std::vector<std::uint8_t> plus_, minus_;
};

struct SimCameraOptions {
    std::filesystem::path folder;  // front.*, side.*, optional background.* (jpg, jpeg or png)
    double fps = 30;
    // The preview is the scene scaled down to fit in this size (aspect kept, never enlarged); stills are the
    // folder's images at full size.
    int previewWidth = 1280;
    int previewHeight = 720;
    int noise = 2;                // +- grey levels of per-frame noise on preview frames (at most 50); 0 = none
    std::uint64_t noiseSeed = 1;  // frames are reproducible for a seed
    // Frames the simulated driver keeps for a slow reader; older ones are dropped (a gap in the sequence).
    int queueDepth = 4;
};

class SimCamera : public Camera {
public:
    // Reads the folder's images. Throws BoothError(BadInput) naming the folder or the file when the folder, a
    // front or side photo is missing, or an image is empty or does not decode; CameraGoneError when the
    // controls say the camera is unplugged.
    SimCamera(SimCameraOptions options, std::shared_ptr<SimCameraControls> controls, std::shared_ptr<Clock> clock);

    void start() override;
    std::optional<CameraFrame> nextFrame(std::chrono::milliseconds timeout) override;
    // The folder's image for the current scene, exactly as read (front, side, or the background plate).
    CameraFrame captureStill() override;
    void stop() override;
    CameraDescription describe() const override;

    // The full-size image of a scene, as captureStill() returns it.
    const cv::Mat& sceneImage(SimScene scene) const { return stills_[static_cast<std::size_t>(scene)]; }
    SimCameraControls& controls() { return *controls_; }

private:
    void checkConnected();
    SteadyTime dueTime(std::uint64_t index) const;

    SimCameraOptions options_;
    std::shared_ptr<SimCameraControls> controls_;
    std::shared_ptr<Clock> clock_;
    std::string label_;
    std::array<cv::Mat, 3> stills_;    // by SimScene
    std::array<cv::Mat, 3> previews_;  // by SimScene, all of the preview size
    SensorNoise noise_;
    bool gone_ = false;
    bool streaming_ = false;
    SteadyTime streamStart_{};
    std::uint64_t streamFirstSequence_ = 0;  // sequence of the stream's frame 0
    std::uint64_t nextIndex_ = 0;            // within the stream
    std::uint64_t stillsTaken_ = 0;
};

}  // namespace avatarbooth
