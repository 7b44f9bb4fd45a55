// Running a list of batch items on N worker threads: skipping sessions completed by an earlier run, stopping
// cleanly when asked (Ctrl-C), reporting progress, collecting one record per session.
#pragma once

#include "batch/batch_input.h"

#include <nlohmann/json.hpp>

#include <atomic>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

// The outcome of one session, as summary.json and the report show it. Paths under `files` are relative to the
// batch's output folder (so that the folder can be moved, and merged reports can point into shard folders).
struct SessionRecord {
    std::string id;
    bool ok = false;
    bool reused = false;   // complete from an earlier run, not fitted again
    std::string source;    // where the item came from ("pairs.csv:4", a folder)
    std::string front, side;
    std::string reason;    // when failed: bad_row, missing_file, bad_image, no_face, mismatch, output, internal
    std::string message;   // when failed: the error, naming the file
    double seconds = 0.0;  // wall time of this session in this run (0 when reused)
    std::vector<std::pair<std::string, double>> stageSeconds;  // from fit.json, in pipeline order
    double residualRmsMm = 0.0, residualMaxMm = 0.0;
    std::string residualWorstPoint;
    std::vector<std::string> warnings;
    std::map<std::string, std::string> files;  // session, glb, glb_js, front, side, front_overlay, side_overlay
};

nlohmann::json recordToJson(const SessionRecord& record);
SessionRecord recordFromJson(const nlohmann::json& json);

// Thrown by a worker when it notices the stop request in the middle of a session; the runner drops that session
// (its output was staged under a temporary name and is removed), it is not a failure.
struct BatchInterrupted : std::exception {
    const char* what() const noexcept override { return "batch interrupted"; }
};

// Processes items on one thread; made on that thread (an EGL context, a face detector of its own).
class BatchWorker {
public:
    virtual ~BatchWorker() = default;
    // Fits one item and writes its session folder; failures of the item are returned as a record with ok = false.
    // Throws BatchInterrupted when `stop` became true before the session was committed.
    virtual SessionRecord process(const BatchItem& item, const std::atomic<bool>& stop) = 0;
    // The record of a session completed by an earlier run (its fit.json read back), re-making report files if needed.
    virtual SessionRecord reuse(const BatchItem& item) = 0;
};
using WorkerFactory = std::function<std::unique_ptr<BatchWorker>()>;

// The output folder's layout.
std::filesystem::path sessionFolder(const std::filesystem::path& out, const std::string& id);      // OUT/sessions/ID
std::filesystem::path reportFilesFolder(const std::filesystem::path& out, const std::string& id);  // OUT/report_files/ID
// A session is complete when its folder holds fit.json, which the pipeline writes last before the folder is renamed
// into place.
bool sessionComplete(const std::filesystem::path& out, const std::string& id);

struct BatchProgress {
    int done = 0, total = 0;      // sessions finished in this run (fitted, failed or reused) out of the run's total
    int ok = 0, failed = 0, reused = 0;
    double elapsedSeconds = 0.0;
    const SessionRecord* last = nullptr;  // the session just finished
};

struct BatchRunOptions {
    std::filesystem::path out;
    int jobs = 1;
    bool force = false;                          // redo sessions an earlier run completed
    const std::atomic<bool>* stop = nullptr;     // set (e.g. from a SIGINT handler) to stop after the current stage
    std::function<void(const BatchProgress&)> onProgress;  // called under a lock, from the worker threads
};

struct BatchRunResult {
    std::vector<SessionRecord> records;  // input order; sessions not reached before a stop are absent
    bool interrupted = false;
    double wallSeconds = 0.0;
    int jobs = 1;
};

// Runs every item: sessions already complete are reused unless `force`; the others go to `jobs` workers made by
// `makeWorker` (each on its own thread). A worker that cannot be made (throws) fails the run: the exception is
// rethrown after the other workers stopped.
BatchRunResult runBatch(const std::vector<BatchItem>& items, const BatchRunOptions& options, const WorkerFactory& makeWorker);

}  // namespace avatarbooth
