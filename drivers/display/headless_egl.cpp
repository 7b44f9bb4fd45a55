// Headless display: EGL surfaceless (Mesa) or device platform, a GLES 3 context current without a surface.
#define EGL_NO_X11 1
#define MESA_EGL_NO_X11_HEADERS 1

#include "drivers/display/headless_egl.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace avatarbooth {
namespace {

const char* eglErrorName(EGLint code) {
    switch (code) {
        case EGL_SUCCESS: return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
        case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
        case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
        case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
        case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
        case EGL_BAD_DEVICE_EXT: return "EGL_BAD_DEVICE_EXT";
        default: return "unknown EGL error";
    }
}

// "eglInitialize failed: EGL_NOT_INITIALIZED (0x3001)", reading (and clearing) the thread's EGL error.
std::string failure(std::string_view call) {
    const EGLint code = eglGetError();
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04X", static_cast<unsigned>(code));
    return std::string(call) + " failed: " + eglErrorName(code) + " (" + hex + ")";
}

[[noreturn]] void fail(std::string_view call) {
    throw std::runtime_error("headless EGL display: " + failure(call));
}


// Any config that can render OpenGL ES 3: surface type 0 because we draw into framebuffer objects only (the
// default, EGL_WINDOW_BIT, matches nothing on the surfaceless platform).
constexpr EGLint kConfigAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};

// EGL displays are per-process: eglGetPlatformDisplay returns the same handle to every caller and one
// eglTerminate ends it for all of them. Count our users per display and terminate with the last one.
std::mutex& displayMutex() {
    static std::mutex m;
    return m;
}
std::map<EGLDisplay, int>& displayUsers() {
    static std::map<EGLDisplay, int> users;
    return users;
}

// Initialises `display` and checks it can give a surfaceless GLES 3 context; on success counts one more user
// (caller holds displayMutex()). On failure appends the reason to `why` and leaves the display as it was.
bool adoptDisplay(EGLDisplay display, std::string_view label, std::vector<std::string>& why) {
    auto& users = displayUsers();
    const bool inUse = users.count(display) > 0;
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor)) {
        why.push_back(std::string(label) + ": " + failure("eglInitialize"));
        return false;
    }
    std::string problem;
    if (!eglExtensionListHas(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context")) {
        problem = "EGL_KHR_surfaceless_context is not offered";
    } else if (major == 1 && minor < 4) {
        problem = "EGL " + std::to_string(major) + "." + std::to_string(minor) + " is older than 1.4";
    } else {
        const EGLint* attribs = kConfigAttribs;
        EGLint count = 0;
        if (!eglChooseConfig(display, attribs, nullptr, 0, &count)) problem = failure("eglChooseConfig");
        else if (count == 0) problem = "no EGL config supports OpenGL ES 3 (EGL_OPENGL_ES3_BIT)";
    }
    if (!problem.empty()) {
        why.push_back(std::string(label) + ": " + problem);
        if (!inUse) eglTerminate(display);
        return false;
    }
    ++users[display];
    return true;
}

// Drops one user of `display`, terminating it with the last (caller holds displayMutex()).
void disownDisplay(EGLDisplay display) {
    auto& users = displayUsers();
    const auto it = users.find(display);
    if (it == users.end()) return;
    if (--it->second > 0) return;
    users.erase(it);
    eglTerminate(display);
    if (eglGetCurrentContext() == EGL_NO_CONTEXT) eglReleaseThread();
}

// Opens and initialises a display: Mesa surfaceless first, then each enumerated device (hardware before the
// software rasteriser). Caller holds displayMutex().
EGLDisplay openDisplay() {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (client == nullptr) fail("eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS) (EGL client extensions)");
    const auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!eglExtensionListHas(client, "EGL_EXT_platform_base") || getPlatformDisplay == nullptr)
        throw std::runtime_error(
            "headless EGL display: EGL_EXT_platform_base (eglGetPlatformDisplayEXT) is not offered by this EGL");

    std::vector<std::string> why;
    if (eglExtensionListHas(client, "EGL_MESA_platform_surfaceless")) {
        const EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (display == EGL_NO_DISPLAY)
            why.push_back(failure("eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA)"));
        else if (adoptDisplay(display, "surfaceless platform", why))
            return display;
    } else {
        why.push_back("EGL_MESA_platform_surfaceless is not offered");
    }

    const bool canEnumerate = eglExtensionListHas(client, "EGL_EXT_device_enumeration") ||
                              eglExtensionListHas(client, "EGL_EXT_device_base");
    const auto queryDevices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    const auto queryDeviceString =
        reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
    if (!canEnumerate || !eglExtensionListHas(client, "EGL_EXT_platform_device") || queryDevices == nullptr) {
        why.push_back("EGL_EXT_device_enumeration with EGL_EXT_platform_device is not offered");
    } else {
        EGLint count = 0;
        std::vector<EGLDeviceEXT> devices;
        if (!queryDevices(0, nullptr, &count)) {
            why.push_back(failure("eglQueryDevicesEXT"));
        } else {
            devices.resize(static_cast<std::size_t>(std::max(count, 0)));
            if (count > 0 && !queryDevices(count, devices.data(), &count)) why.push_back(failure("eglQueryDevicesEXT"));
            devices.resize(static_cast<std::size_t>(std::max(count, 0)));
            if (devices.empty()) why.push_back("eglQueryDevicesEXT found no device");
        }
        const auto isSoftware = [&](EGLDeviceEXT device) {
            return queryDeviceString != nullptr &&
                   eglExtensionListHas(queryDeviceString(device, EGL_EXTENSIONS), "EGL_MESA_device_software");
        };
        std::stable_partition(devices.begin(), devices.end(), [&](EGLDeviceEXT d) { return !isSoftware(d); });
        for (std::size_t i = 0; i < devices.size(); ++i) {
            const std::string label = "device " + std::to_string(i) + (isSoftware(devices[i]) ? " (software)" : "");
            const EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
            if (display == EGL_NO_DISPLAY)
                why.push_back(label + ": " + failure("eglGetPlatformDisplayEXT(EGL_PLATFORM_DEVICE_EXT)"));
            else if (adoptDisplay(display, label, why))
                return display;
        }
    }

    std::string message = "headless EGL display: no display could be opened";
    for (const auto& reason : why) message += "; " + reason;
    throw std::runtime_error(message);
}

}  // namespace

HeadlessEglContext::HeadlessEglContext() {
    std::lock_guard lock(displayMutex());
    const EGLDisplay display = openDisplay();
    display_ = display;
    try {
        if (!eglBindAPI(EGL_OPENGL_ES_API)) fail("eglBindAPI(EGL_OPENGL_ES_API)");
        EGLConfig config = nullptr;
        EGLint count = 0;
        if (!eglChooseConfig(display, kConfigAttribs, &config, 1, &count) || count < 1)
            fail("eglChooseConfig(EGL_OPENGL_ES3_BIT)");
        // Asking for 3.0 gives the highest compatible 3.x version the driver has (3.2 under Mesa).
        const EGLint contextAttribs[] = {EGL_CONTEXT_CLIENT_VERSION, 3, EGL_NONE};
        const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
        if (context == EGL_NO_CONTEXT) fail("eglCreateContext(OpenGL ES 3)");
        context_ = context;
        if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
            fail("eglMakeCurrent(EGL_NO_SURFACE, EGL_NO_SURFACE) (surfaceless)");

        const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
        const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
        int glMajor = 0, glMinor = 0;
        if (version == nullptr || std::sscanf(version, "OpenGL ES %d.%d", &glMajor, &glMinor) != 2 || glMajor < 3)
            throw std::runtime_error(std::string("headless EGL display: the context is not OpenGL ES 3 ") +
                                     "(GL_VERSION \"" + (version != nullptr ? version : "(null)") + "\")");
        renderer_ = renderer ? renderer : "(unknown)";
    } catch (...) {
        if (context_ != nullptr) {
            eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
            eglDestroyContext(display, static_cast<EGLContext>(context_));
        }
        disownDisplay(display);
        throw;
    }
}

HeadlessEglContext::~HeadlessEglContext() {
    std::lock_guard lock(displayMutex());
    const auto display = static_cast<EGLDisplay>(display_);
    const auto context = static_cast<EGLContext>(context_);
    eglBindAPI(EGL_OPENGL_ES_API);
    if (eglGetCurrentContext() == context) eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
    disownDisplay(display);
}

void HeadlessEglContext::makeCurrent() {
    const auto display = static_cast<EGLDisplay>(display_);
    const auto context = static_cast<EGLContext>(context_);
    eglBindAPI(EGL_OPENGL_ES_API);
    if (eglGetCurrentContext() == context && eglGetCurrentDisplay() == display) return;
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
        fail("eglMakeCurrent (is the context current on another thread?)");
}

void HeadlessEglContext::release() {
    const auto display = static_cast<EGLDisplay>(display_);
    eglBindAPI(EGL_OPENGL_ES_API);
    if (eglGetCurrentContext() != static_cast<EGLContext>(context_)) return;
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT))
        fail("eglMakeCurrent(EGL_NO_CONTEXT)");
}

bool eglExtensionListHas(const char* list, std::string_view name) {
    if (list == nullptr) return false;
    std::string_view rest(list);
    while (!rest.empty()) {
        const auto end = rest.find(' ');
        if (rest.substr(0, end) == name) return true;
        if (end == std::string_view::npos) break;
        rest.remove_prefix(end + 1);
    }
    return false;
}

}  // namespace avatarbooth
