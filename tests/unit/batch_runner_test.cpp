// The batch runner with a stand-in worker (no fitting): every item processed once on N threads, completed sessions
// skipped on a re-run and redone with force, a stop request keeps finished sessions only; and the summary's figures
// (median and worst per stage, failures by reason) and the merge of shard summaries.
#include "batch/batch_report.h"
#include "batch/batch_runner.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <mutex>
#include <set>
#include <thread>

namespace fs = std::filesystem;
using namespace avatarbooth;

namespace {

// Writes a minimal complete session folder (fit.json marks it complete) the way the real worker does: staged, renamed.
class FakeWorker : public BatchWorker {
public:
    FakeWorker(fs::path out, std::mutex& m, std::vector<std::string>& processed, std::set<std::thread::id>& threads,
               std::chrono::milliseconds delay)
        : out_(std::move(out)), m_(m), processed_(processed), threads_(threads), delay_(delay) {}

    SessionRecord process(const BatchItem& item, const std::atomic<bool>& stop) override {
        {
            const std::lock_guard<std::mutex> g(m_);
            processed_.push_back(item.id);
            threads_.insert(std::this_thread::get_id());
        }
        SessionRecord r;
        r.id = item.id;
        if (!item.problem.empty() || item.id.find("bad") != std::string::npos) {
            r.reason = item.problem.empty() ? "no_face" : item.problemKind;
            r.message = "fails";
            return r;
        }
        StagedDirectory dir(sessionFolder(out_, item.id), "fit.json");
        std::this_thread::sleep_for(delay_);
        if (stop.load()) throw BatchInterrupted();  // nothing committed: the staging folder goes away
        writeFileAtomically(dir.staging() / "fit.json", R"({"stages":[{"stage":"a","seconds":1.0}],"residual_rms_mm":2.0})");
        dir.commit();
        r.ok = true;
        r.stageSeconds = {{"a", 1.0}};
        return r;
    }
    SessionRecord reuse(const BatchItem& item) override {
        SessionRecord r;
        r.id = item.id;
        r.ok = true;
        r.reused = true;
        return r;
    }

private:
    fs::path out_;
    std::mutex& m_;
    std::vector<std::string>& processed_;
    std::set<std::thread::id>& threads_;
    std::chrono::milliseconds delay_;
};

std::vector<BatchItem> itemsNamed(const std::vector<std::string>& ids) {
    std::vector<BatchItem> items;
    for (const auto& id : ids) items.push_back(BatchItem{id, "f.jpg", "s.jpg", {}, "test", "", ""});
    return items;
}

struct Harness {
    fs::path out;
    std::mutex m;
    std::vector<std::string> processed;
    std::set<std::thread::id> threads;
    std::chrono::milliseconds delay{5};

    BatchRunResult run(const std::vector<BatchItem>& items, int jobs, bool force, const std::atomic<bool>* stop = nullptr,
                       std::function<void(const BatchProgress&)> onProgress = {}) {
        processed.clear();
        threads.clear();
        BatchRunOptions o;
        o.out = out;
        o.jobs = jobs;
        o.force = force;
        o.stop = stop;
        o.onProgress = std::move(onProgress);
        return runBatch(items, o, [this] { return std::make_unique<FakeWorker>(out, m, processed, threads, delay); });
    }
};

}  // namespace

TEST(BatchRunner, EveryItemOnceOnSeveralThreadsInInputOrder) {
    Harness h;
    h.out = test::scratchDir("unit_batch_runner_all");
    std::vector<std::string> ids;
    for (int k = 0; k < 20; ++k) ids.push_back("s" + std::to_string(100 + k));
    ids.push_back("bad1");
    int calls = 0, lastDone = 0;
    const auto result = h.run(itemsNamed(ids), 3, false, nullptr, [&](const BatchProgress& p) {
        ++calls;
        EXPECT_EQ(p.done, lastDone + 1);  // under the runner's lock: one at a time, counting up
        lastDone = p.done;
        EXPECT_EQ(p.total, 21);
        ASSERT_NE(p.last, nullptr);
    });
    EXPECT_FALSE(result.interrupted);
    EXPECT_EQ(result.jobs, 3);
    ASSERT_EQ(result.records.size(), ids.size());
    for (std::size_t k = 0; k < ids.size(); ++k) EXPECT_EQ(result.records[k].id, ids[k]);
    EXPECT_EQ(std::set<std::string>(h.processed.begin(), h.processed.end()).size(), ids.size());
    EXPECT_EQ(h.processed.size(), ids.size());
    EXPECT_GE(h.threads.size(), 2u);
    EXPECT_EQ(calls, 21);
    EXPECT_FALSE(result.records.back().ok);
    for (int k = 0; k < 20; ++k) EXPECT_TRUE(sessionComplete(h.out, ids[static_cast<std::size_t>(k)]));
}

TEST(BatchRunner, RerunSkipsCompletedSessionsAndForceRedoesThem) {
    Harness h;
    h.out = test::scratchDir("unit_batch_runner_skip");
    const auto items = itemsNamed({"a", "b", "bad", "c"});
    h.run(itemsNamed({"a", "b"}), 2, false);
    EXPECT_EQ(h.processed.size(), 2u);

    const auto again = h.run(items, 2, false);
    // a and b were complete: reused; the failed one is tried again, as is the new one.
    EXPECT_EQ(std::set<std::string>(h.processed.begin(), h.processed.end()), (std::set<std::string>{"bad", "c"}));
    ASSERT_EQ(again.records.size(), 4u);
    EXPECT_TRUE(again.records[0].reused);
    EXPECT_TRUE(again.records[1].reused);
    EXPECT_FALSE(again.records[3].reused);

    const auto forced = h.run(items, 2, true);
    EXPECT_EQ(h.processed.size(), 4u);
    for (const auto& r : forced.records) EXPECT_FALSE(r.reused) << r.id;
}

TEST(BatchRunner, StopKeepsFinishedSessionsAndLeavesNothingPartial) {
    Harness h;
    h.out = test::scratchDir("unit_batch_runner_stop");
    h.delay = std::chrono::milliseconds(40);
    std::vector<std::string> ids;
    for (int k = 0; k < 30; ++k) ids.push_back("p" + std::to_string(k));
    std::atomic<bool> stop{false};
    const auto result = h.run(itemsNamed(ids), 2, false, &stop, [&](const BatchProgress& p) {
        if (p.done == 3) stop = true;  // as a SIGINT handler would, while other sessions are mid-way
    });
    EXPECT_TRUE(result.interrupted);
    EXPECT_GE(result.records.size(), 3u);
    EXPECT_LT(result.records.size(), ids.size());
    std::size_t complete = 0;
    for (const auto& e : fs::directory_iterator(h.out / "sessions")) {
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
        EXPECT_TRUE(fs::exists(e.path() / "fit.json")) << e.path();
        ++complete;
    }
    EXPECT_EQ(complete, result.records.size());
    // The next run picks up where this one stopped.
    const auto rest = h.run(itemsNamed(ids), 2, false);
    EXPECT_FALSE(rest.interrupted);
    EXPECT_EQ(h.processed.size(), ids.size() - complete);
}

TEST(BatchRunner, AWorkerThatCannotStartFailsTheRun) {
    BatchRunOptions o;
    o.out = test::scratchDir("unit_batch_runner_factory");
    o.jobs = 2;
    EXPECT_THROW(runBatch(itemsNamed({"a", "b"}), o, []() -> std::unique_ptr<BatchWorker> { throw std::runtime_error("no GL"); }),
                 std::runtime_error);
}

TEST(BatchSummary, MedianWorstAndFailuresByReason) {
    const SampleStats odd = sampleStats({{3.0, "a"}, {1.0, "b"}, {2.0, "c"}});
    EXPECT_DOUBLE_EQ(odd.median, 2.0);
    EXPECT_DOUBLE_EQ(odd.worst, 3.0);
    EXPECT_EQ(odd.worstSession, "a");
    const SampleStats even = sampleStats({{4.0, "a"}, {1.0, "b"}, {2.0, "c"}, {10.0, "d"}});
    EXPECT_DOUBLE_EQ(even.median, 3.0);
    EXPECT_EQ(even.worstSession, "d");
    EXPECT_EQ(sampleStats({}).count, 0);

    std::vector<SessionRecord> records(6);
    for (std::size_t k = 0; k < records.size(); ++k) records[k].id = "s" + std::to_string(k);
    records[0].ok = records[1].ok = records[2].ok = true;
    records[0].stageSeconds = {{"front_landmarks", 0.5}, {"head_fit", 2.0}};
    records[1].stageSeconds = {{"front_landmarks", 0.1}, {"head_fit", 1.0}};
    records[2].stageSeconds = {{"front_landmarks", 0.3}, {"head_fit", 9.0}};
    records[0].residualRmsMm = 1.0;
    records[1].residualRmsMm = 3.0;
    records[2].residualRmsMm = 2.0;
    records[2].reused = true;
    records[3].reason = "no_face";
    records[4].reason = "missing_file";
    records[5].reason = "no_face";
    records[5].stageSeconds = {{"front_landmarks", 100.0}};  // failed sessions do not count in the stage figures
    const nlohmann::json s = summarize(records, {{"jobs", 2}});
    EXPECT_EQ(s["counts"]["total"], 6);
    EXPECT_EQ(s["counts"]["ok"], 3);
    EXPECT_EQ(s["counts"]["failed"], 3);
    EXPECT_EQ(s["counts"]["reused"], 1);
    EXPECT_EQ(s["counts"]["failed_by_reason"]["no_face"], 2);
    EXPECT_EQ(s["counts"]["failed_by_reason"]["missing_file"], 1);
    ASSERT_EQ(s["stages"].size(), 2u);
    EXPECT_EQ(s["stages"][0]["stage"], "front_landmarks");  // pipeline order kept
    EXPECT_DOUBLE_EQ(s["stages"][0]["median_seconds"].get<double>(), 0.3);
    EXPECT_DOUBLE_EQ(s["stages"][0]["worst_seconds"].get<double>(), 0.5);
    EXPECT_EQ(s["stages"][1]["worst_session"], "s2");
    EXPECT_DOUBLE_EQ(s["residual_rms_mm"]["median"].get<double>(), 2.0);
    EXPECT_EQ(s["residual_rms_mm"]["worst_session"], "s1");
    EXPECT_EQ(s["run"]["jobs"], 2);
    // Records survive the trip through summary.json.
    const auto back = recordsOfSummary(nlohmann::json::parse(s.dump()));
    ASSERT_EQ(back.size(), records.size());
    EXPECT_EQ(back[0].stageSeconds, records[0].stageSeconds);
    EXPECT_EQ(back[3].reason, "no_face");
    EXPECT_TRUE(back[2].reused);
}

TEST(BatchSummary, MergeRewritesPathsAndJoinsShards) {
    const fs::path root = test::scratchDir("unit_batch_merge");
    const auto part = [&](const std::string& name, const std::vector<SessionRecord>& records) {
        fs::create_directories(root / name);
        writeFileAtomically(root / name / "summary.json", summarize(records, {{"shard", name}}).dump());
        return root / name;
    };
    SessionRecord a;
    a.id = "a";
    a.ok = true;
    a.files = {{"glb", "sessions/a/avatar.glb"}};
    SessionRecord b;
    b.id = "b";
    b.reason = "no_face";
    SessionRecord bAgain = b;  // the same session in two parts: its ok entry wins
    bAgain.ok = true;
    const fs::path p1 = part("shard1", {b, a});
    const fs::path p2 = part("shard2", {bAgain});
    const nlohmann::json m = mergeSummaries({p1, p2}, root / "merged");
    EXPECT_EQ(m["counts"]["total"], 2);
    EXPECT_EQ(m["counts"]["ok"], 2);
    EXPECT_EQ(m["run"]["duplicates"], 1);
    EXPECT_EQ(m["sessions"][0]["id"], "a");  // sorted by id
    EXPECT_EQ(m["sessions"][0]["files"]["glb"], "../shard1/sessions/a/avatar.glb");
    EXPECT_EQ(m["run"]["parts"].size(), 2u);
    EXPECT_THROW(mergeSummaries({root / "nothing"}, root / "merged"), BoothError);
}
