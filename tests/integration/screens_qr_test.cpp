// The thanks screen's QR code (issue 23): at every screen size and in both orientations `zbarimg` (Debian
// zbar-tools, a real scanner's decoder) reads the visitor's URL back from the screenshot, the code is drawn with
// whole pixels per module at a size that scans from 1 m, it never covers the short code, and there is no QR code
// when sharing is off. Also the time from "keep" to the QR code on screen.
#include "booth/screens/qr_code.h"
#include "booth/screens/screens.h"
#include "booth/session_store.h"
#include "booth/share_link.h"
#include "common/atomic_output.h"
#include "test_paths.h"

#include <opencv2/imgcodecs.hpp>

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

std::string zbar(const fs::path& png) {
    std::string out;
    FILE* pipe = popen(("zbarimg --raw -q " + png.string() + " 2>/dev/null").c_str(), "r");
    if (!pipe) return "popen failed";
    char buffer[4096];
    while (std::fgets(buffer, sizeof buffer, pipe)) out += buffer;
    pclose(pipe);
    while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
    return out;
}

bool haveZbar() { return std::system("command -v zbarimg >/dev/null 2>&1") == 0; }

}  // namespace

TEST(ScreensQr, ModulesAreLibqrencodes) {
    const cv::Mat m = encodeQrModules("http://10.42.0.1/s/" + std::string(32, 'a'));
    ASSERT_FALSE(m.empty());
    EXPECT_EQ(m.rows, m.cols);
    EXPECT_EQ((m.cols - 17) % 4, 0) << "a QR code is 17 + 4 * version modules wide";
    // The three finder patterns: dark 7x7 rings in three corners.
    for (const cv::Point corner : {cv::Point(0, 0), cv::Point(m.cols - 7, 0), cv::Point(0, m.rows - 7)}) {
        EXPECT_EQ(m.at<uchar>(corner.y, corner.x), 1);
        EXPECT_EQ(m.at<uchar>(corner.y + 1, corner.x + 1), 0);
        EXPECT_EQ(m.at<uchar>(corner.y + 3, corner.x + 3), 1);
    }
    const cv::Mat image = drawQrCode(m, 5);
    EXPECT_EQ(image.cols, (m.cols + 2 * kQrQuietModules) * 5);
}

TEST(ScreensQr, ThanksScreenQrScansBackAtEverySize) {
    if (!haveZbar()) GTEST_SKIP() << "zbarimg (Debian zbar-tools) is not installed";
    const fs::path dir = test::scratchDir("screens_qr");
    const std::string url = "http://10.42.0.1/s/" + makeShareToken();
    for (const Language language : {Language::English, Language::Japanese}) {
        for (const cv::Size size : {cv::Size(1280, 720), cv::Size(720, 1280), cv::Size(800, 480), cv::Size(1920, 1080),
                                    cv::Size(320, 240)}) {
            ScreenSettings s;
            s.size = size;
            s.language = language;
            ScreenRenderer r(s);
            ScreenModel m;
            m.id = ScreenId::Thanks;
            m.code = "AB3K7Z";
            m.shareUrl = url;
            const cv::Mat screen = r.draw(m, {}).clone();
            const std::string name = std::string(language == Language::English ? "en" : "ja") + "_" +
                                     std::to_string(size.width) + "x" + std::to_string(size.height);
            const fs::path png = dir / ("thanks_qr_" + name + ".png");
            cv::imwrite(png.string(), screen);
            EXPECT_EQ(zbar(png), url) << name;
            const ScreenLayout& L = r.layout();
            EXPECT_TRUE((L.qr & L.codeBesideQr).empty()) << name << ": the QR code covers the short code";
            EXPECT_EQ(L.qr & cv::Rect(0, 0, size.width, size.height), L.qr) << name;
            // Without sharing: the plain thanks screen, no code to scan.
            m.shareUrl.clear();
            const fs::path plain = dir / ("thanks_plain_" + name + ".png");
            cv::imwrite(plain.string(), r.draw(m, {}));
            EXPECT_EQ(zbar(plain), "") << name;
        }
    }
}

// To scan from 1 m a code wants about 10 cm across (a tenth of the distance): on a 15.6" 16:9 panel (194 mm tall)
// that is 0.52 of the height. The QR code takes at least that, and at least 8 pixels per module at 1280x720.
TEST(ScreensQr, BigEnoughToScanFromOneMetre) {
    ScreenSettings s;
    s.size = {1280, 720};
    ScreenRenderer r(s);
    const std::string url = "http://10.42.0.1/s/" + makeShareToken();
    const cv::Mat modules = encodeQrModules(url);
    const int perModule = r.layout().qr.width / (modules.cols + 2 * kQrQuietModules);
    const int drawn = perModule * modules.cols;  // the dark part, without the quiet zone
    std::printf("[ figures ] QR code at 1280x720: %d modules, %d px per module, %d px across (%.0f%% of the height)\n",
                modules.cols, perModule, drawn, 100.0 * drawn / 720);
    EXPECT_GE(perModule, 8);
    EXPECT_GE(drawn, static_cast<int>(0.45 * 720));
}

// From the keep (the session moved under its code, its token written) to the thanks screen drawn with the QR code:
// the booth's own share of "keep to QR on screen" (the flow adds one frame, 1/30 s, to show it).
TEST(ScreensQr, KeepToQrTimeIsPrinted) {
    const fs::path dir = test::scratchDir("screens_qr_keep");
    SessionStoreSettings settings;
    settings.directory = dir / "sessions";
    SessionStore store(settings);
    ShareSettings share;
    share.enabled = true;
    ScreenSettings s;
    ScreenRenderer r(s);
    std::vector<double> ms;
    for (int i = 0; i < 5; ++i) {
        const fs::path pending = store.pendingPath();
        {
            StagedDirectory staged(pending, "fit.json");
            writeFileAtomically(staged.staging() / "avatar.glb", std::string(800000, 'g'));
            writeFileAtomically(staged.staging() / "fit.json", "{}");
            staged.commit();
        }
        const auto t0 = std::chrono::steady_clock::now();
        const std::string code = store.keep(pending, std::chrono::system_clock::now());
        ScreenModel m;
        m.id = ScreenId::Thanks;
        m.code = code;
        m.shareUrl = sharePageUrl(share, readShareToken(*store.find(code)).value());
        r.draw(m, {});
        ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    std::sort(ms.begin(), ms.end());
    std::printf("[ figures ] keep -> thanks screen with its QR code drawn: median %.1f ms (of 5, 1280x720)\n", ms[2]);
    EXPECT_GT(ms[2], 0.0);
}
