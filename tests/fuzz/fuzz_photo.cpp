// libFuzzer target: the photo loading path (common/image_io readPhoto: header checks, then the decoders of
// common/image_codec: libjpeg-turbo, libpng, stb_image for BMP, its own PNM reader).
// Every input must end in a decoded image or a BoothError; anything else (another exception, a sanitizer report,
// an allocation beyond the limit) is a bug.
#include "fuzz_files.h"

#include "common/error.h"
#include "common/image_io.h"

#include <cstddef>
#include <cstdint>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    static const avatarbooth::fuzz::ScratchDir dir("photo");
    const auto path = dir.path() / "photo";
    avatarbooth::fuzz::writeBytes(path, data, size);
    try {
        const cv::Mat image = avatarbooth::readPhoto(path);
        if (image.empty() || image.type() != CV_8UC3) __builtin_trap();  // readPhoto promises 8-bit BGR or throws
    } catch (const avatarbooth::BoothError&) {
    }
    return 0;
}
