// `avatarbooth batch INPUT -o OUT [-j N] [--force] [--shard I/N]` and `avatarbooth batch --merge OUT1 OUT2 ... -o OUT`:
// many photo pairs through the kiosk's fit pipeline, with OUT/summary.json and OUT/report.html.
#include "cli/commands.h"

#include "batch/batch_fit_worker.h"
#include "batch/batch_input.h"
#include "batch/batch_report.h"
#include "batch/batch_runner.h"
#include "cli/exit_codes.h"
#include "common/error.h"
#include "config/booth_config.h"
#include "fit/fit_pipeline.h"

#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <iostream>
#include <sstream>
#include <thread>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

std::atomic<bool> gStopRequested{false};

void onInterrupt(int) {
    gStopRequested.store(true);
    static const char kMessage[] =
        "\navatarbooth batch: stopping after the sessions in progress reach a safe point (Ctrl-C again to kill)\n";
    [[maybe_unused]] const ssize_t n = ::write(STDERR_FILENO, kMessage, sizeof kMessage - 1);
}

// The first Ctrl-C asks for a clean stop; SA_RESETHAND gives the second one its default action (end the process).
void installInterruptHandler() {
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

std::string hms(double seconds) {
    if (!(seconds >= 0.0) || seconds > 359999.0) return "--:--";
    const int s = static_cast<int>(seconds + 0.5);
    char text[32];
    if (s >= 3600) std::snprintf(text, sizeof text, "%d:%02d:%02d", s / 3600, s / 60 % 60, s % 60);
    else std::snprintf(text, sizeof text, "%d:%02d", s / 60, s % 60);
    return text;
}

// A progress bar redrawn in place on a terminal; one line per session otherwise (logs, CI).
class ProgressPrinter {
public:
    explicit ProgressPrinter(bool terminal) : terminal_(terminal) {}

    void operator()(const BatchProgress& p) {
        const int fitted = p.done - p.reused;
        const double perMinute = p.elapsedSeconds > 0.0 ? 60.0 * fitted / p.elapsedSeconds : 0.0;
        const double left = perMinute > 0.0 ? 60.0 * (p.total - p.done) / perMinute : -1.0;
        std::ostringstream rate;
        rate.setf(std::ios::fixed);
        rate.precision(1);
        rate << perMinute << " sessions/min, " << hms(left) << " left";
        if (terminal_) {
            constexpr int kWidth = 30;
            const int filled = p.total > 0 ? kWidth * p.done / p.total : kWidth;
            std::string bar(static_cast<std::size_t>(filled), '#');
            bar.resize(kWidth, '.');
            std::cerr << "\r[" << bar << "] " << p.done << "/" << p.total << "  " << rate.str() << "  ok " << p.ok
                      << ", failed " << p.failed << "   " << std::flush;
            if (p.done == p.total) std::cerr << "\n";
        } else if (p.last) {
            std::cout << "[" << p.done << "/" << p.total << "] " << p.last->id << " "
                      << (p.last->ok ? (p.last->reused ? "ok (earlier run)" : "ok") : "failed: " + p.last->reason);
            if (!p.last->reused) std::cout << " " << static_cast<int>(p.last->seconds * 1000.0) << " ms";
            std::cout << " (" << rate.str() << ")\n" << std::flush;
        }
    }

    void interrupted() {
        if (terminal_) std::cerr << "\n";
    }

private:
    bool terminal_;
};

// Leftovers of a run that was killed (not stopped) mid-write: hidden staging folders next to the sessions.
void removeStaleStaging(const fs::path& out) {
    std::error_code ec;
    const fs::path sessions = out / "sessions";
    if (!fs::is_directory(sessions, ec)) return;
    for (const auto& entry : fs::directory_iterator(sessions, ec)) {
        const std::string name = entry.path().filename().string();
        if (!name.empty() && name.front() == '.' && name.find(".partial-") != std::string::npos) fs::remove_all(entry.path(), ec);
    }
}

void printOutcome(const nlohmann::json& summary, const fs::path& out) {
    const auto& c = summary["counts"];
    std::cout << c.value("total", 0) << " sessions: " << c.value("ok", 0) << " ok, " << c.value("failed", 0) << " failed";
    if (!c["failed_by_reason"].empty()) {
        std::cout << " (";
        bool first = true;
        for (const auto& [reason, n] : c["failed_by_reason"].items()) {
            std::cout << (first ? "" : ", ") << reason << " " << n.get<int>();
            first = false;
        }
        std::cout << ")";
    }
    if (c.value("reused", 0) > 0) std::cout << "; " << c.value("reused", 0) << " complete from an earlier run";
    std::cout << "\nreport: " << (out / "report.html").string() << "\nsummary: " << (out / "summary.json").string() << "\n";
}

}  // namespace

void registerBatchCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("batch", "Fit many photo pairs (a folder of session folders or a CSV manifest), "
                                            "with an HTML report and summary.json");
    struct Options {
        std::string input, out;
        int jobs = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
        bool force = false;
        std::string shard;
        ManifestColumns columns;
        std::vector<std::string> merge;
        std::string config;
        std::string model = AVATARBOOTH_DEFAULT_DLIB_MODEL;
        std::string modelViewer;
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("INPUT", o->input, "A folder of session folders (front.*, side.*, optional background.*) or a CSV manifest");
    cmd->add_option("-o,--output", o->out, "Output folder: sessions/, report.html, summary.json")->required();
    cmd->add_option("-j,--jobs", o->jobs, "Worker threads (default: all cores)")->check(CLI::Range(1, 256));
    cmd->add_flag("--force", o->force, "Fit again the sessions an earlier run completed (default: keep them)");
    cmd->add_option("--shard", o->shard, "Take only shard I of N (1 <= I <= N), split by a stable hash of the session id");
    cmd->add_option("--front-column", o->columns.front, "CSV: column of the front photo")->capture_default_str();
    cmd->add_option("--side-column", o->columns.side,
                    "CSV: column of the side photo; several (repeat or comma-separate) make one session per column")
        ->delimiter(',')
        ->capture_default_str();
    cmd->add_option("--background-column", o->columns.background, "CSV: column of the empty-booth photo (optional)");
    cmd->add_option("--id-column", o->columns.id, "CSV: column naming the session (default: the first column)");
    cmd->add_option("--merge", o->merge, "Join the summaries of these batch output folders (shards) into one report in -o")
        ->expected(1, -1);
    cmd->add_option("--config", o->config, "Booth configuration: its [fit] table sets the fit (as for `fit`)");
    cmd->add_option("--landmark-model", o->model, "dlib 68-point shape predictor (iBUG 300-W: non-commercial terms)")
        ->capture_default_str();
    cmd->add_option("--model-viewer", o->modelViewer,
                    "model-viewer-umd.min.js to copy next to the report (default: found where tests/setup.sh installs it)");
    cmd->callback([o, cmd] {
        const fs::path out = o->out;
        const fs::path viewer = findModelViewer(o->modelViewer);
        if (viewer.empty())
            std::cerr << "avatarbooth: warning: model-viewer not found (run tests/setup.sh, or give --model-viewer): "
                         "the report will show no 3-D views\n";
        if (!o->merge.empty()) {
            if (!o->input.empty()) throw BoothError(ErrorKind::BadConfig, "--merge", "give either INPUT or --merge, not both");
            std::vector<fs::path> parts(o->merge.begin(), o->merge.end());
            const nlohmann::json summary = mergeSummaries(parts, out);
            writeSummaryAndReport(out, summary, viewer);
            printOutcome(summary, out);
            if (summary["counts"].value("failed", 0) > 0) throw CLI::RuntimeError(kExitSomeFailed);
            return;
        }
        if (o->input.empty()) throw BoothError(ErrorKind::BadConfig, "INPUT", "name a folder or a CSV manifest (or use --merge)");

        std::vector<BatchItem> items = readBatchInput(o->input, o->columns);
        requireUniqueIds(items);
        const std::size_t everything = items.size();
        Shard shard;
        if (!o->shard.empty()) {
            shard = parseShard(o->shard);
            items = selectShard(items, shard);
        }

        BoothConfig config;
        if (!o->config.empty()) config = loadBoothConfig(o->config);
        FitSettings settings = config.fit.settings;
        BatchFolderSettings folders{std::nullopt, config.fit.previewSize};
        if (config.character.enabled) folders.character = config.character.settings;
        if (cmd->count("--landmark-model") > 0 || o->config.empty()) settings.landmarkModel = o->model;
        // The landmark model is loaded once here; each worker shares it (see FitPipeline::forAnotherThread).
        const auto base = configuredBaseHead(config.fit);
        const FitPipeline pipeline(settings, *base);

        removeStaleStaging(out);
        installInterruptHandler();
        ProgressPrinter printer(::isatty(STDERR_FILENO) == 1);
        BatchRunOptions options;
        options.out = out;
        options.jobs = o->jobs;
        options.force = o->force;
        options.stop = &gStopRequested;
        options.onProgress = [&printer](const BatchProgress& p) { printer(p); };
        std::cout << "batch: " << items.size() << " sessions";
        if (!o->shard.empty()) std::cout << " (shard " << o->shard << " of " << everything << ")";
        std::cout << " on " << std::min<std::size_t>(static_cast<std::size_t>(o->jobs), std::max<std::size_t>(1, items.size()))
                  << " workers; landmark model loaded in " << static_cast<int>(pipeline.modelLoadSeconds() * 1000.0) << " ms\n"
                  << std::flush;
        const BatchRunResult result = runBatch(items, options, [&] { return makeFitWorker(pipeline, folders, out); });
        signal(SIGINT, SIG_DFL);
        signal(SIGTERM, SIG_DFL);
        if (result.interrupted) printer.interrupted();

        int fitted = 0;
        for (const auto& r : result.records) fitted += r.reused ? 0 : 1;
        nlohmann::json run;
        run["input"] = o->input;
        run["shard"] = o->shard.empty() ? nlohmann::json() : nlohmann::json(o->shard);
        run["jobs"] = result.jobs;
        run["wall_seconds"] = result.wallSeconds;
        run["processed"] = fitted;
        run["sessions_per_minute"] = result.wallSeconds > 0.0 ? 60.0 * fitted / result.wallSeconds : 0.0;
        run["model_load_seconds"] = pipeline.modelLoadSeconds();
        run["interrupted"] = result.interrupted;
        run["force"] = o->force;
        const nlohmann::json summary = summarize(result.records, run);
        writeSummaryAndReport(out, summary, viewer);
        printOutcome(summary, out);
        if (result.interrupted) {
            std::cerr << "avatarbooth: interrupted: " << result.records.size() << " of " << items.size()
                      << " sessions done; run the same command again to finish\n";
            throw CLI::RuntimeError(kExitInterrupted);
        }
        if (summary["counts"].value("failed", 0) > 0) throw CLI::RuntimeError(kExitSomeFailed);
    });
}

}  // namespace avatarbooth
