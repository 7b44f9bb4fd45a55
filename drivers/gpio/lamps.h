// Lamps: the button lamps and the flash, switched on and off by name; patterns (blink, flash) as pure logic.
#pragma once

#include "common/clock.h"
#include "drivers/gpio/raw_lines.h"

#include <chrono>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace avatarbooth {

class Lamps {
public:
    virtual ~Lamps() = default;
    // Switches lamp `name` on or off; throws BoothError(BadConfig) for a name that is not configured.
    virtual void set(const std::string& name, bool on) = 0;
    // Whether the lamp was last set on.
    virtual bool isOn(const std::string& name) const = 0;
    // The configured lamps, in order.
    virtual std::vector<std::string> names() const = 0;
    virtual std::string describe() const = 0;
};

// Lamps on output lines (GPIO): lamp i is line i; `activeLow[i]` when the lamp lights with the line low (most
// relay boards). All lamps start off.
class LineLamps final : public Lamps {
public:
    LineLamps(std::unique_ptr<RawOutputLines> lines, std::vector<std::string> names, std::vector<bool> activeLow);
    void set(const std::string& name, bool on) override;
    bool isOn(const std::string& name) const override;
    std::vector<std::string> names() const override { return names_; }
    std::string describe() const override { return lines_->describe(); }

private:
    std::size_t index(const std::string& name) const;
    std::unique_ptr<RawOutputLines> lines_;
    std::vector<std::string> names_;
    std::vector<bool> activeLow_;
    std::vector<bool> on_;
};

// Simulated lamps: remember every change with its time, for tests and for the screen to draw the lamps.
class SimLamps final : public Lamps {
public:
    struct Change {
        std::string lamp;
        bool on = false;
        SteadyTime time;
        bool operator==(const Change&) const = default;
    };

    SimLamps(std::vector<std::string> names, const Clock& clock);
    // Records a change only when the state changes (setting a lamp to what it is records nothing).
    void set(const std::string& name, bool on) override;
    // The changes (changes()) are a record for tests, so only the most recent are kept: the simulated booth
    // (`avatarbooth run`) may run for days, and a visitor's session makes a few dozen changes.
    // At least kKeptChanges / 2 of them, at most kKeptChanges, oldest first.
    static constexpr std::size_t kKeptChanges = 4096;
    bool isOn(const std::string& name) const override;
    std::vector<std::string> names() const override { return names_; }
    std::string describe() const override { return "sim lamps"; }
    const std::vector<Change>& changes() const { return changes_; }

private:
    std::vector<std::string> names_;
    const Clock& clock_;
    std::map<std::string, bool> on_;
    std::vector<Change> changes_;
};

// What a lamp does over time. Evaluated at a given time, so it needs no thread or timer of its own.
class LampPattern {
public:
    static LampPattern off();
    static LampPattern steady();
    // On for the first `onFraction` of every `period`, periods counted from `start`; off before `start`.
    // The attract screen blinks the start button's lamp so that passers-by see which button to press.
    static LampPattern blink(std::chrono::nanoseconds period, SteadyTime start, double onFraction = 0.5);
    // One pulse: on from `start` for `pulse`, off before and after (the flash at the moment of capture).
    static LampPattern flash(std::chrono::nanoseconds pulse, SteadyTime start);

    bool isOn(SteadyTime t) const;
    // The first time after `t` at which isOn changes; nullopt when it never changes again.
    std::optional<SteadyTime> nextChange(SteadyTime t) const;

private:
    enum class Kind { Off, Steady, Blink, Flash };
    Kind kind_ = Kind::Off;
    std::chrono::nanoseconds period_{0};  // blink period, or flash pulse length
    std::chrono::nanoseconds onTime_{0};  // blink: on part of each period
    SteadyTime start_{};
};

// Applies a pattern per lamp at each update(now), touching a lamp only when its state changes.
class LampDriver {
public:
    explicit LampDriver(Lamps& lamps) : lamps_(lamps) {}
    // Gives lamp `name` a pattern (takes effect at the next update). Throws BoothError(BadConfig) for an unknown lamp.
    void setPattern(const std::string& name, LampPattern pattern);
    // Switches every lamp with a pattern to the state its pattern has at `now`.
    void update(SteadyTime now);
    // The earliest time after `now` at which update() would switch a lamp (to sleep until then).
    std::optional<SteadyTime> nextChange(SteadyTime now) const;
    // Whether a lamp of that name is configured.
    bool has(const std::string& name) const;
    // The configured lamps.
    std::vector<std::string> lampNames() const { return lamps_.names(); }

private:
    Lamps& lamps_;
    std::map<std::string, LampPattern> patterns_;
};

// The booth's lamp scenes; lamps a booth does not have are skipped.
// Attract: the "start" lamp blinks with `period` from `now` (passers-by see which button to press), every other
// lamp off.
void showAttractLamps(LampDriver& driver, SteadyTime now, std::chrono::nanoseconds period = std::chrono::seconds(1));
// Capture: the "flash" lamp gives one pulse of `pulse` from `now`; the other lamps keep their patterns.
void flashForCapture(LampDriver& driver, SteadyTime now,
                     std::chrono::nanoseconds pulse = std::chrono::milliseconds(200));

}  // namespace avatarbooth
