// The visitor's turntable picture (issue 23): frames of the avatar turning, encoded as one animated WebP with
// libwebp's WebPAnimEncoder (Debian libwebp-dev), which phones' browsers and galleries play and save as they are.
#pragma once

#include <opencv2/core.hpp>

#include <string>
#include <vector>

namespace avatarbooth {

// BGR frames of one size, shown `frameMs` each and looped forever, lossy at `quality` (0-100). Throws
// BoothError(Internal) with libwebp's reason when encoding fails (frames of different sizes, out of memory).
std::string encodeAnimatedWebp(const std::vector<cv::Mat>& frames, int frameMs, float quality);

}  // namespace avatarbooth
