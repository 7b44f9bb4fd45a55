// KMS display: DRM connector/mode/CRTC, GBM surface, EGL, page flips (the kmscube sequence); the writeback read-back.
#define EGL_NO_X11 1
#define MESA_EGL_NO_X11_HEADERS 1

#include "drivers/display/kms_display.h"

#include "common/error.h"
#include "drivers/display/egl_surface.h"
#include "drivers/display/quad_presenter.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <drm_fourcc.h>
#include <fcntl.h>
#include <gbm.h>
#include <poll.h>
#include <sys/mman.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <vector>

namespace avatarbooth {
namespace {

std::string connectorName(const drmModeConnector* c) {
    const char* type = drmModeGetConnectorTypeName(c->connector_type);
    return std::string(type != nullptr ? type : "Unknown") + "-" + std::to_string(c->connector_type_id);
}

std::vector<std::string> cardPaths() {
    std::vector<std::string> out;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator("/dev/dri", ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("card", 0) == 0) out.push_back(e.path().string());
    }
    std::sort(out.begin(), out.end());
    return out;
}

// One DRM device with a chosen connected connector, mode and CRTC.
struct Output {
    int fd = -1;
    std::string path;
    std::string connector;
    std::uint32_t connectorId = 0;
    std::uint32_t crtcId = 0;
    drmModeModeInfo mode{};
};

// The CRTC for `conn`: its current encoder's, else the first one a possible encoder can drive.
std::optional<std::uint32_t> findCrtc(int fd, const drmModeRes* res, const drmModeConnector* conn) {
    if (conn->encoder_id != 0) {
        if (drmModeEncoder* enc = drmModeGetEncoder(fd, conn->encoder_id)) {
            const std::uint32_t crtc = enc->crtc_id;
            drmModeFreeEncoder(enc);
            if (crtc != 0) return crtc;
        }
    }
    for (int i = 0; i < conn->count_encoders; ++i) {
        drmModeEncoder* enc = drmModeGetEncoder(fd, conn->encoders[i]);
        if (enc == nullptr) continue;
        for (int k = 0; k < res->count_crtcs; ++k) {
            if (enc->possible_crtcs & (1u << k)) {
                const std::uint32_t crtc = res->crtcs[k];
                drmModeFreeEncoder(enc);
                return crtc;
            }
        }
        drmModeFreeEncoder(enc);
    }
    return std::nullopt;
}

// The mode the kernel's command line asks for (`video=HDMI-A-1:1280x720@60`, the Pi's cmdline.txt way of choosing
// a mode: the kernel marks it USERDEF), else the preferred one (the panel's native mode), else the largest.
int chooseMode(const drmModeConnector* conn) {
    for (int m = 0; m < conn->count_modes; ++m)
        if (conn->modes[m].type & DRM_MODE_TYPE_USERDEF) return m;
    int best = 0;
    for (int m = 0; m < conn->count_modes; ++m) {
        if (conn->modes[m].type & DRM_MODE_TYPE_PREFERRED) return m;
        if (conn->modes[m].hdisplay * conn->modes[m].vdisplay > conn->modes[best].hdisplay * conn->modes[best].vdisplay)
            best = m;
    }
    return best;
}

// Looks at one device: sets `out` and returns true when it has a usable connected connector (`wanted` empty:
// the first); otherwise appends why not.
bool probeCard(const std::string& path, const std::string& wanted, Output& out, std::string& why) {
    const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) {
        why += "; " + path + ": " + std::strerror(errno) + (errno == EACCES ? " (add the user to the \"video\" group)" : "");
        return false;
    }
    drmModeRes* res = drmModeGetResources(fd);
    if (res == nullptr) {
        why += "; " + path + ": not a KMS device (no display controller)";
        ::close(fd);
        return false;
    }
    std::string seen;
    bool found = false;
    for (int i = 0; i < res->count_connectors && !found; ++i) {
        drmModeConnector* conn = drmModeGetConnector(fd, res->connectors[i]);
        if (conn == nullptr) continue;
        const std::string name = connectorName(conn);
        const bool connected = conn->connection == DRM_MODE_CONNECTED && conn->count_modes > 0;
        seen += (seen.empty() ? "" : ", ") + name + (connected ? " connected" : " not connected");
        if (connected && (wanted.empty() || wanted == name)) {
            if (auto crtc = findCrtc(fd, res, conn)) {
                out = {fd, path, name, conn->connector_id, *crtc, conn->modes[chooseMode(conn)]};
                found = true;
            } else {
                seen += " (no CRTC free for it)";
            }
        }
        drmModeFreeConnector(conn);
    }
    drmModeFreeResources(res);
    if (!found) {
        why += "; " + path + ": " +
               (seen.empty() ? "no connectors"
                             : (wanted.empty() ? "no screen connected" : "connector " + wanted + " not usable") +
                                   " (" + seen + ")");
        ::close(fd);
    }
    return found;
}

// Finds the output the settings ask for; "no DRM device" when there is none at all.
std::optional<Output> findOutput(const std::string& device, const std::string& connector, std::string& why) {
    std::vector<std::string> cards;
    if (!device.empty()) {
        cards.push_back(device);
    } else {
        cards = cardPaths();
        if (cards.empty()) {
            why = "no DRM device (no /dev/dri/card*: no GPU or display controller, or its driver is not loaded)";
            return std::nullopt;
        }
    }
    Output out;
    for (const auto& c : cards)
        if (probeCard(c, connector, out, why)) return out;
    if (why.rfind("; ", 0) == 0) why = why.substr(2);
    if (!device.empty() && !std::filesystem::exists(device)) why = "no DRM device " + device;
    return std::nullopt;
}

struct FramebufferTag {
    int fd;
    std::uint32_t fb;
};

// The KMS framebuffer of a GBM buffer, made once and kept with the buffer (freed when GBM destroys it).
std::uint32_t framebufferFor(int fd, gbm_bo* bo) {
    if (auto* tag = static_cast<FramebufferTag*>(gbm_bo_get_user_data(bo))) return tag->fb;
    std::uint32_t fb = 0;
    const int rc = drmModeAddFB(fd, gbm_bo_get_width(bo), gbm_bo_get_height(bo), 24, 32, gbm_bo_get_stride(bo),
                                gbm_bo_get_handle(bo).u32, &fb);
    if (rc != 0)
        throw BoothError(ErrorKind::Device, "kms display", std::string("drmModeAddFB failed: ") + std::strerror(-rc));
    gbm_bo_set_user_data(bo, new FramebufferTag{fd, fb}, [](gbm_bo*, void* data) {
        auto* tag = static_cast<FramebufferTag*>(data);
        drmModeRmFB(tag->fd, tag->fb);
        delete tag;
    });
    return fb;
}

// Why a KMS call on a device that is there failed: a device unplugged (a USB display, a driver unbound) answers
// every call with ENODEV from then on.
std::string failure(const std::string& what, int err) {
    return what + ": " + std::strerror(err) +
           (err == ENODEV ? " (the display device is gone: unplugged, or its driver was unloaded)" : "");
}

// The id of the property `name` of a KMS object; 0 when it has none.
std::uint32_t propertyId(int fd, std::uint32_t object, std::uint32_t type, const char* name) {
    drmModeObjectProperties* props = drmModeObjectGetProperties(fd, object, type);
    if (props == nullptr) return 0;
    std::uint32_t id = 0;
    for (std::uint32_t i = 0; i < props->count_props && id == 0; ++i) {
        if (drmModePropertyRes* p = drmModeGetProperty(fd, props->props[i])) {
            if (std::strcmp(p->name, name) == 0) id = p->prop_id;
            drmModeFreeProperty(p);
        }
    }
    drmModeFreeObjectProperties(props);
    return id;
}

// A dumb buffer (XRGB8888, CPU-mapped) with its KMS framebuffer: the writeback connector's target.
struct DumbFramebuffer {
    int fd = -1;
    std::uint32_t handle = 0, pitch = 0, fb = 0;
    std::uint64_t size = 0;
    void* map = MAP_FAILED;

    DumbFramebuffer(int device, std::uint32_t width, std::uint32_t height, const std::string& where) : fd(device) {
        try {
            make(width, height, where);
        } catch (...) {
            release();
            throw;
        }
    }
    ~DumbFramebuffer() { release(); }
    DumbFramebuffer(const DumbFramebuffer&) = delete;
    DumbFramebuffer& operator=(const DumbFramebuffer&) = delete;

private:
    void make(std::uint32_t width, std::uint32_t height, const std::string& where) {
        drm_mode_create_dumb create{};
        create.width = width;
        create.height = height;
        create.bpp = 32;
        if (drmIoctl(fd, DRM_IOCTL_MODE_CREATE_DUMB, &create) != 0)
            throw BoothError(ErrorKind::Device, where, failure("cannot create a dumb buffer", errno));
        handle = create.handle;
        pitch = create.pitch;
        size = create.size;
        const std::uint32_t handles[4] = {handle, 0, 0, 0}, pitches[4] = {pitch, 0, 0, 0}, offsets[4] = {0, 0, 0, 0};
        if (drmModeAddFB2(fd, width, height, DRM_FORMAT_XRGB8888, handles, pitches, offsets, &fb, 0) != 0)
            throw BoothError(ErrorKind::Device, where, failure("drmModeAddFB2 (writeback target) failed", errno));
        drm_mode_map_dumb mapReq{};
        mapReq.handle = handle;
        if (drmIoctl(fd, DRM_IOCTL_MODE_MAP_DUMB, &mapReq) != 0)
            throw BoothError(ErrorKind::Device, where, failure("cannot map the dumb buffer", errno));
        map = ::mmap(nullptr, size, PROT_READ, MAP_SHARED, fd, static_cast<off_t>(mapReq.offset));
        if (map == MAP_FAILED) throw BoothError(ErrorKind::Device, where, failure("mmap of the dumb buffer", errno));
    }
    void release() {
        if (map != MAP_FAILED) ::munmap(map, size);
        if (fb != 0) drmModeRmFB(fd, fb);
        if (handle != 0) {
            drm_mode_destroy_dumb destroy{};
            destroy.handle = handle;
            drmIoctl(fd, DRM_IOCTL_MODE_DESTROY_DUMB, &destroy);
        }
        map = MAP_FAILED;
        fb = handle = 0;
    }
};

}  // namespace

struct KmsDisplay::State {
    Output output;
    gbm_device* gbm = nullptr;
    gbm_surface* surface = nullptr;
    std::unique_ptr<EglWindowSurface> egl;
    std::unique_ptr<QuadPresenter> presenter;
    gbm_bo* shown = nullptr;  // the buffer on screen now
    bool modeSet = false;
    drmModeCrtc* savedCrtc = nullptr;  // what was on screen before us, restored at the end
    KmsDisplay::Flip lastFlip;

    std::string where() const { return "kms display " + output.path + " " + output.connector; }

    ~State() {
        if (savedCrtc != nullptr) {
            drmModeSetCrtc(output.fd, savedCrtc->crtc_id, savedCrtc->buffer_id, savedCrtc->x, savedCrtc->y,
                           &output.connectorId, 1, &savedCrtc->mode);
            drmModeFreeCrtc(savedCrtc);
        }
        presenter.reset();
        egl.reset();
        if (shown != nullptr && surface != nullptr) gbm_surface_release_buffer(surface, shown);
        if (surface != nullptr) gbm_surface_destroy(surface);
        if (gbm != nullptr) gbm_device_destroy(gbm);
        if (output.fd >= 0) ::close(output.fd);
    }

    // A screen unplugged (HDMI pulled, a panel switched off that drops hot-plug detect) leaves the CRTC scanning out
    // to nothing and its flips completing as before: only the connector's status says so. The status the kernel
    // last detected (drmModeGetConnectorCurrent probes nothing: one ioctl, no EDID read).
    void checkConnected() const {
        drmModeConnector* conn = drmModeGetConnectorCurrent(output.fd, output.connectorId);
        if (conn == nullptr)
            throw BoothError(ErrorKind::Device, where(), failure("cannot read the connector's state", errno));
        const auto state = conn->connection;
        drmModeFreeConnector(conn);
        if (state == DRM_MODE_DISCONNECTED)
            throw BoothError(ErrorKind::Device, where(),
                             "the screen was disconnected (connector " + output.connector +
                                 " reports no screen): check its cable and power");
    }
};

KmsDisplay::KmsDisplay(const DisplaySettings& settings)
    : state_(std::make_unique<State>()), rotation_(rotationFromDegrees(settings.rotation)) {
    std::string why;
    auto output = findOutput(settings.drmDevice, settings.connector, why);
    if (!output)
        throw BoothError(ErrorKind::Device, settings.drmDevice.empty() ? "/dev/dri" : settings.drmDevice, why);
    State& s = *state_;
    s.output = *output;
    const std::string where = s.where();
    s.gbm = gbm_create_device(s.output.fd);
    if (s.gbm == nullptr) throw BoothError(ErrorKind::Device, where, "gbm_create_device failed");
    s.surface = gbm_surface_create(s.gbm, s.output.mode.hdisplay, s.output.mode.vdisplay, GBM_FORMAT_XRGB8888,
                                   GBM_BO_USE_SCANOUT | GBM_BO_USE_RENDERING);
    if (s.surface == nullptr) throw BoothError(ErrorKind::Device, where, "gbm_surface_create (XRGB8888) failed");
    s.egl = std::make_unique<EglWindowSurface>(EGL_PLATFORM_GBM_KHR, s.gbm, static_cast<int>(GBM_FORMAT_XRGB8888), where);
    s.egl->attach(s.surface);
    s.presenter = std::make_unique<QuadPresenter>();
    s.savedCrtc = drmModeGetCrtc(s.output.fd, s.output.crtcId);
}

KmsDisplay::~KmsDisplay() = default;

cv::Size KmsDisplay::size() const {
    return rotatedSize({state_->output.mode.hdisplay, state_->output.mode.vdisplay}, rotation_);
}

void KmsDisplay::present(const cv::Mat& bgr) {
    State& s = *state_;
    s.checkConnected();
    const cv::Size panel(s.output.mode.hdisplay, s.output.mode.vdisplay);
    s.egl->makeCurrent();
    s.presenter->draw(bgr, panel, rotation_);
    s.egl->swap();
    gbm_bo* next = gbm_surface_lock_front_buffer(s.surface);
    if (next == nullptr) throw BoothError(ErrorKind::Device, "kms display", "gbm_surface_lock_front_buffer failed");
    std::uint32_t fb = 0;
    try {
        fb = framebufferFor(s.output.fd, next);
    } catch (...) {
        gbm_surface_release_buffer(s.surface, next);
        throw;
    }
    const std::string where = s.where();
    if (!s.modeSet) {
        if (drmModeSetCrtc(s.output.fd, s.output.crtcId, fb, 0, 0, &s.output.connectorId, 1, &s.output.mode) != 0) {
            const int err = errno;
            gbm_surface_release_buffer(s.surface, next);
            throw BoothError(ErrorKind::Device, where,
                             failure("cannot set the mode", err) +
                                 (err == EACCES || err == EPERM
                                      ? " (another program, such as X, Wayland or a console, holds the screen)"
                                      : ""));
        }
        s.modeSet = true;
    } else {
        struct Pending {
            bool done = false;
            Flip flip;
        } pending;
        if (drmModePageFlip(s.output.fd, s.output.crtcId, fb, DRM_MODE_PAGE_FLIP_EVENT, &pending) != 0) {
            const int err = errno;
            gbm_surface_release_buffer(s.surface, next);
            throw BoothError(ErrorKind::Device, where, failure("page flip failed", err));
        }
        drmEventContext events{};
        events.version = 2;
        // The kernel's vblank count and time (CLOCK_MONOTONIC, steady_clock's clock) of the refresh that showed it.
        events.page_flip_handler = [](int, unsigned sequence, unsigned sec, unsigned usec, void* data) {
            auto* p = static_cast<Pending*>(data);
            p->done = true;
            p->flip = {sequence, std::chrono::steady_clock::time_point(std::chrono::seconds(sec) +
                                                                       std::chrono::microseconds(usec))};
        };
        while (!pending.done) {
            pollfd p{s.output.fd, POLLIN, 0};
            const int ready = ::poll(&p, 1, 1000);
            if (ready < 0 && errno == EINTR) continue;
            if (ready <= 0)
                throw BoothError(ErrorKind::Device, where, "the page flip did not complete within 1 s");
            if (drmHandleEvent(s.output.fd, &events) != 0)
                throw BoothError(ErrorKind::Device, where, failure("cannot read the page flip's event", errno));
        }
        s.lastFlip = pending.flip;
    }
    // The previous buffer has left the screen: give it back to GBM for the next frame.
    if (s.shown != nullptr) gbm_surface_release_buffer(s.surface, s.shown);
    s.shown = next;
}

KmsDisplay::Flip KmsDisplay::lastFlip() const { return state_->lastFlip; }

double KmsDisplay::refreshHz() const {
    const drmModeModeInfo& m = state_->output.mode;
    return m.htotal > 0 && m.vtotal > 0 ? m.clock * 1000.0 / (static_cast<double>(m.htotal) * m.vtotal) : m.vrefresh;
}

cv::Mat KmsDisplay::readBack() {
    State& s = *state_;
    const std::string where = s.where();
    if (!s.modeSet) throw BoothError(ErrorKind::Internal, where, "nothing shown yet");
    const int fd = s.output.fd;
    // Writeback connectors are listed only to atomic clients that ask for them.
    if (drmSetClientCap(fd, DRM_CLIENT_CAP_ATOMIC, 1) != 0 || drmSetClientCap(fd, DRM_CLIENT_CAP_WRITEBACK_CONNECTORS, 1) != 0)
        throw BoothError(ErrorKind::Device, where, failure("the device offers no atomic modesetting or writeback", errno));
    std::uint32_t writeback = 0;
    if (drmModeRes* res = drmModeGetResources(fd)) {
        int crtcIndex = -1;
        for (int k = 0; k < res->count_crtcs; ++k)
            if (res->crtcs[k] == s.output.crtcId) crtcIndex = k;
        for (int i = 0; i < res->count_connectors && writeback == 0; ++i) {
            drmModeConnector* conn = drmModeGetConnectorCurrent(fd, res->connectors[i]);
            if (conn == nullptr) continue;
            if (conn->connector_type == DRM_MODE_CONNECTOR_WRITEBACK && crtcIndex >= 0) {
                for (int e = 0; e < conn->count_encoders && writeback == 0; ++e) {
                    if (drmModeEncoder* enc = drmModeGetEncoder(fd, conn->encoders[e])) {
                        if (enc->possible_crtcs & (1u << crtcIndex)) writeback = conn->connector_id;
                        drmModeFreeEncoder(enc);
                    }
                }
            }
            drmModeFreeConnector(conn);
        }
        drmModeFreeResources(res);
    }
    if (writeback == 0)
        throw BoothError(ErrorKind::Device, where, "the device has no writeback connector for this CRTC");
    const std::uint32_t crtcProp = propertyId(fd, writeback, DRM_MODE_OBJECT_CONNECTOR, "CRTC_ID");
    const std::uint32_t fbProp = propertyId(fd, writeback, DRM_MODE_OBJECT_CONNECTOR, "WRITEBACK_FB_ID");
    const std::uint32_t fenceProp = propertyId(fd, writeback, DRM_MODE_OBJECT_CONNECTOR, "WRITEBACK_OUT_FENCE_PTR");
    if (crtcProp == 0 || fbProp == 0 || fenceProp == 0)
        throw BoothError(ErrorKind::Device, where, "the writeback connector lacks CRTC_ID/WRITEBACK_FB_ID/WRITEBACK_OUT_FENCE_PTR");

    const std::uint32_t width = s.output.mode.hdisplay, height = s.output.mode.vdisplay;
    DumbFramebuffer target(fd, width, height, where);
    // The commit routes the writeback connector to our CRTC (a modeset the first time: the CRTC's connectors change)
    // and gives it a buffer for one frame; the out-fence signals once the CRTC's next refresh was written into it.
    std::int32_t fence = -1;
    drmModeAtomicReq* req = drmModeAtomicAlloc();
    drmModeAtomicAddProperty(req, writeback, crtcProp, s.output.crtcId);
    drmModeAtomicAddProperty(req, writeback, fbProp, target.fb);
    drmModeAtomicAddProperty(req, writeback, fenceProp, reinterpret_cast<std::uintptr_t>(&fence));
    const int rc = drmModeAtomicCommit(fd, req, DRM_MODE_ATOMIC_ALLOW_MODESET, nullptr);
    const int err = errno;
    drmModeAtomicFree(req);
    if (rc != 0) throw BoothError(ErrorKind::Device, where, failure("the writeback commit failed", err));
    struct CloseFence {
        int fd;
        ~CloseFence() {
            if (fd >= 0) ::close(fd);
        }
    } closeFence{fence};
    if (fence >= 0) {
        pollfd p{fence, POLLIN, 0};
        int ready = 0;
        while ((ready = ::poll(&p, 1, 1000)) < 0 && errno == EINTR) {
        }
        if (ready <= 0) throw BoothError(ErrorKind::Device, where, "the writeback did not complete within 1 s");
    }
    cv::Mat bgr;
    cv::cvtColor(cv::Mat(static_cast<int>(height), static_cast<int>(width), CV_8UC4, target.map, target.pitch), bgr,
                 cv::COLOR_BGRA2BGR);
    return bgr;
}

std::string KmsDisplay::describe() const {
    const auto& o = state_->output;
    std::string s = "kms " + o.path + " " + o.connector + " " + std::to_string(o.mode.hdisplay) + "x" +
                    std::to_string(o.mode.vdisplay) + "@" + std::to_string(o.mode.vrefresh);
    if (rotation_ != Rotation::R0) s += " rotated " + std::to_string(degrees(rotation_));
    return s + " (" + state_->egl->renderer() + ")";
}

bool kmsScreenAvailable(const std::string& device, const std::string& connector, std::string* why) {
    std::string reason;
    auto output = findOutput(device, connector, reason);
    if (output) {
        ::close(output->fd);
        return true;
    }
    if (why != nullptr) *why = reason;
    return false;
}

bool kmsScreenExpected(const std::string& device, const std::string& connector, std::string* what) {
    const std::vector<std::string> cards = device.empty() ? cardPaths() : std::vector<std::string>{device};
    std::string seen;
    bool found = false;
    for (const auto& path : cards) {
        const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
        if (fd < 0) continue;
        if (drmModeRes* res = drmModeGetResources(fd)) {
            for (int i = 0; i < res->count_connectors; ++i) {
                drmModeConnector* conn = drmModeGetConnectorCurrent(fd, res->connectors[i]);
                if (conn == nullptr) continue;
                // A writeback connector (vkms's, the Pi's TXP) is no place for a screen.
                const std::string name = connectorName(conn);
                if (conn->connector_type != DRM_MODE_CONNECTOR_WRITEBACK && (connector.empty() || connector == name)) {
                    found = true;
                    seen += (seen.empty() ? "" : ", ") + path + " " + name +
                            (conn->connection == DRM_MODE_CONNECTED ? " connected" : " not connected");
                }
                drmModeFreeConnector(conn);
            }
            drmModeFreeResources(res);
        }
        ::close(fd);
    }
    if (what != nullptr) *what = seen;
    return found;
}

}  // namespace avatarbooth
