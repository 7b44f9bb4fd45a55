// The simulated camera: folder images in, paced noisy preview frames and exact stills out.
#include "drivers/camera/sim_camera.h"

#include "common/image_io.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <vector>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

const cv::Scalar kNeutralBackdrop(160, 160, 160);

std::string lower(std::string s) {
    for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
}

[[noreturn]] void badFile(const fs::path& path, const std::string& why) {
    throw BoothError(ErrorKind::BadInput, path.string(), why);
}

// The folder's <stem>.jpg / .jpeg / .png; an empty path when there is none.
fs::path findImage(const fs::path& folder, const std::string& stem) {
    std::vector<fs::path> found;
    for (const auto& entry : fs::directory_iterator(folder)) {
        const auto ext = lower(entry.path().extension().string());
        if (lower(entry.path().stem().string()) == stem && (ext == ".jpg" || ext == ".jpeg" || ext == ".png"))
            found.push_back(entry.path());
    }
    if (found.size() > 1) {
        std::sort(found.begin(), found.end());
        badFile(found[0], "more than one " + stem + " image in the folder (also " + found[1].filename().string() +
                              "); keep one");
    }
    return found.empty() ? fs::path() : found[0];
}

// `image` scaled to fit in `size` (aspect kept), centred on the neutral backdrop. An image that already fits is
// shared, not copied (the camera never writes into its stills or previews: every frame is a copy).
cv::Mat fitInto(const cv::Mat& image, cv::Size size) {
    if (image.size() == size) return image;
    const double scale = std::min(static_cast<double>(size.width) / image.cols, static_cast<double>(size.height) / image.rows);
    const cv::Size scaled(std::max(1, static_cast<int>(std::lround(image.cols * scale))),
                          std::max(1, static_cast<int>(std::lround(image.rows * scale))));
    cv::Mat out(size, CV_8UC3, kNeutralBackdrop);
    const cv::Rect at((size.width - scaled.width) / 2, (size.height - scaled.height) / 2, scaled.width, scaled.height);
    cv::resize(image, out(at), scaled, 0, 0, scale < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    return out;
}

}  // namespace

const char* simSceneName(SimScene scene) {
    switch (scene) {
        case SimScene::Empty: return "empty";
        case SimScene::Front: return "front";
        case SimScene::Side: return "side";
    }
    return "?";
}

void SimCameraControls::setScene(SimScene scene) {
    std::lock_guard lock(mutex_);
    scene_ = scene;
}

SimScene SimCameraControls::scene() const {
    std::lock_guard lock(mutex_);
    return scene_;
}

void SimCameraControls::vanish() {
    std::lock_guard lock(mutex_);
    vanished_ = true;
}

void SimCameraControls::comeBack() {
    std::lock_guard lock(mutex_);
    vanished_ = false;
}

bool SimCameraControls::vanished() const {
    std::lock_guard lock(mutex_);
    return vanished_;
}

void SimCameraControls::corruptNextFrames(int count) {
    std::lock_guard lock(mutex_);
    corruptFrames_ = std::max(0, count);
}

void SimCameraControls::delayNextFrame(std::chrono::nanoseconds by) {
    std::lock_guard lock(mutex_);
    delay_ = by;
}

bool SimCameraControls::takeCorruption() {
    std::lock_guard lock(mutex_);
    if (corruptFrames_ == 0) return false;
    --corruptFrames_;
    return true;
}

std::chrono::nanoseconds SimCameraControls::takeDelay() {
    std::lock_guard lock(mutex_);
    return std::exchange(delay_, std::chrono::nanoseconds{0});
}

SimCamera::SimCamera(SimCameraOptions options, std::shared_ptr<SimCameraControls> controls,
                     std::shared_ptr<Clock> clock)
    : options_(std::move(options)), controls_(std::move(controls)), clock_(std::move(clock)),
      label_("sim:" + options_.folder.string()) {
    if (!controls_) controls_ = std::make_shared<SimCameraControls>();
    if (!clock_) clock_ = std::make_shared<SteadyClock>();
    if (!(options_.fps > 0)) throw BoothError(ErrorKind::BadConfig, "", "sim camera: the frame rate must be positive");
    if (options_.previewWidth <= 0 || options_.previewHeight <= 0)
        throw BoothError(ErrorKind::BadConfig, "", "sim camera: the preview size must be positive");
    checkConnected();

    const auto& folder = options_.folder;
    if (folder.empty()) throw BoothError(ErrorKind::BadConfig, "", "sim camera: no session folder given (camera.sim_folder)");
    if (!fs::is_directory(folder)) badFile(folder, "sim camera folder not found");
    for (const auto scene : {SimScene::Front, SimScene::Side}) {
        const std::string stem = simSceneName(scene);
        const auto path = findImage(folder, stem);
        if (path.empty())
            badFile(folder / (stem + ".*"), "no " + stem + " photo (" + stem + ".jpg or " + stem + ".png) in the sim camera folder");
        stills_[static_cast<std::size_t>(scene)] = readPhoto(path);
    }
    const auto& front = stills_[static_cast<std::size_t>(SimScene::Front)];
    const auto background = findImage(folder, "background");
    stills_[static_cast<std::size_t>(SimScene::Empty)] =
        background.empty() ? cv::Mat(front.size(), CV_8UC3, kNeutralBackdrop) : readPhoto(background);

    const double scale = std::min({1.0, static_cast<double>(options_.previewWidth) / front.cols,
                                   static_cast<double>(options_.previewHeight) / front.rows});
    const cv::Size previewSize(std::max(1, static_cast<int>(std::lround(front.cols * scale))),
                               std::max(1, static_cast<int>(std::lround(front.rows * scale))));
    for (std::size_t i = 0; i < stills_.size(); ++i) previews_[i] = fitInto(stills_[i], previewSize);
    noise_ = SensorNoise(static_cast<std::size_t>(previewSize.area()) * 3, options_.noiseSeed, options_.noise);
}

void SimCamera::checkConnected() {
    if (controls_->vanished()) gone_ = true;
    if (gone_) throw CameraGoneError(label_, "simulated unplug");
}

SteadyTime SimCamera::dueTime(std::uint64_t index) const {
    return streamStart_ + std::chrono::nanoseconds(std::llround(static_cast<double>(index) * 1e9 / options_.fps));
}

void SimCamera::start() {
    checkConnected();
    if (streaming_) return;
    streaming_ = true;
    streamStart_ = clock_->now();
    nextIndex_ = 0;
}

std::optional<CameraFrame> SimCamera::nextFrame(std::chrono::milliseconds timeout) {
    start();
    streamStart_ += controls_->takeDelay();
    const auto now = clock_->now();
    const auto deadline = now + timeout;

    // The newest frame the sensor has produced by now; a reader that fell behind by more than the queue gets
    // the oldest frame still queued, and the ones before it are lost.
    std::uint64_t index = nextIndex_;
    if (dueTime(index) <= now) {
        auto newest = static_cast<std::uint64_t>(std::max(0.0, std::floor(static_cast<double>((now - streamStart_).count()) * options_.fps / 1e9)));
        while (dueTime(newest + 1) <= now) ++newest;
        while (newest > 0 && dueTime(newest) > now) --newest;
        const auto depth = static_cast<std::uint64_t>(std::max(1, options_.queueDepth));
        if (newest + 1 > depth) index = std::max(index, newest + 1 - depth);
    }
    const auto due = dueTime(index);
    if (due > deadline) {
        clock_->sleepUntil(deadline);
        checkConnected();
        return std::nullopt;
    }
    clock_->sleepUntil(due);
    checkConnected();

    CameraFrame frame;
    frame.sequence = streamFirstSequence_ + index;
    frame.timestamp = std::chrono::duration_cast<std::chrono::nanoseconds>(due.time_since_epoch());
    frame.image = previews_[static_cast<std::size_t>(controls_->scene())].clone();
    noise_.apply(frame.image, options_.noiseSeed ^ (frame.sequence * 0xD1B54A32D192ED03ull));
    if (controls_->takeCorruption())
        frame.image.rowRange(frame.image.rows / 2, frame.image.rows).setTo(cv::Scalar(0, 135, 0));
    nextIndex_ = index + 1;
    return frame;
}

CameraFrame SimCamera::captureStill() {
    checkConnected();
    CameraFrame frame;
    frame.image = stills_[static_cast<std::size_t>(controls_->scene())].clone();
    frame.sequence = stillsTaken_++;
    frame.timestamp = std::chrono::duration_cast<std::chrono::nanoseconds>(clock_->now().time_since_epoch());
    return frame;
}

void SimCamera::stop() {
    if (!streaming_) return;
    streaming_ = false;
    streamFirstSequence_ += nextIndex_;
}

CameraDescription SimCamera::describe() const {
    CameraDescription d;
    d.backend = "sim";
    d.device = options_.folder.string();
    d.name = "simulated camera";
    const auto& preview = previews_[0];
    d.preview = {"BGR", preview.cols, preview.rows, options_.fps};
    const auto& front = stills_[static_cast<std::size_t>(SimScene::Front)];
    d.still = {"BGR", front.cols, front.rows, 0};
    return d;
}

namespace {

// How far the per-frame window may slide over the noise field: this many distinct noise frames.
constexpr std::size_t kNoiseOffsets = 1 << 16;
// The field covers a quarter of a frame; each quarter of a frame takes it from its own offset (the two tables of a
// whole frame's were 4 MB of the simulated booth's peak memory).
constexpr std::size_t kNoiseParts = 4;

std::uint64_t splitmix(std::uint64_t x) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

}  // namespace

SensorNoise::SensorNoise(std::size_t frameBytes, std::uint64_t seed, int amplitude) : frameBytes_(frameBytes) {
    if (amplitude <= 0 || frameBytes == 0) return;
    amplitude = std::min(amplitude, 50);
    plus_.resize((frameBytes + kNoiseParts - 1) / kNoiseParts + kNoiseOffsets);
    minus_.resize(plus_.size());
    const auto span = static_cast<std::uint64_t>(2 * amplitude + 1);
    std::uint64_t state = seed;
    for (std::size_t i = 0; i < plus_.size(); ++i) {
        const int v = static_cast<int>(splitmix(state++) % span) - amplitude;
        plus_[i] = static_cast<std::uint8_t>(std::max(v, 0));
        minus_[i] = static_cast<std::uint8_t>(std::max(-v, 0));
    }
}

void SensorNoise::apply(cv::Mat& image, std::uint64_t frameSeed) const {
    if (plus_.empty()) return;
    CV_Assert(image.isContinuous() && image.depth() == CV_8U && image.total() * image.elemSize() == frameBytes_);
    cv::Mat flat = image.reshape(1, 1);
    const std::size_t part = (frameBytes_ + kNoiseParts - 1) / kNoiseParts;
    std::uint64_t state = splitmix(frameSeed);
    for (std::size_t from = 0; from < frameBytes_; from += part) {
        const auto offset = static_cast<std::size_t>(splitmix(state++) % kNoiseOffsets);
        const int n = static_cast<int>(std::min(part, frameBytes_ - from));
        cv::Mat piece = flat.colRange(static_cast<int>(from), static_cast<int>(from) + n);
        cv::add(piece, cv::Mat(1, n, CV_8UC1, const_cast<std::uint8_t*>(plus_.data() + offset)), piece);
        cv::subtract(piece, cv::Mat(1, n, CV_8UC1, const_cast<std::uint8_t*>(minus_.data() + offset)), piece);
    }
}

}  // namespace avatarbooth
