// EGL with a window surface, shared by the KMS (GBM surface) and window (X11) displays; private to this folder.
// EGL types stay in the .cpp: handles are void* here, platform constants plain integers.
#pragma once

#include <string>

namespace avatarbooth {

class EglWindowSurface {
public:
    // Opens the EGL display of `platform` (EGL_PLATFORM_GBM_KHR, EGL_PLATFORM_X11_KHR) on `nativeDisplay`
    // (gbm_device*, X11 Display*) and picks an RGB888 window config for OpenGL ES 2; with `visualId` not 0 only a
    // config of that native visual (a GBM format) is taken. `who` prefixes errors ("kms display"). Throws
    // BoothError(Device) naming the EGL call and error.
    EglWindowSurface(unsigned platform, void* nativeDisplay, int visualId, std::string who);
    ~EglWindowSurface();
    EglWindowSurface(const EglWindowSurface&) = delete;
    EglWindowSurface& operator=(const EglWindowSurface&) = delete;

    // The native visual of the chosen config (an X11 visual id to create the window with).
    int nativeVisualId() const { return visualId_; }
    // Creates the window surface on `nativeWindow` (as EGL_EXT_platform_base wants it: gbm_surface*, or a pointer
    // to the X11 Window) and a GLES 2 context, and makes them current.
    void attach(void* nativeWindow);
    // Makes the surface and its context current again: the kiosk's offscreen renders (the avatar) make their own
    // context current on the same thread between two frames. Throws on failure.
    void makeCurrent();
    // eglSwapBuffers; throws on failure.
    void swap();
    const std::string& renderer() const { return renderer_; }

private:
    std::string who_;
    void* display_ = nullptr;
    void* config_ = nullptr;
    void* surface_ = nullptr;
    void* context_ = nullptr;
    int visualId_ = 0;
    std::string renderer_;
};

}  // namespace avatarbooth
