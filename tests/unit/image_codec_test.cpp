// The booth's image files (app/common/image_codec): every format and variant decodes to the very pixels OpenCV's
// imread made of it before (the tests link imgcodecs to compare; the product does not), EXIF orientation included;
// written files read back exactly (PNG) or closely (JPEG); damaged files give the decoder's reason.
#include "common/image_codec.h"
#include "common/image_header.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cstdint>
#include <iterator>
#include <string>
#include <vector>

namespace avatarbooth {
namespace {

// An asymmetric test picture (a gradient, a block near one corner, some noise), so that a flip, a transpose or a
// channel swap changes pixels.
cv::Mat picture(int width = 96, int height = 64) {
    cv::Mat m(height, width, CV_8UC3);
    cv::RNG rng(7);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x)
            m.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(x * 255 / width),
                                              static_cast<std::uint8_t>(y * 255 / height),
                                              static_cast<std::uint8_t>(rng.uniform(0, 64)));
    cv::rectangle(m, cv::Rect(4, 6, 20, 10), cv::Scalar(0, 0, 255), cv::FILLED);
    return m;
}

std::vector<unsigned char> encodedByOpenCv(const cv::Mat& image, const std::string& ext, const std::vector<int>& params = {}) {
    std::vector<unsigned char> bytes;
    EXPECT_TRUE(cv::imencode(ext, image, bytes, params)) << ext;
    return bytes;
}

cv::Mat decoded(const std::vector<unsigned char>& bytes) { return decodeImage(bytes.data(), bytes.size()); }

double maxDifference(const cv::Mat& a, const cv::Mat& b) {
    if (a.size() != b.size() || a.type() != b.type()) return 1e9;
    return cv::norm(a, b, cv::NORM_INF);
}

// `jpeg` with an EXIF APP1 segment (little-endian TIFF, IFD0 holding only the orientation) after its SOI marker.
std::vector<unsigned char> withExifOrientation(const std::vector<unsigned char>& jpeg, std::uint16_t orientation) {
    const std::vector<unsigned char> payload = {
        'E', 'x', 'i', 'f', 0, 0,
        'I', 'I', 42, 0, 8, 0, 0, 0,                   // TIFF header: IFD0 at offset 8
        1, 0,                                          // one entry
        0x12, 0x01, 3, 0, 1, 0, 0, 0,                  // tag 0x0112 (orientation), SHORT, count 1
        static_cast<unsigned char>(orientation), 0, 0, 0,
        0, 0, 0, 0};                                   // no next IFD
    const std::size_t length = payload.size() + 2;
    const unsigned char marker[4] = {0xFF, 0xE1, static_cast<unsigned char>(length >> 8),
                                     static_cast<unsigned char>(length & 0xFF)};
    std::vector<unsigned char> out;
    out.reserve(jpeg.size() + 4 + payload.size());
    out.insert(out.end(), jpeg.begin(), jpeg.begin() + 2);  // SOI
    out.insert(out.end(), std::begin(marker), std::end(marker));
    out.insert(out.end(), payload.begin(), payload.end());
    out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
    return out;
}

TEST(ImageCodec, JpegDecodesToTheSamePixelsAsImread) {
    for (const int quality : {50, 95}) {
        const auto jpeg = encodedByOpenCv(picture(), ".jpg", {cv::IMWRITE_JPEG_QUALITY, quality});
        EXPECT_EQ(maxDifference(decoded(jpeg), cv::imdecode(jpeg, cv::IMREAD_COLOR)), 0.0) << quality;
    }
    cv::Mat grey;
    cv::cvtColor(picture(), grey, cv::COLOR_BGR2GRAY);
    const auto greyJpeg = encodedByOpenCv(grey, ".jpg");
    const cv::Mat greyDecoded = decoded(greyJpeg);
    EXPECT_EQ(greyDecoded.type(), CV_8UC3);
    EXPECT_EQ(maxDifference(greyDecoded, cv::imdecode(greyJpeg, cv::IMREAD_COLOR)), 0.0);
}

TEST(ImageCodec, JpegExifOrientationTurnsThePictureAsImreadDoes) {
    const auto jpeg = encodedByOpenCv(picture(96, 64), ".jpg", {cv::IMWRITE_JPEG_QUALITY, 90});
    for (std::uint16_t o = 1; o <= 8; ++o) {
        const auto tagged = withExifOrientation(jpeg, o);
        const cv::Mat ours = decoded(tagged);
        EXPECT_EQ(ours.size(), o >= 5 ? cv::Size(64, 96) : cv::Size(96, 64)) << "orientation " << o;
        EXPECT_EQ(maxDifference(ours, cv::imdecode(tagged, cv::IMREAD_COLOR)), 0.0) << "orientation " << o;
    }
    // 6: the camera was turned a quarter clockwise; upright, the red block (top left as stored) is at the top right.
    const cv::Mat upright = decoded(withExifOrientation(jpeg, 6));
    EXPECT_GT(upright.at<cv::Vec3b>(10, 64 - 1 - 10)[2], 200);
    EXPECT_LT(upright.at<cv::Vec3b>(10, 10)[2], 100);
}

TEST(ImageCodec, PngVariantsDecodeToTheSamePixelsAsImread) {
    const cv::Mat bgr = picture();
    cv::Mat grey, bgra, deep;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
    for (int y = 0; y < bgra.rows; ++y) bgra.at<cv::Vec4b>(y, y % bgra.cols)[3] = 0;  // some transparent pixels
    bgr.convertTo(deep, CV_16UC3, 257.0);
    deep += cv::Scalar(99, 3, 200);  // low bytes that differ from the high ones
    const std::vector<std::pair<const char*, cv::Mat>> variants = {
        {"BGR", bgr}, {"grey", grey}, {"BGRA", bgra}, {"16-bit", deep}};
    for (const auto& [name, image] : variants) {
        const auto png = encodedByOpenCv(image, ".png");
        const cv::Mat ours = decoded(png);
        EXPECT_EQ(ours.type(), CV_8UC3) << name;
        EXPECT_EQ(maxDifference(ours, cv::imdecode(png, cv::IMREAD_COLOR)), 0.0) << name;
    }
    EXPECT_EQ(maxDifference(decoded(encodedByOpenCv(bgr, ".png")), bgr), 0.0);  // lossless
}

TEST(ImageCodec, BmpAndBinaryPnmDecodeToTheSamePixelsAsImread) {
    cv::Mat grey;
    cv::cvtColor(picture(), grey, cv::COLOR_BGR2GRAY);
    for (const auto& [ext, image] : std::vector<std::pair<std::string, cv::Mat>>{
             {".bmp", picture()}, {".ppm", picture()}, {".pgm", grey}}) {
        const auto bytes = encodedByOpenCv(image, ext);
        EXPECT_EQ(maxDifference(decoded(bytes), cv::imdecode(bytes, cv::IMREAD_COLOR)), 0.0) << ext;
    }
}

// A PNM file: its header text, then the samples as bytes.
std::vector<unsigned char> pnm(const std::string& header, const std::vector<unsigned char>& samples) {
    std::vector<unsigned char> bytes(header.begin(), header.end());
    bytes.insert(bytes.end(), samples.begin(), samples.end());
    return bytes;
}

// The blue, green and red of each pixel of a one-row image.
std::vector<cv::Vec3b> row(const cv::Mat& image) {
    EXPECT_EQ(image.rows, 1);
    return std::vector<cv::Vec3b>(image.begin<cv::Vec3b>(), image.end<cv::Vec3b>());
}

// The decoder's reason for refusing `bytes`, or "decoded without error".
std::string decodeError(const std::vector<unsigned char>& bytes) {
    try {
        decoded(bytes);
        return "decoded without error";
    } catch (const ImageDecodeError& e) {
        return e.what();
    }
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(ImageCodec, PnmSamplesScaleByMaxvalAndWideSamplesAreBigEndian) {
    using V = cv::Vec3b;
    // maxval 15: 0..15 spread over 0..255 (round(v * 255 / 15) = 17 v); 20 is above maxval and counts as 15.
    EXPECT_EQ(row(decoded(pnm("P5 4 1 15\n", {0, 7, 15, 20}))),
              (std::vector<V>{{0, 0, 0}, {119, 119, 119}, {255, 255, 255}, {255, 255, 255}}));
    // maxval 255: the samples as they are; P6 is red, green, blue, the result blue, green, red.
    EXPECT_EQ(row(decoded(pnm("P6\n# a comment\n2 1\n255\n", {1, 2, 3, 250, 251, 252}))),
              (std::vector<V>{{3, 2, 1}, {252, 251, 250}}));
    // maxval 1000: two bytes a sample, high byte first. 500 -> round(127.5) = 128, 100 -> round(25.5) = 26.
    EXPECT_EQ(row(decoded(pnm("P5 4 1 1000\n", {0x00, 0x00, 0x01, 0xF4, 0x03, 0xE8, 0x00, 0x64}))),
              (std::vector<V>{{0, 0, 0}, {128, 128, 128}, {255, 255, 255}, {26, 26, 26}}));
    EXPECT_EQ(row(decoded(pnm("P6 1 1 1000\n", {0x03, 0xE8, 0x01, 0xF4, 0x00, 0x00}))),
              (std::vector<V>{{0, 128, 255}}));
    // maxval 65535: the high byte, as for 16-bit PNGs and as imread does (0x00FF would round to 1, it gives 0).
    const auto wide = pnm("P5 4 1 65535\n", {0x00, 0xFF, 0x12, 0x34, 0xFF, 0xFF, 0x80, 0x7F});
    EXPECT_EQ(row(decoded(wide)), (std::vector<V>{{0, 0, 0}, {0x12, 0x12, 0x12}, {255, 255, 255}, {0x80, 0x80, 0x80}}));
    EXPECT_EQ(maxDifference(decoded(wide), cv::imdecode(wide, cv::IMREAD_COLOR)), 0.0);
    // A 16-bit picture written by OpenCV reads back as its high bytes (v * 257 has v in both bytes), and as imread
    // reads it when the low bytes differ.
    cv::Mat deep;
    picture().convertTo(deep, CV_16UC3, 257.0);
    EXPECT_EQ(maxDifference(decoded(encodedByOpenCv(deep, ".ppm")), picture()), 0.0);
    const auto noisyPpm = encodedByOpenCv(deep + cv::Scalar(99, 3, 200), ".ppm");
    EXPECT_EQ(maxDifference(decoded(noisyPpm), cv::imdecode(noisyPpm, cv::IMREAD_COLOR)), 0.0);
}

TEST(ImageCodec, DamagedPnmHeadersAndShortSamplesGiveTheReason) {
    // Found by fuzz_photo in CI: 6x3000 with maxval 30000 and four bytes of samples. stb_image read past its
    // buffer here (AddressSanitizer: SEGV in stbi_load_from_memory).
    const std::vector<unsigned char> fuzzFound = {'P', '5', '\t', '\t', '6', '\n', '3', '0', '0', '0', ' ', '3', '0',
                                                  '0', '0', '0', '\n', '2', 0x80, 0x80, 0x80};
    EXPECT_TRUE(has(decodeError(fuzzFound), "PNM data is truncated: its header declares 6x3000 but only 4 bytes"))
        << decodeError(fuzzFound);
    // One byte short, in 8 and in 16 bits; one byte more than needed is fine (trailing bytes are ignored).
    EXPECT_TRUE(has(decodeError(pnm("P6 2 1 255\n", {1, 2, 3, 4, 5})), "truncated"));
    EXPECT_TRUE(has(decodeError(pnm("P5 2 1 256\n", {1, 2, 3})), "truncated"));
    EXPECT_EQ(decoded(pnm("P5 2 1 255\n", {1, 2, 3})).cols, 2);
    // Sides far beyond the data (and beyond 32 bits) are refused before anything is allocated.
    EXPECT_TRUE(has(decodeError(pnm("P6 99999999999 99999999999 255\n", {1, 2, 3})), "truncated"));
    EXPECT_TRUE(has(decodeError(pnm("P5 4 1 0\n", {0, 0, 0, 0})), "maxval 0 is not 1-65535"));
    EXPECT_TRUE(has(decodeError(pnm("P5 4 1 70000\n", {0, 0, 0, 0, 0, 0, 0, 0})), "maxval 70000 is not 1-65535"));
    EXPECT_TRUE(has(decodeError(pnm("P5 0 4 255\n", {0, 0, 0, 0})), "declares no pixels"));
    EXPECT_TRUE(has(decodeError(pnm("P5 4 1", {})), "cut short or damaged"));
    EXPECT_TRUE(has(decodeError(pnm("P5 4 1 255", {})), "cut short or damaged"));  // no whitespace after maxval
    EXPECT_TRUE(has(decodeError(pnm("P5 4 x 255\n", {0, 0, 0, 0})), "cut short or damaged"));
    EXPECT_TRUE(has(decodeError(pnm("P54 1 255\n", {0, 0, 0, 0})), "no space after its P5/P6"));
}

TEST(ImageCodec, Os2BitmapDeclaresItsSizeAndDecodes) {
    // A 2x2 24-bit BMP with the 12-byte OS/2 header (16-bit sides): rows bottom-up, blue-green-red, 4-byte rows.
    std::vector<unsigned char> bmp = {'B', 'M', 42, 0, 0, 0, 0, 0, 0, 0, 26, 0, 0, 0,  // file header, pixels at 26
                                      12, 0, 0, 0, 2, 0, 2, 0, 1, 0, 24, 0,             // core header: 2x2, 24 bits
                                      10, 20, 30, 40, 50, 60, 0, 0,                     // bottom row
                                      70, 80, 90, 100, 110, 120, 0, 0};                 // top row
    const ImageHeader header = readImageHeader(bmp.data(), bmp.size());
    EXPECT_EQ(header.format, ImageFormat::Bmp);
    EXPECT_EQ(header.width, 2);  // not the two 16-bit fields read as one 32-bit number
    EXPECT_EQ(header.height, 2);
    const cv::Mat image = decoded(bmp);
    ASSERT_EQ(image.size(), cv::Size(2, 2));
    EXPECT_EQ(image.at<cv::Vec3b>(0, 0), cv::Vec3b(70, 80, 90));
    EXPECT_EQ(image.at<cv::Vec3b>(1, 1), cv::Vec3b(40, 50, 60));
    const std::vector<unsigned char> headerOnly(bmp.begin(), bmp.begin() + 26);
    bmp.pop_back();
    EXPECT_TRUE(has(decodeError(headerOnly), "BMP data is truncated: its header declares 42 bytes, the file has 26"))
        << decodeError(headerOnly);
    EXPECT_TRUE(has(decodeError(bmp), "BMP data is truncated: its header declares 42 bytes, the file has 41"))
        << decodeError(bmp);
}

TEST(ImageCodec, WrittenPngReadsBackExactlyAndImreadAgrees) {
    const cv::Mat bgr = picture();
    const std::string png = encodePng(bgr);
    const std::vector<unsigned char> bytes(png.begin(), png.end());
    EXPECT_EQ(maxDifference(decoded(bytes), bgr), 0.0);
    EXPECT_EQ(maxDifference(cv::imdecode(bytes, cv::IMREAD_COLOR), bgr), 0.0);
    // Grey is written as grey (one channel) and BGRA with its alpha.
    cv::Mat grey, bgra;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
    bgra.at<cv::Vec4b>(3, 5)[3] = 17;
    const std::string greyPng = encodePng(grey), bgraPng = encodePng(bgra);
    EXPECT_EQ(maxDifference(cv::imdecode(std::vector<unsigned char>(greyPng.begin(), greyPng.end()), cv::IMREAD_UNCHANGED), grey), 0.0);
    EXPECT_EQ(maxDifference(cv::imdecode(std::vector<unsigned char>(bgraPng.begin(), bgraPng.end()), cv::IMREAD_UNCHANGED), bgra), 0.0);
    // A view into a larger image (rows not contiguous) is written as the view.
    const cv::Mat view = bgr(cv::Rect(10, 5, 40, 30));
    const std::string viewPng = encodePng(view);
    EXPECT_EQ(maxDifference(decoded(std::vector<unsigned char>(viewPng.begin(), viewPng.end())), view), 0.0);
}

TEST(ImageCodec, WrittenJpegIsCloseAtItsQualityAndDecodesAlikeEverywhere) {
    const cv::Mat bgr = picture(160, 120);
    const std::string high = encodeJpeg(bgr, 92), low = encodeJpeg(bgr, 30);
    const std::vector<unsigned char> highBytes(high.begin(), high.end()), lowBytes(low.begin(), low.end());
    EXPECT_LT(low.size(), high.size());
    const cv::Mat back = decoded(highBytes);
    // The same encoder with the same settings as OpenCV's imwrite: the same bytes.
    EXPECT_EQ(highBytes, encodedByOpenCv(bgr, ".jpg", {cv::IMWRITE_JPEG_QUALITY, 92}));
    EXPECT_EQ(lowBytes, encodedByOpenCv(bgr, ".jpg", {cv::IMWRITE_JPEG_QUALITY, 30}));
    EXPECT_GT(cv::PSNR(back, bgr), 25.0);  // the picture's blue channel is noise, halved in resolution by 4:2:0
    EXPECT_LT(cv::PSNR(decoded(lowBytes), bgr), cv::PSNR(back, bgr));
    EXPECT_EQ(maxDifference(back, cv::imdecode(highBytes, cv::IMREAD_COLOR)), 0.0);
    cv::Mat bgra;
    cv::cvtColor(bgr, bgra, cv::COLOR_BGR2BGRA);
    EXPECT_EQ(encodeJpeg(bgra, 92), high);  // alpha dropped, nothing else changes
}

TEST(ImageCodec, DamagedAndUnknownDataGiveTheReason) {
    const auto expectError = [](const std::vector<unsigned char>& bytes, const std::string& part) {
        try {
            decoded(bytes);
            ADD_FAILURE() << "decoded without error; expected: " << part;
        } catch (const ImageDecodeError& e) {
            EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
        }
    };
    const auto png = encodedByOpenCv(picture(), ".png");
    expectError(std::vector<unsigned char>(png.begin(), png.begin() + static_cast<long>(png.size() / 2)), "truncated");
    auto corrupt = png;
    corrupt[40] ^= 0xFF;  // inside the first chunk after IHDR: its CRC no longer matches
    expectError(corrupt, "PNG data cannot be decoded");
    const auto jpeg = encodedByOpenCv(picture(), ".jpg");
    expectError(std::vector<unsigned char>(jpeg.begin(), jpeg.begin() + 20), "JPEG data cannot be decoded");
    expectError({'G', 'I', 'F', '8', '9', 'a', 0, 0}, "is not a JPEG, PNG, BMP or PNM image");
    expectError({'P', '3', '\n', '1', ' ', '1', '\n', '2', '5', '5', '\n', '0', ' ', '0', ' ', '0', '\n'}, "P1-P4");
    expectError({'B', 'M', 0, 0}, "BMP data cannot be decoded");
    // A BMP cut short: stb_image alone would fill the missing rows with black (96x64 at 24 bits: 54 + 64 * 288).
    const auto bmp = encodedByOpenCv(picture(), ".bmp");
    ASSERT_EQ(bmp.size(), 54u + 64u * 288u);
    expectError(std::vector<unsigned char>(bmp.begin(), bmp.end() - 1), "BMP data is truncated: its header declares 18486 bytes, the file has 18485");
    expectError(std::vector<unsigned char>(bmp.begin(), bmp.begin() + 60), "BMP data is truncated");
    expectError({'P', '6', '9', '2', '\n', '9'}, "PNM data cannot be decoded");  // found by fuzz_photo
    EXPECT_THROW(encodePng(cv::Mat()), std::runtime_error);
    EXPECT_THROW(encodeJpeg(cv::Mat(4, 4, CV_32FC3), 90), std::runtime_error);
}

}  // namespace
}  // namespace avatarbooth
