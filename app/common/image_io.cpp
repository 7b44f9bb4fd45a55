// Photo reading: check the file and its header first, then let OpenCV decode it.
#include "common/image_io.h"

#include "common/error.h"

#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const fs::path& path, const std::string& why) {
    throw BoothError(ErrorKind::BadInput, path.string(), why);
}

unsigned readBigEndian(const std::vector<unsigned char>& b, std::size_t at, int bytes) {
    unsigned v = 0;
    for (int i = 0; i < bytes; ++i) v = (v << 8) | b[at + static_cast<std::size_t>(i)];
    return v;
}

// Width and height from a JPEG's start-of-frame marker; {0,0} when there is none before the data ends.
cv::Size jpegSize(const std::vector<unsigned char>& b) {
    std::size_t i = 2;
    while (i + 9 < b.size()) {
        if (b[i] != 0xFF) return {};
        const unsigned char marker = b[i + 1];
        if (marker == 0xFF) {
            ++i;
            continue;
        }
        const unsigned length = readBigEndian(b, i + 2, 2);
        const bool startOfFrame = marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 && marker != 0xCC;
        if (startOfFrame)
            return {static_cast<int>(readBigEndian(b, i + 7, 2)), static_cast<int>(readBigEndian(b, i + 5, 2))};
        i += 2 + length;
    }
    return {};
}

}  // namespace

std::string encodeImage(const cv::Mat& image, const std::string& ext, int jpegQuality) {
    std::vector<unsigned char> bytes;
    std::vector<int> params;
    if (ext == ".jpg") params = {cv::IMWRITE_JPEG_QUALITY, jpegQuality};
    if (!cv::imencode(ext, image, bytes, params)) throw BoothError(ErrorKind::Internal, "", "could not encode an image as " + ext);
    return std::string(bytes.begin(), bytes.end());
}

cv::Mat readPhoto(const fs::path& path, const PhotoLimits& limits) {
    std::error_code ec;
    if (!fs::exists(path, ec)) bad(path, "file not found");
    if (!fs::is_regular_file(path, ec)) bad(path, "is not a regular file");
    std::ifstream in(path, std::ios::binary);
    if (!in) bad(path, "cannot be opened (permissions?)");
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (bytes.empty()) bad(path, "is empty (0 bytes)");

    cv::Size declared;
    const bool isJpeg = bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
    const bool isPng = bytes.size() >= 8 && bytes[0] == 0x89 && bytes[1] == 'P' && bytes[2] == 'N' && bytes[3] == 'G';
    const bool isBmp = bytes.size() >= 2 && bytes[0] == 'B' && bytes[1] == 'M';
    const bool isPnm = bytes.size() >= 2 && bytes[0] == 'P' && bytes[1] >= '1' && bytes[1] <= '6';
    if (isJpeg) {
        declared = jpegSize(bytes);
        if (declared.area() == 0) bad(path, "is a truncated or damaged JPEG (no frame header)");
        // A complete JPEG ends with the end-of-image marker (some writers pad with zeros after it).
        std::size_t end = bytes.size();
        while (end > 2 && bytes[end - 1] == 0x00) --end;
        if (!(bytes[end - 2] == 0xFF && bytes[end - 1] == 0xD9)) bad(path, "is a truncated JPEG (no end-of-image marker)");
    } else if (isPng) {
        if (bytes.size() < 33) bad(path, "is a truncated PNG");
        declared = {static_cast<int>(readBigEndian(bytes, 16, 4)), static_cast<int>(readBigEndian(bytes, 20, 4))};
    } else if (!isBmp && !isPnm) {
        bad(path, "is not a JPEG or PNG image");
    }
    if (declared.area() != 0) {
        const long long pixels = static_cast<long long>(declared.width) * declared.height;
        if (declared.width <= 0 || declared.height <= 0 || pixels > limits.maxPixels)
            bad(path, "is too large (" + std::to_string(declared.width) + "x" + std::to_string(declared.height) +
                          "; at most " + std::to_string(limits.maxPixels / 1'000'000) + " megapixels)");
    }
    cv::Mat image;
    try {
        image = cv::imdecode(bytes, cv::IMREAD_COLOR);
    } catch (const cv::Exception& e) {
        bad(path, std::string("cannot be decoded: ") + e.what());
    }
    if (image.empty()) bad(path, "cannot be decoded (corrupt or truncated image)");
    if (static_cast<long long>(image.cols) * image.rows > limits.maxPixels) bad(path, "is too large");
    if (std::min(image.cols, image.rows) < limits.minSide)
        bad(path, "is too small (" + std::to_string(image.cols) + "x" + std::to_string(image.rows) + ")");
    return image;
}

}  // namespace avatarbooth
