// Recognising a combination of buttons held for a while (the operator's lock).
#include "drivers/gpio/buttons.h"

#include <algorithm>

namespace avatarbooth {

HoldDetector::HoldDetector(std::vector<std::string> combination, std::chrono::nanoseconds holdFor)
    : combination_(std::move(combination)), holdFor_(holdFor), down_(combination_.size(), false) {}

void HoldDetector::observe(const ButtonEvent& event) {
    const auto it = std::find(combination_.begin(), combination_.end(), event.button);
    if (it == combination_.end()) return;
    down_[static_cast<std::size_t>(it - combination_.begin())] = event.action == ButtonAction::Press;
    const bool all = !combination_.empty() && std::all_of(down_.begin(), down_.end(), [](bool d) { return d; });
    if (all && !allDown_) {
        allDownSince_ = event.time;
        firedThisHold_ = false;
    }
    allDown_ = all;
}

std::optional<SteadyTime> HoldDetector::due() const {
    if (!allDown_ || firedThisHold_) return std::nullopt;
    return allDownSince_ + holdFor_;
}

bool HoldDetector::fired(SteadyTime now) {
    const auto when = due();
    if (!when || now < *when) return false;
    firedThisHold_ = true;
    return true;
}

}  // namespace avatarbooth
