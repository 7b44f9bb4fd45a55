// QR codes for the thanks screen (the visitor's page, booth/share_link.h), made with libqrencode.
#pragma once

#include <opencv2/core.hpp>

#include <string>

namespace avatarbooth {

// The modules of a QR code holding `text` (8-bit mode, error correction level M: 15 % of it may be unreadable, a
// glare on the screen or a finger on the corner), the smallest version that fits: CV_8U, 1 = dark, without the
// quiet zone. Throws BoothError(Internal) when the text does not fit in a QR code.
cv::Mat encodeQrModules(const std::string& text);

// The quiet zone around a code, in modules (ISO/IEC 18004 asks for 4).
inline constexpr int kQrQuietModules = 4;

// `modules` drawn black on white at `modulePixels` per module (whole pixels: every module the same size, which
// scanners need), with the quiet zone: a BGR image of (modules + 2 * kQrQuietModules) * modulePixels per side.
cv::Mat drawQrCode(const cv::Mat& modules, int modulePixels);

}  // namespace avatarbooth
