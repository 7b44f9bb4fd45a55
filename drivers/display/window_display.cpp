// Window display: X11 window, EGL on the X11 platform, the shared quad presenter, key events.
#include "drivers/display/window_display.h"

#include "common/error.h"
#include "drivers/display/egl_surface.h"
#include "drivers/display/quad_presenter.h"

// X11 after everything else: its macros (None, Status, Bool, ...) would clash with other headers.
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <X11/XKBlib.h>
#include <X11/Xlib.h>
#include <X11/Xutil.h>

#include <cstdlib>

namespace avatarbooth {

struct WindowDisplay::State {
    ::Display* x = nullptr;
    Window window = 0;
    Atom deleteWindow = 0;
    Colormap colormap = 0;
    std::unique_ptr<EglWindowSurface> egl;
    std::unique_ptr<QuadPresenter> presenter;
    cv::Size windowSize;
    std::string name;

    ~State() {
        presenter.reset();
        egl.reset();
        if (x != nullptr) {
            if (window != 0) XDestroyWindow(x, window);
            if (colormap != 0) XFreeColormap(x, colormap);
            XCloseDisplay(x);
        }
    }
};

WindowDisplay::WindowDisplay(const DisplaySettings& settings)
    : state_(std::make_unique<State>()),
      panel_(settings.width, settings.height),
      rotation_(rotationFromDegrees(settings.rotation)) {
    if (settings.width < 1 || settings.height < 1 || settings.width > 16384 || settings.height > 16384)
        throw BoothError(ErrorKind::BadConfig, "display.width/height",
                         std::to_string(settings.width) + "x" + std::to_string(settings.height) +
                             " is not a window size (1-16384 pixels each way)");
    const char* name = std::getenv("DISPLAY");
    if (name == nullptr || *name == '\0')
        throw BoothError(ErrorKind::Device, "$DISPLAY",
                         "is not set: there is no X server to open the window on (use the kms or headless display)");
    State& s = *state_;
    s.name = name;
    s.x = XOpenDisplay(name);
    if (s.x == nullptr)
        throw BoothError(ErrorKind::Device, "$DISPLAY=" + s.name,
                         "cannot open the X display (is the X server running, and may this user use it?)");
    const std::string where = "window display on " + s.name;
    s.egl = std::make_unique<EglWindowSurface>(EGL_PLATFORM_X11_KHR, s.x, 0, where);

    // A window with the visual of the EGL config, so the surface can be made on it.
    XVisualInfo want{};
    want.visualid = static_cast<VisualID>(s.egl->nativeVisualId());
    int count = 0;
    XVisualInfo* visual = XGetVisualInfo(s.x, VisualIDMask, &want, &count);
    if (visual == nullptr || count == 0)
        throw BoothError(ErrorKind::Device, where,
                         "no X visual " + std::to_string(s.egl->nativeVisualId()) + " for the EGL config");
    const Window root = RootWindow(s.x, visual->screen);
    XSetWindowAttributes attrs{};
    s.colormap = XCreateColormap(s.x, root, visual->visual, AllocNone);
    attrs.colormap = s.colormap;
    attrs.background_pixel = 0;
    attrs.border_pixel = 0;
    attrs.event_mask = KeyPressMask | KeyReleaseMask | StructureNotifyMask | ExposureMask;
    s.window = XCreateWindow(s.x, root, 0, 0, static_cast<unsigned>(panel_.width),
                             static_cast<unsigned>(panel_.height), 0, visual->depth, InputOutput, visual->visual,
                             CWColormap | CWBackPixel | CWBorderPixel | CWEventMask, &attrs);
    XFree(visual);
    XStoreName(s.x, s.window, settings.windowTitle.c_str());
    s.deleteWindow = XInternAtom(s.x, "WM_DELETE_WINDOW", False);
    XSetWMProtocols(s.x, s.window, &s.deleteWindow, 1);
    // Without this a held key sends release+press pairs; with it, only repeated presses (folded by the keyboard
    // buttons into one).
    Bool supported = False;
    XkbSetDetectableAutoRepeat(s.x, True, &supported);
    XMapWindow(s.x, s.window);
    XFlush(s.x);
    s.windowSize = panel_;
    s.egl->attach(&s.window);
    s.presenter = std::make_unique<QuadPresenter>();
}

WindowDisplay::~WindowDisplay() = default;

void WindowDisplay::present(const cv::Mat& bgr) {
    State& s = *state_;
    s.egl->makeCurrent();
    s.presenter->draw(bgr, s.windowSize, rotation_);
    s.egl->swap();
}

std::vector<KeyEvent> WindowDisplay::pollKeys() {
    State& s = *state_;
    std::vector<KeyEvent> keys;
    while (XPending(s.x) > 0) {
        XEvent e;
        XNextEvent(s.x, &e);
        switch (e.type) {
            case KeyPress:
            case KeyRelease: {
                const KeySym sym = XLookupKeysym(&e.xkey, 0);
                const char* keyName = XKeysymToString(sym);
                if (keyName != nullptr)
                    keys.push_back({keyName, e.type == KeyPress, std::chrono::steady_clock::now()});
                break;
            }
            case ConfigureNotify:
                s.windowSize = {e.xconfigure.width, e.xconfigure.height};
                break;
            case ClientMessage:
                if (static_cast<Atom>(e.xclient.data.l[0]) == s.deleteWindow) closeRequested_ = true;
                break;
            default: break;
        }
    }
    return keys;
}

std::string WindowDisplay::describe() const {
    std::string d = "window " + std::to_string(panel_.width) + "x" + std::to_string(panel_.height) + " on " +
                    state_->name;
    if (rotation_ != Rotation::R0) d += " rotated " + std::to_string(degrees(rotation_));
    return d + " (" + state_->egl->renderer() + ")";
}

}  // namespace avatarbooth
