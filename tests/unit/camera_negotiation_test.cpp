// V4L2 format negotiation over hand-made format lists (what real cameras and vivid report).
#include "drivers/camera/format_negotiation.h"
#include "drivers/camera/frame_conversion.h"

#include <gtest/gtest.h>

using namespace avatarbooth;

namespace {

constexpr auto YUYV = fourccCode('Y', 'U', 'Y', 'V');
constexpr auto MJPG = fourccCode('M', 'J', 'P', 'G');
constexpr auto GREY = fourccCode('G', 'R', 'E', 'Y');
constexpr auto BA81 = fourccCode('B', 'A', '8', '1');
constexpr auto RGB3 = fourccCode('R', 'G', 'B', '3');

using S = V4l2FrameSize;

// A typical USB 2.0 webcam: YUYV is slow at high resolutions (bus bandwidth), MJPEG keeps 30 fps.
std::vector<V4l2Format> webcam() {
    return {{YUYV, "YUYV 4:2:2", {S::discrete(640, 480, 30), S::discrete(1280, 720, 10), S::discrete(1920, 1080, 5)}},
            {MJPG, "Motion-JPEG", {S::discrete(640, 480, 30), S::discrete(1280, 720, 30), S::discrete(1920, 1080, 30)}}};
}

void expectChoice(const std::optional<V4l2FormatChoice>& c, std::uint32_t fourcc, int w, int h) {
    ASSERT_TRUE(c.has_value());
    EXPECT_EQ(fourccName(c->fourcc), fourccName(fourcc));
    EXPECT_EQ(c->width, w);
    EXPECT_EQ(c->height, h);
}

}  // namespace

TEST(CameraNegotiation, WebcamPreviewTakesMjpegForTheRateAndStillTakesLargestYuyv) {
    expectChoice(negotiateV4l2Format(webcam(), 1280, 720, 30), MJPG, 1280, 720);
    // Largest size: both formats offer 1920x1080; YUYV wins the tie (no decoding, no JPEG artefacts).
    const auto still = negotiateV4l2Format(webcam(), 0, 0, 0);
    expectChoice(still, YUYV, 1920, 1080);
    EXPECT_EQ(still->maxFps, 5);
    // 640x480 at 30 fps is offered by both: YUYV.
    expectChoice(negotiateV4l2Format(webcam(), 640, 480, 30), YUYV, 640, 480);
}

TEST(CameraNegotiation, LargeEnoughSizeComesBeforeTheRate) {
    const std::vector<V4l2Format> yuyvOnly{{YUYV, "", {S::discrete(640, 480, 30), S::discrete(1280, 720, 10)}}};
    expectChoice(negotiateV4l2Format(yuyvOnly, 1280, 720, 30), YUYV, 1280, 720);
}

TEST(CameraNegotiation, AmongLargeEnoughSizesTheRateComesBeforeTheExactSize) {
    const std::vector<V4l2Format> formats{{YUYV, "", {S::discrete(1280, 720, 10)}},
                                          {MJPG, "", {S::discrete(1920, 1080, 30)}}};
    expectChoice(negotiateV4l2Format(formats, 1280, 720, 30), MJPG, 1920, 1080);
    // Without a wanted rate the exact size wins.
    expectChoice(negotiateV4l2Format(formats, 1280, 720, 0), YUYV, 1280, 720);
}

TEST(CameraNegotiation, SmallestSizeCoveringTheWantedOneWhenNoneIsExact) {
    const std::vector<V4l2Format> formats{
        {YUYV, "", {S::discrete(640, 480), S::discrete(1920, 1080), S::discrete(1600, 1200), S::discrete(1024, 768)}}};
    // 1600x1200 (1.92 Mpx) is smaller than 1920x1080 (2.07 Mpx); 1024x768 is too narrow.
    expectChoice(negotiateV4l2Format(formats, 1280, 720, 30), YUYV, 1600, 1200);
}

TEST(CameraNegotiation, LargestSizeWhenTheDeviceIsSmallerThanWanted) {
    const std::vector<V4l2Format> formats{{MJPG, "", {S::discrete(320, 240, 30), S::discrete(640, 480, 30)}}};
    expectChoice(negotiateV4l2Format(formats, 1280, 720, 30), MJPG, 640, 480);
}

TEST(CameraNegotiation, RateOfNinetyNinePercentCounts) {
    const std::vector<V4l2Format> formats{{YUYV, "", {S::discrete(1280, 720, 29.97)}},
                                          {MJPG, "", {S::discrete(1280, 720, 60)}}};
    expectChoice(negotiateV4l2Format(formats, 1280, 720, 30), YUYV, 1280, 720);
}

TEST(CameraNegotiation, UnknownRateCountsAsReachingIt) {
    const std::vector<V4l2Format> formats{{YUYV, "", {S::discrete(1280, 720, 0)}}, {MJPG, "", {S::discrete(1280, 720, 30)}}};
    expectChoice(negotiateV4l2Format(formats, 1280, 720, 30), YUYV, 1280, 720);
}

TEST(CameraNegotiation, FormatsWeCannotReadAreIgnored) {
    const std::vector<V4l2Format> sensor{{BA81, "8-bit Bayer", {S::discrete(3280, 2464, 15)}},
                                         {GREY, "grey", {S::discrete(1280, 720, 30)}}};
    EXPECT_FALSE(negotiateV4l2Format(sensor, 1280, 720, 30).has_value());
    EXPECT_FALSE(negotiateV4l2Format({}, 0, 0, 0).has_value());
    auto withRgb = sensor;
    withRgb.push_back({RGB3, "RGB24", {S::discrete(640, 480, 30)}});
    expectChoice(negotiateV4l2Format(withRgb, 1280, 720, 30), RGB3, 640, 480);
    expectChoice(negotiateV4l2Format(withRgb, 0, 0, 0), RGB3, 640, 480);
}

TEST(CameraNegotiation, SteppedRangesRoundUpToCoverAndClampToTheMaximum) {
    const std::vector<V4l2Format> range{{YUYV, "", {{16, 1920, 2, 16, 1080, 2, 0}}}};
    expectChoice(negotiateV4l2Format(range, 1280, 720, 30), YUYV, 1280, 720);
    expectChoice(negotiateV4l2Format(range, 1281, 721, 30), YUYV, 1282, 722);
    expectChoice(negotiateV4l2Format(range, 3000, 2000, 30), YUYV, 1920, 1080);
    expectChoice(negotiateV4l2Format(range, 8, 8, 30), YUYV, 16, 16);
    expectChoice(negotiateV4l2Format(range, 0, 0, 0), YUYV, 1920, 1080);
    // A maximum off the step grid: the largest step below it.
    const std::vector<V4l2Format> offGrid{{YUYV, "", {{16, 1919, 4, 16, 1080, 4, 0}}}};
    expectChoice(negotiateV4l2Format(offGrid, 1919, 720, 0), YUYV, 1916, 720);
}

TEST(CameraNegotiation, DescribesFormatsForErrorMessages) {
    const std::vector<V4l2Format> formats{{YUYV, "", {S::discrete(640, 480, 30), S::discrete(1280, 720, 7.5)}},
                                          {BA81, "", {{16, 1920, 2, 16, 1080, 2, 0}}}};
    EXPECT_EQ(describeV4l2Formats(formats), "YUYV 640x480@30 1280x720@7.5; BA81 16x16-1920x1080/2x2");
    EXPECT_EQ(describeV4l2Formats({}), "no formats");
}
