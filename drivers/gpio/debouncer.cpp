// Debouncing by rate limit: the reported state changes at most once per debounce period.
#include "drivers/gpio/debouncer.h"

#include <algorithm>

namespace avatarbooth {

Debouncer::Debouncer(DebounceSettings settings, bool levelHigh, SteadyTime start)
    : settings_(settings), lastEdge_(start) {
    if (settings_.period < std::chrono::nanoseconds::zero()) settings_.period = std::chrono::nanoseconds::zero();
    lastChange_ = start - settings_.period;
    pressed_ = raw_ = isPressedLevel(levelHigh);
}

std::optional<ButtonTransition> Debouncer::advance(SteadyTime now) {
    if (raw_ == pressed_) return std::nullopt;
    const SteadyTime due = lastChange_ + settings_.period;
    if (now < due) return std::nullopt;
    pressed_ = raw_;
    lastChange_ = due;
    return ButtonTransition{pressed_, due};
}

std::vector<ButtonTransition> Debouncer::edge(bool levelHigh, SteadyTime t) {
    t = std::max(t, lastEdge_);
    lastEdge_ = t;
    std::vector<ButtonTransition> out;
    if (auto waiting = advance(t)) out.push_back(*waiting);
    raw_ = isPressedLevel(levelHigh);
    if (raw_ != pressed_ && t >= lastChange_ + settings_.period) {
        pressed_ = raw_;
        lastChange_ = t;
        out.push_back({pressed_, t});
    }
    return out;
}

std::optional<SteadyTime> Debouncer::pendingUntil() const {
    if (raw_ == pressed_) return std::nullopt;
    return lastChange_ + settings_.period;
}

}  // namespace avatarbooth
