// A simulated visitor for the simulated booth: walks up, presses Start, faces the camera, turns for the profile,
// keeps the avatar (or retakes a photo first) and walks away. Plain logic: told the screen and the time, it says
// what the simulated camera sees and which button it presses.
#pragma once

#include "kiosk/kiosk.h"

namespace avatarbooth {

struct SimVisitorScript {
    Millis walkUpAfter{1500};      // on the attract screen this long before pressing Start
    Millis pressIfStuckAfter{5000};// in a guide this long without a countdown: press Start (as people do)
    Millis lookAtAvatarFor{3000};  // on the reveal this long before deciding
    bool retakeSideOnce = false;   // on the first reveal ask to retake the side photo, then keep
};

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
};

}  // namespace avatarbooth
