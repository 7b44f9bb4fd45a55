// The simulated booth's other paths end to end: a retake, the camera unplugged and back, the operator's menu, a
// Japanese booth, each seen in the screenshots `avatarbooth run` writes.
#include "run_binary.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <fstream>
#include <regex>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {

// The screenshots of a run, in the order shown, with their index prefixes cut ("attract", "front_guide", ...).
std::vector<std::string> screensShown(const fs::path& dir) {
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(dir)) files.push_back(e.path().filename().string());
    std::sort(files.begin(), files.end());
    std::vector<std::string> names;
    for (const auto& f : files) names.push_back(f.substr(3, f.size() - 3 - 4));
    return names;
}

fs::path screenshot(const fs::path& dir, const std::string& name) {
    for (const auto& e : fs::directory_iterator(dir)) {
        const std::string f = e.path().filename().string();
        if (f.size() > 7 && f.substr(3, f.size() - 7) == name) return e.path();
    }
    return {};
}

// A sim booth config in `dir`; `extra` is appended (more tables).
fs::path writeConfig(const fs::path& dir, const std::string& extra) {
    const fs::path config = dir / "booth.toml";
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n"
                          << extra;
    return config;
}

// The share of pixels that differ (any channel by more than 40) inside `box` of two screenshots.
double differingShare(const cv::Mat& a, const cv::Mat& b, cv::Rect box) {
    int n = 0;
    for (int y = box.y; y < box.br().y; ++y)
        for (int x = box.x; x < box.br().x; ++x) {
            const cv::Vec3b p = a.at<cv::Vec3b>(y, x), q = b.at<cv::Vec3b>(y, x);
            if (std::abs(p[0] - q[0]) > 40 || std::abs(p[1] - q[1]) > 40 || std::abs(p[2] - q[2]) > 40) ++n;
        }
    return static_cast<double>(n) / box.area();
}

}  // namespace

// The operator holds the lock, frees disk and leaves; then a visitor asks to retake the side photo, loses the
// camera in the front guide (it comes back) and keeps the avatar. The booth speaks Japanese.
TEST(KioskSim, RetakeCameraLostOperatorMenuInJapanese) {
    const fs::path dir = scratchDir("kiosk_paths_ja");
    // Short countdowns and thanks: the paths are what is tested here, not the timing. The visitor looks at the
    // avatar long enough for the reveal to be pictured (with every style: the character comes 1-4 s after the photo
    // style on a busy 2-core machine) before asking for the retake.
    const std::string quick = "[flow]\nlock_hold_s = 1.5\ncountdown_s = 1.0\nthanks_time_s = 2.0\nthanks_min_time_s = 1.0\n";
    const fs::path config = writeConfig(dir, quick + "[screen]\nlanguage = \"ja\"\n");
    const CommandResult r = runAvatarbooth("run --config " + config.string() + " --sessions 2 --screenshots " +
                                           (dir / "screens").string() +
                                           " --visitor-does operator-menu,unplug-camera,retake-side,look-at-avatar=8s");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.output, m, std::regex("kept: ([2-9A-Z]{6})"))) << r.output;
    EXPECT_TRUE(fs::is_regular_file(dir / "sessions" / m[1].str() / "avatar.glb"));
    EXPECT_FALSE(fs::exists(dir / "sessions" / ".pending") && !fs::is_empty(dir / "sessions" / ".pending"))
        << "a pending fit was left behind (the retake's first fit must be removed)";

    const std::vector<std::string> shown = screensShown(dir / "screens");
    const auto position = [&](const std::string& name, std::size_t from = 0) {
        return static_cast<std::size_t>(std::find(shown.begin() + static_cast<std::ptrdiff_t>(from), shown.end(), name) -
                                        shown.begin());
    };
    std::string all;
    for (const auto& s : shown) all += s + " ";
    // The operator: menu, the free-disk page with its figures, the menu again, back to attract.
    const std::size_t menu = position("operator_menu");
    ASSERT_LT(menu, shown.size()) << all;
    EXPECT_LT(position("operator_menu_free_disk", menu), shown.size()) << all;
    EXPECT_NE(r.output.find("operator freed disk"), std::string::npos) << r.output;
    // The camera unplugged in the front guide: the camera-lost screen, then the front guide again.
    const std::size_t lost = position("camera_lost");
    ASSERT_LT(lost, shown.size()) << all;
    ASSERT_GT(lost, 0u);
    EXPECT_EQ(shown[lost - 1], "front_guide") << all;
    ASSERT_LT(lost + 1, shown.size()) << all;
    EXPECT_EQ(shown[lost + 1], "front_guide") << all;
    EXPECT_NE(r.output.find("camera back"), std::string::npos) << r.output;
    // The retake: reveal, the question, the side guide again, and a second reveal that is kept.
    const std::size_t question = position("retake_choice");
    ASSERT_LT(question, shown.size()) << all;
    EXPECT_EQ(shown[question - 1], "reveal") << all;
    EXPECT_EQ(shown[question + 1], "side_guide") << all;
    EXPECT_LT(position("reveal", question), position("thanks", question)) << all;

    // The camera-lost screen is its own picture (what is wrong, in words), not the guide's preview.
    const cv::Mat lostPicture = cv::imread(screenshot(dir / "screens", "camera_lost").string());
    const cv::Mat guidePicture = cv::imread(screenshot(dir / "screens", "front_guide").string());
    ASSERT_FALSE(lostPicture.empty());
    ASSERT_FALSE(guidePicture.empty());
    EXPECT_GT(differingShare(lostPicture, guidePicture, cv::Rect(0, 0, lostPicture.cols, lostPicture.rows)), 0.3);
    cv::Scalar lostMean, lostStddev;
    cv::meanStdDev(lostPicture, lostMean, lostStddev);
    EXPECT_GT(lostStddev[0] + lostStddev[1] + lostStddev[2], 15.0) << "the camera-lost screen is blank";

    // Japanese text: the same screens as an English booth's, with other text. An English operator visit (short)
    // for the comparison.
    const fs::path en = scratchDir("kiosk_paths_en");
    const fs::path enConfig = writeConfig(en, quick);
    const CommandResult e = runAvatarbooth("run --config " + enConfig.string() + " --sessions 1 --screenshots " +
                                           (en / "screens").string() + " --visitor-does operator-menu");
    ASSERT_EQ(e.exitCode, 0) << e.output;
    for (const std::string name : {"attract", "operator_menu", "operator_menu_free_disk"}) {
        const cv::Mat ja = cv::imread(screenshot(dir / "screens", name).string());
        const cv::Mat english = cv::imread(screenshot(en / "screens", name).string());
        ASSERT_FALSE(ja.empty()) << name;
        ASSERT_FALSE(english.empty()) << name;
        ASSERT_EQ(ja.size(), english.size()) << name;
        // The title band (top eighth): text in both, different glyphs.
        const cv::Rect title(0, 0, ja.cols, ja.rows / 8);
        EXPECT_GT(differingShare(ja, english, title), 0.01) << name << ": the Japanese title looks like the English";
        // Glyphs were drawn in Japanese too (not an empty band): the band is not one flat colour.
        cv::Scalar mean, stddev;
        cv::meanStdDev(ja(title), mean, stddev);
        EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 15.0) << name << ": no text in the Japanese title band";
    }
}
