// Reading photos with checks that turn every kind of bad file into a clear error naming the file.
#pragma once

#include <opencv2/core.hpp>

#include <filesystem>
#include <string>

namespace avatarbooth {

struct PhotoLimits {
    // Larger photos are refused before decoding (a 24-megapixel still is the largest a booth camera makes).
    long long maxPixels = 40'000'000;
    int minSide = 64;
};

// Encodes an image as ".jpg" (at the given quality) or ".png" bytes. Throws BoothError(Internal) on failure.
std::string encodeImage(const cv::Mat& image, const std::string& ext, int jpegQuality = 90);

// Reads a JPEG or PNG (or BMP/PPM) photo as 8-bit BGR. Throws BoothError(BadInput) naming the file and the
// reason: missing, not a regular file, empty, unknown format, truncated, too large, undecodable.
cv::Mat readPhoto(const std::filesystem::path& path, const PhotoLimits& limits = {});
// The same checks, read as 8-bit BGRA (a PNG's alpha kept; other images opaque): textures with transparency.
cv::Mat readImageWithAlpha(const std::filesystem::path& path, const PhotoLimits& limits = {});
// The same checks and decoding of a file's bytes already in memory (`where` names them in the error): as
// readImageWithAlpha when `keepAlpha`, else as readPhoto.
cv::Mat decodeCheckedImage(const std::string& bytes, const std::string& where, const PhotoLimits& limits, bool keepAlpha);

}  // namespace avatarbooth
