// What the visitor does, as flow events: the buttons (GPIO or scripted), the keyboard of a window display, and
// the simulated visitor (who also sets what the simulated camera sees and unplugs it).
#pragma once

#include "booth/flow_types.h"
#include "drivers/camera/sim_camera.h"
#include "drivers/display/display.h"
#include "drivers/gpio/button_board.h"
#include "kiosk/kiosk.h"

#include <memory>
#include <utility>
#include <vector>

namespace avatarbooth {

class KioskInputs {
public:
    // `visitor` and `simControls` may be null (no simulated visitor); all must outlive this.
    KioskInputs(ButtonBoard& board, Display& display, VisitorScript* visitor, std::shared_ptr<SimCameraControls> simControls);

    // The presses and releases since the last call, in order. `screen`: what the simulated visitor sees.
    std::vector<FlowEvent> poll(const ScreenModel& screen, FlowTime now);

private:
    ButtonBoard& board_;
    Display& display_;
    VisitorScript* visitor_;
    std::shared_ptr<SimCameraControls> simControls_;
    std::vector<std::pair<Button, FlowTime>> releases_;  // simulated presses to release
};

}  // namespace avatarbooth
