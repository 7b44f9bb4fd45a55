// Buttons made of raw input lines: one Debouncer per line, events merged in time order.
#pragma once

#include "drivers/gpio/buttons.h"
#include "drivers/gpio/debouncer.h"
#include "drivers/gpio/raw_lines.h"

#include <deque>
#include <memory>

namespace avatarbooth {

struct DebouncedLine {
    std::string name;           // the button's name
    DebounceSettings debounce;  // period and polarity of this line
};

class DebouncedButtons final : public Buttons {
public:
    // `config[i]` describes line i of `lines`. Reads the lines' levels once to start from the current state.
    DebouncedButtons(std::unique_ptr<RawInputLines> lines, std::vector<DebouncedLine> config);

    std::optional<ButtonEvent> poll(std::chrono::milliseconds timeout) override;
    bool isDown(const std::string& button) const override;
    std::vector<std::string> names() const override;
    std::string describe() const override;
    bool finished() const override;

private:
    // Moves transitions confirmed by time `now` into the queue, in time order.
    void collect(std::vector<RawEdge> edges, SteadyTime now);

    std::unique_ptr<RawInputLines> lines_;
    std::vector<DebouncedLine> config_;
    std::vector<Debouncer> debouncers_;
    std::vector<bool> reportedDown_;  // as told by the events handed out
    std::deque<std::pair<std::size_t, ButtonTransition>> queue_;
};

}  // namespace avatarbooth
