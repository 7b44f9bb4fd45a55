// `avatarbooth run [--config booth.toml] [--sessions N] [--screenshots DIR]`: the kiosk.
#include "cli/commands.h"
#include "cli/exit_codes.h"

#include "common/error.h"
#include "config/booth_config.h"
#include "drivers/camera/camera_factory.h"
#include "drivers/gpio/button_board.h"
#include "kiosk/kiosk.h"
#include "sim/sim_visitor.h"
#include "sim/synthetic_visitor.h"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <iostream>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

std::atomic<bool> stopRequested{false};
extern "C" void onStopSignal(int) { stopRequested.store(true); }

constexpr const char* kInstalledConfig = "/etc/avatarbooth/booth.toml";

// Whether this process may create and write the folder (or its nearest existing parent).
bool writable(fs::path dir) {
    while (!dir.empty() && !fs::exists(dir)) dir = dir.parent_path();
    return !dir.empty() && ::access(dir.c_str(), W_OK | X_OK) == 0;
}

// A developer's own data folder, for runs without a config on a machine where /var/lib is the system's.
fs::path userDataDir() {
    if (const char* s = std::getenv("XDG_STATE_HOME"); s && *s) return fs::path(s) / "avatarbooth";
    if (const char* h = std::getenv("HOME"); h && *h) return fs::path(h) / ".local/state/avatarbooth";
    return fs::temp_directory_path() / "avatarbooth";
}

}  // namespace

void registerRunCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("run", "Run the booth: camera, buttons, screen and the visitor flow (the kiosk)");
    struct Options {
        std::string config;
        int sessions = 0;
        std::string screenshots;
        std::string visitor = "auto";
        std::string visitorDoes;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--config", o->config,
                    std::string("Configuration file (default: ") + kInstalledConfig + " when it exists, else built-in defaults)");
    cmd->add_option("--sessions", o->sessions, "Stop after this many visitor sessions (default: run until stopped)")
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--screenshots", o->screenshots, "Write a PNG of every screen shown into this folder");
    cmd->add_option("--visitor", o->visitor,
                    "Simulated visitor at a simulated booth: auto (when camera and buttons are both simulated), "
                    "yes, no")
        ->check(CLI::IsMember({"auto", "yes", "no"}))
        ->capture_default_str();
    cmd->add_option("--visitor-does", o->visitorDoes,
                    "What the simulated visitor does besides one plain session, comma-separated: retake-side (asks "
                    "to retake the side photo once), unplug-camera (the camera vanishes in the front guide and comes "
                    "back), operator-menu (an operator opens the menu with the lock first and frees disk), "
                    "look-at-avatar=SECONDSs (on the reveal that long before keeping; default 3s)");
    cmd->callback([o] {
        spdlog::set_level(spdlog::get_level() > spdlog::level::info ? spdlog::level::info : spdlog::get_level());
        BoothConfig config;
        if (!o->config.empty()) config = loadBoothConfig(o->config);
        else if (fs::exists(kInstalledConfig)) config = loadBoothConfig(kInstalledConfig);
        const bool configured = !config.file.empty();

        // Real devices when present, the simulated booth otherwise. The camera's "auto" is resolved here, once, by
        // the camera table's walk (the kiosk then opens exactly that camera): the simulated booth is exactly when
        // that walk ends on the sim camera.
        if (config.camera.backend == "auto") {
            const CameraBackendChoice camera = chooseCameraBackend(config.camera);
            spdlog::info("camera: {}", cameraChoiceLog(camera));
            if (camera.backend == "sim") std::cerr << "avatarbooth: no camera found: running the simulated booth\n";
            config.camera = resolvedCameraSettings(config.camera, camera);
        }
        if (!configured && !writable(config.sessions.directory)) {
            const fs::path fallback = userDataDir() / "sessions";
            std::cerr << "avatarbooth: " << config.sessions.directory.string() << " is not writable for this user; "
                      << "sessions go to " << fallback.string() << "\n";
            config.sessions.directory = fallback;
        }
        if (config.camera.backend == "sim" && config.camera.simFolder.empty()) {
            // The simulated camera shows the synthetic visitor: a head of known shape with its photos.
            // (Made once: a restarted booth must be on its attract screen within 2 s.)
            const fs::path dir = ensureSyntheticVisitorFolder(config.sessions.directory.parent_path() / "synthetic-visitor");
            config.camera.simFolder = dir.string();
            std::cerr << "avatarbooth: the simulated camera shows the synthetic visitor in " << dir.string() << "\n";
        }
        // The same walk the button board takes when the kiosk opens it.
        const bool simButtons = chooseButtonBackend(config.buttons).backend->name == "sim";
        const bool visitor = o->visitor == "yes" ||
                             (o->visitor == "auto" && config.camera.backend == "sim" && simButtons &&
                              config.buttons.timeline.empty());
        SimVisitorScript script = parseSimVisitorScript(o->visitorDoes);
        script.lockHold = config.flow.lockHold + Millis(300);  // the operator holds the lock a little longer
        SimVisitor simVisitor(script);
        if (visitor) std::cerr << "avatarbooth: a simulated visitor uses the booth\n";

        std::signal(SIGINT, onStopSignal);
        std::signal(SIGTERM, onStopSignal);
        KioskOptions options;
        options.sessions = o->sessions;
        options.screenshots = o->screenshots;
        options.visitor = visitor ? &simVisitor : nullptr;
        options.stop = &stopRequested;
        const KioskReport report = runKiosk(config, options);

        std::cout << report.sessionsEnded << " visitor session(s); kept:";
        for (const auto& code : report.keptCodes) std::cout << " " << code;
        if (report.keptCodes.empty()) std::cout << " none";
        if (static_cast<std::size_t>(report.sessionsKept) > report.keptCodes.size())
            std::cout << " (the last " << report.keptCodes.size() << " of " << report.sessionsKept << " kept)";
        std::cout << "\n";
        for (const auto& code : report.keptCodes)
            std::cout << "session " << code << ": " << (report.sessionsDirectory / code).string()
                      << " (avatar.glb, previews, photos)\n";
        if (!report.screenshots.empty())
            std::cout << report.screenshots.size() << " screenshots in " << o->screenshots << "\n";
        std::printf("figures: start-up to ready %.0f ms; guides %.1f frames/s with %.1f face-guidance analyses/s; "
                    "side photo to avatar on screen %.2f s; reveal frame %.1f ms (%.0f fps possible); peak RSS %.0f MB\n",
                    report.startupToReadySeconds * 1000.0, report.guideFramesPerSecond, report.analysesPerSecond,
                    report.sideCaptureToRevealSeconds, report.revealFrameMilliseconds,
                    report.revealFrameMilliseconds > 0.0 ? 1000.0 / report.revealFrameMilliseconds : 0.0,
                    report.peakRssMegabytes);
        std::printf("styles: character %.1f ms (%d renders), toon %.1f ms (%d renders), stage %.1f ms (%d renders) over "
                    "%d attract/reveal frames; toon drawn in %.2f s\n",
                    report.characterFrameMilliseconds, report.characterRenders, report.toonFrameMilliseconds,
                    report.toonRenders, report.stageRenderMilliseconds, report.stageRenders, report.styleFrames,
                    report.toonBuildSeconds);
        if (report.revealFrameMilliseconds > 0.0)
            std::printf("reveal frame parts: avatar render %.1f ms (%zu triangles, %d samples, %.0f%% of the frames "
                        "render a new pose, the others show the pose held from before), screen %.1f ms, present "
                        "%.1f ms; slowest frame %.1f ms\n",
                        report.revealRenderMilliseconds, report.avatarTriangles, report.avatarSamples,
                        100.0 * report.revealRenderedShare, report.revealComposeMilliseconds,
                        report.revealPresentMilliseconds, report.revealSlowestFrameMilliseconds);
    });
}

}  // namespace avatarbooth
