// The textured-quad presenter of the kms and window displays, drawn into an offscreen framebuffer of a headless
// EGL context and read back: it must reproduce composeForPanel (exactly where no scaling is involved).
#include "drivers/display/display_geometry.h"
#include "drivers/display/headless_egl.h"
#include "drivers/display/quad_presenter.h"

#include <GLES3/gl3.h>
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <memory>

namespace avatarbooth {
namespace {

// An RGBA8 framebuffer object of a given size, bound while it lives.
class OffscreenTarget {
public:
    explicit OffscreenTarget(cv::Size size) : size_(size) {
        glGenRenderbuffers(1, &colour_);
        glBindRenderbuffer(GL_RENDERBUFFER, colour_);
        glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, size.width, size.height);
        glGenFramebuffers(1, &fbo_);
        glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
        glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour_);
        complete_ = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    }
    ~OffscreenTarget() {
        glBindFramebuffer(GL_FRAMEBUFFER, 0);
        glDeleteFramebuffers(1, &fbo_);
        glDeleteRenderbuffers(1, &colour_);
    }
    bool complete() const { return complete_; }

    // The framebuffer as a BGR image, top row first (GL's row 0 is the bottom).
    cv::Mat read() const {
        cv::Mat rgba(size_, CV_8UC4);
        glPixelStorei(GL_PACK_ALIGNMENT, 1);
        glReadPixels(0, 0, size_.width, size_.height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
        cv::Mat flipped, bgr;
        cv::flip(rgba, flipped, 0);
        cv::cvtColor(flipped, bgr, cv::COLOR_RGBA2BGR);
        return bgr;
    }

private:
    cv::Size size_;
    GLuint fbo_ = 0, colour_ = 0;
    bool complete_ = false;
};

cv::Mat pattern(cv::Size s, int seed) {
    cv::Mat m(s, CV_8UC3);
    cv::RNG rng(static_cast<std::uint64_t>(seed));
    rng.fill(m, cv::RNG::UNIFORM, cv::Scalar::all(0), cv::Scalar::all(256));
    return m;
}

class DisplayPresenter : public ::testing::Test {
protected:
    void SetUp() override {
        try {
            context_ = std::make_unique<HeadlessEglContext>();
        } catch (const std::exception& e) {
            GTEST_SKIP() << "no headless EGL here: " << e.what();
        }
        presenter_ = std::make_unique<QuadPresenter>();
    }
    void TearDown() override {
        presenter_.reset();
        context_.reset();
    }

    cv::Mat present(const cv::Mat& image, cv::Size panel, Rotation r) {
        OffscreenTarget target(panel);
        EXPECT_TRUE(target.complete());
        presenter_->draw(image, panel, r);
        EXPECT_EQ(glGetError(), static_cast<GLenum>(GL_NO_ERROR));
        return target.read();
    }

    std::unique_ptr<HeadlessEglContext> context_;
    std::unique_ptr<QuadPresenter> presenter_;
};

TEST_F(DisplayPresenter, ReproducesTheImageExactlyAtEveryRotation) {
    // Odd sizes: rows not a multiple of 4 bytes, so the unpack alignment matters.
    const cv::Mat image = pattern({173, 97}, 1);
    for (const Rotation r : {Rotation::R0, Rotation::R90, Rotation::R180, Rotation::R270}) {
        const cv::Size panel = rotatedSize(image.size(), r);
        const cv::Mat shown = present(image, panel, r);
        const cv::Mat expected = composeForPanel(image, panel, r);
        EXPECT_EQ(cv::norm(shown, expected, cv::NORM_INF), 0.0) << "rotation " << degrees(r);
        // One pixel spelled out: the image's top-left corner after turning.
        const cv::Point p = rotatedPixel({0, 0}, image.size(), r);
        EXPECT_EQ(shown.at<cv::Vec3b>(p), image.at<cv::Vec3b>(0, 0)) << "rotation " << degrees(r);
    }
}

TEST_F(DisplayPresenter, LetterboxesLikeTheCpuPath) {
    // A landscape 1280x720 frame on a portrait 720x1280 panel without turning: bars above and below.
    const cv::Mat image = pattern({128, 72}, 2);
    cv::Mat smooth;
    cv::GaussianBlur(image, smooth, {0, 0}, 3.0);  // bilinear scaling of GPU and CPU agree closely on smooth images
    const cv::Size panel(144, 256);
    const cv::Mat shown = present(smooth, panel, Rotation::R0);
    const cv::Mat expected = composeForPanel(smooth, panel, Rotation::R0);
    const cv::Rect rect = fitRect(smooth.size(), panel);
    EXPECT_EQ(rect, cv::Rect(0, 87, 144, 81));
    // The bars are black exactly.
    EXPECT_EQ(cv::countNonZero(cv::Mat(shown(cv::Rect(0, 0, 144, 87))).reshape(1)), 0);
    EXPECT_EQ(cv::countNonZero(cv::Mat(shown(cv::Rect(0, 168, 144, 88))).reshape(1)), 0);
    // Inside, GPU and CPU bilinear sampling differ by rounding only.
    cv::Mat diff;
    cv::absdiff(shown(rect), expected(rect), diff);
    const double mean = cv::mean(diff.reshape(1))[0];
    EXPECT_LT(mean, 2.0);
    std::printf("letterbox 128x72 -> 144x81 in 144x256: mean |GPU - CPU| = %.3f\n", mean);
}

TEST_F(DisplayPresenter, ChangingFrameSizesReallocatesTheTexture) {
    const cv::Mat small = pattern({40, 30}, 3), large = pattern({64, 50}, 4);
    EXPECT_EQ(cv::norm(present(small, {40, 30}, Rotation::R0), small, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(present(large, {64, 50}, Rotation::R0), large, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(present(small, {40, 30}, Rotation::R0), small, cv::NORM_INF), 0.0);
    // A view into a larger image (rows not contiguous) is drawn as the view.
    const cv::Mat view = large(cv::Rect(3, 5, 40, 30));
    EXPECT_EQ(cv::norm(present(view, {40, 30}, Rotation::R0), view, cv::NORM_INF), 0.0);
}

}  // namespace
}  // namespace avatarbooth
