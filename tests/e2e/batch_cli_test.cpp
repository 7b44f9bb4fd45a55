// `avatarbooth batch` run as a user runs it: a small CSV manifest of real pairs with a corrupt photo and a missing
// one (summary.json, the files, a re-run that skips, the report opened in headless Chromium), a folder of session
// folders split into shards and merged, and Ctrl-C in the middle of a run.
#include "run_binary.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <set>
#include <thread>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {

nlohmann::json readJson(const fs::path& p) { return nlohmann::json::parse(readFileBytes(p)); }

fs::path frmdb(const std::string& person, const std::string& file) { return sharedData() / "frmdb" / person / file; }

void expectNoPartialFolders(const fs::path& sessions) {
    if (!fs::exists(sessions)) return;
    for (const auto& e : fs::directory_iterator(sessions)) {
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
        EXPECT_TRUE(fs::is_regular_file(e.path() / "fit.json")) << e.path() << " is not a complete session";
    }
}

int countOf(const std::string& text, const std::string& what) {
    int n = 0;
    for (auto p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
    return n;
}

}  // namespace

TEST(BatchCli, ManifestWithBadRowsThenRerunThenReportInChromium) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path dir = scratchDir("e2e_batch_manifest");
    // A photo cut short in its middle (a copy is made here, in the test's scratch folder, not in the repository).
    const std::string jpeg = readFileBytes(frmdb("004", "Img_33.jpg"));
    std::ofstream(dir / "truncated.jpg", std::ios::binary) << jpeg.substr(0, jpeg.size() / 3);
    std::ofstream(dir / "manifest.csv")
        << "session,front,side\n"
        << "p001," << frmdb("001", "Img_33.jpg").string() << "," << frmdb("001", "Img_13.jpg").string() << "\n"
        << "p002," << frmdb("002", "Img_33.jpg").string() << "," << frmdb("002", "Img_53.jpg").string() << "\n"
        << "p003," << frmdb("003", "Img_33.jpg").string() << "," << frmdb("003", "Img_13.jpg").string() << "\n"
        << "corrupt,truncated.jpg," << frmdb("004", "Img_13.jpg").string() << "\n"
        << "missing,no_such_front.jpg," << frmdb("005", "Img_13.jpg").string() << "\n";
    const fs::path out = dir / "out";
    const auto t0 = std::chrono::steady_clock::now();
    const CommandResult r = runAvatarbooth("batch " + (dir / "manifest.csv").string() + " -o " + out.string() + " -j 2");
    const double firstRun = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(r.exitCode, 9) << r.output;  // finished, some sessions failed
    EXPECT_NE(r.output.find("[5/5]"), std::string::npos) << r.output;  // plain progress lines when not on a terminal
    EXPECT_NE(r.output.find("sessions/min"), std::string::npos) << r.output;

    const nlohmann::json s = readJson(out / "summary.json");
    EXPECT_EQ(s["counts"]["total"], 5);
    EXPECT_EQ(s["counts"]["ok"], 3) << s.dump(2);
    EXPECT_EQ(s["counts"]["failed"], 2);
    EXPECT_EQ(s["counts"]["failed_by_reason"]["bad_image"], 1) << s["counts"].dump();
    EXPECT_EQ(s["counts"]["failed_by_reason"]["missing_file"], 1) << s["counts"].dump();
    EXPECT_EQ(s["run"]["jobs"], 2);
    std::set<std::string> stages;
    for (const auto& st : s["stages"]) {
        stages.insert(st["stage"].get<std::string>());
        EXPECT_GT(st["worst_seconds"].get<double>(), 0.0) << st.dump();
        EXPECT_LE(st["median_seconds"].get<double>(), st["worst_seconds"].get<double>()) << st.dump();
        EXPECT_EQ(st["sessions"], 3);
    }
    for (const char* stage : {"read_photos", "front_landmarks", "side_profile", "head_fit", "texture", "previews"})
        EXPECT_TRUE(stages.count(stage)) << stage;
    ASSERT_EQ(s["sessions"].size(), 5u);
    for (const auto& session : s["sessions"]) {
        const std::string id = session["id"];
        if (id == "corrupt" || id == "missing") {
            EXPECT_EQ(session["status"], "failed");
            const std::string message = session["message"];
            EXPECT_NE(message.find(id == "corrupt" ? "truncated.jpg" : "no_such_front.jpg"), std::string::npos) << message;
            EXPECT_FALSE(fs::exists(out / "sessions" / id)) << id;
            continue;
        }
        EXPECT_EQ(session["status"], "ok") << session.dump(2);
        EXPECT_GT(session["residual_rms_mm"].get<double>(), 0.0);
        for (const char* f : {"avatar.glb", "fit.json", "landmarks.json", "front_overlay.jpg", "side_overlay.jpg"})
            EXPECT_TRUE(fs::is_regular_file(out / "sessions" / id / f)) << id << "/" << f;
        for (const char* key : {"front", "side", "front_overlay", "side_overlay", "glb", "glb_js"}) {
            ASSERT_TRUE(session["files"].contains(key)) << id << " " << key;
            EXPECT_TRUE(fs::is_regular_file(out / session["files"][key].get<std::string>())) << id << " " << key;
        }
        const cv::Mat thumb = cv::imread((out / session["files"]["front_overlay"].get<std::string>()).string());
        ASSERT_FALSE(thumb.empty());
        EXPECT_LE(std::max(thumb.cols, thumb.rows), 320);
    }
    expectNoPartialFolders(out / "sessions");
    const std::string html = readFileBytes(out / "report.html");
    EXPECT_EQ(countOf(html, "<model-viewer "), 3);
    EXPECT_NE(html.find("model-viewer/model-viewer-umd.min.js"), std::string::npos);
    EXPECT_TRUE(fs::is_regular_file(out / "model-viewer" / "model-viewer-umd.min.js"));

    // Again: the three complete sessions are kept, the two failures tried again (and fail again).
    const auto t1 = std::chrono::steady_clock::now();
    const CommandResult again = runAvatarbooth("batch " + (dir / "manifest.csv").string() + " -o " + out.string() + " -j 2");
    const double secondRun = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    EXPECT_EQ(again.exitCode, 9) << again.output;
    EXPECT_EQ(countOf(again.output, "ok (earlier run)"), 3) << again.output;
    EXPECT_EQ(readJson(out / "summary.json")["counts"]["reused"], 3);
    EXPECT_LT(secondRun, firstRun) << "the re-run fitted again";

    // The report in a real browser: every avatar viewer loaded its model and draws it; no console errors.
    const fs::path checker = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "browser";
    ASSERT_TRUE(fs::exists(checker / "node_modules" / "puppeteer-core"))
        << "puppeteer-core is not installed in " << checker << " (tests/setup.sh installs it with npm)";
    ASSERT_TRUE(fs::exists("/usr/bin/chromium")) << "Debian's chromium is not installed (tests/setup.sh installs it)";
    const fs::path shot = dir / "report.png";
    FILE* pipe = popen(("cd '" + checker.string() + "' && node check_report.mjs '" + (out / "report.html").string() + "' '" +
                        shot.string() + "' 2>&1")
                           .c_str(),
                       "r");
    std::string browser;
    char buf[4096];
    while (fgets(buf, sizeof buf, pipe)) browser += buf;
    const int status = pclose(pipe);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << browser;
    const auto brace = browser.find('{');
    ASSERT_NE(brace, std::string::npos) << browser;
    const nlohmann::json found = nlohmann::json::parse(browser.substr(brace));
    EXPECT_EQ(found["viewers"], 3) << browser;
    EXPECT_EQ(found["loaded"], 3) << browser;
    EXPECT_TRUE(found["consoleErrors"].empty()) << browser;
    EXPECT_TRUE(found["blank"].empty()) << browser;
    EXPECT_TRUE(fs::is_regular_file(shot));
    EXPECT_GT(fs::file_size(shot), 20000u) << "the screenshot of the report is nearly empty";
}

TEST(BatchCli, SessionFoldersInShardsThenMerged) {
    const fs::path dir = scratchDir("e2e_batch_shards");
    const fs::path in = dir / "in";
    // One real session (the synthetic visitor, with a face), five photos of noise (no face) and a folder without a side.
    const CommandResult v = runAvatarbooth("make-visitor --seed 3 -o " + (in / "visitor").string());
    ASSERT_EQ(v.exitCode, 0) << v.output;
    cv::RNG rng(7);
    for (int k = 0; k < 5; ++k) {
        cv::Mat noise(240, 320, CV_8UC3);
        rng.fill(noise, cv::RNG::UNIFORM, 0, 255);
        fs::create_directories(in / ("noise" + std::to_string(k)));
        cv::imwrite((in / ("noise" + std::to_string(k)) / "front.png").string(), noise);
        cv::imwrite((in / ("noise" + std::to_string(k)) / "side.png").string(), noise);
    }
    fs::create_directories(in / "halfway");
    cv::imwrite((in / "halfway" / "front.jpg").string(), cv::Mat(240, 320, CV_8UC3, cv::Scalar(90, 90, 90)));

    std::set<std::string> seen;
    std::vector<fs::path> parts;
    for (int i = 1; i <= 2; ++i) {
        const fs::path out = dir / ("shard" + std::to_string(i));
        const CommandResult r = runAvatarbooth("batch " + in.string() + " -o " + out.string() + " -j 2 --shard " +
                                               std::to_string(i) + "/2");
        EXPECT_TRUE(r.exitCode == 0 || r.exitCode == 9) << r.output;
        const nlohmann::json s = readJson(out / "summary.json");
        EXPECT_EQ(s["run"]["shard"], std::to_string(i) + "/2");
        for (const auto& session : s["sessions"]) EXPECT_TRUE(seen.insert(session["id"].get<std::string>()).second) << session["id"];
        parts.push_back(out);
    }
    EXPECT_EQ(seen.size(), 7u);  // every session in exactly one shard

    const fs::path merged = dir / "merged";
    const CommandResult m = runAvatarbooth("batch --merge " + parts[0].string() + " " + parts[1].string() + " -o " + merged.string());
    EXPECT_EQ(m.exitCode, 9) << m.output;
    const nlohmann::json s = readJson(merged / "summary.json");
    EXPECT_EQ(s["counts"]["total"], 7);
    EXPECT_EQ(s["counts"]["ok"], 1) << s.dump(2);
    EXPECT_EQ(s["counts"]["failed_by_reason"]["no_face"], 5) << s["counts"].dump();
    EXPECT_EQ(s["counts"]["failed_by_reason"]["missing_file"], 1) << s["counts"].dump();
    for (const auto& session : s["sessions"]) {
        if (session["status"] != "ok") continue;
        // Paths now lead from the merged report into the shard that made the session.
        const std::string glb = session["files"]["glb_js"];
        EXPECT_EQ(glb.rfind("../shard", 0), 0u) << glb;
        EXPECT_TRUE(fs::is_regular_file(merged / glb)) << glb;
    }
    EXPECT_TRUE(fs::is_regular_file(merged / "report.html"));
    EXPECT_TRUE(fs::is_regular_file(merged / "model-viewer" / "model-viewer-umd.min.js"));

    const CommandResult bad = runAvatarbooth("batch " + in.string() + " -o " + (dir / "x").string() + " --shard 3/2");
    EXPECT_EQ(bad.exitCode, 6) << bad.output;
    EXPECT_NE(bad.output.find("--shard"), std::string::npos) << bad.output;
}

TEST(BatchCli, ManifestMissingColumnNamesIt) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path pairs = sharedData() / "frmdb" / "pairs.csv";
    const CommandResult r = runAvatarbooth("batch " + pairs.string() + " -o " + (scratchDir("e2e_batch_columns") / "o").string());
    EXPECT_EQ(r.exitCode, 3) << r.output;
    EXPECT_NE(r.output.find("no column 'side'"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("pairs.csv"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("profile_nose_left"), std::string::npos) << r.output;  // lists the columns there are
}

TEST(BatchCli, CtrlCKeepsFinishedSessionsOnly) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path dir = scratchDir("e2e_batch_sigint");
    const fs::path out = dir / "out";
    const fs::path log = dir / "log.txt";
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        dup2(fd, 1);
        dup2(fd, 2);
        const std::string pairs = (sharedData() / "frmdb" / "pairs.csv").string();
        execl(binary().c_str(), "avatarbooth", "batch", pairs.c_str(), "--side-column", "profile_nose_left", "-o",
              out.c_str(), "-j", "1", static_cast<char*>(nullptr));
        _exit(127);
    }
    // Wait for the first complete session, then interrupt the second (or a later one) in the middle.
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(180);
    while (!fs::exists(out / "sessions" / "001" / "fit.json") && std::chrono::steady_clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    ASSERT_TRUE(fs::exists(out / "sessions" / "001" / "fit.json")) << readFileBytes(log);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    kill(pid, SIGINT);
    int status = 0;
    waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFEXITED(status)) << readFileBytes(log);
    EXPECT_EQ(WEXITSTATUS(status), 130) << readFileBytes(log);
    EXPECT_NE(readFileBytes(log).find("interrupted"), std::string::npos) << readFileBytes(log);
    expectNoPartialFolders(out / "sessions");
    const nlohmann::json s = readJson(out / "summary.json");
    EXPECT_TRUE(s["run"]["interrupted"].get<bool>());
    std::size_t folders = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(out / "sessions")) ++folders;
    EXPECT_EQ(s["counts"]["ok"].get<std::size_t>(), folders) << s.dump(2);
    EXPECT_LT(folders, 8u);
}
