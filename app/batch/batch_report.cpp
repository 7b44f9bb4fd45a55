// summary.json and report.html of a batch run, and the merging of shard summaries.
#include "batch/batch_report.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/file_bytes.h"
#include "common/html_text.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <map>
#include <sstream>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

std::string html(const std::string& text) { return escapeHtml(text); }

// A relative path as a URL path: each segment percent-encoded where needed (ids are plain, input names may not be).
std::string url(const std::string& relative) {
    static constexpr char kHex[] = "0123456789ABCDEF";
    std::string out;
    for (const char ch : relative) {
        const auto c = static_cast<unsigned char>(ch);
        const bool plain = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                           c == '_' || c == '.' || c == '/' || c == '~';
        if (plain) {
            out += ch;
        } else {
            out += '%';
            out += kHex[c >> 4];
            out += kHex[c & 15];
        }
    }
    return out;
}

std::string fixed(double v, int digits) {
    std::ostringstream s;
    s.setf(std::ios::fixed);
    s.precision(digits);
    s << v;
    return s.str();
}

std::string fileOf(const nlohmann::json& session, const char* key) {
    if (!session.contains("files") || !session["files"].contains(key)) return {};
    return session["files"][key].get<std::string>();
}

constexpr const char* kViewerFile = "model-viewer-umd.min.js";

const char* kStyle = R"(
body { font-family: system-ui, sans-serif; margin: 1.5em; color: #222; }
h1 { font-size: 1.4em; } h2 { font-size: 1.15em; margin-top: 1.5em; }
table { border-collapse: collapse; } td, th { border: 1px solid #ccc; padding: 4px 8px; vertical-align: top; }
th { background: #f2f2f2; text-align: left; } td.num { text-align: right; font-variant-numeric: tabular-nums; }
tr.failed td.status { color: #b00; font-weight: bold; } tr.ok td.status { color: #070; font-weight: bold; }
.photos img { height: 150px; margin: 2px; border: 1px solid #ddd; }
model-viewer { width: 260px; height: 260px; background: #e8ecf0; }
.viewer-state { font-size: 0.8em; color: #555; } .viewer-state.error { color: #b00; font-weight: bold; }
.message { max-width: 28em; font-size: 0.9em; } .warnings { font-size: 0.8em; color: #850; }
)";

// Loads each avatar when its row comes near the screen: the glb arrives as a script (file:// pages may not fetch),
// becomes a Blob URL, and is handed to its <model-viewer>. Each viewer's state is shown and kept in data-state
// (loading / loaded / error) for people and for the browser test.
const char* kScript = R"(
(function () {
  const viewers = new Map();
  const setState = (el, state, text) => {
    el.dataset.state = state;
    const label = el.parentElement.querySelector('.viewer-state');
    if (label) { label.textContent = text; label.classList.toggle('error', state === 'error'); }
  };
  window.avatarboothGlb = (id, base64) => {
    const el = viewers.get(id);
    if (!el) return;
    const text = atob(base64);
    const bytes = new Uint8Array(text.length);
    for (let i = 0; i < text.length; ++i) bytes[i] = text.charCodeAt(i);
    el.src = URL.createObjectURL(new Blob([bytes], { type: 'model/gltf-binary' }));
  };
  const load = (el) => {
    if (el.dataset.requested) return;
    el.dataset.requested = '1';
    viewers.set(el.dataset.id, el);
    setState(el, 'loading', 'loading the avatar...');
    const script = document.createElement('script');
    script.src = el.dataset.glbJs;
    script.onerror = () => { setState(el, 'error', 'avatar file missing: ' + el.dataset.glbJs); console.error('avatar file missing: ' + el.dataset.glbJs); };
    document.head.appendChild(script);
  };
  window.avatarboothLoadAll = () => document.querySelectorAll('model-viewer[data-glb-js]').forEach(load);
  document.addEventListener('DOMContentLoaded', () => {
    const all = document.querySelectorAll('model-viewer[data-glb-js]');
    if (!customElements.get('model-viewer')) {
      all.forEach((el) => setState(el, 'error', 'the 3-D viewer (model-viewer) is not next to this report: see the README'));
      console.error('model-viewer is missing');
      return;
    }
    all.forEach((el) => {
      el.addEventListener('load', () => setState(el, 'loaded', 'drag to turn, scroll to zoom'));
      el.addEventListener('error', (e) => { setState(el, 'error', 'the avatar did not load'); console.error('model-viewer error for ' + el.dataset.id + ': ' + JSON.stringify(e.detail && e.detail.type)); });
    });
    const observer = new IntersectionObserver((entries) => entries.forEach((e) => { if (e.isIntersecting) load(e.target); }), { rootMargin: '800px' });
    all.forEach((el) => observer.observe(el));
  });
})();
)";

std::string renderHtml(const nlohmann::json& summary, bool haveViewer) {
    std::ostringstream h;
    const auto& counts = summary["counts"];
    const auto& run = summary["run"];
    h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>avatarbooth batch report</title>\n"
      << "<style>" << kStyle << "</style>\n";
    if (haveViewer) h << "<script src=\"model-viewer/" << kViewerFile << "\"></script>\n";
    h << "<script>" << kScript << "</script>\n</head>\n<body>\n<h1>avatarbooth batch report</h1>\n";
    h << "<p>" << counts.value("total", 0) << " sessions: <b>" << counts.value("ok", 0) << " ok</b>, <b>"
      << counts.value("failed", 0) << " failed</b>";
    if (counts.value("reused", 0) > 0) h << " (" << counts.value("reused", 0) << " complete from an earlier run)";
    if (run.value("interrupted", false)) h << ". <b>The run was interrupted</b>: sessions not reached are not listed";
    h << ".</p>\n<table>\n";
    for (const char* key : {"input", "shard", "jobs", "wall_seconds", "sessions_per_minute", "version"}) {
        if (!run.contains(key) || run[key].is_null()) continue;
        const auto& v = run[key];
        h << "<tr><th>" << html(key) << "</th><td>"
          << html(v.is_string() ? v.get<std::string>() : (v.is_number_float() ? fixed(v.get<double>(), 2) : v.dump()))
          << "</td></tr>\n";
    }
    if (run.contains("parts")) {
        h << "<tr><th>merged from</th><td>";
        for (const auto& p : run["parts"]) h << html(p.value("folder", "")) << " (" << p.value("sessions", 0) << " sessions)<br>";
        h << "</td></tr>\n";
    }
    h << "</table>\n";

    h << "<h2>Failures by reason</h2>\n";
    if (counts["failed_by_reason"].empty()) {
        h << "<p>None.</p>\n";
    } else {
        h << "<table><tr><th>reason</th><th>sessions</th></tr>\n";
        for (const auto& [reason, n] : counts["failed_by_reason"].items())
            h << "<tr><td>" << html(reason) << "</td><td class=\"num\">" << n.get<int>() << "</td></tr>\n";
        h << "</table>\n";
    }

    h << "<h2>Time per stage (sessions that are ok)</h2>\n<table><tr><th>stage</th><th>median s</th><th>worst s</th>"
         "<th>worst session</th></tr>\n";
    for (const auto& s : summary["stages"])
        h << "<tr><td>" << html(s.value("stage", "")) << "</td><td class=\"num\">" << fixed(s.value("median_seconds", 0.0), 3)
          << "</td><td class=\"num\">" << fixed(s.value("worst_seconds", 0.0), 3) << "</td><td>"
          << html(s.value("worst_session", "")) << "</td></tr>\n";
    const auto& rms = summary["residual_rms_mm"];
    h << "</table>\n<p>Fit residual (RMS over the feature points, mm): median " << fixed(rms.value("median", 0.0), 2)
      << ", worst " << fixed(rms.value("worst", 0.0), 2) << " (" << html(rms.value("worst_session", "")) << ").</p>\n";

    h << "<h2>Sessions</h2>\n<table id=\"sessions\">\n<tr><th>session</th><th>status</th><th>front: photo, landmarks</th>"
         "<th>side: photo, profile</th><th>avatar</th><th>fit residuals</th></tr>\n";
    for (const auto& s : summary["sessions"]) {
        const bool ok = s.value("status", "") == "ok";
        const std::string id = s.value("id", "");
        h << "<tr class=\"" << (ok ? "ok" : "failed") << "\" id=\"session-" << html(id) << "\">\n<td><b>" << html(id)
          << "</b><br><small>" << html(s.value("source", "")) << "</small></td>\n<td class=\"status\">"
          << (ok ? "ok" : "failed: " + html(s.value("reason", "")));
        if (s.value("reused", false)) h << "<br><small>(earlier run)</small>";
        if (!ok) h << "<div class=\"message\">" << html(s.value("message", "")) << "</div>";
        if (s.value("seconds", 0.0) > 0.0) h << "<br><small>" << fixed(s.value("seconds", 0.0), 1) << " s</small>";
        h << "</td>\n";
        for (const auto& pair : {std::pair<const char*, const char*>{"front", "front_overlay"}, {"side", "side_overlay"}}) {
            h << "<td class=\"photos\">";
            for (const char* key : {pair.first, pair.second}) {
                const std::string f = fileOf(s, key);
                if (!f.empty()) h << "<img src=\"" << html(url(f)) << "\" alt=\"" << html(id) << " " << key << "\">";
            }
            h << "</td>\n";
        }
        h << "<td>";
        const std::string glbJs = fileOf(s, "glb_js");
        if (ok && !glbJs.empty()) {
            h << "<model-viewer data-id=\"" << html(id) << "\" data-glb-js=\"" << html(url(glbJs))
              << "\" loading=\"eager\" camera-controls auto-rotate interaction-prompt=\"none\" alt=\"avatar of " << html(id)
              << "\"></model-viewer><div class=\"viewer-state\"></div>"
              << "<small><a href=\"" << html(url(fileOf(s, "glb"))) << "\">avatar.glb</a> &middot; <a href=\""
              << html(url(fileOf(s, "session"))) << "/\">session folder</a></small>";
        }
        h << "</td>\n<td>";
        if (ok) {
            h << "RMS " << fixed(s.value("residual_rms_mm", 0.0), 2) << " mm<br>max " << fixed(s.value("residual_max_mm", 0.0), 2)
              << " mm<br><small>" << html(s.value("residual_worst_point", "")) << "</small>";
            const auto& w = s["warnings"];
            if (!w.empty()) {
                h << "<div class=\"warnings\">";
                for (const auto& text : w) h << html(text.get<std::string>()) << "<br>";
                h << "</div>";
            }
        }
        h << "</td>\n</tr>\n";
    }
    h << "</table>\n<p><small>Made by avatarbooth " << html(summary.value("version", "")) << ". Photos are personal data: "
      << "keep this folder private.</small></p>\n</body>\n</html>\n";
    return h.str();
}

}  // namespace

SampleStats sampleStats(std::vector<std::pair<double, std::string>> values) {
    SampleStats s;
    s.count = static_cast<int>(values.size());
    if (values.empty()) return s;
    std::sort(values.begin(), values.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    const std::size_t n = values.size();
    s.median = n % 2 == 1 ? values[n / 2].first : 0.5 * (values[n / 2 - 1].first + values[n / 2].first);
    s.worst = values.back().first;
    s.worstSession = values.back().second;
    return s;
}

nlohmann::json summarize(const std::vector<SessionRecord>& records, const nlohmann::json& run) {
    nlohmann::json j;
    j["format"] = "avatarbooth-batch-summary/1";
    j["version"] = AVATARBOOTH_VERSION;
    j["run"] = run;
    int ok = 0, failed = 0, reused = 0;
    std::map<std::string, int> byReason;
    std::vector<std::string> stageOrder;
    std::map<std::string, std::vector<std::pair<double, std::string>>> stageValues;
    std::vector<std::pair<double, std::string>> rms, sessionSeconds;
    for (const auto& r : records) {
        if (r.reused) ++reused;
        if (!r.ok) {
            ++failed;
            ++byReason[r.reason];
            continue;
        }
        ++ok;
        for (const auto& [stage, seconds] : r.stageSeconds) {
            if (!stageValues.count(stage)) stageOrder.push_back(stage);
            stageValues[stage].emplace_back(seconds, r.id);
        }
        rms.emplace_back(r.residualRmsMm, r.id);
        if (!r.reused) sessionSeconds.emplace_back(r.seconds, r.id);
    }
    j["counts"] = {{"total", static_cast<int>(records.size())}, {"ok", ok}, {"failed", failed}, {"reused", reused},
                   {"failed_by_reason", byReason}};
    nlohmann::json stages = nlohmann::json::array();
    for (const auto& name : stageOrder) {
        const SampleStats s = sampleStats(stageValues[name]);
        stages.push_back({{"stage", name}, {"median_seconds", s.median}, {"worst_seconds", s.worst},
                          {"worst_session", s.worstSession}, {"sessions", s.count}});
    }
    j["stages"] = stages;
    const SampleStats r = sampleStats(rms);
    j["residual_rms_mm"] = {{"median", r.median}, {"worst", r.worst}, {"worst_session", r.worstSession}};
    const SampleStats t = sampleStats(sessionSeconds);
    j["session_seconds"] = {{"median", t.median}, {"worst", t.worst}, {"worst_session", t.worstSession}, {"sessions", t.count}};
    nlohmann::json sessions = nlohmann::json::array();
    for (const auto& rec : records) sessions.push_back(recordToJson(rec));
    j["sessions"] = sessions;
    return j;
}

std::vector<SessionRecord> recordsOfSummary(const nlohmann::json& summary) {
    std::vector<SessionRecord> records;
    for (const auto& s : summary.at("sessions")) records.push_back(recordFromJson(s));
    return records;
}

fs::path findModelViewer(const std::string& given) {
    if (!given.empty()) {
        std::error_code ec;
        if (!fs::is_regular_file(given, ec)) throw BoothError(ErrorKind::BadConfig, given, "--model-viewer: no such file");
        return given;
    }
    std::vector<fs::path> places;
    if (const char* env = std::getenv("AVATARBOOTH_MODEL_VIEWER"); env && *env) places.emplace_back(env);
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) places.push_back(exe.parent_path().parent_path() / "share" / "avatarbooth" / "model-viewer" / kViewerFile);
    places.push_back(fs::path(AVATARBOOTH_MODEL_VIEWER_DIR) / kViewerFile);  // the source tree (npm)
    places.push_back(fs::path("/usr/share/avatarbooth/model-viewer") / kViewerFile);
    for (const auto& p : places)
        if (fs::is_regular_file(p, ec)) return p;
    return {};
}

void writeSummaryAndReport(const fs::path& out, const nlohmann::json& summary, const fs::path& modelViewerJs) {
    std::error_code ec;
    fs::create_directories(out, ec);
    if (ec) throw BoothError(ErrorKind::Output, out.string(), "cannot create folder: " + ec.message());
    if (!modelViewerJs.empty()) {
        fs::create_directories(out / "model-viewer", ec);
        writeFileAtomically(out / "model-viewer" / kViewerFile, readFileBytes(modelViewerJs));
        // model-viewer is Apache-2.0 (bundling three.js, MIT): its licence travels with the copy.
        const fs::path licence = modelViewerJs.parent_path().parent_path() / "LICENSE";
        if (fs::is_regular_file(licence, ec)) writeFileAtomically(out / "model-viewer" / "LICENSE", readFileBytes(licence));
    }
    writeFileAtomically(out / "summary.json", summary.dump(2) + "\n");
    writeFileAtomically(out / "report.html", renderHtml(summary, !modelViewerJs.empty()));
}

nlohmann::json mergeSummaries(const std::vector<fs::path>& parts, const fs::path& out) {
    std::error_code ec;
    fs::create_directories(out, ec);
    const fs::path outAbs = fs::weakly_canonical(fs::absolute(out));
    std::vector<SessionRecord> merged;
    std::map<std::string, std::size_t> where;
    nlohmann::json partsJson = nlohmann::json::array();
    int duplicates = 0;
    for (const auto& part : parts) {
        const fs::path file = part / "summary.json";
        nlohmann::json summary;
        try {
            summary = nlohmann::json::parse(readFileBytes(file));
        } catch (const nlohmann::json::exception& e) {
            throw BoothError(ErrorKind::BadInput, file.string(), std::string("not valid JSON: ") + e.what());
        }
        if (summary.value("format", "") != "avatarbooth-batch-summary/1")
            throw BoothError(ErrorKind::BadInput, file.string(), "not a summary written by avatarbooth batch");
        const fs::path partAbs = fs::weakly_canonical(fs::absolute(part));
        std::vector<SessionRecord> records;
        try {
            records = recordsOfSummary(summary);
        } catch (const nlohmann::json::exception& e) {
            throw BoothError(ErrorKind::BadInput, file.string(), std::string("a session entry is malformed: ") + e.what());
        }
        partsJson.push_back({{"folder", part.string()}, {"sessions", static_cast<int>(records.size())},
                             {"run", summary.value("run", nlohmann::json::object())}});
        for (auto& r : records) {
            // Paths were relative to the part's folder; make them relative to the merged report.
            for (auto& [key, path] : r.files) path = (partAbs / path).lexically_relative(outAbs).string();
            const auto found = where.find(r.id);
            if (found == where.end()) {
                where.emplace(r.id, merged.size());
                merged.push_back(std::move(r));
            } else {
                ++duplicates;
                if (!merged[found->second].ok && r.ok) merged[found->second] = std::move(r);
            }
        }
    }
    nlohmann::json run;
    run["merged"] = true;
    run["parts"] = partsJson;
    run["duplicates"] = duplicates;
    bool interrupted = false;
    for (const auto& p : partsJson) {
        interrupted = interrupted || p["run"].value("interrupted", false);
        if (p["run"].contains("input")) run["input"] = p["run"]["input"];
    }
    run["interrupted"] = interrupted;
    // Shards interleave the input; one order for the merged report whatever the order of the parts.
    std::sort(merged.begin(), merged.end(), [](const SessionRecord& a, const SessionRecord& b) { return a.id < b.id; });
    return summarize(merged, run);
}

}  // namespace avatarbooth
