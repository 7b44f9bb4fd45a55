// The kiosk's main loop and its worker threads (model loading + fitting, preview analysis).
#include "kiosk/kiosk.h"

#include "animation/avatar_motion.h"
#include "booth/guidance.h"
#include "booth/session_store.h"
#include "booth/visitor_flow.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "drivers/camera/camera_factory.h"
#include "drivers/camera/reopening_camera.h"
#include "drivers/display/display_factory.h"
#include "drivers/gpio/button_board.h"
#include "drivers/gpio/clock.h"
#include "drivers/gpio/lamps.h"
#include "face/landmarks68.h"
#include "kiosk/reveal_styles.h"
#include "pipeline/fit_pipeline.h"
#include "render/mesh_renderer.h"
#include "screens/screens.h"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <glm/gtc/matrix_transform.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <deque>
#include <functional>
#include <mutex>
#include <random>
#include <thread>

#include <sys/resource.h>
#include <unistd.h>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;
using Seconds = std::chrono::duration<double>;

constexpr auto kFramePeriod = std::chrono::microseconds(33333);  // the screen's 30 fps
constexpr auto kReleaseAfter = std::chrono::milliseconds(120);    // a simulated press lasts this long
constexpr auto kRetentionEvery = std::chrono::minutes(10);

// The fraction of the fit done when a stage starts (the stages' shares of the time measured by `bench`).
double stageProgress(const std::string& stage) {
    if (stage == "front_landmarks") return 0.05;
    if (stage == "front_silhouette") return 0.2;
    if (stage == "side_profile") return 0.3;
    if (stage == "head_fit") return 0.4;
    if (stage == "texture") return 0.5;
    if (stage == "export") return 0.85;
    return 0.0;
}

// How a failed fit is told to the visitor, and which photo it asks for again.
FitFailed fitFailureFor(const BoothError& e, FlowTime t) {
    FitFailed f{RetakeWhich::Both, FitFailure::Other, e.what(), t};
    const std::string where = e.where();
    const bool aboutSide = where.find("side") != std::string::npos;
    const bool aboutFront = where.find("front") != std::string::npos;
    switch (e.kind()) {
        case ErrorKind::NoFace:
            f.reason = FitFailure::NoFace;
            f.retake = aboutSide ? RetakeWhich::Side : RetakeWhich::Front;
            break;
        case ErrorKind::Mismatch:
            if (std::string(e.what()).find("front view") != std::string::npos) {
                f.reason = FitFailure::NotProfile;
                f.retake = RetakeWhich::Side;
            } else {
                f.reason = FitFailure::Mismatch;
                f.retake = RetakeWhich::Both;
            }
            break;
        case ErrorKind::BadInput:
            f.retake = aboutSide ? RetakeWhich::Side : aboutFront ? RetakeWhich::Front : RetakeWhich::Both;
            break;
        default:
            break;
    }
    return f;
}

// The avatar turning on the reveal and attract screens: the fitted head (or the base head before any visitor),
// rendered offscreen each frame with the head pose of the keyframed motion (full or limited animation).
class AvatarStage {
public:
    AvatarStage(const AnimationSettings& animation, int size)
        : size_(size),
          reveal_(playAnimation(revealMotion(), animation)),
          attract_(playAnimation(attractMotion(), animation)),
          fps_(animation.fps) {}

    void show(const Mesh& mesh, const cv::Mat& texture) {
        renderer_.upload(mesh, texture);
        glm::dvec3 lo, hi;
        mesh.bounds(lo, hi);
        centre_ = (lo + hi) * 0.5;
        extent_ = glm::length(hi - lo);
        loaded_ = true;
    }
    bool loaded() const { return loaded_; }

    // BGRA: the lit, textured head with its coverage as alpha.
    cv::Mat frame(bool reveal, Millis since) {
        if (!loaded_) return {};
        const auto& clip = reveal ? reveal_ : attract_;
        if (clip.empty()) return {};
        const auto index = static_cast<std::size_t>(std::chrono::duration<double>(since).count() * fps_) % clip.size();
        const glm::dmat4 model = clip[index].headModel;
        // Turn the camera the other way round the head's centre instead of moving the mesh: one upload per visitor.
        const glm::dmat4 inverse = glm::inverse(model);
        const glm::dvec3 eye = glm::dvec3(inverse * glm::dvec4(centre_ + glm::dvec3(0.0, 0.0, 3.0 * extent_), 1.0));
        const glm::dvec3 target = glm::dvec3(inverse * glm::dvec4(centre_, 1.0));
        const glm::dvec3 up = glm::normalize(glm::dvec3(inverse * glm::dvec4(0.0, 1.0, 0.0, 0.0)));
        RenderCamera camera = RenderCamera::orthographic(eye, target, up, extent_ * 0.85 / size_, size_, size_);
        camera.background = cv::Scalar(0, 0, 0);
        const RenderResult r = renderer_.render(camera);
        cv::Mat bgra;
        cv::cvtColor(r.bgr, bgra, cv::COLOR_BGR2BGRA);
        cv::Mat channels[4];
        cv::split(bgra, channels);
        channels[3] = r.mask;
        cv::merge(channels, 4, bgra);
        return bgra;
    }

private:
    MeshRenderer renderer_;
    int size_;
    std::vector<AnimationFrame> reveal_, attract_;
    double fps_;
    glm::dvec3 centre_{0.0};
    double extent_ = 1.0;
    bool loaded_ = false;
};

// What a finished fit hands back to the loop.
struct FitResult {
    std::uint64_t job = 0;
    bool ok = false;
    fs::path folder;        // the pending session folder (complete) when ok
    Mesh mesh;
    cv::Mat texture;
    StyleInputs styles;  // for the reveal's other styles (character head, photos and masks for the toon)
    std::optional<BoothError> error;
};

// Lowers the calling thread's priority (Linux: nice is per thread): the screen and the watchdog come first when
// the cores are busy. Best effort: without it the booth still works, only its frame rate suffers under load.
void lowerThisThreadsPriority(int nice) {
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice) != 0)
        spdlog::debug("setpriority({}): {}", nice, std::strerror(errno));
}

// Loads the landmark model on one thread, then fits one job at a time on another (with its own offscreen renderer:
// EGL contexts belong to a thread). dlib's deserialisation cannot be interrupted (minutes on a slow board or under
// emulation) and the booth must stop within systemd's TimeoutStopSec, so the loading thread is the one thread the
// kiosk may leave running: everything it uses lives in the State it shares, and a worker destroyed while the model
// is still loading detaches it instead of joining it (see ~FitWorker and kioskLeftAThreadRunning()).
class FitWorker {
public:
    FitWorker(FitSettings settings, std::shared_ptr<const BaseHead> base, std::shared_ptr<std::mutex> detectorMutex)
        : state_(std::make_shared<State>()) {
        state_->detectorMutex = std::move(detectorMutex);
        state_->base = std::move(base);  // the pipeline refers to it: it lives as long as the State
        loader_ = std::thread([state = state_, settings = std::move(settings)] { load(*state, settings); });
        fitter_ = std::thread([state = state_] { fit(*state); });
    }
    ~FitWorker() {
        bool loading = false;
        {
            std::lock_guard lock(state_->mutex);
            state_->quit = true;
            loading = state_->loading;
        }
        state_->wake.notify_all();
        fitter_.join();  // waiting for the model or a job: wakes at once (a fit in flight is finished first)
        if (!loading) {
            loader_.join();
            return;
        }
        // Still inside the model's deserialisation: left to finish on its own. Once it does, it sees `quit` and
        // drops the model without touching anything outside its State (no logging, no detector mutex). The process
        // must then end without running static destructors (the load reads the built-in base head and fills the
        // texture step's static caches): `avatarbooth run` ends with std::quick_exit when kioskLeftAThreadRunning().
        spdlog::info("stopping while the landmark model is still loading: its thread is left to the process's exit");
        threadLeftRunning.store(true);
        loader_.detach();
    }

    // The pipeline once the model has loaded (null before); its error if loading failed.
    const FitPipeline* pipeline() const {
        std::lock_guard lock(state_->mutex);
        return state_->pipeline.get();
    }
    std::optional<std::string> loadError() const {
        std::lock_guard lock(state_->mutex);
        return state_->loadError;
    }

    void submit(std::uint64_t job, cv::Mat front, cv::Mat side, fs::path out) {
        {
            std::lock_guard lock(state_->mutex);
            state_->job = Job{job, std::move(front), std::move(side), std::move(out)};
        }
        state_->wake.notify_all();
    }
    std::optional<FitResult> takeResult() {
        std::lock_guard lock(state_->mutex);
        std::optional<FitResult> r = std::move(state_->result);
        state_->result.reset();
        return r;
    }
    std::optional<std::string> takeStage() {
        std::lock_guard lock(state_->mutex);
        std::optional<std::string> s = std::move(state_->stage);
        state_->stage.reset();
        return s;
    }

    static inline std::atomic<bool> threadLeftRunning{false};

private:
    struct Job {
        std::uint64_t id;
        cv::Mat front, side;
        fs::path out;
    };
    struct State {
        std::shared_ptr<std::mutex> detectorMutex;
        std::shared_ptr<const BaseHead> base;
        std::mutex mutex;
        std::condition_variable wake;
        bool loading = true;
        bool quit = false;
        std::unique_ptr<FitPipeline> pipeline;
        std::optional<std::string> loadError;
        std::optional<Job> job;
        std::optional<FitResult> result;
        std::optional<std::string> stage;
    };

    static void load(State& s, const FitSettings& settings) {
        // (Not niced: nice is weighed against every process on the machine, and a model that loads minutes late keeps
        // a visitor on the processing screen; the main loop never waits for it anyway.)
        std::unique_ptr<FitPipeline> loaded;
        std::optional<std::string> error;
        try {
            loaded = std::make_unique<FitPipeline>(settings, *s.base);
        } catch (const std::exception& e) {
            error = e.what();
        }
        std::lock_guard lock(s.mutex);
        s.loading = false;
        if (s.quit) return;  // abandoned (or stopped) while loading: the model is dropped here, nothing logged
        if (error) {
            spdlog::error("cannot load the landmark model: {}", *error);
            s.loadError = error;
            return;
        }
        spdlog::info("landmark model loaded in {:.2f} s", loaded->modelLoadSeconds());
        s.pipeline = std::move(loaded);
        s.wake.notify_all();
    }

    static void fit(State& s) {
        std::unique_ptr<MeshRenderer> renderer;
        for (;;) {
            Job job;
            {
                std::unique_lock lock(s.mutex);
                s.wake.wait(lock, [&] { return s.quit || (s.pipeline && s.job.has_value()); });
                if (s.quit) return;
                job = std::move(*s.job);
                s.job.reset();
            }
            FitResult result;
            result.job = job.id;
            try {
                if (!renderer) renderer = std::make_unique<MeshRenderer>();
                const FitInputs names{"front photo", "side photo", {}};
                FitOutcome outcome;
                {
                    std::lock_guard detector(*s.detectorMutex);
                    outcome = s.pipeline->fit(job.front, job.side, cv::Mat(), names, [&](const std::string& stage) {
                        std::lock_guard lock(s.mutex);
                        s.stage = stage;
                    });
                }
                {
                    std::lock_guard lock(s.mutex);
                    s.stage = "export";
                }
                // No input files: the photos are in memory and are written as JPEGs (file names here would be
                // read from the working directory).
                CharacterHead character;
                s.pipeline->write(outcome, FitInputs{}, job.out, *renderer, &character);
                result.styles = styleInputsFrom(outcome, std::move(character));
                result.ok = true;
                result.folder = job.out;
                result.mesh = outcome.fit.mesh;
                result.texture = outcome.texture.texture;
            } catch (const BoothError& e) {
                result.error = e;
            } catch (const std::exception& e) {
                result.error = BoothError(ErrorKind::Internal, "", e.what());
            }
            std::lock_guard lock(s.mutex);
            s.result = std::move(result);
        }
    }

    std::shared_ptr<State> state_;
    std::thread loader_, fitter_;
};

// The systemd watchdog (sd_notify WATCHDOG=1). Pinged from its own thread at half of WatchdogSec (WATCHDOG_USEC,
// sd_watchdog_enabled(): the convention sd_notify(3) gives), so the pings keep their rate however long one frame
// takes on a slow board -- but only while the main loop is alive: every loop iteration calls alive(), and when
// none has for a whole WatchdogSec the pings stop (logged once) and systemd kills and restarts the hung booth.
// Without a watchdog in the environment it pings once a second (a no-op without NOTIFY_SOCKET).
class WatchdogPinger {
public:
    WatchdogPinger() {
        std::uint64_t usec = 0;
        if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
            interval_ = std::chrono::microseconds(usec / 2);
            stalledAfter_ = std::chrono::microseconds(usec);
        }
        alive();
        spdlog::info("watchdog: a ping every {} ms while the main loop runs", std::chrono::duration_cast<std::chrono::milliseconds>(interval_).count());
        thread_ = std::thread([this] { run(); });
    }
    ~WatchdogPinger() {
        {
            std::lock_guard lock(mutex_);
            quit_ = true;
        }
        wake_.notify_all();
        thread_.join();
    }
    void alive() { lastAlive_.store(std::chrono::steady_clock::now().time_since_epoch().count()); }

private:
    void run() {
        bool withheld = false;
        std::unique_lock lock(mutex_);
        for (;;) {
            if (wake_.wait_for(lock, interval_, [&] { return quit_; })) return;
            const auto age = std::chrono::steady_clock::now() -
                             std::chrono::steady_clock::time_point(std::chrono::steady_clock::duration(lastAlive_.load()));
            if (age <= stalledAfter_) {
                sd_notify(0, "WATCHDOG=1");
                if (withheld) spdlog::warn("watchdog: the main loop runs again, pings resumed");
                withheld = false;
            } else if (!withheld) {
                spdlog::error("watchdog: the main loop has not run for {:.1f} s, pings withheld", Seconds(age).count());
                withheld = true;
            }
        }
    }

    std::chrono::steady_clock::duration interval_ = std::chrono::seconds(1);
    std::chrono::steady_clock::duration stalledAfter_ = std::chrono::seconds(10);
    std::atomic<std::chrono::steady_clock::rep> lastAlive_{0};
    std::mutex mutex_;
    std::condition_variable wake_;
    bool quit_ = false;
    std::thread thread_;  // last: starts once everything above exists
};

// Analyses preview frames on its own thread, the newest frame only (older ones are dropped: the hint must be about
// what the visitor does now), so the screen keeps its rate whatever the analysis costs.
class PreviewWorker {
public:
    PreviewWorker(GuidanceSettings settings, std::mutex& detectorMutex)
        : settings_(std::move(settings)), detectorMutex_(detectorMutex), thread_([this] { run(); }) {}
    ~PreviewWorker() {
        {
            std::lock_guard lock(mutex_);
            quit_ = true;
        }
        wake_.notify_all();
        thread_.join();
    }
    // The analyser is rebuilt with it by the worker thread, between two analyses (never under a running one).
    void setDetector(const LandmarkDetector* detector) {
        std::lock_guard lock(mutex_);
        detector_ = detector;
    }
    // Offers a frame; ignored while the previous one is still being analysed.
    void offer(Photo photo, const cv::Mat& frame, FlowTime t) {
        {
            std::lock_guard lock(mutex_);
            if (busy_ || pending_) return;
            pending_ = Pending{photo, frame.clone(), t};
        }
        wake_.notify_all();
    }
    std::optional<PreviewAnalysed> take() {
        std::lock_guard lock(mutex_);
        auto r = result_;
        result_.reset();
        return r;
    }
    // Drops a frame not yet analysed; true when no analysis is running (the fit may take the detector). Never
    // waits: the main loop asks again next frame rather than stand still for a slow analysis.
    bool release() {
        std::lock_guard lock(mutex_);
        pending_.reset();
        return !busy_;
    }
    double analysesPerSecond() const {
        std::lock_guard lock(mutex_);
        return rate_;
    }

private:
    struct Pending {
        Photo photo;
        cv::Mat frame;
        FlowTime t;
    };
    void run() {
        lowerThisThreadsPriority(5);  // the hint may lag a frame; the screen and the watchdog must not
        for (;;) {
            Pending job;
            const LandmarkDetector* detector = nullptr;
            {
                std::unique_lock lock(mutex_);
                wake_.wait(lock, [&] { return quit_ || pending_.has_value(); });
                if (quit_) return;
                job = std::move(*pending_);
                pending_.reset();
                busy_ = true;
                detector = detector_;
            }
            if (!analyser_ || detector != analyserDetector_) {
                analyser_ = std::make_unique<PreviewAnalyser>(detector, PreviewAnalyser::Options{});
                analyserDetector_ = detector;
            }
            std::optional<PreviewAnalysed> result;
            const auto t0 = std::chrono::steady_clock::now();
            try {
                std::lock_guard detectorLock(detectorMutex_);
                result = analyser_->analyse(job.photo, job.frame, settings_, job.t);
            } catch (const std::exception& e) {
                spdlog::warn("preview analysis failed: {}", e.what());
            }
            const double seconds = Seconds(std::chrono::steady_clock::now() - t0).count();
            std::lock_guard lock(mutex_);
            rate_ = seconds > 0.0 ? 1.0 / seconds : 0.0;
            result_ = result;
            busy_ = false;
        }
    }

    GuidanceSettings settings_;
    std::mutex& detectorMutex_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    const LandmarkDetector* detector_ = nullptr;
    std::unique_ptr<PreviewAnalyser> analyser_;      // used by the worker thread only
    const LandmarkDetector* analyserDetector_ = nullptr;
    std::optional<Pending> pending_;
    std::optional<PreviewAnalysed> result_;
    bool busy_ = false;
    bool quit_ = false;
    double rate_ = 0.0;
    std::thread thread_;
};

// spdlog pattern with the visitor session's id on every line ("-" between sessions).
void setLogSession(const std::string& id) {
    spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] [session " + (id.empty() ? std::string("-") : id) + "] %v");
}

std::string newSessionId() {
    static std::mt19937 random(std::random_device{}());
    static const char* digits = "0123456789abcdef";
    std::string id;
    for (int i = 0; i < 8; ++i) id += digits[random() % 16];
    return id;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

// replace: the screen's picture again, over the one written before under this index.
void writeScreenshot(const fs::path& dir, int index, ScreenId id, const cv::Mat& frame, KioskReport& report,
                     bool replace = false) {
    char name[64];
    std::snprintf(name, sizeof name, "%02d_%s.png", index, toString(id));
    const fs::path path = dir / name;
    try {
        writeFileAtomically(path, encodeImage(frame, ".png"));
        if (!replace) report.screenshots.push_back(path);
    } catch (const BoothError& e) {
        spdlog::warn("screenshot not written: {}", e.what());
    }
}

}  // namespace

bool kioskLeftAThreadRunning() { return FitWorker::threadLeftRunning.load(); }

KioskReport runKiosk(const BoothConfig& config, const KioskOptions& options) {
    const auto startup = std::chrono::steady_clock::now();
    setLogSession("");
    KioskReport report;
    const auto note = [&](const std::string& line) {
        spdlog::info("{}", line);
        report.devices.push_back(line);
    };
    if (!config.file.empty()) note("config: " + config.file.string());
    else note("config: none given, built-in defaults");

    // --- Devices. The display first, so that whatever goes wrong later can be shown.
    OpenedDisplay opened = createDisplay(config.display);
    Display& display = *opened.display;
    note(opened.description);
    ScreenSettings screenSettings = config.screen;
    screenSettings.size = display.size();
    ScreenRenderer screens(screenSettings);

    auto simControls = options.simControls ? options.simControls : std::make_shared<SimCameraControls>();
    std::unique_ptr<ReopeningCamera> camera = openReopeningCamera(config.camera, CameraEnvironment{simControls, nullptr});
    note("camera: " + camera->describe().summary());
    const bool simCamera = camera->describe().backend == "sim";

    SteadyClock clock;
    ButtonBoard board = openButtonBoard(config.buttons, clock);
    note("buttons: " + board.description);
    LampDriver lamps(*board.lamps);

    SessionStore store(config.sessions);
    note("sessions: " + config.sessions.directory.string());
    report.sessionsDirectory = config.sessions.directory;
    if (const int removed = store.removeLeftovers(); removed > 0)
        spdlog::warn("removed {} unfinished session folder(s) left by an earlier run", removed);
    store.applyRetention(std::chrono::system_clock::now());
    if (!options.screenshots.empty()) fs::create_directories(options.screenshots);

    // --- Workers: the model loads in the background while the attract screen already runs.
    // OpenCV's worker pool is made by the first thread that needs it and its threads inherit that thread's priority:
    // made here, by the main loop's thread, before the workers lower theirs.
    cv::parallel_for_(cv::Range(0, 2 * std::max(1, cv::getNumThreads())), [](const cv::Range&) {});
    // (Shared: the fitter's State holds it, and that State may outlive this function with the loading thread.)
    auto detectorMutex = std::make_shared<std::mutex>();
    FitWorker fitter(config.fit.settings, configuredBaseHead(config.fit), detectorMutex);
    PreviewWorker previews(config.guidance, *detectorMutex);
    bool detectorGiven = false;
    AvatarStage stage(config.animation, 480);
    std::unique_ptr<RevealStyles> styles;
    {
        // Before the first visitor, the attract screen turns the base head (skin-coloured, untextured).
        const auto base = configuredBaseHead(config.fit);
        stage.show(base->mesh, cv::Mat(8, 8, CV_8UC3, cv::Scalar(150, 170, 210)));
        // 400: the side styles' places are about 400 px wide on a 1280x720 screen (fewer pixels for llvmpipe).
        styles = std::make_unique<RevealStyles>(config.reveal, config.stage, config.animation, *base, 400);
    }

    // --- The flow.
    VisitorFlow flow(config.flow, FlowClock::now());
    std::deque<FlowEvent> events;
    std::vector<FlowCommand> commands = flow.initialCommands();
    cv::Mat frontPhoto, sidePhoto, lastPreview;
    std::optional<Photo> previewFor;
    std::uint64_t fitJob = 0;
    bool fitWanted = false;   // StartFit received, waiting for the preview analysis to let go of the detector
    fs::path pendingFolder;   // the current fit's output, until kept or discarded
    bool saveWanted = false;  // SaveSession received, waiting for the toon to be drawn (its strip goes with it)
    std::string cameraProblem;
    std::string sessionId;
    ScreenId lastScreen = flow.screen().id;
    Hint lastHint = Hint::None;
    bool screenshotDue = !options.screenshots.empty();
    int screenshotIndex = 0;
    int hintlessGuideShot = -1;  // the index of a guide's screenshot taken before its first hint was known
    std::vector<std::pair<Button, FlowTime>> releases;  // simulated presses to release
    auto lastRetention = std::chrono::steady_clock::now();
    // Benchmark figures.
    int guideFrames = 0, analyses = 0;
    double guideSeconds = 0.0;
    std::vector<double> revealFrameSeconds, captureToReveal;
    // (Plain time points with a flag: gcc 12 takes optional<time_point> for maybe-uninitialised here.)
    std::chrono::steady_clock::time_point sideTakenAt{}, lastGuideFrame{};
    bool sideTaken = false, inGuide = false;
    std::optional<WatchdogPinger> watchdog;  // from READY on
    bool ready = false;

    const auto execute = [&](const FlowCommand& command, FlowTime now) {
        spdlog::debug("command {}", describe(command));
        std::visit(
            [&](const auto& c) {
                using T = std::decay_t<decltype(c)>;
                if constexpr (std::is_same_v<T, StartPreview>) {
                    if (previewFor != c.photo) lastPreview.release();  // never show the other pose's last frame
                    previewFor = c.photo;
                    try {
                        camera->start();
                    } catch (const BoothError& e) {
                        spdlog::warn("camera: {}", e.what());
                    }
                } else if constexpr (std::is_same_v<T, StopPreview>) {
                    previewFor.reset();
                } else if constexpr (std::is_same_v<T, CapturePhoto>) {
                    try {
                        CameraFrame still = camera->captureStill();
                        (c.photo == Photo::Front ? frontPhoto : sidePhoto) = still.image;
                        spdlog::info("{} photo taken: {}x{}", c.photo == Photo::Front ? "front" : "side",
                                     still.image.cols, still.image.rows);
                        events.push_back(CaptureDone{c.photo, now});
                        if (c.photo == Photo::Side) {
                            sideTakenAt = std::chrono::steady_clock::now();
                            sideTaken = true;
                        }
                    } catch (const std::exception& e) {
                        spdlog::warn("capture failed: {}", e.what());
                        events.push_back(CaptureFailed{c.photo, e.what(), now});
                    }
                } else if constexpr (std::is_same_v<T, StartFit>) {
                    fitWanted = true;
                } else if constexpr (std::is_same_v<T, CancelFit>) {
                    ++fitJob;  // its result will be dropped
                    fitWanted = false;
                } else if constexpr (std::is_same_v<T, SaveSession>) {
                    saveWanted = true;  // kept below, once the toon (drawn in the background) can go with it
                } else if constexpr (std::is_same_v<T, DiscardSession>) {
                    saveWanted = false;
                    if (!pendingFolder.empty()) {
                        try {
                            store.discard(pendingFolder);
                        } catch (const BoothError& e) {
                            spdlog::error("discarding the session: {}", e.what());
                        }
                        pendingFolder.clear();
                    }
                    frontPhoto.release();
                    sidePhoto.release();
                    ++fitJob;
                    spdlog::info("session discarded: nothing of it is kept");
                } else if constexpr (std::is_same_v<T, SetLamps>) {
                    const auto pattern = [&](LampMode mode) {
                        switch (mode) {
                            case LampMode::Off: return LampPattern::off();
                            case LampMode::On: return LampPattern::steady();
                            case LampMode::SlowBlink: return LampPattern::blink(std::chrono::milliseconds(1000), clock.now());
                            case LampMode::FastBlink: return LampPattern::blink(std::chrono::milliseconds(250), clock.now());
                        }
                        return LampPattern::off();
                    };
                    for (const auto& name : board.lamps->names()) {
                        if (name == "start") lamps.setPattern(name, pattern(c.lamps.start));
                        else if (name == "retake") lamps.setPattern(name, pattern(c.lamps.retake));
                        else if (name == "flash") lamps.setPattern(name, pattern(c.lamps.flash));
                    }
                } else if constexpr (std::is_same_v<T, FreeDisk>) {
                    const RetentionReport r = store.applyRetention(std::chrono::system_clock::now());
                    const int leftovers = store.removeLeftovers();
                    spdlog::info("operator freed disk: {} photos, {} sessions, {} leftovers, {} bytes", r.photosDeleted,
                                 r.sessionsDeleted, leftovers, r.bytesFreed);
                }
            },
            command);
    };

    for (auto nextFrame = std::chrono::steady_clock::now();; nextFrame += kFramePeriod) {
        if (options.stop && options.stop->load()) break;
        const FlowTime now = FlowClock::now();
        for (const auto& c : commands) execute(c, now);
        commands.clear();

        // Buttons, keyboard, and the simulated visitor.
        if (board.keyboard)
            for (const auto& key : display.pollKeys()) board.keyboard->feed(key.key, key.pressed, key.time);
        while (auto e = board.buttons->poll(std::chrono::milliseconds(0))) {
            if (const auto b = parseButton(e->button)) {
                if (e->action == ButtonAction::Press) events.push_back(ButtonPressed{*b, now});
                else events.push_back(ButtonReleased{*b, now});
            }
        }
        if (options.visitor) {
            const VisitorScript::Action a = options.visitor->step(flow.screen(), now);
            simControls->setScene(a.scene);
            if (a.press) {
                events.push_back(ButtonPressed{*a.press, now});
                releases.emplace_back(*a.press, now + kReleaseAfter);
            }
        }
        for (auto it = releases.begin(); it != releases.end();) {
            if (it->second <= now) {
                events.push_back(ButtonReleased{it->first, now});
                it = releases.erase(it);
            } else {
                ++it;
            }
        }

        // The camera: its state, and the newest preview frame for the guide and the analysis.
        const std::string problem = camera->status().message;
        if (problem != cameraProblem) {
            if (!problem.empty()) {
                spdlog::warn("{}", problem);
                events.push_back(CameraLost{problem, now});
            } else {
                spdlog::info("camera back: {}", camera->describe().summary());
                events.push_back(CameraBack{now});
            }
            cameraProblem = problem;
        }
        if (!previewFor && !cameraProblem.empty()) {
            // A lost camera is reopened by ReopeningCamera's calls; with no preview running (the camera-lost and
            // attract screens stop it) nothing would call it, and the booth would never see the camera come back.
            try {
                (void)camera->nextFrame(std::chrono::milliseconds(0));
                if (camera->status().ok) camera->stop();
            } catch (const BoothError& e) {
                spdlog::debug("camera retry: {}", e.what());
            }
        }
        if (previewFor) {
            try {
                while (auto frame = camera->nextFrame(std::chrono::milliseconds(lastPreview.empty() ? 30 : 0)))
                    lastPreview = frame->image;
            } catch (const BoothError& e) {
                spdlog::debug("preview: {}", e.what());
            }
            if (!lastPreview.empty() && !fitWanted) previews.offer(*previewFor, lastPreview, now);
        }
        if (!detectorGiven) {
            if (const FitPipeline* p = fitter.pipeline()) {
                previews.setDetector(&p->detector());
                detectorGiven = true;
            } else if (const auto error = fitter.loadError()) {
                throw BoothError(ErrorKind::BadConfig, config.fit.settings.landmarkModel.string(), *error);
            }
        }
        if (auto analysed = previews.take()) {
            events.push_back(*analysed);
            ++analyses;
        }

        // The fit: started once the model is there and the analysis has let go of the detector.
        if (fitWanted && fitter.pipeline() && previews.release()) {
            (void)previews.take();
            // A retake fits again: the earlier fit's folder (the visitor's photos) goes first.
            if (!pendingFolder.empty()) {
                try {
                    store.discard(pendingFolder);
                } catch (const BoothError& e) {
                    spdlog::error("discarding the earlier fit: {}", e.what());
                }
            }
            pendingFolder = store.pendingPath();
            fitter.submit(++fitJob, frontPhoto, sidePhoto, pendingFolder);
            spdlog::info("fitting into {}", pendingFolder.string());
            fitWanted = false;
        }
        if (auto stageName = fitter.takeStage()) events.push_back(FitProgress{stageProgress(*stageName), *stageName, now});
        if (auto result = fitter.takeResult()) {
            if (result->job != fitJob) {
                spdlog::info("a cancelled fit finished; its output is removed");
                if (result->ok) store.discard(result->folder);
            } else if (result->ok) {
                stage.show(result->mesh, result->texture);
                styles->visitor(std::move(result->styles));
                events.push_back(FitDone{now});
            } else {
                spdlog::warn("fit failed: {}", result->error->what());
                if (!pendingFolder.empty() && fs::exists(pendingFolder)) store.discard(pendingFolder);
                pendingFolder.clear();
                events.push_back(fitFailureFor(*result->error, now));
            }
        }

        // Keeping the session, with the toon's strip in it: the thanks screen says "saving" until then.
        if (saveWanted && styles->toonSettled()) {
            saveWanted = false;
            try {
                if (!pendingFolder.empty()) styles->writeToonStrip(pendingFolder);
                const std::string code = store.keep(pendingFolder, std::chrono::system_clock::now());
                spdlog::info("session kept as {}", code);
                report.keptCodes.push_back(code);
                pendingFolder.clear();
                events.push_back(SessionSaved{code, now});
            } catch (const BoothError& e) {
                spdlog::error("session not kept: {}", e.what());
                events.push_back(SessionSaveFailed{e.what(), now});
                // Nothing of a session that could not be kept stays behind (the flow sends no discard after a
                // keep, and the next fit would reuse pendingFolder).
                try {
                    if (!pendingFolder.empty()) store.discard(pendingFolder);
                } catch (const BoothError& d) {
                    spdlog::error("discarding the session that was not kept: {}", d.what());
                }
                pendingFolder.clear();
            }
        }

        // The flow: every event, then a tick for the timeouts and the countdown.
        events.push_back(Tick{now});
        const ScreenId before = flow.screen().id;
        while (!events.empty()) {
            const FlowEvent e = events.front();
            events.pop_front();
            for (auto& c : flow.handle(e)) commands.push_back(std::move(c));
        }
        const ScreenModel& screen = flow.screen();
        if (before == ScreenId::Attract && screen.id != ScreenId::Attract) {
            sessionId = newSessionId();
            setLogSession(sessionId);
            spdlog::info("a visitor started a session");
        }
        if (before != ScreenId::Attract && screen.id == ScreenId::Attract) {
            ++report.sessionsEnded;
            spdlog::info("session ended ({} so far)", report.sessionsEnded);
            sessionId.clear();
            setLogSession("");
        }
        lamps.update(clock.now());

        // The screen.
        const auto drawStart = std::chrono::steady_clock::now();
        ScreenInputs inputs;
        const bool previewScreen = screen.id == ScreenId::FrontGuide || screen.id == ScreenId::SideGuide ||
                                   screen.id == ScreenId::Countdown;
        if (previewScreen) inputs.preview = lastPreview;
        if (screen.id == ScreenId::Reveal || screen.id == ScreenId::Attract) {
            inputs.avatar = stage.frame(screen.id == ScreenId::Reveal, screen.sinceEntered);
            styles->fill(inputs, screen.id == ScreenId::Reveal, screen.sinceEntered, screens.layout());
        }
        if (screen.id == ScreenId::RetakeChoice) {
            inputs.frontPhoto = frontPhoto;
            inputs.sidePhoto = sidePhoto;
        }
        if (screen.id == ScreenId::OperatorMenu) {
            for (const auto& s : store.list()) {
                if (inputs.operatorInfo.recentCodes.size() >= 10) break;
                inputs.operatorInfo.recentCodes.emplace_back(s.code, s.keptAt);
            }
            inputs.operatorInfo.sessionsStored = static_cast<int>(store.list().size());
            inputs.operatorInfo.freeBytes = store.freeBytes();
        }
        const cv::Mat& drawn = screens.draw(screen, inputs);
        display.present(drawn);
        const auto drawEnd = std::chrono::steady_clock::now();
        if (screen.id == ScreenId::FrontGuide || screen.id == ScreenId::SideGuide) {
            if (inGuide) {  // frame intervals within one guide
                ++guideFrames;
                guideSeconds += Seconds(drawEnd - lastGuideFrame).count();
            }
            lastGuideFrame = drawEnd;
            inGuide = true;
        } else {
            inGuide = false;
        }
        if (screen.id == ScreenId::Reveal && !inputs.avatar.empty()) {
            revealFrameSeconds.push_back(Seconds(drawEnd - drawStart).count());
            if (sideTaken) {
                captureToReveal.push_back(Seconds(drawEnd - sideTakenAt).count());
                sideTaken = false;
            }
        }
        if (screen.id != lastScreen) {
            screenshotDue = !options.screenshots.empty();
            hintlessGuideShot = -1;
        }
        // A screen's picture once it has what it shows: the preview on guides, the avatar on the reveal. A guide
        // whose first hint was not known yet (the first analysis is slow on a slow board) is taken again, under the
        // same name, once it is.
        const bool guide = screen.id == ScreenId::FrontGuide || screen.id == ScreenId::SideGuide;
        if (guide && (screen.id != lastScreen || screen.hint != lastHint))
            spdlog::info("{}: hint {}", toString(screen.id), toString(screen.hint));
        lastHint = screen.hint;
        if (hintlessGuideShot >= 0 && screen.hint != Hint::None) {
            writeScreenshot(options.screenshots, hintlessGuideShot, screen.id, drawn, report, true);
            hintlessGuideShot = -1;
        }
        const bool complete = (!previewScreen || (!inputs.preview.empty() && screen.sinceEntered >= Millis(700))) &&
                              // (every style drawn; a toon still drawing after 2.5 s is pictured as it is)
                              (screen.id != ScreenId::Reveal ||
                               (!inputs.avatar.empty() && (styles->complete() || screen.sinceEntered >= Millis(2500)))) &&
                              (screen.id != ScreenId::Thanks || !screen.code.empty());
        lastScreen = screen.id;
        if (screenshotDue && complete) {
            if (guide && screen.hint == Hint::None) hintlessGuideShot = screenshotIndex;
            writeScreenshot(options.screenshots, screenshotIndex++, screen.id, drawn, report);
            screenshotDue = false;
        }
        if (!ready) {
            sd_notify(0, "READY=1");
            ready = true;
            report.startupToReadySeconds = Seconds(std::chrono::steady_clock::now() - startup).count();
            spdlog::info("ready in {:.2f} s{}", report.startupToReadySeconds, simCamera ? " (simulated booth)" : "");
            watchdog.emplace();
        }

        // Housekeeping: the watchdog hears that the loop is alive; retention.
        watchdog->alive();
        const auto wall = std::chrono::steady_clock::now();
        if (wall - lastRetention >= kRetentionEvery) {
            const RetentionReport r = store.applyRetention(std::chrono::system_clock::now());
            if (r.photosDeleted || r.sessionsDeleted)
                spdlog::info("retention: deleted {} photos and {} sessions", r.photosDeleted, r.sessionsDeleted);
            lastRetention = wall;
        }
        if (options.sessions > 0 && report.sessionsEnded >= options.sessions) break;
        if (display.closeRequested()) break;
        std::this_thread::sleep_until(nextFrame + kFramePeriod);
        if (std::chrono::steady_clock::now() > nextFrame + 4 * kFramePeriod) nextFrame = std::chrono::steady_clock::now();
    }
    sd_notify(0, "STOPPING=1");
    watchdog.reset();
    report.guideFramesPerSecond = guideSeconds > 0.0 ? guideFrames / guideSeconds : 0.0;
    report.analysesPerSecond = guideSeconds > 0.0 ? analyses / guideSeconds : 0.0;
    report.sideCaptureToRevealSeconds = median(captureToReveal);
    report.revealFrameMilliseconds = 1000.0 * median(revealFrameSeconds);
    const StyleFigures figures = styles->figures();
    report.characterFrameMilliseconds = figures.characterMs;
    report.toonFrameMilliseconds = figures.toonMs;
    report.stageRenderMilliseconds = figures.stageMs;
    report.toonBuildSeconds = figures.toonBuildSeconds;
    report.styleFrames = figures.frames;
    report.characterRenders = figures.characterRenders;
    report.toonRenders = figures.toonRenders;
    report.stageRenders = figures.stageRenders;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    report.peakRssMegabytes = static_cast<double>(usage.ru_maxrss) / 1024.0;
    // Leave nothing of a visitor who was still in the middle of a session.
    if (!pendingFolder.empty()) store.discard(pendingFolder);
    return report;
}

}  // namespace avatarbooth
