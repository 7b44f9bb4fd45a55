// The KMS screen's device taken away under it, as a USB display is unplugged: qemu's virtio-gpu (a KMS device
// without 3-D here, which Mesa renders to with kms_swrast) removed from its PCI bus through sysfs. The kernel
// unplugs the DRM device (drm_dev_unplug) and answers every ioctl with ENODEV; vkms on 6.1 cannot be taken away
// under an open node (tests/kernel/README.md).
#include "kernel_guest.h"

#include "common/error.h"
#include "drivers/display/kms_display.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <xf86drm.h>

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

// The /dev/dri/card* node of the virtio-gpu driver, or "".
std::string virtioCard() {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator("/dev/dri", ec)) {
        if (e.path().filename().string().rfind("card", 0) != 0) continue;
        const int fd = ::open(e.path().c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) continue;
        drmVersion* v = drmGetVersion(fd);
        const bool virtio = v != nullptr && std::string(v->name, static_cast<std::size_t>(v->name_len)) == "virtio_gpu";
        drmFreeVersion(v);
        ::close(fd);
        if (virtio) return e.path().string();
    }
    return "";
}

TEST(KmsRemoval, ADisplayDeviceRemovedUnderTheScreenIsADeviceErrorSayingItIsGone) {
    AVATARBOOTH_REQUIRE_KERNEL_GUEST();
    ASSERT_EQ(kernel_test::modprobe("virtio-gpu"), 0);
    const std::string card = virtioCard();
    ASSERT_FALSE(card.empty()) << "virtio-gpu loaded but no card (run.sh gives qemu -device virtio-gpu-pci)";
    const fs::path pci = fs::canonical("/sys/class/drm" / fs::path(card).filename() / "device");
    ASSERT_TRUE(fs::exists(pci / "remove")) << pci << " is not a PCI device";

    DisplaySettings settings;
    settings.backend = "kms";
    settings.drmDevice = card;
    {
        KmsDisplay display(settings);
        std::printf("[removal] %s on %s\n", display.describe().c_str(), pci.c_str());
        const cv::Mat frame(display.size(), CV_8UC3, cv::Scalar(0, 128, 255));
        display.present(frame);
        display.present(frame);
        ASSERT_TRUE(kernel_test::writeFile(pci / "remove", "1"));
        EXPECT_FALSE(fs::exists(card));
        try {
            display.present(frame);
            ADD_FAILURE() << "present() went on after the display device was removed";
        } catch (const BoothError& e) {
            EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
            EXPECT_NE(std::string(e.what()).find("the display device is gone"), std::string::npos) << e.what();
            std::printf("[removal] %s\n", e.what());
        }
    }  // closing a display whose device is gone: no crash, no hang
    try {
        KmsDisplay again(settings);
        ADD_FAILURE() << "a display opened on a removed device: " << again.describe();
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Device) << e.what();
        EXPECT_NE(std::string(e.what()).find("no DRM device " + card), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace avatarbooth
