// The batch runner: a shared queue of items, N worker threads, skip/force, clean stop, progress.
#include "batch/batch_runner.h"

#include <chrono>
#include <exception>
#include <mutex>
#include <optional>
#include <thread>

namespace avatarbooth {
namespace fs = std::filesystem;

nlohmann::json recordToJson(const SessionRecord& r) {
    nlohmann::json j;
    j["id"] = r.id;
    j["status"] = r.ok ? "ok" : "failed";
    j["reused"] = r.reused;
    j["source"] = r.source;
    j["front"] = r.front;
    j["side"] = r.side;
    if (!r.ok) {
        j["reason"] = r.reason;
        j["message"] = r.message;
    }
    j["seconds"] = r.seconds;
    nlohmann::json stages = nlohmann::json::array();
    for (const auto& [name, s] : r.stageSeconds) stages.push_back({{"stage", name}, {"seconds", s}});
    j["stages"] = stages;
    if (r.ok) {
        j["residual_rms_mm"] = r.residualRmsMm;
        j["residual_max_mm"] = r.residualMaxMm;
        j["residual_worst_point"] = r.residualWorstPoint;
    }
    j["warnings"] = r.warnings;
    j["files"] = r.files;
    return j;
}

SessionRecord recordFromJson(const nlohmann::json& j) {
    SessionRecord r;
    r.id = j.at("id").get<std::string>();
    r.ok = j.at("status").get<std::string>() == "ok";
    r.reused = j.value("reused", false);
    r.source = j.value("source", "");
    r.front = j.value("front", "");
    r.side = j.value("side", "");
    r.reason = j.value("reason", "");
    r.message = j.value("message", "");
    r.seconds = j.value("seconds", 0.0);
    if (j.contains("stages"))
        for (const auto& s : j.at("stages")) r.stageSeconds.emplace_back(s.at("stage").get<std::string>(), s.at("seconds").get<double>());
    r.residualRmsMm = j.value("residual_rms_mm", 0.0);
    r.residualMaxMm = j.value("residual_max_mm", 0.0);
    r.residualWorstPoint = j.value("residual_worst_point", "");
    if (j.contains("warnings")) r.warnings = j.at("warnings").get<std::vector<std::string>>();
    if (j.contains("files")) r.files = j.at("files").get<std::map<std::string, std::string>>();
    return r;
}

fs::path sessionFolder(const fs::path& out, const std::string& id) { return out / "sessions" / id; }
fs::path reportFilesFolder(const fs::path& out, const std::string& id) { return out / "report_files" / id; }

bool sessionComplete(const fs::path& out, const std::string& id) {
    std::error_code ec;
    return fs::is_regular_file(sessionFolder(out, id) / "fit.json", ec);
}

BatchRunResult runBatch(const std::vector<BatchItem>& items, const BatchRunOptions& options, const WorkerFactory& makeWorker) {
    using Clock = std::chrono::steady_clock;
    const auto t0 = Clock::now();
    const int jobs = std::max(1, std::min<int>(options.jobs, std::max<int>(1, static_cast<int>(items.size()))));
    std::vector<std::optional<SessionRecord>> records(items.size());
    std::atomic<std::size_t> next{0};
    std::atomic<bool> interrupted{false};
    std::atomic<bool> workerFailed{false};
    std::mutex lock;
    std::exception_ptr firstError;
    BatchProgress progress;
    progress.total = static_cast<int>(items.size());
    const std::atomic<bool> never{false};
    const std::atomic<bool>& stop = options.stop ? *options.stop : never;

    const auto finish = [&](std::size_t i, SessionRecord record) {
        const std::lock_guard<std::mutex> guard(lock);
        records[i] = std::move(record);
        const SessionRecord& r = *records[i];
        ++progress.done;
        if (r.reused) ++progress.reused;
        if (r.ok) ++progress.ok; else ++progress.failed;
        progress.elapsedSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
        progress.last = &r;
        if (options.onProgress) options.onProgress(progress);
        progress.last = nullptr;
    };

    const auto work = [&] {
        std::unique_ptr<BatchWorker> worker;
        try {
            worker = makeWorker();
        } catch (...) {
            const std::lock_guard<std::mutex> guard(lock);
            if (!firstError) firstError = std::current_exception();
            workerFailed = true;
            return;
        }
        for (;;) {
            if (stop.load() || workerFailed.load()) {
                if (stop.load()) interrupted = true;
                return;
            }
            const std::size_t i = next.fetch_add(1);
            if (i >= items.size()) return;
            const BatchItem& item = items[i];
            const auto s0 = Clock::now();
            try {
                if (!options.force && item.problem.empty() && sessionComplete(options.out, item.id)) {
                    finish(i, worker->reuse(item));
                } else {
                    SessionRecord r = worker->process(item, stop);
                    r.seconds = std::chrono::duration<double>(Clock::now() - s0).count();
                    finish(i, std::move(r));
                }
            } catch (const BatchInterrupted&) {
                interrupted = true;
                return;
            } catch (const std::exception& e) {
                // A worker is meant to turn every failure of an item into a record; anything else is still only
                // this item's failure, not the end of the run.
                SessionRecord r;
                r.id = item.id;
                r.source = item.source;
                r.front = item.front.string();
                r.side = item.side.string();
                r.reason = "internal";
                r.message = e.what();
                finish(i, std::move(r));
            }
        }
    };

    std::vector<std::thread> threads;
    for (int k = 1; k < jobs; ++k) threads.emplace_back(work);
    work();  // the calling thread is one of the workers
    for (auto& t : threads) t.join();
    if (firstError) std::rethrow_exception(firstError);

    BatchRunResult result;
    result.jobs = jobs;
    result.interrupted = interrupted.load() || (stop.load() && next.load() < items.size());
    for (auto& r : records)
        if (r) result.records.push_back(std::move(*r));
    result.wallSeconds = std::chrono::duration<double>(Clock::now() - t0).count();
    return result;
}

}  // namespace avatarbooth
