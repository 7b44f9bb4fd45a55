// `avatarbooth check [--config FILE] [--json]`: the hardware and set-up self-test an operator runs first.
//
// One line per thing the booth needs: OK, WARN (works, but not as a booth would on real hardware: "auto" falls back
// to a simulation) or FAIL (what the configuration asks for is missing). Cameras, buttons and the display get one
// line per backend of their table (drivers/*/..._backends.h) with its probe's result, and a last line with what
// the configured backend (or "auto", walking the same table as the booth) comes to. Nothing is taken: cameras are
// listed, GPIO lines looked up but not requested, the screen probed without keeping it, so check can run next to a
// running booth. The exit code is non-zero when anything FAILs (the code of the first failure's kind, see exit_codes.h).
#include "cli/commands.h"
#include "cli/exit_codes.h"

#include "common/error.h"
#include "config/booth_config.h"
#include "common/backend_table.h"
#include "drivers/camera/camera_factory.h"
#include "drivers/display/display_backends.h"
#include "drivers/display/display_factory.h"
#include "drivers/gpio/button_backends.h"
#include "drivers/gpio/gpiod_lines.h"
#include "fit/face/landmarks68.h"
#include "batch/batch_report.h"
#include "booth/screens/strings.h"
#include "booth/share_link.h"
#include "print/cups_queue.h"
#include "drivers/sound/sound_player.h"

#include <nlohmann/json.hpp>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

constexpr const char* kInstalledConfig = "/etc/avatarbooth/booth.toml";

enum class Status { Ok, Warn, Fail };

struct CheckLine {
    std::string what;  // "config", "camera", "gpio", "display", "landmarks", "strings", "sessions", "share"
    Status status = Status::Ok;
    std::string message;
    ErrorKind kind = ErrorKind::Internal;  // for the exit code of a FAIL
};

const char* statusName(Status s) {
    switch (s) {
        case Status::Ok: return "OK";
        case Status::Warn: return "WARN";
        case Status::Fail: return "FAIL";
    }
    return "?";
}

class Report {
public:
    void ok(const std::string& what, const std::string& message) {
        lines_.push_back({what, Status::Ok, message, ErrorKind::Internal});
    }
    void warn(const std::string& what, const std::string& message) {
        lines_.push_back({what, Status::Warn, message, ErrorKind::Internal});
    }
    void fail(const std::string& what, const std::string& message, ErrorKind kind) {
        lines_.push_back({what, Status::Fail, message, kind});
    }
    const std::vector<CheckLine>& lines() const { return lines_; }

private:
    std::vector<CheckLine> lines_;
};

// The configuration: the file given, else the installed one, else the built-in defaults. An invalid file FAILs
// and the other checks go on with the defaults, so one run shows everything that is wrong.
BoothConfig checkConfig(const std::string& given, Report& report) {
    const fs::path file = !given.empty() ? fs::path(given) : fs::exists(kInstalledConfig) ? fs::path(kInstalledConfig) : fs::path();
    if (file.empty()) {
        report.warn("config", std::string("no --config and no ") + kInstalledConfig + ": the built-in defaults apply");
        return BoothConfig{};
    }
    try {
        BoothConfig config = loadBoothConfig(file);
        report.ok("config", file.string() + " is valid");
        return config;
    } catch (const ConfigErrors& e) {
        for (const BoothError& mistake : e.mistakes()) report.fail("config", mistake.what(), ErrorKind::BadConfig);
    } catch (const BoothError& e) {
        report.fail("config", e.what(), ErrorKind::BadConfig);
    }
    return BoothConfig{};
}

// Each backend of a kind's table with its probe's result, then what the configuration comes to (the last line). A
// failed probe is FAIL when the configuration names that backend, and otherwise information only (the booth does
// not need it). For "auto" the last line names the backend it takes, the same walk as at start-up: WARN when that is
// the simulation at the table's end (`simulation` says what the booth would then run). Returns the backend the
// booth would use, or null when the one named cannot be used.
template <typename Entry, typename Settings>
const Entry* checkBackends(const std::string& what, const std::string& key, std::span<const Entry> table,
                           const Settings& settings, const std::string& simulation, Report& report) {
    const std::string& configured = settings.backend;
    const auto line = [&](std::size_t i, const BackendProbe& probe) {
        const std::string name(table[i].name);
        if (probe.usable) report.ok(what, name + ": " + probe.text);
        else if (name == configured)
            report.fail(what, name + ": " + probe.text + " (" + key + " = \"" + name + "\")", ErrorKind::Device);
        else report.ok(what, name + ": not usable here: " + probe.text);
    };
    if (configured != "auto") {
        const Entry* named = findBackend(table, configured);
        for (std::size_t i = 0; i < table.size(); ++i)
            if (&table[i] != named) line(i, table[i].probe(settings));
        if (!named) {
            report.fail(what, "\"" + configured + "\" is not a backend (" + backendWordList(table) + ")", ErrorKind::BadConfig);
            return nullptr;
        }
        const BackendProbe probe = named->probe(settings);
        line(static_cast<std::size_t>(named - table.data()), probe);
        return probe.usable ? named : nullptr;
    }
    const BackendChoice<Entry> choice = probeBackends(table, settings);
    for (std::size_t i = 0; i < choice.passed.size(); ++i) line(i, {false, choice.passed[i].why, ""});
    if (!choice.backend) {
        report.fail(what, "auto: no backend is usable", ErrorKind::Device);
        return nullptr;
    }
    const auto chosen = static_cast<std::size_t>(choice.backend - table.data());
    line(chosen, choice.probe);
    for (std::size_t i = chosen + 1; i < table.size(); ++i) line(i, table[i].probe(settings));
    const std::string name(choice.backend->name);
    const std::string why = autoWhy(choice);
    const std::string because = why.empty() ? std::string() : " (" + why + ")";
    if (chosen + 1 == table.size()) report.warn(what, "auto: the booth would run " + simulation + because);
    else report.ok(what, "auto: " + name + because);
    return choice.backend;
}

void checkCameras(const CameraSettings& settings, Report& report) {
    for (const auto& c : listCameras()) {
        const std::string line = c.backend + " " + c.device + ": " + c.name + "; " + c.formats;
        if (c.usable) report.ok("camera", line);
        else report.warn("camera", line + " (not usable)");
    }
    const CameraBackend* used =
        checkBackends("camera", "camera.backend", cameraBackends(), settings, "the simulated camera", report);
    if (used && used->name == "sim" && !settings.simFolder.empty() && !fs::is_directory(settings.simFolder))
        report.fail("camera", "sim: camera.sim_folder " + settings.simFolder + " is not a folder", ErrorKind::BadConfig);
}

void checkGpio(const GpioSettings& settings, Report& report) {
    const ButtonBackend* used =
        checkBackends("gpio", "buttons.backend", buttonBackends(), settings, "simulated buttons", report);
    if (!used || used->name != "gpiod") return;
    std::vector<unsigned> offsets;
    std::vector<std::string> labels;
    for (const auto& b : settings.buttons) {
        offsets.push_back(b.offset);
        labels.push_back(b.name + " button");
    }
    for (const auto& l : settings.lamps) {
        offsets.push_back(l.offset);
        labels.push_back(l.name + " lamp");
    }
    std::string chipName;
    std::vector<GpioLineStatus> lines;
    try {
        lines = gpiodLineStatus(settings.chip, offsets, &chipName);
    } catch (const BoothError& e) {
        report.fail("gpio", e.what(), ErrorKind::Device);  // the chip went away since the probe
        return;
    }
    report.ok("gpio", "chip " + chipName + " (" + gpiodLibraryVersion() + ")");
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const GpioLineStatus& s = lines[i];
        const std::string line = labels[i] + ": line " + std::to_string(s.offset) + (s.name.empty() ? "" : " (" + s.name + ")");
        if (!s.exists) report.fail("gpio", line + " does not exist on " + chipName, ErrorKind::Device);
        else if (s.used && s.consumer == settings.consumer)
            report.warn("gpio", line + " is in use by \"" + s.consumer + "\" (is the booth running?)");
        else if (s.used)
            report.fail("gpio", line + " is in use by \"" + (s.consumer.empty() ? std::string("the kernel") : s.consumer) + "\"",
                        ErrorKind::Device);
        else report.ok("gpio", line + " is free");
    }
}

// The DRM connectors sysfs shows ("card1-HDMI-A-1 connected, card1-HDMI-A-2 disconnected"), without opening a card.
std::string drmConnectors() {
    std::string out;
    std::error_code ec;
    std::vector<std::string> entries;
    for (const auto& e : fs::directory_iterator("/sys/class/drm", ec)) {
        const std::string name = e.path().filename().string();
        std::ifstream status(e.path() / "status");
        std::string state;
        if (name.rfind("card", 0) == 0 && status >> state) entries.push_back(name + " " + state);
    }
    std::sort(entries.begin(), entries.end());
    for (const auto& e : entries) out += (out.empty() ? "" : ", ") + e;
    return out.empty() ? "none found" : out;
}

void checkDisplay(const DisplaySettings& settings, Report& report) {
    if (settings.backend != "headless") report.ok("display", "DRM connectors: " + drmConnectors());
    std::string connectors;
    if (displayWaitsForScreen(settings, &connectors)) {
        // A board whose screen is off or unplugged: the booth starts without it and shows its screens once one is
        // connected (createDisplay). Not a FAIL (the booth runs) nor "would run headless" (it would not).
        for (const DisplayBackend& b : displayBackends()) {
            const BackendProbe probe = b.probe(settings);
            report.ok("display", std::string(b.name) + (probe.usable ? ": " : ": not usable here: ") + probe.text);
        }
        report.warn("display", settings.backend + ": kms, waiting for a screen (" + connectors +
                                   "): the booth starts without one and shows its screens once one is connected");
        return;
    }
    checkBackends("display", "display.backend", displayBackends(), settings, "headless", report);
}

void checkLandmarkModel(const fs::path& model, Report& report) {
    std::error_code ec;
    if (!fs::is_regular_file(model, ec)) {
        report.fail("landmarks", model.string() + " not found (Debian: libdlib-data; [fit] landmark_model)", ErrorKind::BadConfig);
        return;
    }
    const auto size = fs::file_size(model, ec);
    try {
        LandmarkDetector detector(model);  // the real load: a truncated or foreign file fails here, not at the first visitor
        report.ok("landmarks", model.string() + " loads (" + std::to_string(size / (1024 * 1024)) + " MB)");
    } catch (const std::exception& e) {
        report.fail("landmarks", std::string("cannot load: ") + e.what(), ErrorKind::BadConfig);
    }
}

// The base head the fit starts from: the operator's own, or the MakeHuman head the package installs.
void checkBaseHead(const FitConfig& fit, Report& report) {
    try {
        const auto head = configuredBaseHead(fit);
        const std::string where = fit.baseMesh.empty() ? findMakeHumanBaseHead().string() : fit.baseMesh.string();
        report.ok("base head", where + ": " + std::to_string(head->mesh.vertexCount()) + " vertices, " +
                                   std::to_string(head->modifiers ? head->modifiers->modifiers.size() : 0) + " modifiers");
    } catch (const BoothError& e) {
        report.fail("base head", e.what(), ErrorKind::BadConfig);
    }
}

void checkStrings(const fs::path& configured, Report& report) {
    try {
        const fs::path file = configured.empty() ? StringTable::defaultFile() : configured;
        StringTable::load(file);
        report.ok("strings", file.string());
    } catch (const BoothError& e) {
        report.fail("strings", e.what(), ErrorKind::BadConfig);
    }
}

// The sessions directory: writable by this user (tried with a real file) and the free space on its file system.
void checkSessions(const fs::path& dir, Report& report) {
    std::error_code ec;
    fs::path existing = dir;
    while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
    if (existing.empty() || !fs::is_directory(existing, ec)) {
        report.fail("sessions", dir.string() + ": no existing parent folder", ErrorKind::Output);
        return;
    }
    bool writable = false;
    if (existing == dir) {
        const fs::path probe = dir / (".check-" + std::to_string(::getpid()));
        writable = static_cast<bool>(std::ofstream(probe) << "x");
        fs::remove(probe, ec);
    } else {
        writable = ::access(existing.c_str(), W_OK | X_OK) == 0;
    }
    if (!writable) {
        report.fail("sessions", dir.string() + " is not writable for this user (" + existing.string() + ")", ErrorKind::Output);
        return;
    }
    const fs::space_info space = fs::space(existing, ec);
    const double freeMb = ec ? -1.0 : static_cast<double>(space.available) / (1024.0 * 1024.0);
    // A session is a few MB (photos, avatar, previews): below 100 MB the booth stops keeping sessions soon.
    const std::string where = dir.string() + (existing == dir ? std::string() : " (will be created)");
    const std::string freeText = ec ? std::string("free space unknown") : std::to_string(static_cast<long long>(freeMb)) + " MB free";
    if (!ec && freeMb < 100.0) report.fail("sessions", where + ": only " + freeText, ErrorKind::Output);
    else if (!ec && freeMb < 1024.0) report.warn("sessions", where + ": writable, " + freeText + " (less than 1 GB)");
    else report.ok("sessions", where + ": writable, " + freeText);
}

// The visitors' page service ([share], `avatarbooth share`): off (nothing listens), or where it listens, the URL the
// QR codes carry, and whether what it needs is there (TLS files readable, the 3-D viewer installed).
void checkShare(const ShareSettings& share, const SessionStoreSettings& sessions, Report& report) {
    if (!share.enabled) {
        report.ok("share", "off ([share] enabled = false): no QR code, nothing listens");
        return;
    }
    std::string what = "on: avatarbooth-share listens on " + share.listen + (share.tlsCertificate.empty() ? " (http)" : " (https)") +
                       ", QR codes link " + shareBaseUrl(share) + "/s/<token>";
    const auto lifetime = sessions.sessionRetention.count() > 0 ? std::min(share.pageLifetime, sessions.sessionRetention)
                                                                : share.pageLifetime;
    what += ", pages live " + std::to_string(std::chrono::duration_cast<std::chrono::hours>(lifetime).count()) + " h";
    what += std::string(", downloads ") + (share.offerDownloads ? "on" : "off") + ", photos " + (share.offerPhotos ? "on" : "off");
    for (const fs::path& f : {share.tlsCertificate, share.tlsKey}) {
        if (!f.empty() && ::access(f.c_str(), R_OK) != 0) {
            report.fail("share", what + "; " + f.string() + " is not readable", ErrorKind::BadConfig);
            return;
        }
    }
    if (findModelViewer().empty()) {
        report.warn("share", what + "; model-viewer is not installed: pages offer downloads without the 3-D view");
        return;
    }
    report.ok("share", what);
}

// The printed card's queue ([print]): off, or what CUPS says of the queue (there? accepting? stopped, out of paper:
// the printer-state-reasons). A queue that cannot take the card fails; the booth itself would go on without it.
void checkPrint(const PrintSettings& print, Report& report) {
    if (!print.enabled) {
        report.ok("print", "off ([print] enabled = false): Keep prints nothing");
        return;
    }
    const QueueState q = queryQueue(print.queue);
    char card[96];
    std::snprintf(card, sizeof card, "; card %gx%g mm at %d dpi, %d cop%s", print.widthMm, print.heightMm, print.dpi,
                  print.copies, print.copies == 1 ? "y" : "ies");
    const std::string what = "queue " + (q.queue.empty() ? std::string("(CUPS default)") : q.queue) + ": " + q.describe() + card;
    if (!q.found() || !q.accepting || q.stopped) report.fail("print", what, ErrorKind::Device);
    else if (q.problem()) report.warn("print", what);
    else report.ok("print", what);
}

// The sounds ([sound]): off, or the sound cards ALSA finds and whether the sound theme's clips are there. Nothing
// is opened (a running booth holds the device); without a card the booth is silent, which is worth a warning.
void checkSound(const SoundSettings& sound, Report& report) {
    if (!sound.enabled) {
        report.ok("sound", "off ([sound] enabled = false)");
        return;
    }
    const std::vector<std::string> cards = soundCards();
    std::string what = "device " + sound.device + ", volume " + std::to_string(sound.volume) + "%; ";
    if (cards.empty()) what += "no sound card found";
    else {
        what += "sound card";
        for (const auto& c : cards) what += " " + c + ";";
        what.pop_back();
    }
    for (const char* clip : {"camera-shutter.oga", "complete.oga"}) {
        const fs::path file = fs::path(sound.themeDir) / clip;
        if (!fs::exists(file)) {
            report.warn("sound", what + "; " + file.string() + " is missing (sound-theme-freedesktop): silent");
            return;
        }
    }
    if (cards.empty() && sound.device == "default") report.warn("sound", what + ": the booth is silent");
    else report.ok("sound", what);
}

}  // namespace

void registerCheckCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("check", "Self-test: cameras, GPIO lines, screen, landmark model, config, data folder");
    struct Options {
        std::string config;
        bool json = false;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--config", o->config,
                    std::string("Configuration file to check (default: ") + kInstalledConfig + " when it exists)");
    cmd->add_flag("--json", o->json, "Print the results as JSON (for scripts)");
    cmd->callback([o] {
        if (o->json) {
            // Stdout is the report's, which a script parses: what the libraries log while the checks run (libcamera
            // 0.4 complains through spdlog about a machine without dma-buf heaps) goes to stderr instead.
            const auto level = spdlog::default_logger()->level();
            auto logger = spdlog::stderr_color_mt("check");
            logger->set_level(level);
            spdlog::set_default_logger(logger);
        }
        Report report;
        const BoothConfig config = checkConfig(o->config, report);
        checkCameras(config.camera, report);
        checkGpio(config.buttons, report);
        checkDisplay(config.display, report);
        checkLandmarkModel(config.fit.settings.landmarkModel, report);
        checkBaseHead(config.fit, report);
        checkStrings(config.screen.stringsFile, report);
        checkSessions(config.sessions.directory, report);
        checkShare(config.share, config.sessions, report);
        checkPrint(config.print, report);
        checkSound(config.sound, report);

        std::optional<ErrorKind> firstFailure;
        int fails = 0, warns = 0;
        for (const auto& l : report.lines()) {
            if (l.status == Status::Fail) {
                ++fails;
                if (!firstFailure) firstFailure = l.kind;
            }
            if (l.status == Status::Warn) ++warns;
        }
        if (o->json) {
            nlohmann::json out;
            out["ok"] = fails == 0;
            out["failures"] = fails;
            out["warnings"] = warns;
            out["checks"] = nlohmann::json::array();
            for (const auto& l : report.lines())
                out["checks"].push_back({{"check", l.what}, {"status", statusName(l.status)}, {"message", l.message}});
            std::cout << out.dump(2) << "\n";
        } else {
            for (const auto& l : report.lines()) {
                std::string status = statusName(l.status), what = l.what;
                status.resize(5, ' ');
                what.resize(10, ' ');
                std::cout << status << what << l.message << "\n";
            }
            std::cout << (fails ? "check: " + std::to_string(fails) + " failure(s), " : std::string("check: ready, "))
                      << warns << " warning(s)\n";
        }
        if (firstFailure) throw CLI::RuntimeError(exitCodeFor(*firstFailure));
    });
}

}  // namespace avatarbooth
