// A simulated visitor for the simulated booth: walks up, presses Start, faces the camera, turns for the profile,
// keeps the avatar (or retakes a photo first) and walks away. Plain logic: told the screen and the time, it says
// what the simulated camera sees and which button it presses.
#pragma once

#include "kiosk/kiosk.h"

#include <string>

namespace avatarbooth {

struct SimVisitorScript {
    Millis walkUpAfter{1500};      // on the attract screen this long before pressing Start
    Millis pressIfStuckAfter{5000};// in a guide this long without a countdown: press Start (as people do)
    Millis lookAtAvatarFor{3000};  // on the reveal this long before deciding
    bool retakeSideOnce = false;   // on the first reveal ask to retake the side photo, then keep
    // The camera is unplugged in the first front guide (after unplugAfter there) and plugged back after the
    // camera-lost screen has shown for plugBackAfter: the booth must say so, then resume.
    bool unplugCameraOnce = false;
    Millis unplugAfter{1000};
    Millis plugBackAfter{1500};
    // Before the first visitor an operator holds the lock combination (Start + Retake) for lockHold, opens
    // "free disk" in the menu, returns to the menu and leaves it.
    bool operatorFirst = false;
    Millis lockHold{5200};
};

// Reads a comma-separated list of what the simulated visitor does besides a plain session ("retake-side",
// "unplug-camera", "operator-menu", "look-at-avatar=8s": on the reveal that long before deciding); throws
// BoothError(BadInput) naming an unknown item or a bad time.
SimVisitorScript parseSimVisitorScript(const std::string& list);

class SimVisitor final : public VisitorScript {
public:
    explicit SimVisitor(SimVisitorScript script = {}) : script_(script) {}
    Action step(const ScreenModel& screen, FlowTime now) override;

private:
    SimVisitorScript script_;
    ScreenId screen_ = ScreenId::Attract;
    Photo photo_ = Photo::Front;
    FlowTime since_{};
    bool acted_ = false;      // pressed on this screen already
    bool retook_ = false;
    bool present_ = false;    // standing at the booth (between pressing Start and the thanks screen)
    bool unplugged_ = false, pluggedBack_ = false;
    int operatorStep_ = 0;    // operatorFirst: 0 not yet, 1 holding the lock, 2.. in the menu, 6 done
    OperatorPage page_ = OperatorPage::Menu;
    OperatorItem lastItem_ = OperatorItem::LastCodes;
};

}  // namespace avatarbooth
