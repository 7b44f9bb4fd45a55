// Buttons from raw lines: wait for edges or for the end of a debounce window, whichever comes first.
#include "drivers/gpio/debounced_buttons.h"

#include "common/error.h"

#include <algorithm>

namespace avatarbooth {

DebouncedButtons::DebouncedButtons(std::unique_ptr<RawInputLines> lines, std::vector<DebouncedLine> config)
    : lines_(std::move(lines)), config_(std::move(config)) {
    const std::vector<bool> levels = lines_->levels();
    if (levels.size() != config_.size())
        throw BoothError(ErrorKind::Internal, lines_->describe(),
                         "got " + std::to_string(levels.size()) + " line levels for " +
                             std::to_string(config_.size()) + " buttons");
    const SteadyTime start = lines_->now();
    for (std::size_t i = 0; i < config_.size(); ++i) {
        debouncers_.emplace_back(config_[i].debounce, levels[i], start);
        reportedDown_.push_back(debouncers_.back().pressed());
    }
}

void DebouncedButtons::collect(std::vector<RawEdge> edges, SteadyTime now) {
    std::vector<std::pair<std::size_t, ButtonTransition>> found;
    for (const RawEdge& e : edges) {
        if (e.line >= debouncers_.size()) continue;
        for (const ButtonTransition& t : debouncers_[e.line].edge(e.high, e.time)) found.emplace_back(e.line, t);
    }
    for (std::size_t i = 0; i < debouncers_.size(); ++i)
        if (auto t = debouncers_[i].advance(now)) found.emplace_back(i, *t);
    // Per line the transitions are already in order; across lines, order by time (line order breaks ties).
    std::stable_sort(found.begin(), found.end(),
                     [](const auto& a, const auto& b) { return a.second.time < b.second.time; });
    queue_.insert(queue_.end(), found.begin(), found.end());
}

std::optional<ButtonEvent> DebouncedButtons::poll(std::chrono::milliseconds timeout) {
    const SteadyTime deadline = lines_->now() + std::max(timeout, std::chrono::milliseconds::zero());
    bool waitedOnce = false;
    while (queue_.empty()) {
        const SteadyTime now = lines_->now();
        if (waitedOnce && now >= deadline) break;
        // Wake for the earliest of: the caller's deadline, the end of a debounce window that may confirm a change.
        SteadyTime wake = deadline;
        for (const Debouncer& d : debouncers_)
            if (auto due = d.pendingUntil()) wake = std::min(wake, *due);
        std::vector<RawEdge> edges = lines_->waitEdges(wake);
        collect(std::move(edges), lines_->now());
        waitedOnce = true;
    }
    if (queue_.empty()) return std::nullopt;
    const auto [line, transition] = queue_.front();
    queue_.pop_front();
    reportedDown_[line] = transition.pressed;
    return ButtonEvent{config_[line].name, transition.pressed ? ButtonAction::Press : ButtonAction::Release,
                       transition.time};
}

bool DebouncedButtons::isDown(const std::string& button) const {
    for (std::size_t i = 0; i < config_.size(); ++i)
        if (config_[i].name == button) return reportedDown_[i];
    return false;
}

std::vector<std::string> DebouncedButtons::names() const {
    std::vector<std::string> out;
    for (const auto& c : config_) out.push_back(c.name);
    return out;
}

std::string DebouncedButtons::describe() const {
    std::string s = lines_->describe();
    if (!config_.empty())
        s += ", debounce " +
             std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(config_[0].debounce.period).count()) +
             " ms";
    return s;
}

bool DebouncedButtons::finished() const {
    if (!queue_.empty() || !lines_->exhausted()) return false;
    return std::none_of(debouncers_.begin(), debouncers_.end(), [](const Debouncer& d) { return d.pendingUntil(); });
}

}  // namespace avatarbooth
