// The kiosk's main loop and its worker threads (model loading + fitting, preview analysis).
#include "kiosk/kiosk.h"

#include "reveal/styles/avatar_stage.h"
#include "kiosk/session_writer.h"

#include "booth/guidance.h"
#include "booth/session_store.h"
#include "booth/visitor_flow.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "common/recent_timings.h"
#include "drivers/camera/camera_factory.h"
#include "drivers/camera/reopening_camera.h"
#include "drivers/display/display_factory.h"
#include "drivers/display/headless_egl.h"
#include "drivers/gpio/button_board.h"
#include "drivers/gpio/clock.h"
#include "drivers/gpio/lamps.h"
#include "fit/face/landmarks68.h"
#include "reveal/styles/reveal_styles.h"
#include "fit/fit_pipeline.h"
#include "booth/screens/screens.h"

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

#include <malloc.h>
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

// What a finished fit hands back to the loop: the outcome as soon as it has a mesh and a texture (the session
// folder is written afterwards by the SessionWriter, behind the reveal).
struct FitResult {
    std::uint64_t job = 0;
    std::shared_ptr<const FitOutcome> outcome;  // when it worked
    std::optional<BoothError> error;
};

// The character maker's outputs for a fit, made right after it (while the reveal already runs); the session folder
// is written once they are there (they go into it).
struct CharacterResult {
    std::uint64_t job = 0;
    std::shared_ptr<const CharacterOutputs> outputs;  // null when the character is off or could not be made
    std::optional<std::string> error;                 // why it could not be made
};

// Lowers the calling thread's priority (Linux: nice is per thread): the screen and the watchdog come first when
// the cores are busy. Best effort: without it the booth still works, only its frame rate suffers under load.
void lowerThisThreadsPriority(int nice) {
    if (setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), nice) != 0)
        spdlog::debug("setpriority({}): {}", nice, std::strerror(errno));
}

// Loads the landmark model on one thread, then fits one job at a time on another (the session folder is written
// by the SessionWriter afterwards). dlib's deserialisation cannot be interrupted (minutes on a slow board or under
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

    void submit(std::uint64_t job, cv::Mat front, cv::Mat side) {
        {
            std::lock_guard lock(state_->mutex);
            std::erase_if(state_->jobs, [](const Job& j) { return !j.frontOnly; });  // a queued fit is superseded
            state_->jobs.push_back(Job{job, std::move(front), std::move(side), false});
        }
        state_->wake.notify_all();
    }
    // Analyses the front photo now (landmarks, silhouette: about a third of the fit), while the visitor turns for
    // the side photo; the fit of this very photo then starts from it. No result is posted.
    void analyseFrontAhead(cv::Mat front) {
        {
            std::lock_guard lock(state_->mutex);
            state_->jobs.push_back(Job{0, std::move(front), cv::Mat(), true});
        }
        state_->wake.notify_all();
    }
    std::optional<FitResult> takeResult() {
        std::lock_guard lock(state_->mutex);
        std::optional<FitResult> r = std::move(state_->result);
        state_->result.reset();
        return r;
    }
    std::optional<CharacterResult> takeCharacter() {
        std::lock_guard lock(state_->mutex);
        std::optional<CharacterResult> c = std::move(state_->character);
        state_->character.reset();
        return c;
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
        std::uint64_t id = 0;
        cv::Mat front, side;
        bool frontOnly = false;
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
        std::deque<Job> jobs;  // fits and front photos to analyse ahead, oldest first
        std::optional<FitResult> result;
        std::optional<std::string> stage;
        std::optional<CharacterResult> character;
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
        std::optional<FrontAnalysis> ahead;  // of the last front photo analysed ahead
        for (;;) {
            Job job;
            {
                std::unique_lock lock(s.mutex);
                s.wake.wait(lock, [&] { return s.quit || (s.pipeline && !s.jobs.empty()); });
                if (s.quit) return;
                job = std::move(s.jobs.front());
                s.jobs.pop_front();
            }
            if (job.frontOnly) {
                ahead.reset();
                try {
                    std::lock_guard detector(*s.detectorMutex);
                    ahead = s.pipeline->analyseFront(job.front, cv::Mat(), FitInputs{"front photo", "side photo", {}});
                    spdlog::info("front photo analysed ahead in {:.0f} ms",
                                 1000.0 * (ahead->stageSeconds[0].second + ahead->stageSeconds[1].second));
                } catch (const std::exception& e) {
                    spdlog::info("front photo not analysed ahead ({}); the fit will say", e.what());
                }
                continue;
            }
            FitResult result;
            result.job = job.id;
            try {
                const FitInputs names{"front photo", "side photo", {}};
                auto outcome = std::make_shared<FitOutcome>();
                {
                    std::lock_guard detector(*s.detectorMutex);
                    *outcome = s.pipeline->fit(
                        job.front, job.side, cv::Mat(), names,
                        [&](const std::string& stage) {
                            std::lock_guard lock(s.mutex);
                            s.stage = stage;
                        },
                        ahead ? &*ahead : nullptr);
                }
                std::string stages;
                for (const auto& [name, seconds] : outcome->stageSeconds)
                    stages += fmt::format("{}{} {:.0f} ms", stages.empty() ? "" : ", ", name, 1000.0 * seconds);
                spdlog::info("fitted: {}", stages);
                result.outcome = std::move(outcome);
            } catch (const BoothError& e) {
                result.error = e;
            } catch (const std::exception& e) {
                result.error = BoothError(ErrorKind::Internal, "", e.what());
            }
            const std::shared_ptr<const FitOutcome> fitted = result.outcome;
            {
                std::lock_guard lock(s.mutex);
                s.result = std::move(result);
                if (s.quit) return;
            }
            if (!fitted) continue;
            // The character next, on this (un-niced) thread: the visitor watches its place on the reveal.
            CharacterResult character{job.id, nullptr, std::nullopt};
            try {
                CharacterOutputs made = s.pipeline->makeCharacter(*fitted);
                if (!made.json.empty()) character.outputs = std::make_shared<const CharacterOutputs>(std::move(made));
            } catch (const std::exception& e) {
                character.error = e.what();
            }
            std::lock_guard lock(s.mutex);
            s.character = std::move(character);
        }
    }

    std::shared_ptr<State> state_;
    std::thread loader_, fitter_;
};

// The systemd watchdog (sd_notify WATCHDOG=1). Pinged from its own thread at half of WatchdogSec (WATCHDOG_USEC,
// sd_watchdog_enabled(): the convention sd_notify(3) gives), so the pings keep their rate however long one frame
// takes on a slow board -- but only while the main loop is alive: every loop iteration calls alive(), and when
// none has for a whole WatchdogSec the pings stop (logged once) and systemd kills and restarts the hung booth.
// Without a watchdog in the environment (no WatchdogSec, or not under systemd) it sends nothing: pings nobody
// asked for would only fill a notify socket that is not read.
class WatchdogPinger {
public:
    WatchdogPinger() {
        std::uint64_t usec = 0;
        if (sd_watchdog_enabled(0, &usec) <= 0 || usec == 0) {
            spdlog::info("watchdog: none asked for (no WATCHDOG_USEC), no pings");
            return;
        }
        interval_ = std::chrono::microseconds(usec / 2);
        stalledAfter_ = std::chrono::microseconds(usec);
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
        if (thread_.joinable()) thread_.join();
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

// Where one main-loop step spent its time: logged when the step took long enough for the visitor to see the screen
// stand still (the screen runs at 30 fps), so that an operator's log says which part stalled it.
class StepTimer {
public:
    void mark(const char* part) {
        const auto t = std::chrono::steady_clock::now();
        parts_.emplace_back(part, Seconds(t - last_).count());
        last_ = t;
    }
    void reportIfSlow(const char* screen) const {
        const double total = Seconds(last_ - start_).count();
        if (total < kSlowStep) return;
        std::string parts;
        for (const auto& [name, seconds] : parts_)
            if (seconds >= 0.005) parts += fmt::format("{}{} {:.0f} ms", parts.empty() ? "" : ", ", name, 1000.0 * seconds);
        spdlog::warn("slow main-loop step on {}: {:.0f} ms ({})", screen, 1000.0 * total, parts);
    }

private:
    static constexpr double kSlowStep = 0.5;  // seconds
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now(), last_ = start_;
    std::vector<std::pair<const char*, double>> parts_;
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

// replace: the screen's picture again, over the one written before under this index.
void writeScreenshot(const fs::path& dir, int index, const ScreenModel& screen, const cv::Mat& frame,
                     KioskReport& report, bool replace = false) {
    const char* page = "";
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage == OperatorPage::LastCodes) page = "_last_codes";
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage == OperatorPage::FreeDisk) page = "_free_disk";
    char name[80];
    std::snprintf(name, sizeof name, "%02d_%s%s.png", index, toString(screen.id), page);
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

void tuneAllocatorForKiosk() {
    // glibc gives each new thread's allocations their own arena (up to 8 per core); with the fit, writer, preview
    // and llvmpipe threads each keeping freed images in its own, the peak RSS of a session measured 43 MB higher
    // (425 against 382 MB) than with two arenas shared by all.
    mallopt(M_ARENA_MAX, 2);
    // Images (a 720p frame is 2.6 MB) are allocated and freed many times a second. glibc serves blocks above its
    // mmap threshold with their own mapping, returned at free; but the threshold rises to the largest block freed,
    // after which every image comes from the arena and the freed ones stay resident there. A fixed threshold stops
    // that rise: at 1 MB it lowered a session's peak RSS by 40 MB (415 -> 375 MB). At 128 KB the half-size frames,
    // dlib's HOG planes and the meshes' arrays get their own mappings too: the arena then held 12 MB free after 100
    // soak sessions instead of 54 MB (RSS 263 against 282 MB; it had climbed 17 MB over 1000 sessions, pages
    // pinned by small blocks between the freed images), the peak of a session is 9 MB lower, and the frame rates
    // did not change measurably (tests/reliability/soak.cpp; README, Memory).
    mallopt(M_MMAP_THRESHOLD, 128 << 10);
}

KioskReport runKiosk(const BoothConfig& config, const KioskOptions& options) {
    const auto startup = std::chrono::steady_clock::now();
    tuneAllocatorForKiosk();
    setLogSession("");
    // Where the start-up's time goes (`-v`): the booth must be on the attract screen within 2 s of a restart.
    const auto startupStep = [&](const char* what) {
        spdlog::debug("start-up: {} after {:.3f} s", what, Seconds(std::chrono::steady_clock::now() - startup).count());
    };
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
    startupStep("display open");
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
    startupStep("camera and buttons open");
    LampDriver lamps(*board.lamps);

    SessionStore store(config.sessions);
    note("sessions: " + config.sessions.directory.string());
    report.sessionsDirectory = config.sessions.directory;
    if (const int removed = store.removeLeftovers(); removed > 0)
        spdlog::warn("removed {} unfinished session folder(s) left by an earlier run", removed);
    store.applyRetention(std::chrono::system_clock::now());
    if (!options.screenshots.empty()) fs::create_directories(options.screenshots);
    startupStep("leftovers removed, retention applied");

    // --- Workers: the model loads in the background while the attract screen already runs.
    // OpenCV's worker pool is made by the first thread that needs it and its threads inherit that thread's priority:
    // made here, by the main loop's thread, before the workers lower theirs.
    cv::parallel_for_(cv::Range(0, 2 * std::max(1, cv::getNumThreads())), [](const cv::Range&) {});
    startupStep("OpenCV worker pool made");
    // (Shared: the fitter's State holds it, and that State may outlive this function with the loading thread.)
    auto detectorMutex = std::make_shared<std::mutex>();
    FitWorker fitter(config.fit.settings, configuredBaseHead(config.fit), detectorMutex);
    PreviewWorker previews(config.guidance, *detectorMutex);
    bool detectorGiven = false;
    // One GL context for every offscreen render of the main thread (the avatar, the character, the stage): each
    // llvmpipe context costs memory and threads of its own.
    HeadlessEglContext offscreen;
    AvatarStage stage(config.animation, AvatarStageOptions{}, &offscreen);
    SessionWriter writer;  // after the fitter: it writes with the fitter's pipeline
    startupStep("workers started");
    std::unique_ptr<RevealStyles> styles;
    // The avatars' places on the reveal: the photo avatar (the first) and the other styles are rendered at the size
    // they are shown (no rescaling, no more pixels than shown for llvmpipe).
    const int styleCount = std::max<int>(1, static_cast<int>(config.reveal.styles.size()));
    {
        // Before the first visitor, the attract screen turns the base head (skin-coloured, untextured).
        const auto base = configuredBaseHead(config.fit);
        stage.show(base->mesh, cv::Mat(8, 8, CV_8UC3, cv::Scalar(150, 170, 210)));
        const std::vector<cv::Rect> places = screens.avatarImageBoxes(ScreenId::Reveal, styleCount);
        const int styleSize = places.size() > 1 ? std::min(places[1].width, places[1].height) : 400;
        styles = std::make_unique<RevealStyles>(config.reveal, config.stage, config.animation, *base,
                                                std::max(64, styleSize), &offscreen);
    }
    startupStep("avatar stage and styles made");
    std::pair<std::uint64_t, std::uint64_t> shownVersions{0, 0};  // the avatar stage's and the styles' last seen
    std::uint64_t avatarsVersion = 0;                             // changes with either

    // --- The flow.
    VisitorFlow flow(config.flow, FlowClock::now());
    std::deque<FlowEvent> events;
    std::vector<FlowCommand> commands = flow.initialCommands();
    cv::Mat frontPhoto, sidePhoto, lastPreview;
    std::optional<Photo> previewFor;
    std::uint64_t fitJob = 0;
    bool fitWanted = false;   // StartFit received, waiting for the preview analysis to let go of the detector
    // The session folder: written in the background after the reveal has started. pendingFolder is the current
    // visitor's (empty when none); writeJob the write the session waits for (0: none in flight); keepJobs the writes
    // the visitor has already chosen to keep (kept as soon as they are written); any other write is discarded.
    fs::path pendingFolder;
    std::uint64_t writeJob = 0;
    enum class Written { None, Writing, Done, Failed } written = Written::None;
    std::string writeFailure;
    std::vector<std::uint64_t> keepJobs;
    std::uint64_t styleJob = 0;  // the fit whose character and toon the styles show
    // A fitted session whose folder is written once its character is made (the fitter makes it next).
    struct WriteAfterCharacter {
        std::uint64_t job = 0;
        std::shared_ptr<const FitOutcome> outcome;
        fs::path folder;
    };
    std::optional<WriteAfterCharacter> awaitingCharacter;
    // What the current visitor's write was given: a keep after a failed write (disk full) writes it again.
    struct WriteGiven {
        std::uint64_t job = 0;
        std::shared_ptr<const FitOutcome> outcome;
        std::shared_ptr<const CharacterOutputs> character;
    };
    std::optional<WriteGiven> lastWrite;
    fs::path toonStripFor;       // a kept session whose toon is still being drawn (its strip is added when done)
    std::string cameraProblem;
    std::string sessionId;
    ScreenId lastScreen = flow.screen().id;
    Hint lastHint = Hint::None;
    OperatorPage lastMenuPage = OperatorPage::Menu;
    RetentionReport lastFreed;  // what the operator's last "free disk" removed (shown in the menu)
    bool screenshotDue = !options.screenshots.empty();
    int screenshotIndex = 0;
    // The index of a screenshot taken before its screen had everything it shows (a guide before its first hint, a
    // reveal before the toon was drawn): taken again, under the same name, once it has.
    int provisionalShot = -1;
    std::vector<std::pair<Button, FlowTime>> releases;  // simulated presses to release
    auto lastRetention = std::chrono::steady_clock::now();
    // Benchmark figures.
    int guideFrames = 0, analyses = 0;
    double guideSeconds = 0.0;
    // (The most recent frames' times: the booth runs for weeks, and a list of every frame grew without end.)
    RecentTimings revealFrameSeconds, captureToReveal, revealRenderSeconds, revealComposeSeconds, revealPresentSeconds;
    // (Plain time points with a flag: gcc 12 takes optional<time_point> for maybe-uninitialised here.)
    std::chrono::steady_clock::time_point sideTakenAt{}, lastGuideFrame{};
    bool sideTaken = false, inGuide = false;
    std::optional<WatchdogPinger> watchdog;  // from READY on
    bool ready = false;

    const auto discardQuietly = [&](const fs::path& folder) {
        try {
            if (!folder.empty()) store.discard(folder);
        } catch (const BoothError& e) {
            spdlog::error("discarding {}: {}", folder.string(), e.what());
        }
    };
    // Leaves nothing of the current visitor's folder: removed now when written, else when its write ends.
    const auto dropSessionFolder = [&] {
        lastWrite.reset();
        if (awaitingCharacter && awaitingCharacter->job == writeJob) awaitingCharacter.reset();  // never written
        else if (written != Written::Writing) discardQuietly(pendingFolder);
        pendingFolder.clear();
        writeJob = 0;
        written = Written::None;
    };
    const auto keepSession = [&](std::uint64_t job, const fs::path& folder, FlowTime now) {
        try {
            const std::string code = store.keep(folder, std::chrono::system_clock::now());
            spdlog::info("session kept as {}", code);
            ++report.sessionsKept;
            report.keptCodes.push_back(code);
            if (report.keptCodes.size() > KioskReport::kKeptCodesListed) report.keptCodes.pop_front();
            events.push_back(SessionSaved{code, now});
            if (job == styleJob && styles->showsToon()) {
                if (const auto kept = store.find(code)) toonStripFor = *kept;  // its toon strip follows
            }
        } catch (const BoothError& e) {
            spdlog::error("session not kept: {}", e.what());
            discardQuietly(folder);
            events.push_back(SessionSaveFailed{e.what(), now});
        }
    };
    // A finished background write: kept, held for the visitor's choice, or removed.
    const auto handleWritten = [&](const SessionWriter::Done& done, FlowTime now) {
        const auto keep = std::find(keepJobs.begin(), keepJobs.end(), done.job);
        if (done.error) spdlog::error("the session folder was not written: {}", done.error->what());
        else spdlog::info("session folder written in {:.2f} s", done.seconds);
        if (keep != keepJobs.end()) {
            keepJobs.erase(keep);
            if (done.error) {
                discardQuietly(done.folder);
                events.push_back(SessionSaveFailed{done.error->what(), now});
            } else {
                keepSession(done.job, done.folder, now);
            }
        } else if (done.job == writeJob && written == Written::Writing) {
            if (done.error) {
                discardQuietly(done.folder);  // nothing partial stays
                pendingFolder.clear();
                written = Written::Failed;
                writeFailure = done.error->what();
            } else {
                written = Written::Done;
            }
        } else {
            discardQuietly(done.folder);  // the visitor retook a photo or left meanwhile
        }
    };

    const auto addToonStrip = [&] {
        try {
            if (styles->writeToonStrip(toonStripFor))
                spdlog::info("toon strip added to the kept session {}", toonStripFor.filename().string());
        } catch (const BoothError& e) {
            spdlog::error("the kept session {} goes without its toon strip: {}", toonStripFor.filename().string(),
                          e.what());
        }
        toonStripFor.clear();
    };

    // The fit's character: shown among the styles, then the session folder (which holds it) is written.
    const auto characterMade = [&](const CharacterResult& c) {
        if (c.error) spdlog::warn("no character for this visitor: {}", *c.error);
        if (c.job == styleJob) {
            if (c.outputs) styles->visitorCharacter(c.outputs->head.mesh, c.outputs->head.texture);
            else styles->visitorWithoutCharacter();
        }
        if (awaitingCharacter && awaitingCharacter->job == c.job) {
            if (const FitPipeline* p = fitter.pipeline()) {
                writer.submit(c.job, awaitingCharacter->outcome, p, awaitingCharacter->folder, c.outputs);
                lastWrite = WriteGiven{c.job, awaitingCharacter->outcome, c.outputs};
            }
            awaitingCharacter.reset();
        }
    };

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
                        if (c.photo == Photo::Front && fitter.pipeline()) fitter.analyseFrontAhead(frontPhoto);
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
                    if (written == Written::Done) {
                        keepSession(writeJob, pendingFolder, now);
                    } else if (written == Written::Writing) {
                        // Kept as soon as it is written (the thanks screen shows the code then).
                        spdlog::info("the session is kept once its folder is written");
                        keepJobs.push_back(writeJob);
                    } else if (written == Written::Failed && lastWrite && lastWrite->job == writeJob &&
                               fitter.pipeline()) {
                        // The write failed while the visitor looked (e.g. the disk was full): the fit is still in
                        // memory, so the keep writes it again (space may have been freed since) and keeps it.
                        spdlog::warn("the session folder was not written ({}): writing it again for the keep",
                                     writeFailure);
                        const fs::path folder = store.pendingPath();
                        writer.submit(writeJob, lastWrite->outcome, fitter.pipeline(), folder, lastWrite->character);
                        keepJobs.push_back(writeJob);
                    } else {
                        const std::string why = written == Written::Failed ? writeFailure : "no fitted avatar to keep";
                        spdlog::error("session not kept: {}", why);
                        events.push_back(SessionSaveFailed{why, now});
                    }
                    lastWrite.reset();
                    pendingFolder.clear();
                    writeJob = 0;
                    written = Written::None;
                } else if constexpr (std::is_same_v<T, DiscardSession>) {
                    dropSessionFolder();
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
                    // Leftovers are every pending folder: a session still being written must be finished first.
                    writer.waitIdle();
                    while (auto done = writer.take()) handleWritten(*done, now);
                    const RetentionReport r = store.applyRetention(std::chrono::system_clock::now());
                    const int leftovers = store.removeLeftovers();
                    lastFreed = r;
                    spdlog::info("operator freed disk: {} photos, {} sessions, {} leftovers, {} bytes", r.photosDeleted,
                                 r.sessionsDeleted, leftovers, r.bytesFreed);
                }
            },
            command);
    };

    for (auto nextFrame = std::chrono::steady_clock::now();; nextFrame += kFramePeriod) {
        if (options.stop && options.stop->load()) break;
        const FlowTime now = FlowClock::now();
        StepTimer step;
        for (const auto& c : commands) execute(c, now);
        commands.clear();
        step.mark("commands");

        // Buttons, keyboard, and the simulated visitor.
        if (board.keyboard)
            for (const auto& key : display.pollKeys()) board.keyboard->feed(key.key, key.pressed, key.time);
        while (auto e = board.buttons->poll(std::chrono::milliseconds(0))) {
            if (const auto b = parseButton(e->button)) {
                if (e->action == ButtonAction::Press) events.push_back(ButtonPressed{*b, now});
                else events.push_back(ButtonReleased{*b, now});
            }
        }
        // Simulated presses that are over (before any new press: a button is up before it goes down again).
        for (auto it = releases.begin(); it != releases.end();) {
            if (it->second <= now) {
                events.push_back(ButtonReleased{it->first, now});
                it = releases.erase(it);
            } else {
                ++it;
            }
        }
        if (options.visitor) {
            const VisitorScript::Action a = options.visitor->step(flow.screen(), now);
            simControls->setScene(a.scene);
            if (a.cameraPlugged && *a.cameraPlugged != !simControls->vanished()) {
                spdlog::info("simulated visitor: camera {}", *a.cameraPlugged ? "plugged back" : "unplugged");
                if (*a.cameraPlugged) simControls->comeBack();
                else simControls->vanish();
            }
            for (const auto& b : {a.press, a.pressWith}) {
                if (!b) continue;
                events.push_back(ButtonPressed{*b, now});
                releases.emplace_back(*b, now + (a.holdFor > Millis(0) ? a.holdFor : kReleaseAfter));
            }
        }

        step.mark("buttons");
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
                // The newest frame, but at most a queue's worth per loop: where converting a frame takes longer than
                // the camera takes to make the next (a slow board, emulation, a loaded machine), "until none is
                // waiting" never ended, and the screen and the watchdog stood still (seconds under qemu).
                for (int i = 0; i < std::max(1, config.camera.bufferCount); ++i) {
                    auto frame = camera->nextFrame(std::chrono::milliseconds(lastPreview.empty() && i == 0 ? 30 : 0));
                    if (!frame) break;
                    lastPreview = frame->image;
                }
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
            // The figure is about the guides (the countdown analyses too, but its frames are not counted).
            const ScreenId shown = flow.screen().id;
            if (shown == ScreenId::FrontGuide || shown == ScreenId::SideGuide) ++analyses;
        }

        step.mark("camera");
        // The fit: started once the model is there and the analysis has let go of the detector.
        if (fitWanted && fitter.pipeline() && previews.release()) {
            (void)previews.take();
            dropSessionFolder();  // a retake: the earlier fit's folder goes
            fitter.submit(++fitJob, frontPhoto, sidePhoto);
            spdlog::info("fitting the photos (fit {})", fitJob);
            fitWanted = false;
        }
        if (auto stageName = fitter.takeStage()) events.push_back(FitProgress{stageProgress(*stageName), *stageName, now});
        if (auto result = fitter.takeResult()) {
            if (result->job != fitJob) {
                spdlog::info("a cancelled fit finished; its result is dropped");
            } else if (result->outcome) {
                // The reveal starts now; the character is made next (by the fitter) and the folder written behind.
                stage.show(result->outcome->fit.mesh, result->outcome->texture.texture);
                if (!toonStripFor.empty() && !styles->toonSettled())
                    spdlog::warn("the kept session {} goes without its toon strip: the next visitor came first",
                                 toonStripFor.filename().string());
                toonStripFor.clear();
                styles->visitor(styleInputsFrom(*result->outcome));
                styleJob = result->job;
                events.push_back(FitDone{now});
                pendingFolder = store.pendingPath();
                writeJob = result->job;
                written = Written::Writing;  // (the write itself starts once the character is made)
                awaitingCharacter = WriteAfterCharacter{result->job, result->outcome, pendingFolder};
            } else {
                spdlog::warn("fit failed: {}", result->error->what());
                events.push_back(fitFailureFor(*result->error, now));
            }
        }
        if (auto character = fitter.takeCharacter()) characterMade(*character);
        while (auto done = writer.take()) handleWritten(*done, now);

        // A kept session's toon strip, once the toon is drawn (the keep does not wait for it: the thanks screen shows
        // the code at once, and a toon slow to draw on a busy board must not hold the session back).
        if (!toonStripFor.empty() && styles->toonSettled()) addToonStrip();

        step.mark("fit");
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
            // Give back to the system the pages the session's images left free inside the heap (glibc returns only
            // the heap's top on its own): the attract screen then holds what the next visitor needs, not the
            // last one's high-water mark, and a long day shows no slow climb. A few milliseconds.
            const auto trimStart = std::chrono::steady_clock::now();
            malloc_trim(0);
            spdlog::debug("heap trimmed in {:.1f} ms", Seconds(std::chrono::steady_clock::now() - trimStart).count() * 1e3);
        }
        lamps.update(clock.now());

        step.mark("flow");
        // The screen.
        const auto drawStart = std::chrono::steady_clock::now();
        ScreenInputs inputs;
        const bool previewScreen = screen.id == ScreenId::FrontGuide || screen.id == ScreenId::SideGuide ||
                                   screen.id == ScreenId::Countdown;
        if (previewScreen) inputs.preview = lastPreview;
        const std::uint64_t rendersBefore = stage.renders(), stylesBefore = styles->version();
        if (screen.id == ScreenId::Reveal || screen.id == ScreenId::Attract) {
            // Rendered at the size it is shown (no rescaling), and only when the pose changes.
            const cv::Rect box = screens.avatarImageBoxes(screen.id, styleCount)[0];
            inputs.avatar = stage.frame(screen.id == ScreenId::Reveal, screen.sinceEntered, std::min(box.width, box.height));
            if (!ready) startupStep("first photo avatar rendered");
            styles->fill(inputs, screen.id == ScreenId::Reveal, screen.sinceEntered, screens.layout());
            // One version for every image shown: the screen is not composed again while none has changed.
            if (stage.version() != shownVersions.first || styles->version() != shownVersions.second) {
                shownVersions = {stage.version(), styles->version()};
                ++avatarsVersion;
            }
            inputs.avatarVersion = stage.version() == 0 ? 0 : avatarsVersion;
        }
        const bool rendered = stage.renders() != rendersBefore || styles->version() != stylesBefore;
        const auto renderEnd = std::chrono::steady_clock::now();
        step.mark("avatars");
        if (!ready) startupStep("first styles and stage band rendered");
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
            inputs.operatorInfo.lastFreed = lastFreed;
        }
        const cv::Mat& drawn = screens.draw(screen, inputs);
        const auto composeEnd = std::chrono::steady_clock::now();
        step.mark("screen");
        if (!ready) startupStep("first screen composed");
        display.present(drawn);
        const auto drawEnd = std::chrono::steady_clock::now();
        step.mark("present");
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
            revealFrameSeconds.add(Seconds(drawEnd - drawStart).count());
            if (rendered) revealRenderSeconds.add(Seconds(renderEnd - drawStart).count());
            revealComposeSeconds.add(Seconds(composeEnd - renderEnd).count());
            revealPresentSeconds.add(Seconds(drawEnd - composeEnd).count());
            if (sideTaken) {
                captureToReveal.add(Seconds(drawEnd - sideTakenAt).count());
                sideTaken = false;
            }
        }
        // A new screen, or another page of the operator menu, gets its own screenshot.
        if (screen.id != lastScreen || (screen.id == ScreenId::OperatorMenu && screen.menuPage != lastMenuPage)) {
            lastMenuPage = screen.menuPage;
            screenshotDue = !options.screenshots.empty();
            provisionalShot = -1;
        }
        // A screen's picture once it has what it shows: the preview on guides, the avatar on the reveal. A guide
        // whose first hint was not known yet (the first analysis is slow on a slow board) is taken again, under the
        // same name, once it is.
        const bool guide = screen.id == ScreenId::FrontGuide || screen.id == ScreenId::SideGuide;
        if (guide && (screen.id != lastScreen || screen.hint != lastHint))
            spdlog::info("{}: hint {}", toString(screen.id), toString(screen.hint));
        lastHint = screen.hint;
        const bool everythingShown = guide ? screen.hint != Hint::None : screen.id != ScreenId::Reveal || styles->complete();
        if (provisionalShot >= 0 && everythingShown) {
            writeScreenshot(options.screenshots, provisionalShot, screen, drawn, report, true);
            provisionalShot = -1;
        }
        const bool complete = (!previewScreen || (!inputs.preview.empty() && screen.sinceEntered >= Millis(700))) &&
                              // (every style drawn: the character always comes, made right after the fit; a toon
                              // still drawing after 2.5 s is pictured as it is)
                              (screen.id != ScreenId::Reveal ||
                               (!inputs.avatar.empty() && !styles->characterPending() &&
                                (styles->complete() || screen.sinceEntered >= Millis(2500)))) &&
                              (screen.id != ScreenId::Thanks || !screen.code.empty());
        lastScreen = screen.id;
        if (screenshotDue && complete) {
            if (!everythingShown) provisionalShot = screenshotIndex;
            writeScreenshot(options.screenshots, screenshotIndex++, screen, drawn, report);
            screenshotDue = false;
        }
        if (!ready) {
            sd_notify(0, "READY=1");
            ready = true;
            report.startupToReadySeconds = Seconds(std::chrono::steady_clock::now() - startup).count();
            spdlog::info("ready in {:.2f} s{}", report.startupToReadySeconds, simCamera ? " (simulated booth)" : "");
            watchdog.emplace();
        }

        step.mark("screenshots");
        step.reportIfSlow(toString(screen.id));
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
    report.sideCaptureToRevealSeconds = captureToReveal.median();
    report.revealFrameMilliseconds = 1000.0 * revealFrameSeconds.median();
    const StyleFigures figures = styles->figures();
    report.characterFrameMilliseconds = figures.characterMs;
    report.toonFrameMilliseconds = figures.toonMs;
    report.stageRenderMilliseconds = figures.stageMs;
    report.toonBuildSeconds = figures.toonBuildSeconds;
    report.styleFrames = figures.frames;
    report.characterRenders = figures.characterRenders;
    report.toonRenders = figures.toonRenders;
    report.stageRenders = figures.stageRenders;
    report.revealSlowestFrameMilliseconds = 1000.0 * revealFrameSeconds.slowest();
    report.revealRenderMilliseconds = 1000.0 * revealRenderSeconds.median();
    report.revealComposeMilliseconds = 1000.0 * revealComposeSeconds.median();
    report.revealPresentMilliseconds = 1000.0 * revealPresentSeconds.median();
    report.revealRenderedShare = revealFrameSeconds.empty() ? 0.0
        : static_cast<double>(revealRenderSeconds.count()) / static_cast<double>(revealFrameSeconds.count());
    report.avatarTriangles = stage.triangleCount();
    report.avatarSamples = stage.samples();
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    report.peakRssMegabytes = static_cast<double>(usage.ru_maxrss) / 1024.0;
    // Sessions being written: those kept are kept; nothing of a visitor still in the middle of a session stays.
    if (awaitingCharacter && std::find(keepJobs.begin(), keepJobs.end(), awaitingCharacter->job) != keepJobs.end()) {
        const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
        while (awaitingCharacter && std::chrono::steady_clock::now() < deadline) {
            if (auto character = fitter.takeCharacter()) characterMade(*character);
            else std::this_thread::sleep_for(std::chrono::milliseconds(20));
        }
    }
    writer.waitIdle();
    while (auto done = writer.take()) handleWritten(*done, FlowClock::now());
    dropSessionFolder();
    // The last kept session's toon strip: a run of N sessions waits for it (bounded); a stop or a closed window
    // does not (systemd's stop timeout), and the session stays complete without it.
    const bool stopped = (options.stop && options.stop->load()) || display.closeRequested();
    const auto toonDeadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!toonStripFor.empty() && !stopped && !styles->toonSettled() && std::chrono::steady_clock::now() < toonDeadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (!toonStripFor.empty() && styles->toonSettled()) addToonStrip();
    if (!toonStripFor.empty())
        spdlog::warn("the kept session {} goes without its toon strip: still drawing at the end",
                     toonStripFor.filename().string());
    return report;
}

}  // namespace avatarbooth
