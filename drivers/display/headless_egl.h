// Headless display: an OpenGL ES 3 context with no window and no screen, for rendering into framebuffer objects.
//
// Opens EGL through Mesa's surfaceless platform (EGL_PLATFORM_SURFACELESS_MESA) and falls back to device
// enumeration (EGL_EXT_device_enumeration + EGL_EXT_platform_device). The context is made current without a
// surface (EGL_KHR_surfaceless_context), so all drawing goes to framebuffer objects. EGL types stay out of this
// header so including it pulls in no EGL/X11 headers.
#pragma once

#include <string>
#include <string_view>

namespace avatarbooth {

class HeadlessEglContext {
public:
    // Opens the display, creates a GLES 3.x context and makes it current on the calling thread; throws
    // std::runtime_error naming the EGL call that failed and its error code when EGL or GLES 3 is unavailable.
    HeadlessEglContext();
    // Releases the context from the calling thread, destroys it and terminates the display when no other
    // HeadlessEglContext uses it.
    ~HeadlessEglContext();

    HeadlessEglContext(const HeadlessEglContext&) = delete;
    HeadlessEglContext& operator=(const HeadlessEglContext&) = delete;
    HeadlessEglContext(HeadlessEglContext&&) = delete;
    HeadlessEglContext& operator=(HeadlessEglContext&&) = delete;

    // Makes this context current on the calling thread (a no-op when it already is); a context is current on
    // at most one thread at a time, so another thread that used it must call release() first.
    void makeCurrent();
    // Detaches this context from the calling thread so another thread can make it current.
    void release();
    // The GL_RENDERER string of the context, e.g. "llvmpipe (LLVM 15.0.6, 256 bits)".
    const std::string& renderer() const { return renderer_; }

private:
    void* display_ = nullptr;  // EGLDisplay
    void* context_ = nullptr;  // EGLContext
    std::string renderer_;
};

// Whether a space-separated EGL extension list (eglQueryString(..., EGL_EXTENSIONS)) names `name` as a whole word;
// false for a null list. Shared by every EGL user in drivers/display.
bool eglExtensionListHas(const char* list, std::string_view name);

}  // namespace avatarbooth
