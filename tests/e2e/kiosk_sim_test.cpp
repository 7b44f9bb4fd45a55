// The simulated booth end to end: `avatarbooth run` with the sim camera, sim buttons, a headless display and the
// simulated visitor runs one whole session, keeps it under a code, and writes a screenshot of every screen.
#include "cups_server.h"
#include "run_binary.h"
#include "wav_onsets.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <sys/wait.h>

#include <array>
#include <cstdlib>
#include <fstream>
#include <optional>
#include <regex>

namespace fs = std::filesystem;
using namespace avatarbooth::test;

namespace {


// Share of the pixels in the middle of the picture that are skin or hair coloured (red over blue), where the
// booth's background is a dark blue.
double headPixelsInMiddle(const cv::Mat& bgr) {
    const cv::Rect middle(bgr.cols / 3, bgr.rows / 5, bgr.cols / 3, bgr.rows * 3 / 5);
    int count = 0;
    for (int y = middle.y; y < middle.br().y; ++y)
        for (int x = middle.x; x < middle.br().x; ++x) {
            const cv::Vec3b p = bgr.at<cv::Vec3b>(y, x);
            if (p[2] > p[0] + 25 && p[2] > 60) ++count;
        }
    return static_cast<double>(count) / middle.area();
}

}  // namespace

TEST(KioskSim, OneScriptedSessionEndToEnd) {
    const fs::path dir = scratchDir("kiosk_sim");
    const fs::path config = dir / "booth.toml";
    // With the visitor's page on (issue 23): the thanks screen shows its QR code (nothing listens: that is
    // `avatarbooth share`'s job, tests/e2e/share_*_test.cpp).
    // With the card printer on too: a CUPS of the test's own when it runs as root with the packages (the card comes
    // out of its PDF printer), else a scheduler that is not there (the booth goes on and says the card did not print).
    std::optional<CupsServer> cups;
    if (CupsServer::missing().empty()) cups.emplace(dir / "cups");
    else std::printf("printing to a missing CUPS scheduler: %s\n", CupsServer::missing().c_str());
    if (!cups) setenv("CUPS_SERVER", (dir / "no-cupsd.sock").c_str(), 1);
    std::ofstream(config) << "[camera]\nbackend = \"sim\"\n[buttons]\nbackend = \"sim\"\n[display]\nbackend = \"headless\"\n"
                          << "[sessions]\ndirectory = \"" << (dir / "sessions").string() << "\"\n"
                          << "[share]\nenabled = true\nlisten = \"127.0.0.1:8099\"\n"
                          << "[print]\nenabled = true\nqueue = \"" << (cups ? cups->queue() : "photo") << "\"\n"
                          // and the sounds, recorded by ALSA's file output
                          << "[sound]\ndevice = \"file:FILE=" << (dir / "sound.wav").string() << ",FORMAT=wav\"\n";
    const CommandResult r = runAvatarbooth("run --config " + config.string() + " --sessions 1 --screenshots " + (dir / "screens").string());
    if (!cups) unsetenv("CUPS_SERVER");
    ASSERT_EQ(r.exitCode, 0) << r.output;

    // Kept under the code the thanks screen showed, complete, readable only by the booth's user.
    std::smatch m;
    ASSERT_TRUE(std::regex_search(r.output, m, std::regex("kept: ([2-9A-Z]{6})"))) << r.output;
    const fs::path session = dir / "sessions" / m[1].str();
    for (const char* f : {"avatar.glb", "fit.json", "landmarks.json", "front.jpg", "side.jpg", "preview_front.png"})
        EXPECT_TRUE(fs::is_regular_file(session / f)) << f;
    EXPECT_EQ(fs::status(session).permissions() & (fs::perms::group_all | fs::perms::others_all), fs::perms::none);
    EXPECT_FALSE(fs::exists(dir / "sessions" / ".pending") && !fs::is_empty(dir / "sessions" / ".pending"))
        << "a pending fit was left behind";
    // The thanks screenshot's QR code (read by zbarimg, Debian zbar-tools, as a phone would) is the kept session's
    // page: its token, from its session.json.
    if (std::system("command -v zbarimg >/dev/null 2>&1") == 0) {
        std::string qr;
        FILE* pipe = popen(("zbarimg --raw -q " + (dir / "screens" / "09_thanks.png").string() + " 2>/dev/null").c_str(), "r");
        std::array<char, 512> buf{};
        while (fgets(buf.data(), buf.size(), pipe)) qr += buf.data();
        pclose(pipe);
        std::ifstream in(session / "session.json");
        const std::string info((std::istreambuf_iterator<char>(in)), {});
        std::smatch token;
        ASSERT_TRUE(std::regex_search(info, token, std::regex("\"share_token\": \"([0-9a-f]{32})\""))) << info;
        EXPECT_EQ(qr, "http://127.0.0.1:8099/s/" + token[1].str() + "\n");
        // The page's turning picture, made after the keep.
        EXPECT_TRUE(fs::is_regular_file(session / "turntable.webp")) << r.output;
        std::smatch made;
        if (std::regex_search(r.output, made, std::regex("turntable.webp added to the kept session [^\n]*")))
            std::printf("%s\n", made[0].str().c_str());
        // Keep printed the card: it is in the session, and (with a real CUPS) its QR code comes out of the printer.
        EXPECT_TRUE(fs::is_regular_file(session / "card.pdf")) << r.output;
        if (cups) {
            ASSERT_TRUE(cups->ok()) << cups->log();
            EXPECT_NE(r.output.find("print: card " + m[1].str() + " sent"), std::string::npos) << r.output;
            fs::path printed;
            for (int i = 0; i < 300 && printed.empty(); ++i) {
                for (const auto& e : fs::directory_iterator(cups->out()))
                    if (e.path().extension() == ".pdf") printed = e.path();
                if (printed.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(100));
            }
            ASSERT_FALSE(printed.empty()) << "nothing came out of the printer\n" << cups->log();
            const fs::path page = dir / "printed";
            run("pdftoppm -r 100 -png -singlefile '" + printed.string() + "' '" + page.string() + "'");
            EXPECT_EQ(run("zbarimg --raw -q '" + page.string() + ".png'", false).out, qr);
        } else {
            EXPECT_NE(r.output.find("print: card " + m[1].str() + " not printed: no CUPS scheduler"), std::string::npos)
                << r.output;
        }
    }

    // What the visitor heard: three beeps a second apart for each photo's countdown, each photo's shutter, and the
    // reveal's chime, which here follows the side photo's shutter within a few tenths of a second (the simulated
    // fit is quick): the sound after that shutter lasts as long as the chime (1.2 s), not the shutter's 0.35 s.
    const Wav wav = readWav(dir / "sound.wav");
    const std::vector<double> heard = onsets(wav);
    std::string times;
    for (double t : heard) times += " " + std::to_string(t);
    std::printf("sounds heard at (s):%s\n", times.c_str());
    ASSERT_GE(heard.size(), 8u) << times << "\n" << r.output;
    ASSERT_LE(heard.size(), 9u) << times << "\n" << r.output;
    for (std::size_t first : {0u, 4u})
        for (std::size_t i = first; i < first + 2; ++i)
            EXPECT_NEAR(heard[i + 1] - heard[i], 1.0, 0.07) << "countdown beeps a second apart:" << times;
    std::size_t lastSound = 0;
    for (std::size_t i = 0; i < wav.samples.size(); ++i)
        if (std::abs(int{wav.samples[i]}) > 327) lastSound = i;
    EXPECT_GT(static_cast<double>(lastSound) / wav.channels / wav.rate - heard[7], 0.8) << "the reveal's chime";

    // A screenshot of every screen of the session, in the order shown.
    std::vector<std::string> shown;
    for (const auto& e : fs::directory_iterator(dir / "screens")) shown.push_back(e.path().filename().string());
    std::sort(shown.begin(), shown.end());
    const std::vector<std::string> expected = {"00_attract.png",  "01_front_guide.png",   "02_countdown.png",
                                               "03_capture_flash.png", "04_side_guide.png", "05_countdown.png",
                                               "06_capture_flash.png", "07_processing.png", "08_reveal.png",
                                               "09_thanks.png",   "10_attract.png"};
    EXPECT_EQ(shown, expected) << r.output;

    // The reveal shows the avatar: a head's worth of skin and hair in the middle of the screen; the processing
    // screen (same background, no avatar) does not.
    const cv::Mat reveal = cv::imread((dir / "screens" / "08_reveal.png").string());
    const cv::Mat processing = cv::imread((dir / "screens" / "07_processing.png").string());
    ASSERT_FALSE(reveal.empty());
    ASSERT_FALSE(processing.empty());
    EXPECT_GT(headPixelsInMiddle(reveal), 0.10);
    EXPECT_LT(headPixelsInMiddle(processing), 0.03);  // its title and spinner are orange
    // The side guide shows the visitor in profile: the mirrored preview differs from the front guide's.
    const cv::Mat front = cv::imread((dir / "screens" / "01_front_guide.png").string());
    const cv::Mat side = cv::imread((dir / "screens" / "04_side_guide.png").string());
    ASSERT_FALSE(front.empty());
    ASSERT_FALSE(side.empty());
    EXPECT_GT(cv::norm(front, side, cv::NORM_L1) / static_cast<double>(front.total()), 10.0);
}
