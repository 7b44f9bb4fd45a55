// The `kernel` tests' view of a KMS screen from outside the program that drives it: the vkms device, and the
// framebuffer its CRTC scans out, read through DRM_IOCTL_MODE_GETFB2 and a dumb-buffer mapping.
//
// Another process (the booth) holds DRM master, so the test cannot make atomic commits (the writeback connector
// needs one); GETFB2 gives a root (CAP_SYS_ADMIN) client the buffer's GEM handle without master.
#pragma once

#include <drm_fourcc.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>

namespace avatarbooth::kernel_test {

// The /dev/dri/card* node of the vkms driver, or "" when vkms is not loaded.
inline std::string vkmsCard() {
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator("/dev/dri", ec)) {
        const std::string path = e.path().string();
        if (e.path().filename().string().rfind("card", 0) != 0) continue;
        const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) continue;
        drmVersion* v = drmGetVersion(fd);
        const bool vkms = v != nullptr && std::string(v->name, static_cast<std::size_t>(v->name_len)) == "vkms";
        drmFreeVersion(v);
        ::close(fd);
        if (vkms) return path;
    }
    return "";
}

// What the first CRTC of `card` scans out now (BGR, the framebuffer's size), or an empty image with `why` set.
// Opening the card makes this process DRM master when no other holds it: call it once the screen's owner is up.
inline cv::Mat readScanout(const std::string& card, std::string& why) {
    const int fd = ::open(card.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
        why = card + ": " + std::strerror(errno);
        return {};
    }
    struct Close {
        int fd;
        ~Close() { ::close(fd); }
    } closeFd{fd};
    drmModeRes* res = drmModeGetResources(fd);
    if (res == nullptr || res->count_crtcs < 1) {
        drmModeFreeResources(res);
        why = "no CRTC";
        return {};
    }
    drmModeCrtc* crtc = drmModeGetCrtc(fd, res->crtcs[0]);
    drmModeFreeResources(res);
    const std::uint32_t fbId = crtc != nullptr ? crtc->buffer_id : 0;
    drmModeFreeCrtc(crtc);
    if (fbId == 0) {
        why = "the CRTC scans out nothing";
        return {};
    }
    drmModeFB2* fb = drmModeGetFB2(fd, fbId);
    if (fb == nullptr || fb->handles[0] == 0) {
        why = std::string("GETFB2 gave no buffer handle (root, CAP_SYS_ADMIN, is needed): ") + std::strerror(errno);
        drmModeFreeFB2(fb);
        return {};
    }
    const std::uint32_t width = fb->width, height = fb->height, pitch = fb->pitches[0], handle = fb->handles[0];
    const std::uint32_t format = fb->pixel_format;
    drmModeFreeFB2(fb);
    cv::Mat bgr;
    drm_mode_map_dumb mapReq{};
    mapReq.handle = handle;
    if (format != DRM_FORMAT_XRGB8888 && format != DRM_FORMAT_ARGB8888) {
        why = "framebuffer format is not XRGB8888";
    } else if (drmIoctl(fd, DRM_IOCTL_MODE_MAP_DUMB, &mapReq) != 0) {
        why = std::string("MAP_DUMB: ") + std::strerror(errno);
    } else {
        const std::size_t size = static_cast<std::size_t>(pitch) * height;
        void* map = ::mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, static_cast<off_t>(mapReq.offset));
        if (map == MAP_FAILED) {
            why = std::string("mmap: ") + std::strerror(errno);
        } else {
            cv::cvtColor(cv::Mat(static_cast<int>(height), static_cast<int>(width), CV_8UC4, map, pitch), bgr,
                         cv::COLOR_BGRA2BGR);
            ::munmap(map, size);
        }
    }
    drmCloseBufferHandle(fd, handle);
    return bgr;
}

}  // namespace avatarbooth::kernel_test
