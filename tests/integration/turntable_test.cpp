// The visitor's turntable picture (issue 23): made from a kept session's avatar.glb with the booth's renderer
// (headless EGL) and libwebp's WebPAnimEncoder, read back with libwebp's own WebPAnimDecoder: one loop of 36
// frames of 320 x 320 whose views turn (the first and the half-turn differ, the last comes back near the first),
// small enough for a phone on the booth's Wi-Fi; the page offers it. Its cost is printed.
#include "booth/session_store.h"
#include "booth/share_link.h"
#include "common/atomic_output.h"
#include "fit/export/glb.h"
#include "kiosk/turntable_worker.h"
#include "share/share_site.h"
#include "test_paths.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <webp/demux.h>

#include <cmath>
#include <fstream>

using namespace avatarbooth;
namespace fs = std::filesystem;

namespace {

// A head-sized ellipsoid whose texture is red on one side and blue on the other: as it turns, the colour in the
// middle of the picture changes.
Mesh ellipsoid() {
    Mesh m;
    const int rings = 24, segments = 48;
    for (int r = 0; r <= rings; ++r)
        for (int s = 0; s <= segments; ++s) {
            const double v = static_cast<double>(r) / rings, u = static_cast<double>(s) / segments;
            const double theta = v * M_PI, phi = u * 2.0 * M_PI;
            m.positions.push_back({75.0 * std::sin(theta) * std::sin(phi), 110.0 * std::cos(theta),
                                   95.0 * std::sin(theta) * std::cos(phi)});
            m.uvs.push_back({u, v});
        }
    for (int r = 0; r < rings; ++r)
        for (int s = 0; s < segments; ++s) {
            const auto a = static_cast<unsigned>(r * (segments + 1) + s), b = a + segments + 1;
            m.triangles.push_back({a, b, a + 1});
            m.triangles.push_back({a + 1, b, b + 1});
        }
    return m;
}

}  // namespace

TEST(TurntableWebp, MadeFromAKeptSessionOfferedByItsPageAndItsCostIsPrinted) {
    const fs::path dir = test::scratchDir("turntable_webp");
    SessionStoreSettings settings;
    settings.directory = dir / "sessions";
    SessionStore store(settings);
    const fs::path pending = store.pendingPath();
    {
        StagedDirectory staged(pending, "fit.json");
        cv::Mat texture(256, 256, CV_8UC3, cv::Scalar(40, 40, 220));
        texture.colRange(128, 256).setTo(cv::Scalar(220, 60, 40));
        writeFileAtomically(staged.staging() / "avatar.glb", encodeGlb(ellipsoid(), texture, "avatar"));
        writeFileAtomically(staged.staging() / "fit.json", "{}");
        staged.commit();
    }
    const std::string code = store.keep(pending, std::chrono::system_clock::now());
    const fs::path kept = *store.find(code);

    const TurntableEnded made = makeTurntable(kept);
    std::printf("turntable.webp: %zu KB, rendered in %.2f s, encoded in %.2f s (36 frames of 320 x 320)\n",
                made.bytes / 1024, made.renderSeconds, made.encodeSeconds);
    std::ifstream in(kept / "turntable.webp", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_EQ(bytes.size(), made.bytes);
    EXPECT_LT(bytes.size(), 600u * 1024) << "a few hundred KB at most";

    // libwebp's own decoder: an animation of 36 frames that loops forever.
    WebPData data{reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()};
    WebPAnimDecoderOptions options;
    ASSERT_TRUE(WebPAnimDecoderOptionsInit(&options));
    options.color_mode = MODE_BGRA;
    std::unique_ptr<WebPAnimDecoder, decltype(&WebPAnimDecoderDelete)> decoder(WebPAnimDecoderNew(&data, &options),
                                                                              WebPAnimDecoderDelete);
    ASSERT_TRUE(decoder) << "not an animated WebP";
    WebPAnimInfo info;
    ASSERT_TRUE(WebPAnimDecoderGetInfo(decoder.get(), &info));
    EXPECT_EQ(info.canvas_width, 320u);
    EXPECT_EQ(info.canvas_height, 320u);
    EXPECT_EQ(info.frame_count, 36u);
    EXPECT_EQ(info.loop_count, 0u);
    std::vector<cv::Scalar> middles;
    int lastTimestamp = 0;
    while (WebPAnimDecoderHasMoreFrames(decoder.get())) {
        uint8_t* pixels = nullptr;
        ASSERT_TRUE(WebPAnimDecoderGetNext(decoder.get(), &pixels, &lastTimestamp));
        const cv::Mat frame(320, 320, CV_8UC4, pixels);
        middles.push_back(cv::mean(frame(cv::Rect(140, 140, 40, 40))));
    }
    ASSERT_EQ(middles.size(), 36u);
    EXPECT_EQ(lastTimestamp, 36 * 80) << "80 ms a frame";
    // A quarter turn one way shows the red half, the other way the blue one.
    const auto redness = [](const cv::Scalar& c) { return c[2] - c[0]; };
    EXPECT_GT(std::abs(redness(middles[9]) - redness(middles[27])), 80.0) << "a quarter turn each way: red, then blue";
    EXPECT_LT(std::abs(redness(middles[0]) - redness(middles[35])), std::abs(redness(middles[9]) - redness(middles[27])) / 2)
        << "the loop closes";

    // The visitor's page links it and serves it as image/webp.
    ShareSettings share;
    share.enabled = true;
    const std::string token = readShareToken(kept).value();
    ShareSite site(share, settings, "");
    const ShareResponse page = site.answer("GET", "/s/" + token, std::chrono::system_clock::now());
    EXPECT_NE(page.body.find("/s/" + token + "/turntable.webp"), std::string::npos) << page.body;
    const ShareResponse file = site.answer("GET", "/s/" + token + "/turntable.webp", std::chrono::system_clock::now());
    EXPECT_EQ(file.status, 200);
    EXPECT_EQ(file.body, bytes);
}
