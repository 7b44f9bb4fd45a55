// Raw camera buffers to BGR: exact pixels for YUYV colour bars, 4:2:0, packed RGB, and JPEG frames as UVC
// cameras send them (no Huffman tables, zero padding, cut short).
#include "drivers/camera/frame_conversion.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include <array>

using namespace avatarbooth;

namespace {

struct Bar {
    const char* name;
    std::uint8_t y, u, v;
    cv::Vec3b bgr;  // BT.601 limited range, rounded: R = 1.164(Y-16) + 1.596(V-128), ...
};

// 100 % colour bars (EBU order) in BT.601 limited-range YUV, and what they convert to.
const std::array<Bar, 8> kBars{{
    {"white", 235, 128, 128, {255, 255, 255}},
    {"yellow", 210, 16, 146, {0, 255, 255}},
    {"cyan", 170, 166, 16, {255, 255, 1}},
    {"green", 145, 54, 34, {1, 255, 0}},
    {"magenta", 106, 202, 222, {254, 0, 255}},
    {"red", 81, 90, 240, {0, 0, 254}},
    {"blue", 41, 240, 110, {255, 0, 0}},
    {"black", 16, 128, 128, {0, 0, 0}},
}};

// Two pixels per bar: Y U Y V.
std::vector<std::uint8_t> yuyvBars() {
    std::vector<std::uint8_t> bytes;
    for (const auto& b : kBars) bytes.insert(bytes.end(), {b.y, b.u, b.y, b.v});
    return bytes;
}

std::vector<std::uint8_t> encodeJpeg(const cv::Mat& image) {
    std::vector<std::uint8_t> bytes;
    EXPECT_TRUE(cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, 100}));
    return bytes;
}

// The JPEG without its DHT segments, as many UVC cameras send MJPEG frames.
std::vector<std::uint8_t> withoutHuffmanTables(const std::vector<std::uint8_t>& jpeg) {
    std::vector<std::uint8_t> out(jpeg.begin(), jpeg.begin() + 2);
    std::size_t i = 2;
    while (i + 4 <= jpeg.size()) {
        const auto marker = jpeg[i + 1];
        if (marker == 0xDA) {  // start of scan: the rest is entropy-coded data
            out.insert(out.end(), jpeg.begin() + static_cast<long>(i), jpeg.end());
            break;
        }
        const std::size_t length = (std::size_t{jpeg[i + 2]} << 8) | jpeg[i + 3];
        if (marker != 0xC4) out.insert(out.end(), jpeg.begin() + static_cast<long>(i), jpeg.begin() + static_cast<long>(i + 2 + length));
        i += 2 + length;
    }
    return out;
}

}  // namespace

TEST(CameraConversion, YuyvColourBarsGiveExactBgr) {
    const auto bytes = yuyvBars();
    const cv::Mat bgr = yuyvToBgr(bytes, 16, 1);
    ASSERT_EQ(bgr.type(), CV_8UC3);
    ASSERT_EQ(bgr.size(), cv::Size(16, 1));
    for (int i = 0; i < 8; ++i) {
        EXPECT_EQ(bgr.at<cv::Vec3b>(0, 2 * i), kBars[static_cast<std::size_t>(i)].bgr) << kBars[static_cast<std::size_t>(i)].name;
        EXPECT_EQ(bgr.at<cv::Vec3b>(0, 2 * i + 1), kBars[static_cast<std::size_t>(i)].bgr) << kBars[static_cast<std::size_t>(i)].name;
    }
}

TEST(CameraConversion, YuyvGreyRampFollowsLimitedRange) {
    // Y 16 is black, 235 white, in between 1.164 (Y - 16) rounded.
    const std::vector<std::uint8_t> bytes{16, 128, 50, 128, 100, 128, 128, 128, 200, 128, 235, 128};
    const cv::Mat bgr = yuyvToBgr(bytes, 6, 1);
    const int expected[] = {0, 40, 98, 130, 214, 255};
    for (int x = 0; x < 6; ++x) EXPECT_EQ(bgr.at<cv::Vec3b>(0, x), cv::Vec3b::all(static_cast<std::uint8_t>(expected[x]))) << x;
}

TEST(CameraConversion, YuyvHonoursBytesPerLinePadding) {
    // 2x2 pixels, 4 bytes per line of picture and 4 bytes of padding (0xEE) that must not show.
    const std::vector<std::uint8_t> bytes{81, 90, 81, 240, 0xEE, 0xEE, 0xEE, 0xEE, 41, 240, 41, 110};
    const cv::Mat bgr = yuyvToBgr(bytes, 2, 2, 8);
    ASSERT_EQ(bgr.size(), cv::Size(2, 2));
    EXPECT_EQ(bgr.at<cv::Vec3b>(0, 1), cv::Vec3b(0, 0, 254));
    EXPECT_EQ(bgr.at<cv::Vec3b>(1, 0), cv::Vec3b(255, 0, 0));
}

TEST(CameraConversion, YuyvRefusesShortBuffersAndOddWidths) {
    const auto bytes = yuyvBars();  // 32 bytes = 16x1
    EXPECT_TRUE(yuyvToBgr(bytes, 16, 2).empty());
    EXPECT_TRUE(yuyvToBgr(std::span(bytes).first(31), 16, 1).empty());
    EXPECT_TRUE(yuyvToBgr(bytes, 15, 1).empty());
    EXPECT_TRUE(yuyvToBgr(bytes, 16, 1, 16).empty());  // stride shorter than a line
    EXPECT_TRUE(yuyvToBgr(bytes, 0, 1).empty());
}

TEST(CameraConversion, Yuv420PlanesGiveTheSameBars) {
    // 4 bars of 2x2 pixels: Y plane 8x2, chroma per 2x2 block.
    std::vector<std::uint8_t> y, u, v, uv;
    for (int row = 0; row < 2; ++row)
        for (int i = 0; i < 4; ++i) y.insert(y.end(), {kBars[static_cast<std::size_t>(i) + 2].y, kBars[static_cast<std::size_t>(i) + 2].y});
    for (int i = 0; i < 4; ++i) {
        const auto& b = kBars[static_cast<std::size_t>(i) + 2];
        u.push_back(b.u);
        v.push_back(b.v);
        uv.insert(uv.end(), {b.u, b.v});
    }
    const cv::Mat nv12 = rawFrameToBgr({RawPixelFormat::NV12, 8, 2, 0, {y, uv}});
    std::vector<std::uint8_t> packed = y;
    packed.insert(packed.end(), u.begin(), u.end());
    packed.insert(packed.end(), v.begin(), v.end());
    const cv::Mat i420Separate = rawFrameToBgr({RawPixelFormat::YUV420, 8, 2, 0, {y, u, v}});
    const cv::Mat i420Single = rawFrameToBgr({RawPixelFormat::YUV420, 8, 2, 0, {packed}});
    for (const cv::Mat* m : {&nv12, &i420Separate, &i420Single}) {
        ASSERT_EQ(m->size(), cv::Size(8, 2));
        for (int i = 0; i < 4; ++i)
            for (int r = 0; r < 2; ++r)
                for (int c = 0; c < 2; ++c)
                    EXPECT_EQ(m->at<cv::Vec3b>(r, 2 * i + c), kBars[static_cast<std::size_t>(i) + 2].bgr) << kBars[static_cast<std::size_t>(i) + 2].name;
    }
    EXPECT_TRUE(rawFrameToBgr({RawPixelFormat::YUV420, 8, 2, 0, {std::span(packed).first(packed.size() - 1)}}).empty());
    EXPECT_TRUE(rawFrameToBgr({RawPixelFormat::NV12, 8, 2, 0, {y}}).empty());
}

TEST(CameraConversion, PackedRgbLayoutsByMemoryOrder) {
    const std::vector<std::uint8_t> rgb{10, 20, 30, 40, 50, 60};
    const std::vector<std::uint8_t> rgbx{10, 20, 30, 99, 40, 50, 60, 99};
    EXPECT_EQ(rawFrameToBgr({RawPixelFormat::RGB24, 2, 1, 0, {rgb}}).at<cv::Vec3b>(0, 1), cv::Vec3b(60, 50, 40));
    EXPECT_EQ(rawFrameToBgr({RawPixelFormat::BGR24, 2, 1, 0, {rgb}}).at<cv::Vec3b>(0, 1), cv::Vec3b(40, 50, 60));
    EXPECT_EQ(rawFrameToBgr({RawPixelFormat::RGBX32, 2, 1, 0, {rgbx}}).at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
    EXPECT_EQ(rawFrameToBgr({RawPixelFormat::BGRX32, 2, 1, 0, {rgbx}}).at<cv::Vec3b>(0, 1), cv::Vec3b(40, 50, 60));
    EXPECT_TRUE(rawFrameToBgr({RawPixelFormat::BGRX32, 2, 2, 0, {rgbx}}).empty());
}

TEST(CameraConversion, MjpegDecodesExactGreyBlocks) {
    // Flat 16x16 blocks of grey survive JPEG exactly (DC only, no chroma): the decoded pixels are known.
    cv::Mat image(32, 48, CV_8UC3);
    const std::uint8_t levels[] = {0, 128, 255};
    for (int i = 0; i < 3; ++i) image.colRange(16 * i, 16 * i + 16).setTo(cv::Scalar::all(levels[i]));
    image.rowRange(16, 32).setTo(cv::Scalar::all(64));
    const auto jpeg = encodeJpeg(image);
    const cv::Mat bgr = mjpegToBgr(jpeg, 48, 32);
    ASSERT_EQ(bgr.size(), cv::Size(48, 32));
    EXPECT_EQ(cv::norm(bgr, image, cv::NORM_INF), 0.0);
    EXPECT_EQ(bgr.at<cv::Vec3b>(3, 20), cv::Vec3b(128, 128, 128));
    EXPECT_EQ(bgr.at<cv::Vec3b>(20, 40), cv::Vec3b(64, 64, 64));
}

TEST(CameraConversion, MjpegWithoutHuffmanTablesDecodesLikeTheFullJpeg) {
    cv::Mat image(48, 64, CV_8UC3);
    cv::randu(image, 0, 256);
    const auto jpeg = encodeJpeg(image);
    const auto bare = withoutHuffmanTables(jpeg);
    ASSERT_LT(bare.size(), jpeg.size());
    const cv::Mat full = mjpegToBgr(jpeg);
    const cv::Mat fromBare = mjpegToBgr(bare);
    ASSERT_FALSE(fromBare.empty());
    EXPECT_EQ(cv::norm(full, fromBare, cv::NORM_INF), 0.0);
}

TEST(CameraConversion, MjpegRefusesTruncatedGarbageAndWrongSizeFrames) {
    cv::Mat image(32, 32, CV_8UC3, cv::Scalar(10, 200, 30));
    auto jpeg = encodeJpeg(image);
    // Zero padding after the end marker is what UVC payloads look like: accepted.
    auto padded = jpeg;
    padded.insert(padded.end(), 100, 0);
    EXPECT_FALSE(mjpegToBgr(padded, 32, 32).empty());
    // Cut short (a lost USB packet): libjpeg would fill the rest with grey; we drop it.
    EXPECT_TRUE(mjpegToBgr(std::span(jpeg).first(jpeg.size() - 20), 32, 32).empty());
    EXPECT_TRUE(mjpegToBgr(std::span(jpeg).first(jpeg.size() - 20)).empty());
    // Not a JPEG at all, and a JPEG of another size than the stream's.
    const std::vector<std::uint8_t> garbage(500, 0x5A);
    EXPECT_TRUE(mjpegToBgr(garbage).empty());
    EXPECT_TRUE(mjpegToBgr(jpeg, 64, 32).empty());
    // Right markers, broken insides.
    auto broken = jpeg;
    std::fill(broken.begin() + 2, broken.end() - 2, std::uint8_t{0x11});
    EXPECT_TRUE(mjpegToBgr(broken).empty());
}

TEST(CameraConversion, FormatNamesMapToMemoryLayouts) {
    EXPECT_EQ(fourccName(fourccCode('Y', 'U', 'Y', 'V')), "YUYV");
    EXPECT_EQ(fourccName(0x00000001), "????");
    EXPECT_EQ(rawFormatFromV4l2(fourccCode('M', 'J', 'P', 'G')), RawPixelFormat::MJPEG);
    EXPECT_EQ(rawFormatFromV4l2(fourccCode('J', 'P', 'E', 'G')), RawPixelFormat::MJPEG);
    EXPECT_EQ(rawFormatFromV4l2(fourccCode('R', 'G', 'B', '3')), RawPixelFormat::RGB24);
    EXPECT_EQ(rawFormatFromV4l2(fourccCode('B', 'A', '8', '1')), std::nullopt);
    // libcamera follows DRM: RGB888 is B, G, R in memory.
    EXPECT_EQ(rawFormatFromLibcamera("RGB888"), RawPixelFormat::BGR24);
    EXPECT_EQ(rawFormatFromLibcamera("BGR888"), RawPixelFormat::RGB24);
    EXPECT_EQ(rawFormatFromLibcamera("XRGB8888"), RawPixelFormat::BGRX32);
    EXPECT_EQ(rawFormatFromLibcamera("XBGR8888"), RawPixelFormat::RGBX32);
    EXPECT_EQ(rawFormatFromLibcamera("YUV420"), RawPixelFormat::YUV420);
    EXPECT_EQ(rawFormatFromLibcamera("SRGGB10_CSI2P"), std::nullopt);
    EXPECT_STREQ(rawPixelFormatName(RawPixelFormat::NV12), "NV12");
}
