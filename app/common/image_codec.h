// Image files to pixels and back: JPEG with libjpeg-turbo, PNG with libpng, BMP with stb_image, binary PNM read
// here (image_codec.cpp says why).
//
// Why not OpenCV's imgcodecs: Debian builds it against GDAL, so linking it loads about a hundred more libraries
// (GDAL, PROJ, Poppler, HDF5, ...) resident in the kiosk for formats a booth never reads (README, "Memory"). The
// decoders here are the ones imgcodecs uses for JPEG and PNG, set up the same way (8-bit BGR, EXIF orientation
// applied to JPEGs), so the pixels are the same to the bit.
#pragma once

#include <opencv2/core.hpp>

#include <cstddef>
#include <stdexcept>
#include <string>

namespace avatarbooth {

// The decoder's own reason an image could not be read (corrupt data, unsupported variant).
class ImageDecodeError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Decodes a JPEG, PNG, BMP or binary PNM (P5/P6) held in memory to 8-bit BGR (3 channels): grey is replicated,
// alpha dropped, 16-bit samples keep their high byte, PNM samples scale by their maxval (a maxval of 15 is not a
// dark picture), a JPEG's EXIF orientation is applied. The format is taken from the data's first bytes, not from
// a file name. Throws ImageDecodeError.
cv::Mat decodeImage(const unsigned char* data, std::size_t size);
// The same as 8-bit BGRA: a PNG's alpha (or tRNS transparency) kept, every other image opaque.
cv::Mat decodeImageWithAlpha(const unsigned char* data, std::size_t size);

// JPEG bytes of an 8-bit grey, BGR or BGRA image (alpha dropped) at `quality` (1-100), 4:2:0 like libjpeg's
// defaults. Throws std::runtime_error when the image is not 8-bit with 1, 3 or 4 channels.
std::string encodeJpeg(const cv::Mat& image, int quality);

// PNG bytes of an 8-bit grey, BGR or BGRA image: zlib's fastest level (screenshots are written while the screen
// runs). Throws std::runtime_error when the image is not 8-bit with 1, 3 or 4 channels.
std::string encodePng(const cv::Mat& image);

}  // namespace avatarbooth
