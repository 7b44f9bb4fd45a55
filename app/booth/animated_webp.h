// The visitor's turntable picture (issue 23): frames of the avatar turning, encoded as one animated WebP with
// libwebp's WebPAnimEncoder (Debian libwebp-dev), which phones' browsers and galleries play and save as they are.
#pragma once

#include <opencv2/core.hpp>

#include <memory>
#include <string>

namespace avatarbooth {

// BGR frames of width x height, added one at a time (the caller need not hold them all: 36 frames of 320 pixels are
// 11 MB), each shown `frameMs`, looped forever, lossy at `quality` (0-100). Throws BoothError(Internal) with
// libwebp's reason when encoding fails (a frame of another size or type, out of memory).
class AnimatedWebpEncoder {
public:
    AnimatedWebpEncoder(int width, int height, int frameMs, float quality);
    ~AnimatedWebpEncoder();
    AnimatedWebpEncoder(const AnimatedWebpEncoder&) = delete;
    AnimatedWebpEncoder& operator=(const AnimatedWebpEncoder&) = delete;

    void add(const cv::Mat& frameBgr);
    // The file's bytes; no frame may be added after.
    std::string finish();

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace avatarbooth
