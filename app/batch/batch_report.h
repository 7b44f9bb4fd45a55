// A batch's results for people and scripts: OUT/summary.json (counts, failures by reason, per-stage time median and
// worst, one entry per session) and OUT/report.html (the same, with photos, landmark overlays and a 3-D view of
// every avatar through Google's <model-viewer>, copied next to the report so that it opens without a network).
#pragma once

#include "batch/batch_runner.h"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace avatarbooth {

// Median (the mean of the two middle values for an even count) and worst (largest) of a set of values, with the
// session the worst belongs to. All zero for an empty set.
struct SampleStats {
    double median = 0.0;
    double worst = 0.0;
    std::string worstSession;
    int count = 0;
};
SampleStats sampleStats(std::vector<std::pair<double, std::string>> valuesAndSessions);

// The summary of a set of session records. `run` holds facts about how they were made (input, shard, jobs, wall
// time, interrupted, ...) and is stored as is under "run". Stage statistics cover the sessions that are ok, in the
// pipeline's stage order; failures are counted by reason.
nlohmann::json summarize(const std::vector<SessionRecord>& records, const nlohmann::json& run);

// The records of a summary.json (as written by summarize).
std::vector<SessionRecord> recordsOfSummary(const nlohmann::json& summary);

// Where the report's copy of <model-viewer> comes from: `given` when not empty, else $AVATARBOOTH_MODEL_VIEWER, else
// model-viewer-umd.min.js in <exe>/../share/avatarbooth/model-viewer/, in the source tree's app/assets/report/
// node_modules (tests/setup.sh installs it with npm), or /usr/share/avatarbooth/model-viewer/. Empty when none
// exists (the report then says so where the 3-D views would be).
std::filesystem::path findModelViewer(const std::string& given = {});

// Writes OUT/summary.json and OUT/report.html (atomically), copying model-viewer to OUT/model-viewer/.
void writeSummaryAndReport(const std::filesystem::path& out, const nlohmann::json& summary,
                           const std::filesystem::path& modelViewerJs);

// Joins the summaries of several batch output folders (shards) into one summary for `out`: file paths are rewritten
// relative to `out`; a session id found in more than one part keeps its first ok entry (the others are counted
// under run.duplicates). Throws BoothError(BadInput) naming a part whose summary.json is missing or unreadable.
nlohmann::json mergeSummaries(const std::vector<std::filesystem::path>& parts, const std::filesystem::path& out);

}  // namespace avatarbooth
