// EGL display, config, window surface and GLES 2 context for the on-screen displays.
#define EGL_NO_X11 1
#define MESA_EGL_NO_X11_HEADERS 1

#include "drivers/display/egl_surface.h"
#include "drivers/display/headless_egl.h"

#include "common/error.h"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES2/gl2.h>

#include <cstdio>
#include <string_view>
#include <vector>

namespace avatarbooth {
namespace {

std::string eglFailure(std::string_view call) {
    const EGLint code = eglGetError();
    char hex[16];
    std::snprintf(hex, sizeof hex, "0x%04X", static_cast<unsigned>(code));
    return std::string(call) + " failed (EGL error " + hex + ")";
}


}  // namespace

EglWindowSurface::EglWindowSurface(unsigned platform, void* nativeDisplay, int visualId, std::string who)
    : who_(std::move(who)) {
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    const auto getPlatformDisplay =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (!eglExtensionListHas(client, "EGL_EXT_platform_base") || getPlatformDisplay == nullptr)
        throw BoothError(ErrorKind::Device, who_, "EGL_EXT_platform_base (eglGetPlatformDisplayEXT) is not offered");
    const EGLDisplay display = getPlatformDisplay(static_cast<EGLenum>(platform), nativeDisplay, nullptr);
    if (display == EGL_NO_DISPLAY) throw BoothError(ErrorKind::Device, who_, eglFailure("eglGetPlatformDisplayEXT"));
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor))
        throw BoothError(ErrorKind::Device, who_, eglFailure("eglInitialize"));
    display_ = display;
    if (!eglBindAPI(EGL_OPENGL_ES_API)) {
        eglTerminate(display);
        throw BoothError(ErrorKind::Device, who_, eglFailure("eglBindAPI(EGL_OPENGL_ES_API)"));
    }
    const EGLint attribs[] = {EGL_SURFACE_TYPE, EGL_WINDOW_BIT, EGL_RED_SIZE, 8, EGL_GREEN_SIZE, 8, EGL_BLUE_SIZE, 8,
                              EGL_ALPHA_SIZE, 0, EGL_RENDERABLE_TYPE, EGL_OPENGL_ES2_BIT, EGL_NONE};
    EGLint count = 0;
    eglChooseConfig(display, attribs, nullptr, 0, &count);
    std::vector<EGLConfig> configs(static_cast<std::size_t>(count > 0 ? count : 0));
    if (count > 0) eglChooseConfig(display, attribs, configs.data(), count, &count);
    for (EGLConfig c : configs) {
        EGLint id = 0;
        eglGetConfigAttrib(display, c, EGL_NATIVE_VISUAL_ID, &id);
        // With a GBM surface the config's visual must be the surface's format (kmscube's match_config_to_visual).
        if (visualId == 0 || id == visualId) {
            config_ = c;
            visualId_ = id;
            break;
        }
    }
    if (config_ == nullptr) {
        eglTerminate(display);
        throw BoothError(ErrorKind::Device, who_,
                         "no EGL config renders OpenGL ES 2 to an RGB888 window" +
                             (visualId != 0 ? " of native visual " + std::to_string(visualId) : std::string()));
    }
}

EglWindowSurface::~EglWindowSurface() {
    const auto display = static_cast<EGLDisplay>(display_);
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    if (context_ != nullptr) eglDestroyContext(display, static_cast<EGLContext>(context_));
    if (surface_ != nullptr) eglDestroySurface(display, static_cast<EGLSurface>(surface_));
    eglTerminate(display);
}

void EglWindowSurface::attach(void* nativeWindow) {
    const auto display = static_cast<EGLDisplay>(display_);
    const auto config = static_cast<EGLConfig>(config_);
    const auto createSurface = reinterpret_cast<PFNEGLCREATEPLATFORMWINDOWSURFACEEXTPROC>(
        eglGetProcAddress("eglCreatePlatformWindowSurfaceEXT"));
    if (createSurface == nullptr)
        throw BoothError(ErrorKind::Device, who_, "eglCreatePlatformWindowSurfaceEXT is not offered");
    const EGLSurface surface = createSurface(display, config, nativeWindow, nullptr);
    if (surface == EGL_NO_SURFACE)
        throw BoothError(ErrorKind::Device, who_, eglFailure("eglCreatePlatformWindowSurfaceEXT"));
    surface_ = surface;
    const EGLint contextAttribs[] = {EGL_CONTEXT_CLIENT_VERSION, 2, EGL_NONE};
    const EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttribs);
    if (context == EGL_NO_CONTEXT) throw BoothError(ErrorKind::Device, who_, eglFailure("eglCreateContext(GLES 2)"));
    context_ = context;
    if (!eglMakeCurrent(display, surface, surface, context))
        throw BoothError(ErrorKind::Device, who_, eglFailure("eglMakeCurrent"));
    const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    renderer_ = renderer != nullptr ? renderer : "(unknown)";
}

void EglWindowSurface::makeCurrent() {
    const auto display = static_cast<EGLDisplay>(display_);
    const auto surface = static_cast<EGLSurface>(surface_);
    const auto context = static_cast<EGLContext>(context_);
    if (eglGetCurrentContext() == context && eglGetCurrentSurface(EGL_DRAW) == surface) return;
    if (!eglMakeCurrent(display, surface, surface, context))
        throw BoothError(ErrorKind::Device, who_, eglFailure("eglMakeCurrent"));
}

void EglWindowSurface::swap() {
    if (!eglSwapBuffers(static_cast<EGLDisplay>(display_), static_cast<EGLSurface>(surface_)))
        throw BoothError(ErrorKind::Device, who_, eglFailure("eglSwapBuffers"));
}

}  // namespace avatarbooth
