// Photo reading: check the file and its header first, then decode it (common/image_codec).
#include "common/image_io.h"

#include "common/error.h"
#include "common/file_bytes.h"
#include "common/image_codec.h"
#include "common/image_header.h"

#include <span>
#include <string>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const std::string& where, const std::string& why) {
    throw BoothError(ErrorKind::BadInput, where, why);
}

}  // namespace

std::string encodeImage(const cv::Mat& image, const std::string& ext, int jpegQuality) {
    try {
        if (ext == ".jpg") return encodeJpeg(image, jpegQuality);
        if (ext == ".png") return encodePng(image);
    } catch (const std::exception& e) {
        throw BoothError(ErrorKind::Internal, "", e.what());
    }
    throw BoothError(ErrorKind::Internal, "", "could not encode an image as " + ext + " (only .jpg and .png are written)");
}

cv::Mat decodeCheckedImage(const std::string& file, const std::string& path, const PhotoLimits& limits, bool alpha) {
    if (file.empty()) bad(path, "is empty (0 bytes)");
    const std::span<const unsigned char> bytes(reinterpret_cast<const unsigned char*>(file.data()), file.size());

    // The declared size is checked before decoding: a small file declaring a huge image (any format) is refused
    // here instead of making the decoder allocate gigabytes.
    const ImageHeader header = readImageHeader(bytes.data(), bytes.size());
    switch (header.format) {
        case ImageFormat::Jpeg: {
            if (header.width == 0 || header.height == 0) bad(path, "is a truncated or damaged JPEG (no frame header)");
            // A complete JPEG ends with the end-of-image marker (some writers pad with zeros after it).
            std::size_t end = bytes.size();
            while (end > 2 && bytes[end - 1] == 0x00) --end;
            if (!(bytes[end - 2] == 0xFF && bytes[end - 1] == 0xD9)) bad(path, "is a truncated JPEG (no end-of-image marker)");
            break;
        }
        case ImageFormat::Png:
            if (bytes.size() < 33) bad(path, "is a truncated PNG");
            break;
        case ImageFormat::Bmp:
        case ImageFormat::Pnm:
            if (header.width == 0 && header.height == 0) bad(path, "is a truncated image (its header is cut short)");
            break;
        case ImageFormat::Unknown: bad(path, "is not a JPEG or PNG image");
    }
    if (header.width <= 0 || header.height <= 0)
        bad(path, "declares an empty image (" + std::to_string(header.width) + "x" + std::to_string(header.height) + ")");
    // Each side first: the product of two 32-bit sides could overflow.
    if (header.width > limits.maxPixels || header.height > limits.maxPixels ||
        header.width * header.height > limits.maxPixels)
        bad(path, "is too large (" + std::to_string(header.width) + "x" + std::to_string(header.height) +
                      "; at most " + std::to_string(limits.maxPixels / 1'000'000) + " megapixels)");
    cv::Mat image;
    try {
        image = alpha ? decodeImageWithAlpha(bytes.data(), bytes.size()) : decodeImage(bytes.data(), bytes.size());
    } catch (const ImageDecodeError& e) {
        bad(path, e.what());
    }
    if (image.empty()) bad(path, "cannot be decoded (corrupt or truncated image)");
    if (static_cast<long long>(image.cols) * image.rows > limits.maxPixels) bad(path, "is too large");
    if (std::min(image.cols, image.rows) < limits.minSide)
        bad(path, "is too small (" + std::to_string(image.cols) + "x" + std::to_string(image.rows) + ")");
    return image;
}

cv::Mat readPhoto(const fs::path& path, const PhotoLimits& limits) {
    return decodeCheckedImage(readFileBytes(path), path.string(), limits, false);
}

cv::Mat readImageWithAlpha(const fs::path& path, const PhotoLimits& limits) {
    return decodeCheckedImage(readFileBytes(path), path.string(), limits, true);
}

}  // namespace avatarbooth
