// libFuzzer target: the recorded-session-folder reader (the sim camera: finds front.*, side.*, background.* in a
// folder, reads and checks them, scales the previews) and a few frames and stills from it.
//
// Input layout: one flags byte, then the front file's length (2 bytes, big-endian) and bytes, the side file's
// length and bytes, and the rest as the background plate. The flags pick the files' names and odd folder
// contents (see kFlag* below), so the fuzzer also explores folders, not only file bytes.
#include "fuzz_files.h"

#include "common/error.h"
#include "drivers/camera/sim_camera.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace {

constexpr std::uint8_t kFrontPng = 1;          // front.png instead of front.jpg
constexpr std::uint8_t kSidePng = 2;           // side.png instead of side.jpg
constexpr std::uint8_t kBackground = 4;        // the rest is background.png (else no plate)
constexpr std::uint8_t kFrontIsFolder = 8;     // a folder named front.jpg (and the front bytes as FRONT.jpeg)
constexpr std::uint8_t kDuplicateSide = 16;    // side.jpeg as well as side.jpg/png
constexpr std::uint8_t kNonUtf8Names = 32;     // files whose names are not UTF-8 next to the photos
constexpr std::uint8_t kUpperCase = 64;        // SIDE.JPG: names are matched without regard to case

std::string take(const std::uint8_t*& data, std::size_t& size) {
    if (size < 2) {
        data += size;
        size = 0;
        return {};
    }
    std::size_t n = static_cast<std::size_t>(data[0]) << 8 | data[1];
    data += 2;
    size -= 2;
    n = std::min(n, size);
    std::string bytes(reinterpret_cast<const char*>(data), n);
    data += n;
    size -= n;
    return bytes;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace avatarbooth;
    static const fuzz::ScratchDir root("session_folder");
    if (size < 1) return 0;
    const std::uint8_t flags = data[0];
    ++data;
    --size;
    const std::string front = take(data, size);
    const std::string side = take(data, size);
    const std::string background(reinterpret_cast<const char*>(data), size);

    const auto folder = root.path() / "session";
    fuzz::clearFolder(folder);
    if (flags & kFrontIsFolder) {
        std::filesystem::create_directories(folder / "front.jpg");
        fuzz::writeBytes(folder / "FRONT.jpeg", front);
    } else {
        fuzz::writeBytes(folder / ((flags & kFrontPng) ? "front.png" : "front.jpg"), front);
    }
    const std::string sideName = (flags & kUpperCase) ? "SIDE" : "side";
    fuzz::writeBytes(folder / (sideName + ((flags & kSidePng) ? ".png" : ".jpg")), side);
    if (flags & kDuplicateSide) fuzz::writeBytes(folder / "side.jpeg", side);
    if (flags & kBackground) fuzz::writeBytes(folder / "background.png", background);
    if (flags & kNonUtf8Names) {
        fuzz::writeBytes(folder / "\xff\xfe.jpg", front);
        fuzz::writeBytes(folder / "front\xc3\x28.png", side);
    }

    try {
        SimCameraOptions options;
        options.folder = folder;
        options.previewWidth = 160;
        options.previewHeight = 120;
        options.noise = 2;
        auto controls = std::make_shared<SimCameraControls>();
        SimCamera camera(options, controls, std::make_shared<ManualClock>(SteadyTime{}));
        camera.start();
        for (const auto scene : {SimScene::Empty, SimScene::Front, SimScene::Side}) {
            controls->setScene(scene);
            if (!camera.nextFrame(std::chrono::milliseconds(50))) __builtin_trap();  // a manual clock never runs dry
            if (camera.captureStill().image.empty()) __builtin_trap();
        }
        controls->corruptNextFrames(1);
        (void)camera.nextFrame(std::chrono::milliseconds(50));
        camera.stop();
    } catch (const BoothError&) {
    }
    return 0;
}
