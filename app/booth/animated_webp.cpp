// Animated WebP through WebPAnimEncoder (see animated_webp.h).
#include "booth/animated_webp.h"

#include "common/error.h"

#include <webp/encode.h>
#include <webp/mux.h>

#include <memory>

namespace avatarbooth {

std::string encodeAnimatedWebp(const std::vector<cv::Mat>& frames, int frameMs, float quality) {
    if (frames.empty()) throw BoothError(ErrorKind::Internal, "", "animated WebP: no frames");
    const int w = frames.front().cols, h = frames.front().rows;
    WebPAnimEncoderOptions options;
    if (!WebPAnimEncoderOptionsInit(&options)) throw BoothError(ErrorKind::Internal, "", "libwebp version mismatch");
    options.anim_params.loop_count = 0;  // forever
    options.allow_mixed = 0;
    std::unique_ptr<WebPAnimEncoder, decltype(&WebPAnimEncoderDelete)> encoder(WebPAnimEncoderNew(w, h, &options),
                                                                              WebPAnimEncoderDelete);
    if (!encoder) throw BoothError(ErrorKind::Internal, "", "animated WebP: cannot make the encoder");
    WebPConfig config;
    if (!WebPConfigInit(&config)) throw BoothError(ErrorKind::Internal, "", "libwebp version mismatch");
    config.quality = quality;
    config.method = 4;  // libwebp's default trade of speed for size
    int timestamp = 0;
    for (const cv::Mat& frame : frames) {
        if (frame.cols != w || frame.rows != h || frame.type() != CV_8UC3)
            throw BoothError(ErrorKind::Internal, "", "animated WebP: frames differ in size or type");
        WebPPicture picture;
        if (!WebPPictureInit(&picture)) throw BoothError(ErrorKind::Internal, "", "libwebp version mismatch");
        picture.width = w;
        picture.height = h;
        picture.use_argb = 1;
        const cv::Mat packed = frame.isContinuous() ? frame : frame.clone();
        const bool imported = WebPPictureImportBGR(&picture, packed.data, static_cast<int>(packed.step));
        const bool added = imported && WebPAnimEncoderAdd(encoder.get(), &picture, timestamp, &config);
        WebPPictureFree(&picture);
        if (!added)
            throw BoothError(ErrorKind::Internal, "", std::string("animated WebP: ") + WebPAnimEncoderGetError(encoder.get()));
        timestamp += frameMs;
    }
    WebPData data;
    WebPDataInit(&data);
    if (!WebPAnimEncoderAdd(encoder.get(), nullptr, timestamp, nullptr) || !WebPAnimEncoderAssemble(encoder.get(), &data))
        throw BoothError(ErrorKind::Internal, "", std::string("animated WebP: ") + WebPAnimEncoderGetError(encoder.get()));
    std::string bytes(reinterpret_cast<const char*>(data.bytes), data.size);
    WebPDataClear(&data);
    return bytes;
}

}  // namespace avatarbooth
