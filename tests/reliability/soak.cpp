// The soak test: the simulated booth (in this process) serves N random visitors — random button timings,
// walk-aways, retakes of either photo, keeps and discards — and the process's memory, threads and open files are
// sampled whenever the booth is back on the attract screen. Prints the figures; exits 1 when one is out of bounds.
//
// Usage: reliability_soak [--sessions N] [--seed S] [--warmup W] [--work DIR] [--max-drift-mb M] [--samples-csv F]
#include "reliability_support.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "kiosk/kiosk.h"
#include "sim/process_figures.h"
#include "sim/random_visitor.h"

#include <spdlog/spdlog.h>

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

// One sample, taken when a session has ended: the process's figures and the C heap's (glibc mallinfo2, every
// arena): `heapInUse` is what the program holds (a leak makes it grow), `heapFree` what the allocator keeps free
// inside its arenas (growth there is fragmentation or arena growth, which flattens, not a leak).
struct Sample {
    ProcessFigures process;
    bool quiet = true;  // nothing pending: no session folder being written in the background (its file is open)
    double heapInUseMegabytes = 0.0;
    double heapFreeMegabytes = 0.0;
    double brkHeapMegabytes = 0.0;    // resident in the brk heap (glibc's main arena)
    double anonOtherMegabytes = 0.0;  // resident in anonymous mappings (other arenas, large blocks, llvmpipe's code)
    double arenaMegabytes = 0.0;      // of those, in glibc's thread arenas
    double codeMegabytes = 0.0;       // of those, in code compiled at run time (llvmpipe's shaders)
};

Sample takeSample() {
    Sample s;
    s.process = readProcessFigures();
    const struct mallinfo2 m = mallinfo2();
    s.heapInUseMegabytes = static_cast<double>(m.uordblks + m.hblkhd) / (1024.0 * 1024.0);
    s.heapFreeMegabytes = static_cast<double>(m.fordblks) / (1024.0 * 1024.0);
    const std::map<std::string, double> resident = residentByMapping();
    const auto at = [&](const char* name) {
        const auto it = resident.find(name);
        return it == resident.end() ? 0.0 : it->second;
    };
    s.brkHeapMegabytes = at("[heap]");
    s.arenaMegabytes = at("[anon: arena]");
    s.codeMegabytes = at("[anon: code]");
    s.anonOtherMegabytes = at("[anon]") + s.arenaMegabytes + s.codeMegabytes;
    return s;
}

// Least-squares slope of `value` over the samples [from, end), per 100 sessions (0 with fewer than 3 samples).
template <typename F>
double slopePer100(const std::vector<Sample>& s, std::size_t from, F value) {
    const std::size_t n = s.size() > from ? s.size() - from : 0;
    if (n < 3) return 0.0;
    double mx = 0, my = 0;
    for (std::size_t i = from; i < s.size(); ++i) {
        mx += static_cast<double>(i);
        my += value(s[i]);
    }
    mx /= static_cast<double>(n);
    my /= static_cast<double>(n);
    double sxy = 0, sxx = 0;
    for (std::size_t i = from; i < s.size(); ++i) {
        sxy += (static_cast<double>(i) - mx) * (value(s[i]) - my);
        sxx += (static_cast<double>(i) - mx) * (static_cast<double>(i) - mx);
    }
    return 100.0 * sxy / sxx;
}

// The RSS the booth settles at over the samples [from, to): the median of the quiet ones (no session write in
// flight; the writer's images, mesh and GL context add 10-40 MB while it works), or of all of them when none is
// quiet. One reading scatters by about ±12 MB with what the last visitor did (walked away, kept, toon drawn), so a
// drift taken from two single readings measures that scatter, not a leak; the medians of two windows of a hundred
// sessions each do not.
struct SettledRss {
    double megabytes = 0.0;
    std::string over;  // what the median is over: "N quiet ends", or "all N ends, none quiet"
};

SettledRss settledRss(const std::vector<Sample>& s, std::size_t from, std::size_t to) {
    std::vector<double> quiet, all;
    for (std::size_t i = from; i < to && i < s.size(); ++i) {
        all.push_back(s[i].process.rssMegabytes);
        if (s[i].quiet) quiet.push_back(s[i].process.rssMegabytes);
    }
    std::vector<double>& v = quiet.empty() ? all : quiet;
    if (v.empty()) return {0.0, "no ends"};
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    const double median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
    const std::string count = std::to_string(n);
    return {median, quiet.empty() ? "all " + count + " ends, none quiet" : count + " quiet ends"};
}

// Every sample as CSV, for plotting or another estimator.
std::string samplesCsvText(const std::vector<Sample>& s) {
    std::string csv = "session,quiet,rss_mb,heap_in_use_mb,heap_free_mb,open_files,threads,rss_anon_mb,"
                      "rss_file_mb,rss_brk_heap_mb,rss_anon_mappings_mb,rss_arenas_mb,rss_jit_code_mb\n";
    for (std::size_t i = 0; i < s.size(); ++i) {
        char row[240];
        std::snprintf(row, sizeof row, "%zu,%d,%.2f,%.2f,%.2f,%d,%d,%.2f,%.2f,%.2f,%.2f,%.2f,%.2f\n", i + 1,
                      s[i].quiet ? 1 : 0, s[i].process.rssMegabytes, s[i].heapInUseMegabytes, s[i].heapFreeMegabytes,
                      s[i].process.openFiles, s[i].process.threads, s[i].process.anonRssMegabytes,
                      s[i].process.fileRssMegabytes, s[i].brkHeapMegabytes, s[i].anonOtherMegabytes,
                      s[i].arenaMegabytes, s[i].codeMegabytes);
        csv += row;
    }
    return csv;
}

// Watches the booth through the visitor's eyes: samples the process each time the attract screen comes back,
// and clears old kept sessions (after checking them) so that thousands of sessions do not fill the disk.
class SoakProbe final : public VisitorScript {
public:
    SoakProbe(VisitorScript& visitor, fs::path sessions, fs::path samplesCsv, fs::path mappingsCsv)
        : visitor_(visitor), sessions_(std::move(sessions)), samplesCsv_(std::move(samplesCsv)),
          mappingsCsv_(std::move(mappingsCsv)) {}

    Action step(const ScreenModel& screen, FlowTime now) override {
        if (screen.id == ScreenId::Attract && last_ != ScreenId::Attract) sessionEnded();
        last_ = screen.id;
        return visitor_.step(screen, now);
    }

    std::vector<Sample> samples;  // one per session ended
    int checkedComplete = 0;
    std::vector<std::string> problems;
    int leftoversSeen = 0;               // pending entries seen at a session's end (writes in flight included)
    std::vector<std::string> stuck;      // pending entries still there a session later, and kept sessions' partials
    std::set<std::string> withToon;      // kept sessions seen with their toon strip

private:
    void sessionEnded() {
        samples.push_back(takeSample());
        const reliability::SessionsCheck check = reliability::checkSessions(sessions_);
        for (const auto& p : check.problems) problems.push_back(p);
        // The session folder is written in the background (SessionWriter), so a folder may still be pending when
        // the attract screen comes back (its write in flight, a few seconds under load; a discarded one is removed
        // when the write ends), and still at the next end after a visitor who walked away at once. One still there
        // a minute after it was first seen is stuck: a discarded or failed fit must leave nothing behind.
        samples.back().quiet = check.leftovers == 0;
        // A line every 100 sessions: a run of thousands takes hours, and one stopped early still has its figures.
        if (samples.size() % 100 == 0) {
            const Sample& x = samples.back();
            // Where RSS settled over these 100 (the drift is measured the same way at the end).
            const SettledRss settled = settledRss(samples, samples.size() - 100, samples.size());
            std::printf("soak: progress %zu sessions, %.0f s, rss %.1f MB (anon %.1f: brk heap %.1f, mappings %.1f; "
                        "files %.1f), settled %.1f MB over the last 100 (median of %s), heap %.1f in use / %.1f "
                        "free MB, %d open files, %d threads\n",
                        samples.size(), std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(),
                        x.process.rssMegabytes, x.process.anonRssMegabytes, x.brkHeapMegabytes, x.anonOtherMegabytes,
                        x.process.fileRssMegabytes, settled.megabytes, settled.over.c_str(), x.heapInUseMegabytes,
                        x.heapFreeMegabytes, x.process.openFiles, x.process.threads);
            std::fflush(stdout);
            if (!mappingsCsv_.empty()) writeMappings(x);
            if (!samplesCsv_.empty()) {  // so far: a run stopped early still leaves its samples
                try {
                    writeFileAtomically(samplesCsv_, samplesCsvText(samples));
                } catch (const std::exception& e) {
                    std::printf("soak: samples not written: %s\n", e.what());
                }
            }
        }
        leftoversSeen += check.leftovers;
        const auto t = std::chrono::steady_clock::now();
        std::map<std::string, std::chrono::steady_clock::time_point> now;
        for (const auto& name : check.leftoverNames) {
            const auto before = pendingBefore_.find(name);
            now[name] = before == pendingBefore_.end() ? t : before->second;
            if (t - now[name] > std::chrono::seconds(60) && reported_.insert(name).second) stuck.push_back(name);
        }
        // A '.partial-' inside a kept session is never in flight here (the toon strip is written on this thread).
        stuck.insert(stuck.end(), static_cast<std::size_t>(check.leftovers) - check.leftoverNames.size(), "a kept session's .partial-*");
        pendingBefore_ = std::move(now);
        for (const auto& code : check.complete)
            if (fs::exists(sessions_ / code / "toon")) withToon.insert(code);
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

    // Every 100 sessions, the resident megabytes of each mapping (library, [heap], [anon]) are added to a CSV,
    // rewritten whole each time, so that a climb in RSS can be traced to what holds it while the run goes on.
    void writeMappings(const Sample& x) {
        for (const auto& [name, megabytes] : residentByMapping()) {
            if (megabytes < 0.05) continue;
            char row[64];
            std::snprintf(row, sizeof row, "%zu,%d,%.2f,", samples.size(), x.quiet ? 1 : 0, megabytes);
            std::string quoted = "\"";
            for (char c : name) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
            mappingRows_ += row + quoted + "\"\n";
        }
        try {
            writeFileAtomically(mappingsCsv_, "session,quiet,rss_mb,mapping\n" + mappingRows_);
        } catch (const std::exception& e) {
            std::printf("soak: mappings not written: %s\n", e.what());
        }
        // And glibc's own account of each arena (malloc_info: its heaps' size, the free chunks by size), next to
        // the CSV: RSS that climbs in an arena while the bytes in use do not is told apart there as free chunks
        // too small or too scattered to give back, or as heaps added.
        char* text = nullptr;
        std::size_t length = 0;
        if (FILE* out = open_memstream(&text, &length)) {
            malloc_info(0, out);
            std::fclose(out);
            mallocInfo_ += "<at session=\"" + std::to_string(samples.size()) + "\" quiet=\"" + (x.quiet ? "1" : "0") +
                           "\">\n" + std::string(text, length) + "</at>\n";
            std::free(text);
        }
        try {
            writeFileAtomically(fs::path(mappingsCsv_).replace_extension("").replace_extension(".malloc_info.xml"),
                                "<soak>\n" + mallocInfo_ + "</soak>\n");
        } catch (const std::exception& e) {
            std::printf("soak: malloc_info not written: %s\n", e.what());
        }
    }

    VisitorScript& visitor_;
    fs::path sessions_;
    fs::path samplesCsv_;
    fs::path mappingsCsv_;
    std::string mappingRows_;
    std::string mallocInfo_;
    ScreenId last_ = ScreenId::Attract;
    std::set<std::string> counted_;
    std::map<std::string, std::chrono::steady_clock::time_point> pendingBefore_;  // pending entry -> first seen
    std::set<std::string> reported_;
    const std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace

int main(int argc, char** argv) {
    // The allocator set up as the kiosk's process has it, before anything here starts a thread: glibc fixes its
    // arena count when threads first allocate, and the synthetic visitor's render below starts llvmpipe's. Set
    // only later (runKiosk does it again, harmlessly), the soak ran with 7 arenas where `avatarbooth run` has 2.
    tuneAllocatorForKiosk();
    int sessions = 10, warmup = -1;
    std::uint64_t seed = 1;
    double maxDrift = 5.0;
    fs::path work = fs::temp_directory_path() / "avatarbooth-soak";
    fs::path samplesCsv;
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
        else if (a == "--samples-csv") samplesCsv = value();
        else {
            std::cerr << "usage: reliability_soak [--sessions N] [--seed S] [--warmup W] [--work DIR] [--max-drift-mb M] "
                         "[--samples-csv FILE]\n";
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
    fs::path mappingsCsv;
    if (!samplesCsv.empty()) mappingsCsv = fs::path(samplesCsv).replace_extension(".mappings.csv");
    SoakProbe probe(visitor, sessionsDir, samplesCsv, mappingsCsv);
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
            kept += report.sessionsKept;
        } catch (const std::exception& e) {
            ++crashes;
            std::cerr << "soak: the kiosk stopped with an error: " << e.what() << "\n";
        }
    }
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const ProcessFigures end = readProcessFigures();
    const auto& s = probe.samples;
    const std::size_t w = static_cast<std::size_t>(warmup);
    const ProcessFigures warm = s.size() > w ? s[w].process : end;
    const ProcessFigures last = s.empty() ? end : s.back().process;
    double peakAfterWarmup = 0.0;
    int minFds = 1 << 30, maxFds = 0, minThreads = 1 << 30, maxThreads = 0;
    int quietSamples = 0;
    for (std::size_t i = w; i < s.size(); ++i) {
        peakAfterWarmup = std::max(peakAfterWarmup, s[i].process.rssMegabytes);
        if (!s[i].quiet) continue;  // a write in flight holds a file open
        ++quietSamples;
        minFds = std::min(minFds, s[i].process.openFiles);
        maxFds = std::max(maxFds, s[i].process.openFiles);
        minThreads = std::min(minThreads, s[i].process.threads);
        maxThreads = std::max(maxThreads, s[i].process.threads);
    }
    if (quietSamples == 0) minFds = maxFds = minThreads = maxThreads = 0;
    // The drift: where RSS settles over the last tenth of the samples after warm-up, minus where it settled over
    // the first tenth (at least 3 samples each, without overlapping; see settledRss). A leak of 3 kB a session
    // climbs 5 MB over 1800.
    const std::size_t after = s.size() > w ? s.size() - w : 0;
    const std::size_t window = std::max<std::size_t>(1, std::min(std::max<std::size_t>(3, after / 10), after / 2));
    const SettledRss settledFirst = settledRss(s, w, w + window);
    const SettledRss settledLast = settledRss(s, s.size() > window ? std::max(w, s.size() - window) : w, s.size());
    const double drift = after > 0 ? settledLast.megabytes - settledFirst.megabytes : 0.0;
    const double singleDrift = after > 0 ? last.rssMegabytes - warm.rssMegabytes : 0.0;
    const auto rss = [](const Sample& x) { return x.process.rssMegabytes; };
    const auto inUse = [](const Sample& x) { return x.heapInUseMegabytes; };
    const auto heapFree = [](const Sample& x) { return x.heapFreeMegabytes; };
    // The drift's shape: RSS and heap at five points after warm-up (a leak climbs steadily, arena growth flattens),
    // and the least-squares slope per 100 sessions over all samples after warm-up and over the second half of them.
    std::string points, heapPoints;
    if (s.size() > w) {
        for (int q = 0; q <= 4; ++q) {
            const std::size_t i = w + (s.size() - 1 - w) * static_cast<std::size_t>(q) / 4;
            char buf[64];
            std::snprintf(buf, sizeof buf, "%s%zu:%.1f", q ? " " : "", i + 1, s[i].process.rssMegabytes);
            points += buf;
            std::snprintf(buf, sizeof buf, "%s%zu:%.1f/%.1f", q ? " " : "", i + 1, s[i].heapInUseMegabytes,
                          s[i].heapFreeMegabytes);
            heapPoints += buf;
        }
    }
    const std::size_t half = w + (s.size() > w ? (s.size() - w) / 2 : 0);
    const RandomVisitorTally& t = visitor.tally();

    std::printf("soak: sessions run          %d (asked %d, seed %llu, %.1f s, %.2f s per session)\n", ended, sessions,
                static_cast<unsigned long long>(seed), seconds, ended ? seconds / ended : 0.0);
    std::printf("soak: visitors              %d started, %d kept, %d walked away in a guide, %d left the reveal, "
                "%d front and %d side retakes\n",
                t.started, kept, t.walkedAwayInGuide, t.walkedAwayAtReveal, t.retakesFront, t.retakesSide);
    std::printf("soak: crashes               %d\n", crashes);
    std::printf("soak: sessions checked      %d complete (%zu with their toon strip), %zu incomplete or corrupt, "
                "%d pending seen between sessions (writes in flight), %zu stuck\n",
                probe.checkedComplete, probe.withToon.size(), probe.problems.size(), probe.leftoversSeen,
                probe.stuck.size());
    std::printf("soak: rss MB                peak %.1f (whole run), after warm-up (%d sessions) %.1f, final %.1f "
                "(single readings: %+.2f), peak after warm-up %.1f\n",
                end.peakRssMegabytes, warmup, warm.rssMegabytes, last.rssMegabytes, singleDrift, peakAfterWarmup);
    std::printf("soak: rss drift MB          %+.2f: settled %.1f over the last %zu sessions (median of %s) "
                "- %.1f over the first %zu after warm-up (median of %s)\n",
                drift, settledLast.megabytes, window, settledLast.over.c_str(), settledFirst.megabytes, window,
                settledFirst.over.c_str());
    std::printf("soak: rss MB by session     %s\n", points.c_str());
    std::printf("soak: rss slope MB/100      %+.2f after warm-up, %+.2f over the second half\n", slopePer100(s, w, rss),
                slopePer100(s, half, rss));
    std::printf("soak: heap MB by session    %s (in use/free in the arenas)\n", heapPoints.c_str());
    std::printf("soak: heap slope MB/100     in use %+.2f after warm-up, %+.2f over the second half; free %+.2f\n",
                slopePer100(s, w, inUse), slopePer100(s, half, inUse), slopePer100(s, w, heapFree));
    std::printf("soak: open files            after warm-up %d, final %d, range %d..%d (over the %d ends with no "
                "write in flight)\n", warm.openFiles, last.openFiles, minFds, maxFds, quietSamples);
    std::printf("soak: threads               after warm-up %d, final %d, range %d..%d\n", warm.threads,
                last.threads, minThreads, maxThreads);
    if (!samplesCsv.empty()) {
        // Every sample (written whole or not at all; also every 100 sessions while the run goes on).
        try {
            writeFileAtomically(samplesCsv, samplesCsvText(s));
            std::printf("soak: samples               %s\n", samplesCsv.c_str());
        } catch (const std::exception& e) {
            std::printf("soak: samples               not written: %s\n", e.what());
        }
    }
    for (const auto& p : probe.stuck) std::printf("soak: STUCK %s\n", p.c_str());
    for (const auto& p : probe.problems) std::printf("soak: PROBLEM %s\n", p.c_str());

    bool ok = true;
    const auto fail = [&](const std::string& why) {
        std::printf("soak: FAIL %s\n", why.c_str());
        ok = false;
    };
    if (crashes != 0) fail("the kiosk crashed");
    if (ended < sessions) fail("fewer sessions than asked");
    if (!probe.problems.empty()) fail("incomplete or corrupt session folders");
    if (!probe.stuck.empty()) fail("pending or half-deleted folders left behind");
    if (drift >= maxDrift) fail("memory drift after warm-up above " + std::to_string(maxDrift) + " MB");
    if (maxFds != minFds) fail("the number of open files changed after warm-up");
    if (maxThreads != minThreads) fail("the number of threads changed after warm-up");
    if (kept == 0) fail("no session was kept");
    std::printf("soak: %s\n", ok ? "PASS" : "FAIL");
    return ok ? 0 : 1;
}
