// The kiosk's main loop and its worker threads (model loading + fitting, preview analysis).
#include "kiosk/kiosk.h"

#include "kiosk/avatar_stage.h"
#include "kiosk/session_writer.h"

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
#include "pipeline/fit_pipeline.h"
#include "screens/screens.h"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>


#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <deque>
#include <functional>
#include <mutex>
#include <random>

#include <malloc.h>
#include <sys/resource.h>
#include <thread>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;
using Seconds = std::chrono::duration<double>;

constexpr auto kFramePeriod = std::chrono::microseconds(33333);  // the screen's 30 fps
constexpr auto kReleaseAfter = std::chrono::milliseconds(120);    // a simulated press lasts this long
constexpr auto kRetentionEvery = std::chrono::minutes(10);
constexpr auto kWatchdogEvery = std::chrono::seconds(1);

std::optional<Button> buttonNamed(const std::string& name) {
    if (name == "start") return Button::Start;
    if (name == "retake") return Button::Retake;
    if (name == "service") return Button::Service;
    return std::nullopt;
}

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

// Loads the landmark model, then fits one job at a time on its own thread.
class FitWorker {
public:
    FitWorker(FitSettings settings, std::shared_ptr<const BaseHead> base, std::mutex& detectorMutex)
        : settings_(std::move(settings)), base_(std::move(base)), detectorMutex_(detectorMutex),
          thread_([this] { run(); }) {}
    ~FitWorker() {
        {
            std::lock_guard lock(mutex_);
            quit_ = true;
        }
        wake_.notify_all();
        thread_.join();
    }

    // The pipeline once the model has loaded (null before); its error if loading failed.
    const FitPipeline* pipeline() const {
        std::lock_guard lock(mutex_);
        return pipeline_.get();
    }
    std::optional<std::string> loadError() const {
        std::lock_guard lock(mutex_);
        return loadError_;
    }

    void submit(std::uint64_t job, cv::Mat front, cv::Mat side) {
        {
            std::lock_guard lock(mutex_);
            std::erase_if(jobs_, [](const Job& j) { return !j.frontOnly; });  // a queued fit is superseded
            jobs_.push_back(Job{job, std::move(front), std::move(side), false});
        }
        wake_.notify_all();
    }
    // Analyses the front photo now (landmarks, silhouette: about a third of the fit), while the visitor turns for
    // the side photo; the fit of this very photo then starts from it. No result is posted.
    void analyseFrontAhead(cv::Mat front) {
        {
            std::lock_guard lock(mutex_);
            jobs_.push_back(Job{0, std::move(front), cv::Mat(), true});
        }
        wake_.notify_all();
    }
    std::optional<FitResult> takeResult() {
        std::lock_guard lock(mutex_);
        std::optional<FitResult> r = std::move(result_);
        result_.reset();
        return r;
    }
    std::optional<std::string> takeStage() {
        std::lock_guard lock(mutex_);
        std::optional<std::string> s = std::move(stage_);
        stage_.reset();
        return s;
    }

private:
    struct Job {
        std::uint64_t id = 0;
        cv::Mat front, side;
        bool frontOnly = false;
    };

    void run() {
        try {
            auto pipeline = std::make_unique<FitPipeline>(settings_, *base_);
            spdlog::info("landmark model loaded in {:.2f} s", pipeline->modelLoadSeconds());
            std::lock_guard lock(mutex_);
            pipeline_ = std::move(pipeline);
        } catch (const std::exception& e) {
            spdlog::error("cannot load the landmark model: {}", e.what());
            std::lock_guard lock(mutex_);
            loadError_ = e.what();
            return;
        }
        std::optional<FrontAnalysis> ahead;  // of the last front photo analysed ahead
        for (;;) {
            Job job;
            {
                std::unique_lock lock(mutex_);
                wake_.wait(lock, [&] { return quit_ || !jobs_.empty(); });
                if (quit_) return;
                job = std::move(jobs_.front());
                jobs_.pop_front();
            }
            if (job.frontOnly) {
                ahead.reset();
                try {
                    std::lock_guard detector(detectorMutex_);
                    ahead = pipeline_->analyseFront(job.front, cv::Mat(), FitInputs{"front photo", "side photo", {}});
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
                    std::lock_guard detector(detectorMutex_);
                    *outcome = pipeline_->fit(
                        job.front, job.side, cv::Mat(), names,
                        [&](const std::string& stage) {
                            std::lock_guard lock(mutex_);
                            stage_ = stage;
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
            std::lock_guard lock(mutex_);
            result_ = std::move(result);
        }
    }

    FitSettings settings_;
    std::shared_ptr<const BaseHead> base_;
    std::mutex& detectorMutex_;
    mutable std::mutex mutex_;
    std::condition_variable wake_;
    std::unique_ptr<FitPipeline> pipeline_;
    std::optional<std::string> loadError_;
    std::deque<Job> jobs_;
    std::optional<FitResult> result_;
    std::optional<std::string> stage_;
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
    // Waits for an analysis in flight to end (before a fit takes the detector).
    void drain() {
        std::unique_lock lock(mutex_);
        pending_.reset();
        idle_.wait(lock, [&] { return !busy_; });
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
            idle_.notify_all();
        }
    }

    GuidanceSettings settings_;
    std::mutex& detectorMutex_;
    mutable std::mutex mutex_;
    std::condition_variable wake_, idle_;
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

void writeScreenshot(const fs::path& dir, int index, const ScreenModel& screen, const cv::Mat& frame,
                     KioskReport& report) {
    const char* page = "";
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage == OperatorPage::LastCodes) page = "_last_codes";
    if (screen.id == ScreenId::OperatorMenu && screen.menuPage == OperatorPage::FreeDisk) page = "_free_disk";
    char name[80];
    std::snprintf(name, sizeof name, "%02d_%s%s.png", index, toString(screen.id), page);
    const fs::path path = dir / name;
    try {
        writeFileAtomically(path, encodeImage(frame, ".png"));
        report.screenshots.push_back(path);
    } catch (const BoothError& e) {
        spdlog::warn("screenshot not written: {}", e.what());
    }
}

}  // namespace

KioskReport runKiosk(const BoothConfig& config, const KioskOptions& options) {
    const auto startup = std::chrono::steady_clock::now();
    // glibc gives each new thread's allocations their own arena (up to 8 per core); with the fit, writer, preview
    // and llvmpipe threads each keeping freed images in its own, the peak RSS of a session measured 43 MB higher
    // (425 against 382 MB) than with two arenas shared by all.
    mallopt(M_ARENA_MAX, 2);
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

    auto simControls = std::make_shared<SimCameraControls>();
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
    std::mutex detectorMutex;
    FitWorker fitter(config.fit.settings, configuredBaseHead(config.fit), detectorMutex);
    PreviewWorker previews(config.guidance, detectorMutex);
    bool detectorGiven = false;
    AvatarStage stage(config.animation);
    SessionWriter writer;  // after the fitter: it writes with the fitter's pipeline
    {
        // Before the first visitor, the attract screen turns the base head (skin-coloured, untextured).
        const auto base = configuredBaseHead(config.fit);
        stage.show(base->mesh, cv::Mat(8, 8, CV_8UC3, cv::Scalar(150, 170, 210)));
    }

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
    std::string cameraProblem;
    std::string sessionId;
    ScreenId lastScreen = flow.screen().id;
    OperatorPage lastMenuPage = OperatorPage::Menu;
    RetentionReport lastFreed;  // what the operator's last "free disk" removed (shown in the menu)
    bool screenshotDue = !options.screenshots.empty();
    int screenshotIndex = 0;
    std::vector<std::pair<Button, FlowTime>> releases;  // simulated presses to release
    auto lastRetention = std::chrono::steady_clock::now();
    // Benchmark figures.
    int guideFrames = 0, analyses = 0;
    double guideSeconds = 0.0;
    std::vector<double> revealFrameSeconds, captureToReveal, revealRenderSeconds, revealComposeSeconds,
        revealPresentSeconds;
    // (Plain time points with a flag: gcc 12 takes optional<time_point> for maybe-uninitialised here.)
    std::chrono::steady_clock::time_point sideTakenAt{}, lastGuideFrame{};
    bool sideTaken = false, inGuide = false;
    auto lastWatchdog = std::chrono::steady_clock::time_point{};
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
        if (written != Written::Writing) discardQuietly(pendingFolder);
        pendingFolder.clear();
        writeJob = 0;
        written = Written::None;
    };
    const auto keepSession = [&](const fs::path& folder, FlowTime now) {
        try {
            const std::string code = store.keep(folder, std::chrono::system_clock::now());
            spdlog::info("session kept as {}", code);
            report.keptCodes.push_back(code);
            events.push_back(SessionSaved{code, now});
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
                keepSession(done.folder, now);
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
                        keepSession(pendingFolder, now);
                    } else if (written == Written::Writing) {
                        // Kept as soon as it is written (the thanks screen shows the code then).
                        spdlog::info("the session is kept once its folder is written");
                        keepJobs.push_back(writeJob);
                    } else {
                        const std::string why = written == Written::Failed ? writeFailure : "no fitted avatar to keep";
                        spdlog::error("session not kept: {}", why);
                        events.push_back(SessionSaveFailed{why, now});
                    }
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
        for (const auto& c : commands) execute(c, now);
        commands.clear();

        // Buttons, keyboard, and the simulated visitor.
        if (board.keyboard)
            for (const auto& key : display.pollKeys()) board.keyboard->feed(key.key, key.pressed, key.time);
        while (auto e = board.buttons->poll(std::chrono::milliseconds(0))) {
            if (const auto b = buttonNamed(e->button)) {
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
        if (!problem.empty() && !previewFor) {
            // Lost while no preview runs (the camera-lost screen stops it): the reopening camera retries only when
            // asked for a frame, so ask (without waiting) until it is back.
            try {
                (void)camera->nextFrame(std::chrono::milliseconds(0));
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
            // The figure is about the guides (the countdown analyses too, but its frames are not counted).
            const ScreenId shown = flow.screen().id;
            if (shown == ScreenId::FrontGuide || shown == ScreenId::SideGuide) ++analyses;
        }

        // The fit: started once the model is there and the analysis has let go of the detector.
        if (fitWanted && fitter.pipeline()) {
            previews.drain();
            (void)previews.take();
            dropSessionFolder();  // a retake: the earlier fit's folder goes
            fitter.submit(++fitJob, frontPhoto, sidePhoto);
            spdlog::info("fitting");
            fitWanted = false;
        }
        if (auto stageName = fitter.takeStage()) events.push_back(FitProgress{stageProgress(*stageName), *stageName, now});
        if (auto result = fitter.takeResult()) {
            if (result->job != fitJob) {
                spdlog::info("a cancelled fit finished; its result is dropped");
            } else if (result->outcome) {
                // The reveal starts now; the folder is written behind it.
                stage.show(result->outcome->fit.mesh, result->outcome->texture.texture);
                events.push_back(FitDone{now});
                if (const FitPipeline* p = fitter.pipeline()) {
                    pendingFolder = store.pendingPath();
                    writeJob = result->job;
                    written = Written::Writing;
                    writer.submit(result->job, result->outcome, p, pendingFolder);
                }
            } else {
                spdlog::warn("fit failed: {}", result->error->what());
                events.push_back(fitFailureFor(*result->error, now));
            }
        }
        while (auto done = writer.take()) handleWritten(*done, now);

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
        const std::uint64_t rendersBefore = stage.renders();
        if (screen.id == ScreenId::Reveal || screen.id == ScreenId::Attract) {
            // Rendered at the size it is shown (no rescaling), and only when the pose changes.
            const cv::Rect box = screens.avatarBox(screen.id);
            inputs.avatar = stage.frame(screen.id == ScreenId::Reveal, screen.sinceEntered, std::min(box.width, box.height));
            inputs.avatarVersion = stage.version();
        }
        const auto renderEnd = std::chrono::steady_clock::now();
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
            if (stage.renders() != rendersBefore) revealRenderSeconds.push_back(Seconds(renderEnd - drawStart).count());
            revealComposeSeconds.push_back(Seconds(composeEnd - renderEnd).count());
            revealPresentSeconds.push_back(Seconds(drawEnd - composeEnd).count());
            if (sideTaken) {
                captureToReveal.push_back(Seconds(drawEnd - sideTakenAt).count());
                sideTaken = false;
            }
        }
        // A new screen, or another page of the operator menu, gets its own screenshot.
        if (screen.id != lastScreen || (screen.id == ScreenId::OperatorMenu && screen.menuPage != lastMenuPage)) {
            lastScreen = screen.id;
            lastMenuPage = screen.menuPage;
            screenshotDue = !options.screenshots.empty();
        }
        // A screen's picture once it has what it shows: the preview on guides, the avatar on the reveal.
        const bool complete = (!previewScreen || (!inputs.preview.empty() && screen.sinceEntered >= Millis(700))) &&
                              (screen.id != ScreenId::Reveal || !inputs.avatar.empty()) &&
                              (screen.id != ScreenId::Thanks || !screen.code.empty());
        if (screenshotDue && complete) {
            writeScreenshot(options.screenshots, screenshotIndex++, screen, drawn, report);
            screenshotDue = false;
        }
        if (!ready) {
            sd_notify(0, "READY=1");
            ready = true;
            report.startupToReadySeconds = Seconds(std::chrono::steady_clock::now() - startup).count();
            spdlog::info("ready in {:.2f} s{}", report.startupToReadySeconds, simCamera ? " (simulated booth)" : "");
        }

        // Housekeeping: watchdog, retention.
        const auto wall = std::chrono::steady_clock::now();
        if (wall - lastWatchdog >= kWatchdogEvery) {
            sd_notify(0, "WATCHDOG=1");
            lastWatchdog = wall;
        }
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
    report.guideFramesPerSecond = guideSeconds > 0.0 ? guideFrames / guideSeconds : 0.0;
    report.analysesPerSecond = guideSeconds > 0.0 ? analyses / guideSeconds : 0.0;
    report.sideCaptureToRevealSeconds = median(captureToReveal);
    report.revealFrameMilliseconds = 1000.0 * median(revealFrameSeconds);
    report.revealSlowestFrameMilliseconds =
        revealFrameSeconds.empty() ? 0.0 : 1000.0 * *std::max_element(revealFrameSeconds.begin(), revealFrameSeconds.end());
    report.revealRenderMilliseconds = 1000.0 * median(revealRenderSeconds);
    report.revealComposeMilliseconds = 1000.0 * median(revealComposeSeconds);
    report.revealPresentMilliseconds = 1000.0 * median(revealPresentSeconds);
    report.revealRenderedShare = revealFrameSeconds.empty() ? 0.0
        : static_cast<double>(revealRenderSeconds.size()) / static_cast<double>(revealFrameSeconds.size());
    report.avatarTriangles = stage.triangleCount();
    report.avatarSamples = stage.samples();
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    report.peakRssMegabytes = static_cast<double>(usage.ru_maxrss) / 1024.0;
    // Sessions being written: those kept are kept; nothing of a visitor still in the middle of a session stays.
    writer.waitIdle();
    while (auto done = writer.take()) handleWritten(*done, FlowClock::now());
    dropSessionFolder();
    return report;
}

}  // namespace avatarbooth
