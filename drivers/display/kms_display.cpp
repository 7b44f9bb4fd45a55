// KMS display: DRM connector/mode/CRTC, GBM surface, EGL, page flips (the kmscube sequence).
#define EGL_NO_X11 1
#define MESA_EGL_NO_X11_HEADERS 1

#include "drivers/display/kms_display.h"

#include "common/error.h"
#include "drivers/display/egl_surface.h"
#include "drivers/display/quad_presenter.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <fcntl.h>
#include <gbm.h>
#include <poll.h>
#include <unistd.h>
#include <xf86drm.h>
#include <xf86drmMode.h>

#include <algorithm>
#include <cerrno>
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
                // The preferred mode (the panel's native one), else the largest.
                int best = 0;
                for (int m = 0; m < conn->count_modes; ++m) {
                    if (conn->modes[m].type & DRM_MODE_TYPE_PREFERRED) {
                        best = m;
                        break;
                    }
                    if (conn->modes[m].hdisplay * conn->modes[m].vdisplay >
                        conn->modes[best].hdisplay * conn->modes[best].vdisplay)
                        best = m;
                }
                out = {fd, path, name, conn->connector_id, *crtc, conn->modes[best]};
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
};

KmsDisplay::KmsDisplay(const DisplaySettings& settings)
    : state_(std::make_unique<State>()), rotation_(rotationFromDegrees(settings.rotation)) {
    std::string why;
    auto output = findOutput(settings.drmDevice, settings.connector, why);
    if (!output)
        throw BoothError(ErrorKind::Device, settings.drmDevice.empty() ? "/dev/dri" : settings.drmDevice, why);
    State& s = *state_;
    s.output = *output;
    const std::string where = "kms display " + s.output.path + " " + s.output.connector;
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
    const std::string where = "kms display " + s.output.path + " " + s.output.connector;
    if (!s.modeSet) {
        if (drmModeSetCrtc(s.output.fd, s.output.crtcId, fb, 0, 0, &s.output.connectorId, 1, &s.output.mode) != 0) {
            const int err = errno;
            gbm_surface_release_buffer(s.surface, next);
            throw BoothError(ErrorKind::Device, where,
                             std::string("cannot set the mode: ") + std::strerror(err) +
                                 (err == EACCES || err == EPERM
                                      ? " (another program, such as X, Wayland or a console, holds the screen)"
                                      : ""));
        }
        s.modeSet = true;
    } else {
        bool flipped = false;
        if (drmModePageFlip(s.output.fd, s.output.crtcId, fb, DRM_MODE_PAGE_FLIP_EVENT, &flipped) != 0) {
            const int err = errno;
            gbm_surface_release_buffer(s.surface, next);
            throw BoothError(ErrorKind::Device, where, std::string("page flip failed: ") + std::strerror(err));
        }
        drmEventContext events{};
        events.version = 2;
        events.page_flip_handler = [](int, unsigned, unsigned, unsigned, void* data) {
            *static_cast<bool*>(data) = true;
        };
        while (!flipped) {
            pollfd p{s.output.fd, POLLIN, 0};
            const int ready = ::poll(&p, 1, 1000);
            if (ready < 0 && errno == EINTR) continue;
            if (ready <= 0)
                throw BoothError(ErrorKind::Device, where, "the page flip did not complete within 1 s");
            drmHandleEvent(s.output.fd, &events);
        }
    }
    // The previous buffer has left the screen: give it back to GBM for the next frame.
    if (s.shown != nullptr) gbm_surface_release_buffer(s.surface, s.shown);
    s.shown = next;
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

}  // namespace avatarbooth
