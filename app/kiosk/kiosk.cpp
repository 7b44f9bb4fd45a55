// The kiosk's main loop: devices and workers in, the visitor flow and the session lifecycle in the middle, one
// screen per frame out.
#include "kiosk/kiosk.h"

#include "booth/session_lifecycle.h"
#include "booth/session_store.h"
#include "booth/share_link.h"
#include "booth/visitor_flow.h"
#include "booth/screens/screens.h"
#include "common/error.h"
#include "drivers/camera/camera_factory.h"
#include "drivers/display/display_factory.h"
#include "drivers/display/headless_egl.h"
#include "common/clock.h"
#include "drivers/gpio/lamps.h"
#include "kiosk/booth_sounds.h"
#include "kiosk/fit_worker.h"
#include "kiosk/kiosk_figures.h"
#include "kiosk/kiosk_inputs.h"
#include "kiosk/preview_worker.h"
#include "kiosk/print_worker.h"
#include "kiosk/screenshots.h"
#include "kiosk/session_writer.h"
#include "kiosk/style_worker.h"
#include "kiosk/turntable_worker.h"
#include "kiosk/watchdog.h"
#include "reveal/character/character_outputs.h"
#include "reveal/styles/reveal_styles.h"

#include <spdlog/spdlog.h>
#include <systemd/sd-daemon.h>

#include <opencv2/core/utility.hpp>

#include <deque>
#include <random>

#include <malloc.h>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;
using Seconds = std::chrono::duration<double>;
using SteadyClockTime = std::chrono::steady_clock::time_point;

constexpr auto kFramePeriod = std::chrono::microseconds(33333);  // the screen's 30 fps
constexpr auto kEndWait = std::chrono::seconds(60);  // a run of N sessions waits this long for a kept one's parts

// How a failed fit is told to the visitor, and which photo it asks for again: the fit error's own fields.
FitFailed fitFailureFor(const FitError& e, FlowTime t) {
    const RetakeWhich retake = e.photo() == FitPhoto::Front  ? RetakeWhich::Front
                               : e.photo() == FitPhoto::Side ? RetakeWhich::Side
                                                             : RetakeWhich::Both;
    FitFailure reason = FitFailure::Other;
    switch (e.fault()) {
        case FitFault::NoFace: reason = FitFailure::NoFace; break;
        case FitFault::NotProfile: reason = FitFailure::NotProfile; break;
        case FitFault::TurnMore: reason = FitFailure::TurnMore; break;
        case FitFault::TurnBack: reason = FitFailure::TurnBack; break;
        case FitFault::FaceHidden: reason = FitFailure::FaceHidden; break;
        case FitFault::Mismatch: reason = FitFailure::Mismatch; break;
        case FitFault::Other: break;
    }
    return FitFailed{retake, reason, e.what(), t};
}

// spdlog pattern with the visitor session's id on every line ("-" between sessions).
void setLogSession(const std::string& id) {
    spdlog::set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] [session " + (id.empty() ? std::string("-") : id) + "] %v");
}

std::string newSessionId() {
    static thread_local std::mt19937 random(std::random_device{}());
    static constexpr const char* kDigits = "0123456789abcdef";
    std::string id;
    for (int i = 0; i < 8; ++i) id += kDigits[random() % 16];
    return id;
}

LampPattern patternOf(LampMode mode, Clock& clock) {
    switch (mode) {
        case LampMode::Off: return LampPattern::off();
        case LampMode::On: return LampPattern::steady();
        case LampMode::SlowBlink: return LampPattern::blink(std::chrono::milliseconds(1000), clock.now());
        case LampMode::FastBlink: return LampPattern::blink(std::chrono::milliseconds(250), clock.now());
    }
    return LampPattern::off();
}

class Kiosk {
public:
    Kiosk(const BoothConfig& config, const KioskOptions& options, SteadyClockTime startup);
    KioskReport run();

private:
    void note(const std::string& line) {
        spdlog::info("{}", line);
        report_.devices.push_back(line);
    }
    void startupStep(const char* what) const {
        spdlog::debug("start-up: {} after {:.3f} s", what, Seconds(std::chrono::steady_clock::now() - startup_).count());
    }
    void pollCamera(FlowTime now);
    void watchDisplay();
    void startFitWhenFree();
    void handle(const KioskMessage& message, FlowTime now);
    void execute(const FlowCommand& command, FlowTime now);
    void runSession(const std::vector<session::Command>& commands, FlowTime now);
    void runFlow(FlowTime now);
    const cv::Mat& drawScreen(const ScreenModel& screen, KioskFigures::Frame& timing);
    void markReady();
    void waitForMessages(SteadyClockTime until);
    void finish();

    const BoothConfig& config_;
    const KioskOptions& options_;
    const SteadyClockTime startup_;
    KioskReport report_;

    // Devices (the display first, so that whatever goes wrong later can be shown).
    OpenedDisplay opened_;
    Display& display_;
    // Made again when the screen comes back with another size (layOutForDisplay).
    std::unique_ptr<ScreenRenderer> screens_;
    std::shared_ptr<SimCameraControls> simControls_;
    std::unique_ptr<ReopeningCamera> camera_;
    SteadyClock clock_;
    ButtonBoard board_;
    LampDriver lamps_;
    KioskInputs inputs_;
    SessionStore store_;

    // Workers, all posting to one queue.
    std::shared_ptr<const BaseHead> base_;
    KioskQueue queue_;
    std::shared_ptr<std::mutex> detectorMutex_ = std::make_shared<std::mutex>();
    FitWorker fitter_;
    PreviewWorker previews_;
    SessionWriter writer_;
    // One GL context for every offscreen render of the main thread (the styles and the stage): each llvmpipe
    // context costs memory and threads of its own.
    HeadlessEglContext offscreen_;
    RevealStyles styles_;
    StyleWorker styleWorker_;  // after the styles: its work posts to them, it ends first
    std::optional<PrintWorker> printer_;  // [print] on: each kept session's card
    std::unique_ptr<BoothSounds> sounds_;  // null: silent ([sound] off, no sound card)
    std::optional<TurntableWorker> turntables_;  // [share] on: each kept session's turntable.webp
    std::optional<WatchdogPinger> watchdog_;  // from READY on

    // The visitor.
    VisitorFlow flow_;
    SessionLifecycle lifecycle_;
    std::deque<FlowEvent> events_;
    std::vector<FlowCommand> commands_;
    const FitPipeline* pipeline_ = nullptr;  // once the model has loaded
    cv::Mat frontPhoto_, sidePhoto_, lastPreview_;
    std::optional<Photo> previewFor_;
    std::uint64_t fitJob_ = 0;  // the fit the visitor waits for; any other's result is dropped
    bool fitWanted_ = false;    // StartFit received, waiting for the preview analysis to let go of the detector
    std::string cameraProblem_;
    cv::Size displaySizeSeen_;  // the display's size when last looked at (a new one is laid out once)
    Hint lastHint_ = Hint::None;
    RetentionReport lastRetention_, lastFreed_;  // the last retention run, and the operator's last "free disk"
    int leftoversRemoved_ = 0;                   // by the last RemoveLeftovers
    // The printer: its last news for the operator menu, and a kept session whose card waits for its toon strip
    // (the card shows the toon: printed once the strip is written, or without it when the toon never comes).
    std::string printerNews_;
    bool printerProblem_ = false;
    std::optional<PrintCard> cardAfterExtras_;
    void printCard(PrintCard card);
    Screenshots screenshots_;
    KioskFigures figures_;
    bool ready_ = false;
};

Kiosk::Kiosk(const BoothConfig& config, const KioskOptions& options, SteadyClockTime startup)
    : config_(config), options_(options), startup_(startup), opened_(createDisplay(config.display)),
      display_(*opened_.display),
      screens_(std::make_unique<ScreenRenderer>([&] {
          ScreenSettings s = config.screen;
          s.size = display_.size();
          return s;
      }())),
      simControls_(options.simControls ? options.simControls : std::make_shared<SimCameraControls>()),
      camera_(openReopeningCamera(config.camera, CameraEnvironment{simControls_, nullptr})),
      board_(openButtonBoard(config.buttons, clock_)), lamps_(*board_.lamps),
      inputs_(board_, display_, options.visitor, simControls_), store_(config.sessions),
      base_(configuredBaseHead(config.fit)),
      fitter_(config.fit.settings, base_,
              config.character.enabled ? std::optional(config.character.settings) : std::nullopt, detectorMutex_,
              queue_),
      previews_(config.guidance, *detectorMutex_, queue_), writer_(config.fit.previewSize, queue_),
      styles_(config.reveal, config.stage, config.animation, *base_, &offscreen_), styleWorker_(queue_),
      flow_(config.flow, FlowClock::now()),
      lifecycle_([this] { return store_.pendingPath(); }, styles_.hasExtras()),
      screenshots_(options.screenshots) {
    if (!config.file.empty()) note("config: " + config.file.string());
    else note("config: none given, built-in defaults");
    note(opened_.description);
    note("camera: " + camera_->describe().summary());
    note("buttons: " + board_.description);
    note("sessions: " + config.sessions.directory.string());
    report_.sessionsDirectory = config.sessions.directory;
    {
        std::string said;
        sounds_ = BoothSounds::open(config.sound, said);
        note("sound: " + said);
    }
    if (config.share.enabled) turntables_.emplace(queue_);
    if (config.print.enabled) {
        printer_.emplace(config.print, queue_);
        printerNews_ = "on, queue " + (config.print.queue.empty() ? std::string("(CUPS default)") : config.print.queue);
        note("print: " + printerNews_);
    }
    startupStep("devices, workers and styles made");
    commands_ = flow_.initialCommands();
}

KioskReport Kiosk::run() {
    runSession(lifecycle_.handle(session::Started{std::chrono::steady_clock::now()}), FlowClock::now());
    startupStep("leftovers removed, retention applied");
    for (auto nextFrame = std::chrono::steady_clock::now();; nextFrame += kFramePeriod) {
        if (options_.stop && options_.stop->load()) break;
        const FlowTime now = FlowClock::now();
        StepTimer step;
        for (const auto& c : std::exchange(commands_, {})) execute(c, now);
        step.mark("commands");
        for (auto& e : inputs_.poll(flow_.screen(), now)) events_.push_back(std::move(e));
        step.mark("buttons");
        pollCamera(now);
        step.mark("camera");
        startFitWhenFree();
        // A kept session's extras (the toon strip), once drawn: the keep does not wait for them.
        if (lifecycle_.styleExtrasAwaited() && styles_.settled())
            runSession(lifecycle_.handle(session::StylesSettled{}), now);
        runSession(lifecycle_.handle(session::TimePassed{std::chrono::steady_clock::now()}), now);
        step.mark("fit");
        runFlow(now);
        if (sounds_) sounds_->screen(flow_.screen(), now);  // as of this loop step, when the screen changed
        lamps_.update(clock_.now());
        step.mark("flow");

        watchDisplay();  // before drawing: a new layout replaces the image the last screen was drawn into
        const ScreenModel& screen = flow_.screen();
        KioskFigures::Frame timing{screen.id, std::chrono::steady_clock::now(), {}, {}, {}, false, false};
        const cv::Mat& drawn = drawScreen(screen, timing);
        step.mark("screen");
        display_.present(drawn);
        timing.presented = std::chrono::steady_clock::now();
        figures_.frame(timing);
        step.mark("present");

        if (isGuide(screen.id) && screen.hint != lastHint_) spdlog::info("{}: hint {}", toString(screen.id), toString(screen.hint));
        lastHint_ = isGuide(screen.id) ? screen.hint : Hint::None;
        // Pictured once it has what it shows: the preview on guides (and its first hint, else taken again), every
        // style on the reveal (the character always comes; a toon still drawing after 2.5 s is pictured as it is).
        const bool previewScreen = isGuide(screen.id) || screen.id == ScreenId::Countdown;
        const bool everything = isGuide(screen.id) ? screen.hint != Hint::None
                                                   : screen.id != ScreenId::Reveal || styles_.complete();
        const bool complete =
            (!previewScreen || (!lastPreview_.empty() && screen.sinceEntered >= Millis(700))) &&
            (screen.id != ScreenId::Reveal ||
             (styles_.photoShown() && !styles_.awaitingSoon() && (styles_.complete() || screen.sinceEntered >= Millis(2500)))) &&
            (screen.id != ScreenId::Thanks || !screen.code.empty());
        screenshots_.frame(screen, drawn, complete, everything);
        markReady();
        step.mark("screenshots");
        step.reportIfSlow(toString(screen.id));
        watchdog_->alive();
        if (options_.sessions > 0 && report_.sessionsEnded >= options_.sessions) break;
        if (display_.closeRequested()) break;
        waitForMessages(nextFrame + kFramePeriod);
        if (std::chrono::steady_clock::now() > nextFrame + 4 * kFramePeriod) nextFrame = std::chrono::steady_clock::now();
    }
    finish();
    return std::move(report_);
}

// The camera's state, and the newest preview frame for the guide and its analysis.
void Kiosk::pollCamera(FlowTime now) {
    const std::string problem = camera_->status().message;
    if (problem != cameraProblem_) {
        if (!problem.empty()) {
            spdlog::warn("{}", problem);
            events_.push_back(CameraLost{problem, now});
        } else {
            spdlog::info("camera back: {}", camera_->describe().summary());
            events_.push_back(CameraBack{now});
        }
        cameraProblem_ = problem;
    }
    if (!previewFor_ && !cameraProblem_.empty()) {
        // A lost camera is reopened by ReopeningCamera's calls; with no preview running (the camera-lost and
        // attract screens stop it) nothing would call it, and the booth would never see the camera come back.
        try {
            (void)camera_->nextFrame(std::chrono::milliseconds(0));
            if (camera_->status().ok) camera_->stop();
        } catch (const BoothError& e) {
            spdlog::debug("camera retry: {}", e.what());
        }
    }
    if (!previewFor_) return;
    try {
        // The newest frame, but at most a queue's worth per loop: where converting a frame takes longer than the
        // camera takes to make the next (a slow board, emulation, a loaded machine), "until none is waiting" never
        // ended, and the screen and the watchdog stood still.
        for (int i = 0; i < std::max(1, config_.camera.bufferCount); ++i) {
            auto frame = camera_->nextFrame(std::chrono::milliseconds(lastPreview_.empty() && i == 0 ? 30 : 0));
            if (!frame) break;
            lastPreview_ = frame->image;
        }
    } catch (const BoothError& e) {
        spdlog::debug("preview: {}", e.what());
    }
    if (!lastPreview_.empty() && !fitWanted_) previews_.offer(*previewFor_, lastPreview_, now);
}

// The screen coming back with another size (a new monitor, or the first one after waiting at the configured size):
// the screens are laid out for it once. Its loss and return are ReopeningDisplay's to log; while it is away the
// frames presented are dropped and everything else goes on.
void Kiosk::watchDisplay() {
    const cv::Size size = display_.size();
    if (displaySizeSeen_.empty()) displaySizeSeen_ = screens_->settings().size;
    if (size == displaySizeSeen_) return;
    displaySizeSeen_ = size;
    const cv::Size before = screens_->settings().size;
    if (size == before) return;
    ScreenSettings settings = screens_->settings();
    settings.size = size;
    try {
        screens_ = std::make_unique<ScreenRenderer>(std::move(settings));
        spdlog::info("the screen is now {}x{} (was {}x{}): the screens are laid out for it", size.width, size.height,
                     before.width, before.height);
    } catch (const BoothError& e) {
        // A screen the layout cannot use (under 320x240) keeps the old layout, scaled by the display to fit.
        spdlog::warn("the screen is now {}x{}, but the screens cannot be laid out for it ({}): they are drawn at {}x{} "
                     "and scaled to fit", size.width, size.height, e.what(), before.width, before.height);
    }
}

// The fit starts once the model is there and the preview analysis has let go of the detector.
void Kiosk::startFitWhenFree() {
    if (!fitWanted_ || !pipeline_ || !previews_.release()) return;
    fitWanted_ = false;
    ++fitJob_;
    runSession(lifecycle_.handle(session::FitSubmitted{fitJob_}), FlowClock::now());
    fitter_.submit(fitJob_, frontPhoto_, sidePhoto_);
    spdlog::info("fitting the photos (fit {})", fitJob_);
}

void Kiosk::handle(const KioskMessage& message, FlowTime now) {
    std::visit(
        [&](const auto& m) {
            using T = std::decay_t<decltype(m)>;
            if constexpr (std::is_same_v<T, ModelLoaded>) {
                if (!m.pipeline) throw BoothError(ErrorKind::BadConfig, config_.fit.settings.landmarkModel.string(), m.error);
                pipeline_ = m.pipeline;
                previews_.setDetector(&pipeline_->detector());
            } else if constexpr (std::is_same_v<T, FitStepStarted>) {
                if (m.job == fitJob_) events_.push_back(FitProgress{m.step, now});
            } else if constexpr (std::is_same_v<T, FitEnded>) {
                if (m.job != fitJob_) {
                    spdlog::info("a cancelled fit finished; its result is dropped");
                } else if (m.outcome) {
                    // The reveal starts now; the character is made next (by the fitter) and the folder written behind.
                    styleWorker_.submit(styles_.visitor(*m.outcome));
                    events_.push_back(FitDone{now});
                    runSession(lifecycle_.handle(session::Fitted{m.job, m.outcome}), now);
                } else {
                    spdlog::warn("fit failed: {}", m.error->what());
                    events_.push_back(fitFailureFor(*m.error, now));
                }
            } else if constexpr (std::is_same_v<T, CharacterEnded>) {
                if (m.error) spdlog::warn("no character for this visitor: {}", *m.error);
                if (m.job == fitJob_) styles_.visitorCharacter(m.character.get());
                runSession(lifecycle_.handle(session::CharacterMade{m.job, m.character}), now);
            } else if constexpr (std::is_same_v<T, PreviewEnded>) {
                events_.push_back(m.analysed);
                figures_.analysed(flow_.screen().id);
            } else if constexpr (std::is_same_v<T, StyleWorkEnded>) {
                m.apply();
            } else if constexpr (std::is_same_v<T, PrintStatus>) {
                // The booth goes on whatever the printer says: the operator sees it in the menu and the log.
                if (m.problem) spdlog::warn("print: {}", m.line);
                else spdlog::info("print: {}", m.line);
                printerNews_ = m.line;
                printerProblem_ = m.problem;
            } else if constexpr (std::is_same_v<T, TurntableEnded>) {
                if (m.error)
                    spdlog::warn("the kept session {} goes without its turntable picture: {}",
                                 m.keptFolder.filename().string(), *m.error);
                else
                    spdlog::info("turntable.webp added to the kept session {}: {} KB, rendered in {:.2f} s, encoded in "
                                 "{:.2f} s", m.keptFolder.filename().string(), m.bytes / 1024, m.renderSeconds,
                                 m.encodeSeconds);
            } else if constexpr (std::is_same_v<T, FolderEnded>) {
                if (m.error) spdlog::error("the session folder was not written: {}", m.error->what());
                else spdlog::info("session folder written in {:.2f} s", m.seconds);
                std::optional<std::string> error;
                if (m.error) error = m.error->what();
                runSession(lifecycle_.handle(session::FolderWritten{m.job, m.folder, error, now}), now);
            }
        },
        message);
}

void Kiosk::execute(const FlowCommand& command, FlowTime now) {
    spdlog::debug("command {}", describe(command));
    std::visit(
        [&](const auto& c) {
            using T = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<T, StartPreview>) {
                if (previewFor_ != c.photo) lastPreview_.release();  // never show the other pose's last frame
                previewFor_ = c.photo;
                try {
                    camera_->start();
                } catch (const BoothError& e) {
                    spdlog::warn("camera: {}", e.what());
                }
            } else if constexpr (std::is_same_v<T, StopPreview>) {
                previewFor_.reset();
            } else if constexpr (std::is_same_v<T, CapturePhoto>) {
                try {
                    CameraFrame still = camera_->captureStill();
                    (c.photo == Photo::Front ? frontPhoto_ : sidePhoto_) = still.image;
                    spdlog::info("{} photo taken: {}x{}", c.photo == Photo::Front ? "front" : "side", still.image.cols,
                                 still.image.rows);
                    events_.push_back(CaptureDone{c.photo, now});
                    if (c.photo == Photo::Front && pipeline_) fitter_.analyseFrontAhead(frontPhoto_);
                    if (c.photo == Photo::Side) figures_.sidePhotoTaken(std::chrono::steady_clock::now());
                } catch (const std::exception& e) {
                    spdlog::warn("capture failed: {}", e.what());
                    events_.push_back(CaptureFailed{c.photo, e.what(), now});
                }
            } else if constexpr (std::is_same_v<T, StartFit>) {
                fitWanted_ = true;
            } else if constexpr (std::is_same_v<T, CancelFit>) {
                fitter_.cancel(fitJob_);
                ++fitJob_;  // whatever it still posts is dropped
                fitWanted_ = false;
            } else if constexpr (std::is_same_v<T, SaveSession>) {
                runSession(lifecycle_.handle(session::KeepAsked{now}), now);
            } else if constexpr (std::is_same_v<T, DiscardSession>) {
                runSession(lifecycle_.handle(session::DiscardAsked{}), now);
                frontPhoto_.release();
                sidePhoto_.release();
                fitter_.cancel(fitJob_);
                ++fitJob_;
                spdlog::info("session discarded: nothing of it is kept");
            } else if constexpr (std::is_same_v<T, SetLamps>) {
                for (const auto& name : board_.lamps->names()) {
                    if (name == "start") lamps_.setPattern(name, patternOf(c.lamps.start, clock_));
                    else if (name == "retake") lamps_.setPattern(name, patternOf(c.lamps.retake, clock_));
                    else if (name == "flash") lamps_.setPattern(name, patternOf(c.lamps.flash, clock_));
                }
            } else if constexpr (std::is_same_v<T, FreeDisk>) {
                // Leftovers are every pending folder: a session still being written must be finished first.
                writer_.waitIdle();
                waitForMessages(std::chrono::steady_clock::now());
                runSession(lifecycle_.handle(session::FreeDiskAsked{}), now);
                lastFreed_ = lastRetention_;
                spdlog::info("operator freed disk: {} photos, {} sessions, {} leftovers, {} bytes", lastFreed_.photosDeleted,
                             lastFreed_.sessionsDeleted, leftoversRemoved_, lastFreed_.bytesFreed);
            }
        },
        command);
}

void Kiosk::runSession(const std::vector<session::Command>& commands, FlowTime now) {
    for (const auto& command : commands) {
        spdlog::debug("session command {}", session::describe(command));
        std::visit(
            [&](const auto& c) {
                using T = std::decay_t<decltype(c)>;
                if constexpr (std::is_same_v<T, session::WriteFolder>) {
                    writer_.submit(c);
                } else if constexpr (std::is_same_v<T, session::KeepFolder>) {
                    session::KeepDone done{c.job, c.folder, {}, {}, {}, now};
                    try {
                        done.code = store_.keep(c.folder, std::chrono::system_clock::now());
                        if (const auto kept = store_.find(done.code)) done.keptFolder = *kept;
                        // The visitor's page, for the QR code on the thanks screen (only when sharing is on).
                        if (config_.share.enabled)
                            if (const auto token = readShareToken(done.keptFolder))
                                done.shareUrl = sharePageUrl(config_.share, *token);
                    } catch (const BoothError& e) {
                        done.error = e.what();
                    }
                    // Keep prints when printing is on: once the toon strip is in the session (WriteStyleExtras,
                    // perhaps run by this very handle()), or now when no strip is coming.
                    if (printer_ && done.error.empty()) {
                        // An earlier visitor's card still waiting for its toon goes now, without it.
                        if (cardAfterExtras_) printCard(*std::exchange(cardAfterExtras_, {}));
                        cardAfterExtras_ = PrintCard{done.keptFolder, done.code, done.shareUrl};
                    }
                    // The visitor's page gets its turntable picture, made behind the thanks screen.
                    if (turntables_ && done.error.empty()) turntables_->submit(done.keptFolder);
                    runSession(lifecycle_.handle(done), now);
                    if (cardAfterExtras_ && !lifecycle_.styleExtrasAwaited()) printCard(*std::exchange(cardAfterExtras_, {}));
                } else if constexpr (std::is_same_v<T, session::DiscardFolder>) {
                    try {
                        store_.discard(c.folder);
                    } catch (const BoothError& e) {
                        spdlog::error("discarding {}: {}", c.folder.string(), e.what());
                    }
                } else if constexpr (std::is_same_v<T, session::WriteStyleExtras>) {
                    try {
                        if (styles_.writeInto(c.keptFolder))
                            spdlog::info("toon strip added to the kept session {}", c.keptFolder.filename().string());
                    } catch (const BoothError& e) {
                        spdlog::error("the kept session {} goes without its toon strip: {}",
                                      c.keptFolder.filename().string(), e.what());
                    }
                    if (cardAfterExtras_ && cardAfterExtras_->keptFolder == c.keptFolder)
                        printCard(*std::exchange(cardAfterExtras_, {}));
                } else if constexpr (std::is_same_v<T, session::TellFlow>) {
                    if (const auto* saved = std::get_if<SessionSaved>(&c.event)) {
                        ++report_.sessionsKept;
                        report_.keptCodes.push_back(saved->code);
                        if (report_.keptCodes.size() > KioskReport::kKeptCodesListed) report_.keptCodes.pop_front();
                    }
                    events_.push_back(c.event);
                } else if constexpr (std::is_same_v<T, session::RemoveLeftovers>) {
                    leftoversRemoved_ = store_.removeLeftovers();
                    if (leftoversRemoved_ > 0 && !ready_)
                        spdlog::warn("removed {} unfinished session folder(s) left by an earlier run", leftoversRemoved_);
                } else if constexpr (std::is_same_v<T, session::ApplyRetention>) {
                    lastRetention_ = store_.applyRetention(std::chrono::system_clock::now());
                    if (lastRetention_.photosDeleted || lastRetention_.sessionsDeleted)
                        spdlog::info("retention: deleted {} photos and {} sessions ({} bytes)",
                                     lastRetention_.photosDeleted, lastRetention_.sessionsDeleted,
                                     lastRetention_.bytesFreed);
                }
            },
            command);
    }
}

// The flow: every event, then a tick for the timeouts and the countdown; a session's start and end.
void Kiosk::runFlow(FlowTime now) {
    events_.push_back(Tick{now});
    const ScreenId before = flow_.screen().id;
    while (!events_.empty()) {
        const FlowEvent e = std::move(events_.front());
        events_.pop_front();
        for (auto& c : flow_.handle(e)) commands_.push_back(std::move(c));
    }
    const ScreenId after = flow_.screen().id;
    if (before == ScreenId::Attract && after != ScreenId::Attract) {
        setLogSession(newSessionId());
        spdlog::info("a visitor started a session");
    }
    if (before != ScreenId::Attract && after == ScreenId::Attract) {
        ++report_.sessionsEnded;
        spdlog::info("session ended ({} so far)", report_.sessionsEnded);
        setLogSession("");
        // Give back to the system the pages the session's images left free inside the heap (glibc returns only the
        // heap's top on its own): the attract screen then holds what the next visitor needs, not the last one's
        // high-water mark.
        malloc_trim(0);
    }
}

const cv::Mat& Kiosk::drawScreen(const ScreenModel& screen, KioskFigures::Frame& timing) {
    ScreenInputs inputs;
    if (isGuide(screen.id) || screen.id == ScreenId::Countdown) inputs.preview = lastPreview_;
    const std::uint64_t stylesBefore = styles_.version();
    if (screen.id == ScreenId::Reveal || screen.id == ScreenId::Attract) {
        // Each style rendered at the size it is shown (no rescaling), and only when its pose changes.
        std::vector<int> sizes;
        for (const cv::Rect& box : screens_->avatarImageBoxes(screen.id, static_cast<int>(config_.reveal.styles.size())))
            sizes.push_back(std::max(64, std::min(box.width, box.height)));
        StyleImages images;
        styles_.fill(images, screen.id == ScreenId::Reveal, screen.sinceEntered, sizes, screens_->layout().stage.size());
        inputs.avatars = std::move(images.avatars);
        inputs.stage = std::move(images.stage);
        // One version for every image shown: the screen is not composed again while none has changed.
        inputs.avatarVersion = styles_.version();
        timing.avatarShown = styles_.photoShown();
        if (!ready_) startupStep("first styles and stage band rendered");
    }
    timing.rendered = styles_.version() != stylesBefore;
    timing.renderEnd = std::chrono::steady_clock::now();
    if (screen.id == ScreenId::RetakeChoice) {
        inputs.frontPhoto = frontPhoto_;
        inputs.sidePhoto = sidePhoto_;
    }
    if (screen.id == ScreenId::OperatorMenu) {
        const std::vector<StoredSession> stored = store_.list();
        for (const auto& s : stored) {
            if (inputs.operatorInfo.recentCodes.size() >= 10) break;
            inputs.operatorInfo.recentCodes.emplace_back(s.code, s.keptAt);
        }
        inputs.operatorInfo.sessionsStored = static_cast<int>(stored.size());
        inputs.operatorInfo.freeBytes = store_.freeBytes();
        inputs.operatorInfo.lastFreed = lastFreed_;
        inputs.operatorInfo.printer = printerNews_;
        inputs.operatorInfo.printerProblem = printerProblem_;
        if (opened_.reopening) inputs.operatorInfo.screenRecoveries = opened_.reopening->status().recoveries;
    }
    const cv::Mat& drawn = screens_->draw(screen, inputs);
    timing.composeEnd = std::chrono::steady_clock::now();
    if (!ready_) startupStep("first screen composed");
    return drawn;
}

void Kiosk::markReady() {
    if (ready_) return;
    sd_notify(0, "READY=1");
    ready_ = true;
    report_.startupToReadySeconds = Seconds(std::chrono::steady_clock::now() - startup_).count();
    spdlog::info("ready in {:.2f} s{}", report_.startupToReadySeconds,
                 camera_->describe().backend == "sim" ? " (simulated booth)" : "");
    watchdog_.emplace();
}

// Until `until`: the workers' messages as they come.
void Kiosk::waitForMessages(SteadyClockTime until) {
    while (auto m = queue_.waitUntil(until)) handle(*m, FlowClock::now());
}

// Sessions being written: those kept are kept; nothing of a visitor still in the middle of a session stays. A
// kept session's toon strip is waited for by a run of N sessions (bounded), not by a stop or a closed window
// (systemd's stop timeout): the session stays complete without it.
void Kiosk::finish() {
    sd_notify(0, "STOPPING=1");
    watchdog_.reset();
    figures_.report(report_, styles_);
    const auto deadline = std::chrono::steady_clock::now() + kEndWait;
    while (lifecycle_.keptSessionInFlight() && std::chrono::steady_clock::now() < deadline)
        waitForMessages(std::chrono::steady_clock::now() + std::chrono::milliseconds(20));
    writer_.waitIdle();
    waitForMessages(std::chrono::steady_clock::now());
    runSession(lifecycle_.handle(session::DiscardAsked{}), FlowClock::now());
    const bool stopped = (options_.stop && options_.stop->load()) || display_.closeRequested();
    const auto toonDeadline = std::chrono::steady_clock::now() + kEndWait;
    while (lifecycle_.styleExtrasAwaited() && !stopped && !styles_.settled() &&
           std::chrono::steady_clock::now() < toonDeadline)
        waitForMessages(std::chrono::steady_clock::now() + std::chrono::milliseconds(20));
    if (lifecycle_.styleExtrasAwaited() && styles_.settled())
        runSession(lifecycle_.handle(session::StylesSettled{}), FlowClock::now());
    if (lifecycle_.styleExtrasAwaited()) spdlog::warn("a kept session goes without its toon strip: still drawing at the end");
    // A card still waiting for its toon is printed without it; cards are sent before the booth ends (a run of N
    // sessions; a stop does not wait for CUPS longer than its requests' own limits).
    if (cardAfterExtras_) printCard(*std::exchange(cardAfterExtras_, {}));
    if (turntables_ && !stopped) turntables_->waitIdle();
    if (printer_ && !printer_->waitSent(std::chrono::seconds(stopped ? 5 : 30)))
        spdlog::warn("print: a card was still being sent at the end");
    waitForMessages(std::chrono::steady_clock::now());
    report_.screenshots = screenshots_.written();
}

void Kiosk::printCard(PrintCard card) {
    spdlog::info("print: card {} queued", card.code);
    printer_->print(std::move(card));
}

}  // namespace

void tuneAllocatorForKiosk() {
    // Two malloc arenas shared by all threads instead of up to 8 per core (the fit, writer, preview and llvmpipe
    // threads each kept freed images in their own), and a fixed 128 KB mmap threshold, so that images and other
    // large blocks go back to the system when freed instead of staying in an arena whose threshold has risen to
    // the largest block freed. The README ("Memory") has what each measured. The trim threshold at glibc's default
    // again: `main` raised it for the fits of `fit` and `batch` (common/heap_reuse.h).
    mallopt(M_ARENA_MAX, 2);
    mallopt(M_MMAP_THRESHOLD, 128 << 10);
    mallopt(M_TRIM_THRESHOLD, 128 << 10);
}

KioskReport runKiosk(const BoothConfig& config, const KioskOptions& options) {
    const auto startup = std::chrono::steady_clock::now();
    tuneAllocatorForKiosk();
    setLogSession("");
    // OpenCV's worker pool is made by the first thread that needs it and its threads inherit that thread's
    // priority: made here, by the main loop's thread, before the workers lower theirs.
    cv::parallel_for_(cv::Range(0, 2 * std::max(1, cv::getNumThreads())), [](const cv::Range&) {});
    Kiosk kiosk(config, options, startup);
    return kiosk.run();
}

}  // namespace avatarbooth
