// Animated WebP through WebPAnimEncoder (see animated_webp.h).
#include "booth/animated_webp.h"

#include "common/error.h"

#include <webp/encode.h>
#include <webp/mux.h>

#include <memory>

namespace avatarbooth {

struct AnimatedWebpEncoder::Impl {
    int width, height, frameMs, timestamp = 0, frames = 0;
    std::unique_ptr<WebPAnimEncoder, decltype(&WebPAnimEncoderDelete)> encoder{nullptr, WebPAnimEncoderDelete};
    WebPConfig config;
};

AnimatedWebpEncoder::AnimatedWebpEncoder(int width, int height, int frameMs, float quality)
    : impl_(std::make_unique<Impl>()) {
    impl_->width = width;
    impl_->height = height;
    impl_->frameMs = frameMs;
    WebPAnimEncoderOptions options;
    if (!WebPAnimEncoderOptionsInit(&options)) throw BoothError(ErrorKind::Internal, "", "libwebp version mismatch");
    options.anim_params.loop_count = 0;  // forever
    options.allow_mixed = 0;
    impl_->encoder.reset(WebPAnimEncoderNew(width, height, &options));
    if (!impl_->encoder) throw BoothError(ErrorKind::Internal, "", "animated WebP: cannot make the encoder");
    if (!WebPConfigInit(&impl_->config)) throw BoothError(ErrorKind::Internal, "", "libwebp version mismatch");
    impl_->config.quality = quality;
    impl_->config.method = 4;  // libwebp's default trade of speed for size
}

AnimatedWebpEncoder::~AnimatedWebpEncoder() = default;

void AnimatedWebpEncoder::add(const cv::Mat& frame) {
    Impl& e = *impl_;
    if (!e.encoder) throw BoothError(ErrorKind::Internal, "", "animated WebP: a frame added after finish()");
    if (frame.cols != e.width || frame.rows != e.height || frame.type() != CV_8UC3)
        throw BoothError(ErrorKind::Internal, "", "animated WebP: frames differ in size or type");
    WebPPicture picture;
    if (!WebPPictureInit(&picture)) throw BoothError(ErrorKind::Internal, "", "libwebp version mismatch");
    picture.width = e.width;
    picture.height = e.height;
    picture.use_argb = 1;
    const cv::Mat packed = frame.isContinuous() ? frame : frame.clone();
    const bool imported = WebPPictureImportBGR(&picture, packed.data, static_cast<int>(packed.step));
    const bool added = imported && WebPAnimEncoderAdd(e.encoder.get(), &picture, e.timestamp, &e.config);
    WebPPictureFree(&picture);
    if (!added) throw BoothError(ErrorKind::Internal, "", std::string("animated WebP: ") + WebPAnimEncoderGetError(e.encoder.get()));
    e.timestamp += e.frameMs;
    ++e.frames;
}

std::string AnimatedWebpEncoder::finish() {
    Impl& e = *impl_;
    if (!e.encoder || e.frames == 0) throw BoothError(ErrorKind::Internal, "", "animated WebP: no frames");
    WebPData data;
    WebPDataInit(&data);
    if (!WebPAnimEncoderAdd(e.encoder.get(), nullptr, e.timestamp, nullptr) || !WebPAnimEncoderAssemble(e.encoder.get(), &data))
        throw BoothError(ErrorKind::Internal, "", std::string("animated WebP: ") + WebPAnimEncoderGetError(e.encoder.get()));
    std::string bytes(reinterpret_cast<const char*>(data.bytes), data.size);
    WebPDataClear(&data);
    e.encoder.reset();
    return bytes;
}

}  // namespace avatarbooth
