// The textured-quad presenter shared by the KMS and window displays: a BGR frame uploaded as a texture and drawn
// as one quad (OpenGL ES 2 shaders) that turns and letterboxes it exactly as composeForPanel does on the CPU.
#pragma once

#include "drivers/display/display_geometry.h"

#include <opencv2/core.hpp>

namespace avatarbooth {

class QuadPresenter {
public:
    // Needs a current OpenGL ES 2 (or later) context; compiles the shaders and makes the texture and buffer.
    // Throws BoothError(Device) with the compiler's log when the shaders do not build.
    QuadPresenter();
    // Frees the GL objects; the same context must be current.
    ~QuadPresenter();
    QuadPresenter(const QuadPresenter&) = delete;
    QuadPresenter& operator=(const QuadPresenter&) = delete;

    // Draws `bgr` (8UC3) into the bound framebuffer of size `target`: clears it black, turns the image by `r`,
    // fits it with its aspect ratio kept. Sampling is nearest when no scaling is needed (an exact copy) and
    // bilinear otherwise. Images larger than GL_MAX_TEXTURE_SIZE are scaled down on the CPU first.
    void draw(const cv::Mat& bgr, cv::Size target, Rotation r);

private:
    unsigned program_ = 0, texture_ = 0, buffer_ = 0;
    int positionAttrib_ = -1, uvAttrib_ = -1, samplerUniform_ = -1;
    cv::Size textureSize_;
    int maxTextureSize_ = 0;
};

}  // namespace avatarbooth
