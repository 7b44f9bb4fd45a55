// Settings of the screen: which backend, the panel's rotation and size, the KMS device, headless frame dumps.
// A plain struct with the defaults the booth uses; the config file (app/config/) fills it.
#pragma once

#include <string>

namespace avatarbooth {

struct DisplaySettings {
    // "kms" (EGL on GBM/KMS: the kiosk, no X or Wayland), "window" (EGL in an X11 window, for development),
    // "headless" (no screen), or "auto": kms when a DRM device has a connected screen, else window when $DISPLAY
    // is set, else kms waiting for a screen when a DRM device has a connector (a board whose monitor is off), else
    // headless (createDisplay says which and why). A kms screen lost later is waited for (ReopeningDisplay).
    std::string backend = "auto";
    // Degrees the image is turned clockwise on its way to the panel: 0, 90, 180 or 270. A landscape panel mounted
    // in portrait takes 90 or 270, and the kiosk then composes portrait frames (Display::size()).
    int rotation = 0;
    // The panel's size in pixels for the window and headless backends (kms takes the screen's own mode).
    int width = 1280;
    int height = 720;
    // kms: the DRM device, e.g. "/dev/dri/card1"; empty: the first /dev/dri/card* with a connected screen.
    std::string drmDevice;
    // kms: the connector, e.g. "HDMI-A-1", "DSI-1"; empty: the first connected one.
    std::string connector;
    // headless: write every N-th presented frame as frame_NNNNNN.png into framesDir (0: write none).
    int everyNthFrame = 0;
    std::string framesDir;
    // window: the title of the development window.
    std::string windowTitle = "avatarbooth";
};

}  // namespace avatarbooth
