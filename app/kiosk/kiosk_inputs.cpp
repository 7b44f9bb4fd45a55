// The visitor's presses as flow events (see kiosk_inputs.h).
#include "kiosk/kiosk_inputs.h"

#include <spdlog/spdlog.h>

namespace avatarbooth {

namespace {
constexpr auto kReleaseAfter = std::chrono::milliseconds(120);  // a simulated press lasts this long
}

KioskInputs::KioskInputs(ButtonBoard& board, Display& display, VisitorScript* visitor,
                         std::shared_ptr<SimCameraControls> simControls)
    : board_(board), display_(display), visitor_(visitor), simControls_(std::move(simControls)) {}

std::vector<FlowEvent> KioskInputs::poll(const ScreenModel& screen, FlowTime now) {
    std::vector<FlowEvent> events;
    if (board_.keyboard)
        for (const auto& key : display_.pollKeys()) board_.keyboard->feed(key.key, key.pressed, key.time);
    while (auto e = board_.buttons->poll(std::chrono::milliseconds(0))) {
        if (const auto b = parseButton(e->button)) {
            if (e->action == ButtonAction::Press) events.push_back(ButtonPressed{*b, now});
            else events.push_back(ButtonReleased{*b, now});
        }
    }
    // Simulated presses that are over (before any new press: a button is up before it goes down again).
    for (auto it = releases_.begin(); it != releases_.end();) {
        if (it->second <= now) {
            events.push_back(ButtonReleased{it->first, now});
            it = releases_.erase(it);
        } else {
            ++it;
        }
    }
    if (!visitor_) return events;
    const VisitorScript::Action a = visitor_->step(screen, now);
    simControls_->setScene(a.scene);
    if (a.cameraPlugged && *a.cameraPlugged != !simControls_->vanished()) {
        spdlog::info("simulated visitor: camera {}", *a.cameraPlugged ? "plugged back" : "unplugged");
        if (*a.cameraPlugged) simControls_->comeBack();
        else simControls_->vanish();
    }
    for (const auto& b : {a.press, a.pressWith}) {
        if (!b) continue;
        events.push_back(ButtonPressed{*b, now});
        releases_.emplace_back(*b, now + (a.holdFor > Millis(0) ? a.holdFor : kReleaseAfter));
    }
    return events;
}

}  // namespace avatarbooth
