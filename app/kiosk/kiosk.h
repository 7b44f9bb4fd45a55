// The kiosk daemon: wires the camera, buttons, lamps and display to the visitor flow, the screens, the fit and the
// session store, and runs the main loop (`avatarbooth run`).
//
// One thread runs the loop (events in, flow, commands out, one screen per frame); the landmark model loads, the
// preview is analysed, the fit runs and the session folder is written on worker threads (fit_worker.h,
// preview_worker.h, session_writer.h), which post to one queue the loop waits on between frames, so the screen
// never stops. The visitor flow (booth/visitor_flow.h) and the session folder's life (booth/session_lifecycle.h)
// are plain logic; kiosk.cpp is the plumbing between them and the devices.
#pragma once

#include "booth/flow_types.h"
#include "config/booth_config.h"
#include "drivers/camera/sim_camera.h"

#include <atomic>
#include <deque>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

// Someone standing at the simulated booth: told what the screen shows, it says what the simulated camera sees and
// which button it presses. Implemented by sim/sim_visitor.h; the kiosk only knows this interface.
class VisitorScript {
public:
    struct Action {
        SimScene scene = SimScene::Empty;
        std::optional<Button> press;      // pressed now and released a moment later (or after holdFor)
        std::optional<Button> pressWith;  // a second button pressed with it (the operator's lock combination)
        Millis holdFor{0};                // how long the press lasts (0: a short press)
        std::optional<bool> cameraPlugged;  // unplug (false) or plug back (true) the simulated camera
    };
    virtual ~VisitorScript() = default;
    virtual Action step(const ScreenModel& screen, FlowTime now) = 0;
};

struct KioskOptions {
    int sessions = 0;                         // stop after this many visitor sessions have ended (0: run until stopped)
    std::filesystem::path screenshots;        // write a PNG of every screen shown into this folder (empty: none)
    VisitorScript* visitor = nullptr;         // a simulated visitor drives the sim camera's scene and presses
    const std::atomic<bool>* stop = nullptr;  // set (by a signal handler) to stop cleanly
    // The simulated camera's world (scene, faults); made by the kiosk when null. Reliability tests pass their own
    // to unplug the camera or corrupt frames while the booth runs.
    std::shared_ptr<SimCameraControls> simControls;
};

struct KioskReport {
    int sessionsEnded = 0;                        // visitors who came and went (kept, discarded or walked away)
    int sessionsKept = 0;                         // of them, the sessions kept
    // The codes of the most recent kept sessions, oldest first: at most kKeptCodesListed, because a booth left
    // running for weeks would otherwise grow this list without end (every code is in the sessions folder anyway).
    static constexpr std::size_t kKeptCodesListed = 1000;
    std::deque<std::string> keptCodes;
    std::vector<std::filesystem::path> screenshots;  // written, in order
    std::filesystem::path sessionsDirectory;
    std::vector<std::string> devices;             // what was opened, one line each (as logged at start-up)
    double startupToReadySeconds = 0.0;           // to the attract screen and READY=1
    // Figures for the benchmark (printed by `avatarbooth run`; medians where several were measured).
    double guideFramesPerSecond = 0.0;            // screens drawn and presented per second during the guides
    double analysesPerSecond = 0.0;               // preview analyses (face guidance) per second during the guides
    double sideCaptureToRevealSeconds = 0.0;      // the side photo taken -> the avatar on the reveal screen
    double revealFrameMilliseconds = 0.0;         // one reveal frame: avatar render + screen + present
    double revealSlowestFrameMilliseconds = 0.0;  // the slowest reveal frame
    // Its parts: the avatar's render (median over the frames that rendered one; a held pose renders nothing), the
    // screen's composition, the present; and the share of reveal frames that rendered.
    double revealRenderMilliseconds = 0.0;
    double revealComposeMilliseconds = 0.0;
    double revealPresentMilliseconds = 0.0;
    double revealRenderedShare = 0.0;
    std::size_t avatarTriangles = 0;              // of the avatar shown last
    int avatarSamples = 0;                        // the avatar render's samples per pixel
    double peakRssMegabytes = 0.0;                // of the whole process (getrusage)
    // The reveal's other styles (medians over the frames that drew them; held frames reuse the last image).
    double characterFrameMilliseconds = 0.0;      // one character render
    double toonFrameMilliseconds = 0.0;           // one toon billboard render
    double stageRenderMilliseconds = 0.0;         // one stage render (only when the camera angle changed)
    double toonBuildSeconds = 0.0;                // drawing the toon from the photos (background thread)
    int styleFrames = 0, characterRenders = 0, toonRenders = 0, stageRenders = 0;
};

// How the kiosk sets up glibc's allocator (two arenas, a fixed 128 KB mmap threshold: kiosk.cpp says why); runKiosk
// calls it first. Exposed for the memory benchmarks, which measure the same process.
void tuneAllocatorForKiosk();

// Runs the booth until options.sessions have ended or options.stop is set. Throws BoothError when a device or the
// configuration cannot be used at start-up (a camera lost later is waited for, not fatal).
KioskReport runKiosk(const BoothConfig& config, const KioskOptions& options);

}  // namespace avatarbooth
