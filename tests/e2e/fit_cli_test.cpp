// `avatarbooth fit` run as a user runs it: the session folder, the glb under the Khronos validator, and every
// kind of bad input answered with a clear error, its own exit code, and nothing half-written.
#include "run_binary.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <unistd.h>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {


// One synthetic visitor per test process (rendering costs a second); ctest runs each test in its own process,
// several at once, so the folder is the process's own.
const fs::path& visitor() {
    static const fs::path dir = [] {
        const fs::path d = scratchDir("e2e_visitor_" + std::to_string(getpid())) / "visitor";
        const CommandResult r = runAvatarbooth("make-visitor --seed 2 -o " + d.string());
        EXPECT_EQ(r.exitCode, 0) << r.output;
        return d;
    }();
    return dir;
}

std::string fitArgs(const fs::path& front, const fs::path& side, const fs::path& out) {
    return "fit --front '" + front.string() + "' --side '" + side.string() + "' -o '" + out.string() + "'";
}

void writeBytes(const fs::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary) << bytes;
}

// Nothing of a failed run may remain next to the output folder (no partial staging folders either).
void expectNoLeftovers(const fs::path& parent) {
    for (const auto& e : fs::directory_iterator(parent))
        EXPECT_EQ(e.path().filename().string().find(".partial-"), std::string::npos) << e.path();
}

}  // namespace

TEST(FitCli, WritesACompleteSessionFolderWithAValidGlb) {
    const fs::path out = scratchDir("e2e_fit") / "session";
    const CommandResult r = runAvatarbooth(fitArgs(visitor() / "front.jpg", visitor() / "side.jpg", out));
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("avatar written to"), std::string::npos) << r.output;
    for (const char* f : {"avatar.glb", "front.jpg", "side.jpg", "landmarks.json", "fit.json", "front_overlay.jpg",
                          "side_overlay.jpg", "preview_front.png", "preview_side.png", "preview_three_quarter.png"})
        EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
    // Photos are personal data: only the booth's user may read them.
    EXPECT_EQ(fs::status(out / "front.jpg").permissions() & fs::perms::others_read, fs::perms::none);
    const fs::path validator = fs::path(AVATARBOOTH_TEST_SOURCE_DIR) / "tests" / "gltf";
    ASSERT_TRUE(fs::exists(validator / "node_modules" / "gltf-validator"))
        << "the glTF validator is missing: run tests/setup.sh (it installs it from npm)";
    const std::string cmd = "node '" + (validator / "validate.mjs").string() + "' '" + (out / "avatar.glb").string() + "' 2>&1";
    FILE* pipe = popen(cmd.c_str(), "r");
    std::string report;
    std::array<char, 4096> buf{};
    while (fgets(buf.data(), buf.size(), pipe)) report += buf.data();
    EXPECT_EQ(pclose(pipe), 0) << report;
    EXPECT_NE(report.find("\"errors\":0"), std::string::npos) << report;
    // With the product's base head the avatar is made of parts, one node each: the brows blended, the lashes masked.
    const std::string glb = readFileBytes(out / "avatar.glb");
    ASSERT_GT(glb.size(), 20u);
    std::uint32_t jsonLength = 0;
    std::memcpy(&jsonLength, glb.data() + 12, 4);
    const std::string json = glb.substr(20, jsonLength);
    for (const char* node : {"\"name\":\"head\"", "\"name\":\"eyes\"", "\"name\":\"eyebrows\"", "\"name\":\"eyelashes\"",
                             "\"alphaMode\":\"BLEND\"", "\"alphaMode\":\"MASK\""})
        EXPECT_NE(json.find(node), std::string::npos) << node;
    // fit.json says which hair the analysis chose and by what; the avatar wears that hair (a "hair" part) or none.
    const nlohmann::json fitJson = nlohmann::json::parse(readFileBytes(out / "fit.json"));
    ASSERT_TRUE(fitJson.contains("hair")) << fitJson.dump(1);
    const std::string style = fitJson["hair"]["style"].get<std::string>();
    EXPECT_TRUE(style == "none" || style == "short" || style == "bob" || style == "long" || style == "ponytail") << style;
    EXPECT_EQ(json.find("\"name\":\"hair\"") != std::string::npos, style != "none") << style;
    const double crown = fitJson["hair"]["evidence"]["crown"].get<double>();
    EXPECT_GE(crown, 0.0);
    EXPECT_LE(crown, 1.0);
    EXPECT_EQ(fitJson["hair"]["colour_bgr"].size(), 3u);
    // ... and which MakeHuman proxy it wears (none when bald); big hair also says how it was stretched.
    if (style == "none") EXPECT_TRUE(fitJson["hair"]["proxy"].is_null());
    else EXPECT_EQ(fitJson["hair"]["proxy"].get<std::string>().rfind(style == "short" ? "short04" : style, 0), 0u) << fitJson["hair"];
    EXPECT_EQ(fitJson["hair"]["stretch"].empty(), style == "none" || style == "short") << fitJson["hair"];
    // The previews show a head, not an empty grey square.
    const cv::Mat preview = cv::imread((out / "preview_front.png").string());
    ASSERT_FALSE(preview.empty());
    cv::Mat grey, differs;
    cv::cvtColor(preview, grey, cv::COLOR_BGR2GRAY);
    cv::absdiff(grey, grey.at<unsigned char>(0, 0), differs);
    EXPECT_GT(cv::countNonZero(differs > 10), preview.total() / 5);
}

TEST(FitCli, RerunReplacesAnEarlierResultAndAFailedRunKeepsIt) {
    const fs::path dir = scratchDir("e2e_rerun");
    const fs::path out = dir / "session";
    ASSERT_EQ(runAvatarbooth(fitArgs(visitor() / "front.jpg", visitor() / "side.jpg", out)).exitCode, 0);
    const std::string before = readFileBytes(out / "fit.json");
    writeBytes(dir / "empty.jpg", "");
    const CommandResult r = runAvatarbooth(fitArgs(dir / "empty.jpg", visitor() / "side.jpg", out));
    EXPECT_EQ(r.exitCode, 3) << r.output;
    EXPECT_EQ(readFileBytes(out / "fit.json"), before) << "a failed run must leave the earlier result as it was";
    expectNoLeftovers(dir);
}

TEST(FitCli, RefusesToReplaceAFolderThatIsNotAnEarlierResult) {
    const fs::path dir = scratchDir("e2e_foreign");
    fs::create_directories(dir / "holiday");
    writeBytes(dir / "holiday" / "photo.jpg", "keep me");
    const CommandResult r = runAvatarbooth(fitArgs(visitor() / "front.jpg", visitor() / "side.jpg", dir / "holiday"));
    EXPECT_EQ(r.exitCode, 7) << r.output;
    EXPECT_EQ(readFileBytes(dir / "holiday" / "photo.jpg"), "keep me");
}

struct BadInputCase {
    const char* name;
    int exitCode;
    const char* message;  // part of the error text
};

class FitCliBadInput : public ::testing::TestWithParam<BadInputCase> {};

TEST_P(FitCliBadInput, ClearErrorOwnExitCodeNothingWritten) {
    const BadInputCase c = GetParam();
    const fs::path dir = scratchDir(std::string("e2e_bad_") + c.name);
    const std::string frontBytes = readFileBytes(visitor() / "front.jpg");
    fs::path front = visitor() / "front.jpg", side = visitor() / "side.jpg";
    const std::string which = c.name;
    if (which == "truncated_jpeg") {
        front = dir / "front.jpg";
        writeBytes(front, frontBytes.substr(0, frontBytes.size() / 2));
    } else if (which == "zero_bytes") {
        front = dir / "front.jpg";
        writeBytes(front, "");
    } else if (which == "missing_file") {
        front = dir / "nope.jpg";
    } else if (which == "directory") {
        front = dir / "front.jpg";
        fs::create_directories(front);
    } else if (which == "not_an_image") {
        front = dir / "front.jpg";
        writeBytes(front, "this is a text file, not a photo\n");
    } else if (which == "huge_png") {
        // A valid PNG signature and header declaring 100000 x 100000 pixels.
        front = dir / "front.png";
        std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\x01\x86\xa0\0\x01\x86\xa0\x08\x02\0\0\0\0\0\0\0", 33);
        writeBytes(front, png);
    } else if (which == "no_face") {
        front = visitor() / "background.png";
    } else if (which == "side_is_front") {
        side = visitor() / "front.jpg";
    } else if (which == "side_other_framing") {
        // The same side photo at 60 % size (another framing): the heads disagree in size.
        cv::Mat s = cv::imread((visitor() / "side.jpg").string()), small;
        cv::resize(s, small, cv::Size(), 0.6, 0.6, cv::INTER_AREA);
        cv::Mat canvas(s.size(), s.type(), s.at<cv::Vec3b>(0, 0));
        small.copyTo(canvas(cv::Rect((s.cols - small.cols) / 2, s.rows - small.rows, small.cols, small.rows)));
        side = dir / "side.png";
        cv::imwrite(side.string(), canvas);
    }
    const fs::path out = dir / "session";
    const CommandResult r = runAvatarbooth(fitArgs(front, side, out));
    EXPECT_EQ(r.exitCode, c.exitCode) << r.output;
    EXPECT_NE(r.output.find(c.message), std::string::npos) << r.output;
    const fs::path named = (which == "side_is_front" || which == "side_other_framing") ? side : front;
    if (which != "side_other_framing") {
        EXPECT_NE(r.output.find(named.string()), std::string::npos) << "names the file: " << r.output;
    }
    EXPECT_FALSE(fs::exists(out)) << "nothing may be written on failure";
    expectNoLeftovers(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, FitCliBadInput,
    ::testing::Values(BadInputCase{"truncated_jpeg", 3, "truncated"}, BadInputCase{"zero_bytes", 3, "empty"},
                      BadInputCase{"missing_file", 3, "not found"}, BadInputCase{"directory", 3, "not a regular file"},
                      BadInputCase{"not_an_image", 3, "not a JPEG or PNG"}, BadInputCase{"huge_png", 3, "too large"},
                      BadInputCase{"no_face", 4, "no face"}, BadInputCase{"side_is_front", 5, "front view"},
                      BadInputCase{"side_other_framing", 5, "size"}),
    [](const ::testing::TestParamInfo<BadInputCase>& p) { return std::string(p.param.name); });

TEST(FitCli, HelpAndUsageErrors) {
    const CommandResult help = runAvatarbooth("--help");
    EXPECT_EQ(help.exitCode, 0);
    EXPECT_NE(help.output.find("fit"), std::string::npos);
    EXPECT_NE(help.output.find("Exit codes"), std::string::npos);
    EXPECT_EQ(runAvatarbooth("fit --front x.jpg").exitCode, 2) << "missing --side and -o is a usage error";
    const CommandResult kernel = runAvatarbooth(fitArgs(visitor() / "front.jpg", visitor() / "side.jpg", scratchDir("e2e_kernel") / "o") + " --kernel cubic");
    EXPECT_EQ(kernel.exitCode, 6) << kernel.output;
    EXPECT_NE(kernel.output.find("--kernel"), std::string::npos) << kernel.output;
}

TEST(FitCli, ConfigFileGivesTheFitSettingsAndItsMistakesAreNamed) {
    const fs::path dir = scratchDir("e2e_fit_config");
    std::ofstream(dir / "booth.toml") << "[fit]\n\nrbf_kernel = \"cubic\"\n";
    const CommandResult bad = runAvatarbooth(fitArgs(visitor() / "front.jpg", visitor() / "side.jpg", dir / "session") + " --config " +
                                  (dir / "booth.toml").string());
    EXPECT_EQ(bad.exitCode, 6) << bad.output;
    EXPECT_NE(bad.output.find("booth.toml:3: fit.rbf_kernel: \"cubic\" is not one of"), std::string::npos) << bad.output;
    EXPECT_FALSE(fs::exists(dir / "session"));
    std::ofstream(dir / "booth.toml") << "[fit]\nrbf_kernel = \"tps\"\n";
    const CommandResult good = runAvatarbooth(fitArgs(visitor() / "front.jpg", visitor() / "side.jpg", dir / "session") +
                                   " --config " + (dir / "booth.toml").string());
    ASSERT_EQ(good.exitCode, 0) << good.output;
    std::ifstream report(dir / "session" / "fit.json");
    const std::string text((std::istreambuf_iterator<char>(report)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("\"tps\""), std::string::npos) << "the config's kernel was not used";
}
