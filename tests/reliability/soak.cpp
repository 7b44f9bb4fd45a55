// The soak test: the simulated booth (in this process) serves N random visitors — random button timings,
// walk-aways, retakes of either photo, keeps and discards — and the process's memory, threads and open files are
// sampled whenever the booth is back on the attract screen. Prints the figures; exits 1 when one is out of bounds.
//
// Usage: reliability_soak [--sessions N] [--seed S] [--warmup W] [--work DIR] [--max-drift-mb M]
#include "reliability_support.h"

#include "common/error.h"
#include "kiosk/kiosk.h"
#include "sim/process_figures.h"
#include "sim/random_visitor.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

// Watches the booth through the visitor's eyes: samples the process each time the attract screen comes back,
// and clears old kept sessions (after checking them) so that thousands of sessions do not fill the disk.
class SoakProbe final : public VisitorScript {
public:
    SoakProbe(VisitorScript& visitor, fs::path sessions) : visitor_(visitor), sessions_(std::move(sessions)) {}

    Action step(const ScreenModel& screen, FlowTime now) override {
        if (screen.id == ScreenId::Attract && last_ != ScreenId::Attract) sessionEnded();
        last_ = screen.id;
        return visitor_.step(screen, now);
    }

    std::vector<ProcessFigures> samples;  // one per session ended
    int checkedComplete = 0;
    std::vector<std::string> problems;
    int leftoversSeen = 0;

private:
    void sessionEnded() {
        samples.push_back(readProcessFigures());
        const reliability::SessionsCheck check = reliability::checkSessions(sessions_);
        for (const auto& p : check.problems) problems.push_back(p);
        // Between sessions nothing may be pending: a discarded or failed fit leaves nothing behind.
        leftoversSeen += check.leftovers;
        std::vector<fs::path> kept;
        for (const auto& code : check.complete) kept.push_back(sessions_ / code);
        std::sort(kept.begin(), kept.end(), [](const fs::path& a, const fs::path& b) {
            return fs::last_write_time(a) < fs::last_write_time(b);
        });
        for (std::size_t i = 0; i + 10 < kept.size(); ++i) {
            if (counted_.insert(kept[i].filename().string()).second) ++checkedComplete;
            fs::remove_all(kept[i]);
        }
        for (std::size_t i = kept.size() > 10 ? kept.size() - 10 : 0; i < kept.size(); ++i)
            if (counted_.insert(kept[i].filename().string()).second) ++checkedComplete;
    }

    VisitorScript& visitor_;
    fs::path sessions_;
    ScreenId last_ = ScreenId::Attract;
    std::set<std::string> counted_;
};

}  // namespace

int main(int argc, char** argv) {
    int sessions = 10, warmup = -1;
    std::uint64_t seed = 1;
    double maxDrift = 5.0;
    fs::path work = fs::temp_directory_path() / "avatarbooth-soak";
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        const auto value = [&]() -> std::string {
            if (i + 1 >= argc) {
                std::cerr << "soak: " << a << " needs a value\n";
                std::exit(2);
            }
            return argv[++i];
        };
        if (a == "--sessions") sessions = std::stoi(value());
        else if (a == "--seed") seed = std::stoull(value());
        else if (a == "--warmup") warmup = std::stoi(value());
        else if (a == "--work") work = value();
        else if (a == "--max-drift-mb") maxDrift = std::stod(value());
        else {
            std::cerr << "usage: reliability_soak [--sessions N] [--seed S] [--warmup W] [--work DIR] [--max-drift-mb M]\n";
            return 2;
        }
    }
    if (warmup < 0) warmup = std::clamp(sessions / 5, 2, 50);
    if (sessions <= warmup) {
        std::cerr << "soak: --sessions must be larger than the warm-up (" << warmup << ")\n";
        return 2;
    }
    spdlog::set_level(spdlog::level::warn);  // thousands of sessions: the figures are the output
    const fs::path sessionsDir = work / "sessions";
    fs::remove_all(sessionsDir);
    fs::create_directories(work);
    const BoothConfig config = reliability::fastSimBooth(reliability::syntheticVisitorFolder(work), sessionsDir);

    RandomVisitor visitor(RandomVisitorOptions{seed});
    SoakProbe probe(visitor, sessionsDir);
    int crashes = 0, ended = 0, kept = 0;
    const auto t0 = std::chrono::steady_clock::now();
    // A crash (an exception out of the kiosk) is counted and the booth started again, as systemd would.
    while (ended < sessions && crashes < 5) {
        KioskOptions options;
        options.sessions = sessions - ended;
        options.visitor = &probe;
        try {
            const KioskReport report = runKiosk(config, options);
            ended += report.sessionsEnded;
            kept += static_cast<int>(report.keptCodes.size());
        } catch (const std::exception& e) {
            ++crashes;
            std::cerr << "soak: the kiosk stopped with an error: " << e.what() << "\n";
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const ProcessFigures end = readProcessFigures();
    const auto& s = probe.samples;
    const ProcessFigures warm = s.size() > static_cast<std::size_t>(warmup) ? s[static_cast<std::size_t>(warmup)] : end;
    double peakAfterWarmup = 0.0;
    int minFds = 1 << 30, maxFds = 0, minThreads = 1 << 30, maxThreads = 0;
    for (std::size_t i = static_cast<std::size_t>(warmup); i < s.size(); ++i) {
        peakAfterWarmup = std::max(peakAfterWarmup, s[i].rssMegabytes);
        minFds = std::min(minFds, s[i].openFiles);
        maxFds = std::max(maxFds, s[i].openFiles);
        minThreads = std::min(minThreads, s[i].threads);
        maxThreads = std::max(maxThreads, s[i].threads);
    }
    if (s.size() <= static_cast<std::size_t>(warmup)) minFds = maxFds = minThreads = maxThreads = 0;
    const double drift = s.empty() ? 0.0 : s.back().rssMegabytes - warm.rssMegabytes;
    const RandomVisitorTally& t = visitor.tally();

    std::printf("soak: sessions run          %d (asked %d, seed %llu, %.1f s, %.2f s per session)\n", ended, sessions,
                static_cast<unsigned long long>(seed), seconds, ended ? seconds / ended : 0.0);
    std::printf("soak: visitors              %d started, %d kept, %d walked away in a guide, %d left the reveal, "
                "%d front and %d side retakes\n",
                t.started, kept, t.walkedAwayInGuide, t.walkedAwayAtReveal, t.retakesFront, t.retakesSide);
    std::printf("soak: crashes               %d\n", crashes);
    std::printf("soak: sessions checked      %d complete, %zu incomplete or corrupt, %d leftovers seen between sessions\n",
                probe.checkedComplete, probe.problems.size(), probe.leftoversSeen);
    std::printf("soak: rss MB                peak %.1f (whole run), after warm-up (%d sessions) %.1f, final %.1f, "
                "drift %+.2f, peak after warm-up %.1f\n",
                end.peakRssMegabytes, warmup, warm.rssMegabytes, s.empty() ? 0.0 : s.back().rssMegabytes, drift,
                peakAfterWarmup);
    std::printf("soak: open files            after warm-up %d, final %d, range %d..%d\n", warm.openFiles,
                s.empty() ? 0 : s.back().openFiles, minFds, maxFds);
    std::printf("soak: threads               after warm-up %d, final %d, range %d..%d\n", warm.threads,
                s.empty() ? 0 : s.back().threads, minThreads, maxThreads);
    for (const auto& p : probe.problems) std::printf("soak: PROBLEM %s\n", p.c_str());

    bool ok = true;
    const auto fail = [&](const std::string& why) {
        std::printf("soak: FAIL %s\n", why.c_str());
        ok = false;
    };
    if (crashes != 0) fail("the kiosk crashed");
    if (ended < sessions) fail("fewer sessions than asked");
    if (!probe.problems.empty()) fail("incomplete or corrupt session folders");
    if (probe.leftoversSeen != 0) fail("pending or half-deleted folders left between sessions");
    if (drift >= maxDrift) fail("memory drift after warm-up above " + std::to_string(maxDrift) + " MB");
    if (maxFds != minFds) fail("the number of open files changed after warm-up");
    if (maxThreads != minThreads) fail("the number of threads changed after warm-up");
    if (kept == 0) fail("no session was kept");
    std::printf("soak: %s\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
