// `avatarbooth bench --front F --side S [-n N]`: per-stage wall times of the fit (medians over N runs), with
// model loading reported apart. Prints figures; never fails on speed.
#include "cli/commands.h"

#include "fit/head/base_head.h"

#include "common/image_io.h"
#include "common/recent_timings.h"
#include "fit/fit_pipeline.h"
#include "kiosk/kiosk.h"

#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <thread>

namespace avatarbooth {
namespace {

std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);)
        if (line.rfind("model name", 0) == 0) return line.substr(line.find(':') + 2);
    return "unknown CPU";
}

// The 1-minute load average, as /proc/loadavg gives it.
std::string loadAverage() {
    std::ifstream in("/proc/loadavg");
    std::string first;
    in >> first;
    return first.empty() ? "unknown" : first;
}

}  // namespace

void registerBenchCommand(CLI::App& app) {
    auto* cmd = app.add_subcommand("bench", "Time each stage of the fit on one photo pair (medians over runs)");
    struct Options {
        FitPhotoFiles inputs;
        int runs = 5;
        std::string heap = "fit";
    };
    auto o = std::make_shared<Options>();
    cmd->add_option("--front", o->inputs.front, "Front photo")->required();
    cmd->add_option("--side", o->inputs.side, "Side photo")->required();
    cmd->add_option("--background", o->inputs.background, "Empty-booth photo");
    cmd->add_option("-n,--runs", o->runs, "Runs (the first is a warm-up and not counted)")->capture_default_str()->check(CLI::Range(2, 1000));
    cmd->add_option("--heap", o->heap,
                    "Allocator settings: fit (as `fit` and `batch`: freed buffers kept for reuse) or kiosk (as `run`: "
                    "large blocks handed back to the system, two arenas)")
        ->capture_default_str()
        ->check(CLI::IsMember({"fit", "kiosk"}));
    cmd->callback([o] {
        if (o->heap == "kiosk") tuneAllocatorForKiosk();
        const auto base = productBaseHead();
        const FitPipeline pipeline{FitSettings{}, *base};
        const cv::Mat front = readPhoto(o->inputs.front), side = readPhoto(o->inputs.side);
        const cv::Mat background = o->inputs.background.empty() ? cv::Mat() : readPhoto(o->inputs.background);
        std::map<std::string, RecentTimings> times, cpuTimes;  // keeps 2000: every run (at most 1000)
        std::vector<std::string> order;
        RecentTimings totals, cpuTotals;
        for (int i = 0; i < o->runs; ++i) {
            const FitOutcome out = pipeline.fit(front, side, background, FitPhotoNames::of(o->inputs));
            if (i == 0) {
                for (const auto& [name, s] : out.stageSeconds) order.push_back(name);
                continue;  // warm-up: caches, lazy initialisation
            }
            double total = 0.0, cpuTotal = 0.0;
            for (const auto& [name, s] : out.stageSeconds) {
                times[name].add(s);
                total += s;
            }
            for (const auto& [name, s] : out.stageCpuSeconds) {
                cpuTimes[name].add(s);
                cpuTotal += s;
            }
            totals.add(total);
            cpuTotals.add(cpuTotal);
        }
        std::cout << "machine: " << cpuModel() << ", " << std::thread::hardware_concurrency() << " threads\n"
                  << "photos: front " << front.cols << "x" << front.rows << ", side " << side.cols << "x" << side.rows
                  << "; " << o->runs - 1 << " timed runs (after one warm-up)\n"
                  << "heap: " << (o->heap == "kiosk" ? "as the kiosk's (128 kB mmap threshold, two arenas)" : "as `fit`'s (freed buffers up to 32 MB kept for reuse)") << "\n"
                  << "model loading (once, apart): " << static_cast<int>(pipeline.modelLoadSeconds() * 1000) << " ms\n"
                  << "load average when done: " << loadAverage()
                  << " (wall times grow with other work on the machine; processor time is the work itself, all threads)\n";
        for (const auto& name : order)
            std::printf("  %-18s median %7.1f ms   worst %7.1f ms   processor %7.1f ms\n", name.c_str(),
                        1000 * times[name].median(), 1000 * times[name].slowest(), 1000 * cpuTimes[name].median());
        std::printf("  %-18s median %7.1f ms   worst %7.1f ms   processor %7.1f ms   (issue 21: under 200 ms for a 972x544 pair)\n",
                    "whole fit", 1000 * totals.median(), 1000 * totals.slowest(), 1000 * cpuTotals.median());
    });
}

}  // namespace avatarbooth
