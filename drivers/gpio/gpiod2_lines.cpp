// libgpiod 2.x backend of the raw GPIO lines (Debian trixie, Raspberry Pi OS trixie): the same functions as
// gpiod_lines.cpp (libgpiod 1.6); drivers/gpio/CMakeLists.txt compiles one of the two, by pkg-config's version.
//
// What differs from 1.6: chips open by path only, so a label or a name is looked up by scanning /dev/gpiochip*
// (gpiod_chip_info_get_label); all lines of one kind are requested together (line settings + line config +
// request config -> one gpiod_line_request with one fd); edge events are read into an edge event buffer, each
// naming its line offset, stamped in ns on CLOCK_MONOTONIC; the kernel debounces a line when asked
// (gpiod_line_settings_set_debounce_period_us, the v2 uAPI: in hardware where the controller can, else in the
// kernel's own software debouncer).
#include "drivers/gpio/gpiod_lines.h"

#include "common/error.h"

#include <gpiod.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>

namespace avatarbooth {
namespace {

using std::chrono::nanoseconds;

template <typename T, void (*Free)(T*)>
struct Deleter {
    void operator()(T* p) const { Free(p); }
};
using ChipPtr = std::unique_ptr<gpiod_chip, Deleter<gpiod_chip, gpiod_chip_close>>;
using ChipInfoPtr = std::unique_ptr<gpiod_chip_info, Deleter<gpiod_chip_info, gpiod_chip_info_free>>;
using LineInfoPtr = std::unique_ptr<gpiod_line_info, Deleter<gpiod_line_info, gpiod_line_info_free>>;
using SettingsPtr = std::unique_ptr<gpiod_line_settings, Deleter<gpiod_line_settings, gpiod_line_settings_free>>;
using LineConfigPtr = std::unique_ptr<gpiod_line_config, Deleter<gpiod_line_config, gpiod_line_config_free>>;
using RequestConfigPtr =
    std::unique_ptr<gpiod_request_config, Deleter<gpiod_request_config, gpiod_request_config_free>>;
using RequestPtr = std::unique_ptr<gpiod_line_request, Deleter<gpiod_line_request, gpiod_line_request_release>>;
using EventBufferPtr =
    std::unique_ptr<gpiod_edge_event_buffer, Deleter<gpiod_edge_event_buffer, gpiod_edge_event_buffer_free>>;

// Allocation failures of libgpiod's small objects (ENOMEM) are not worth a message of their own.
template <typename P>
P checked(P p, const char* what) {
    if (!p) throw BoothError(ErrorKind::Device, "GPIO", std::string("libgpiod: ") + what + ": " + std::strerror(errno));
    return p;
}

// The character devices present, in name order (gpiochip0, gpiochip1, ...).
std::vector<std::string> chipPaths() {
    std::vector<std::string> paths;
    std::error_code ec;
    for (const auto& e : std::filesystem::directory_iterator("/dev", ec)) {
        const std::string name = e.path().filename().string();
        if (name.rfind("gpiochip", 0) == 0 && gpiod_is_gpiochip_device(e.path().c_str())) paths.push_back(e.path());
    }
    std::sort(paths.begin(), paths.end(), [](const std::string& a, const std::string& b) {
        return a.size() != b.size() ? a.size() < b.size() : a < b;
    });
    return paths;
}

struct ChipFacts {
    std::string name, label;
    std::size_t lines = 0;
};

ChipFacts factsOf(gpiod_chip* chip) {
    ChipInfoPtr info(gpiod_chip_get_info(chip));
    if (!info) return {};
    return {gpiod_chip_info_get_name(info.get()), gpiod_chip_info_get_label(info.get()),
            gpiod_chip_info_get_num_lines(info.get())};
}

std::string chipsPresent() {
    std::string list;
    for (const auto& path : chipPaths()) {
        ChipPtr chip(gpiod_chip_open(path.c_str()));
        if (!chip) {
            list += (list.empty() ? "" : ", ") + path + " (" + std::strerror(errno) + ")";
            continue;
        }
        const ChipFacts f = factsOf(chip.get());
        list += (list.empty() ? "" : ", ") + f.name + " [" + f.label + "] (" + std::to_string(f.lines) + " lines)";
    }
    return list.empty() ? "none (no /dev/gpiochip*)" : list;
}

std::string openFailure(int err) {
    if (err == EACCES || err == EPERM)
        return "permission denied opening the GPIO chip (add the booth's user to the \"gpio\" group, see "
               "firmware/ udev rules)";
    return std::string("not found (looked for it as a label, a name like gpiochip0, a path like /dev/gpiochip0 and "
                       "a number: ") + std::strerror(err) + "); chips here: " + chipsPresent();
}

bool allDigits(const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; });
}

// What gpiod_chip_open_lookup did in 1.6: a path, a number, a name under /dev, else a label. Null with errno set
// when there is no such chip.
gpiod_chip* openLookup(const std::string& descr) {
    if (descr.empty()) {
        errno = ENOENT;
        return nullptr;
    }
    if (descr.front() == '/') return gpiod_chip_open(descr.c_str());
    if (allDigits(descr)) return gpiod_chip_open(("/dev/gpiochip" + descr).c_str());
    const std::string byName = "/dev/" + descr;
    if (descr.find('/') == std::string::npos && gpiod_is_gpiochip_device(byName.c_str()))
        return gpiod_chip_open(byName.c_str());
    int firstError = ENOENT;
    for (const auto& path : chipPaths()) {
        gpiod_chip* chip = gpiod_chip_open(path.c_str());
        if (chip == nullptr) {
            if (firstError == ENOENT) firstError = errno;
            continue;
        }
        if (factsOf(chip).label == descr) return chip;
        gpiod_chip_close(chip);
    }
    // A chip that could not be opened may be the one asked for: say why it could not (permission) over "none".
    errno = firstError;
    return nullptr;
}

SteadyTime steadyNow() { return std::chrono::steady_clock::now(); }

// The v2 uAPI stamps edges on CLOCK_MONOTONIC (steady_clock here) unless asked for another clock. A stamp after the
// time of reading cannot be; it is clamped.
SteadyTime edgeTime(std::uint64_t ns, SteadyTime readAt) {
    return std::min(SteadyTime{nanoseconds(static_cast<long long>(ns))}, readAt);
}

// An open chip, closed on destruction (releasing nothing itself: the line requests hold their lines).
class Chip {
public:
    explicit Chip(const std::string& descr) {
        errno = 0;
        chip_.reset(openLookup(descr));
        if (!chip_)
            throw BoothError(ErrorKind::Device, "GPIO chip \"" + descr + "\"", openFailure(errno ? errno : ENOENT));
        const ChipFacts f = factsOf(chip_.get());
        name_ = f.name + " [" + f.label + "]";
        lines_ = f.lines;
    }

    const std::string& name() const { return name_; }
    gpiod_chip* raw() const { return chip_.get(); }

    std::string where(unsigned offset, const std::string& label) const {
        return "GPIO " + name_ + " line " + std::to_string(offset) + (label.empty() ? "" : " (" + label + ")");
    }

    // A Device error unless the chip has a line at `offset`.
    void checkOffset(unsigned offset, const std::string& label) const {
        if (offset < lines_) return;
        const std::size_t n = lines_;
        throw BoothError(ErrorKind::Device, where(offset, label),
                         "no such line: the chip has " + std::to_string(n) + " lines (0-" +
                             std::to_string(n == 0 ? 0 : n - 1) + ")");
    }

    // Requests the lines `config` names; null with errno set on failure.
    RequestPtr request(const std::string& consumer, gpiod_line_config* config, std::size_t eventBuffer = 0) {
        RequestConfigPtr rc(checked(gpiod_request_config_new(), "request config"));
        gpiod_request_config_set_consumer(rc.get(), consumer.c_str());
        if (eventBuffer != 0) gpiod_request_config_set_event_buffer_size(rc.get(), eventBuffer);
        return RequestPtr(gpiod_chip_request_lines(chip_.get(), rc.get(), config));
    }

    // A Device error for a failed request of `offsets` (errno `err`). The lines are requested together, so a busy
    // one is found by asking the kernel who holds each.
    template <typename Request>
    [[noreturn]] void fail(int err, const std::vector<Request>& requests) {
        if (err == EBUSY) {
            for (const auto& r : requests) {
                LineInfoPtr info(gpiod_chip_get_line_info(chip_.get(), r.offset));
                if (!info || !gpiod_line_info_is_used(info.get())) continue;
                const char* user = gpiod_line_info_get_consumer(info.get());
                throw BoothError(ErrorKind::Device, where(r.offset, r.label),
                                 std::string("the line is already in use") +
                                     (user != nullptr && *user ? " by \"" + std::string(user) + "\"" : std::string()) +
                                     " (another program or a device-tree overlay holds it; see `gpioinfo`)");
            }
        }
        std::string which;
        for (const auto& r : requests) which += (which.empty() ? "" : ", ") + std::to_string(r.offset);
        throw BoothError(ErrorKind::Device, "GPIO " + name_ + " lines " + which,
                         std::string("cannot request the lines: ") + std::strerror(err));
    }

private:
    ChipPtr chip_;
    std::string name_;
    std::size_t lines_ = 0;
};

gpiod_line_bias biasOf(LineBias bias) {
    switch (bias) {
        case LineBias::AsIs: return GPIOD_LINE_BIAS_AS_IS;
        case LineBias::PullUp: return GPIOD_LINE_BIAS_PULL_UP;
        case LineBias::PullDown: return GPIOD_LINE_BIAS_PULL_DOWN;
        case LineBias::Disabled: return GPIOD_LINE_BIAS_DISABLED;
    }
    return GPIOD_LINE_BIAS_AS_IS;
}

class Gpiod2InputLines final : public RawInputLines {
public:
    Gpiod2InputLines(const std::string& chip, const std::vector<InputLineRequest>& requests,
                     const std::string& consumer)
        : chip_(chip) {
        for (const auto& r : requests) {
            chip_.checkOffset(r.offset, r.label);
            offsets_.push_back(r.offset);
        }
        request_ = chip_.request(consumer, config(requests, true).get(), kBufferedEvents);
        if (!request_) {
            const int err = errno;
            const bool anyBias = std::any_of(requests.begin(), requests.end(),
                                             [](const InputLineRequest& r) { return r.bias != LineBias::AsIs; });
            if (!anyBias || (err != EINVAL && err != EOPNOTSUPP)) chip_.fail(err, requests);
            // Some controllers refuse a bias: use the lines as they are and say so.
            request_ = chip_.request(consumer, config(requests, false).get(), kBufferedEvents);
            if (!request_) chip_.fail(errno, requests);
            notes_ += " (bias refused, needs external resistors)";
        }
        for (const auto& r : requests)
            if (r.kernelDebounce.count() > 0) {
                notes_ += ", kernel debounce " + std::to_string(r.kernelDebounce.count()) + " us";
                break;
            }
        events_.reset(checked(gpiod_edge_event_buffer_new(kBufferedEvents), "edge event buffer"));
    }

    std::vector<bool> levels() override {
        std::vector<gpiod_line_value> values(offsets_.size(), GPIOD_LINE_VALUE_ERROR);
        if (gpiod_line_request_get_values_subset(request_.get(), offsets_.size(), offsets_.data(), values.data()) != 0)
            throw BoothError(ErrorKind::Device, "GPIO " + chip_.name(),
                             std::string("cannot read the lines: ") + std::strerror(errno));
        std::vector<bool> out;
        for (const auto v : values) out.push_back(v == GPIOD_LINE_VALUE_ACTIVE);
        return out;
    }

    std::vector<RawEdge> waitEdges(SteadyTime deadline) override {
        std::vector<RawEdge> out;
        const auto left = std::max(deadline - steadyNow(), SteadyTime::duration::zero());
        // Round up to the ms as the 1.6 backend's poll() does, so that a wake-up for the end of a debounce window
        // does not come early.
        const auto ns = std::chrono::duration_cast<nanoseconds>(std::chrono::ceil<std::chrono::milliseconds>(left));
        const int ready = gpiod_line_request_wait_edge_events(request_.get(), ns.count());
        if (ready < 0) {
            if (errno == EINTR) return out;
            throw BoothError(ErrorKind::Device, "GPIO " + chip_.name(),
                             std::string("waiting for button edges failed: ") + std::strerror(errno));
        }
        if (ready == 0) return out;
        const SteadyTime readAt = steadyNow();
        const int n = gpiod_line_request_read_edge_events(request_.get(), events_.get(), kBufferedEvents);
        if (n < 0)
            throw BoothError(ErrorKind::Device, "GPIO " + chip_.name(),
                             std::string("reading edge events failed: ") + std::strerror(errno));
        for (int k = 0; k < n; ++k) {
            gpiod_edge_event* e = gpiod_edge_event_buffer_get_event(events_.get(), static_cast<unsigned long>(k));
            const auto at = std::find(offsets_.begin(), offsets_.end(), gpiod_edge_event_get_line_offset(e));
            if (at == offsets_.end()) continue;
            out.push_back({static_cast<std::size_t>(at - offsets_.begin()),
                           gpiod_edge_event_get_event_type(e) == GPIOD_EDGE_EVENT_RISING_EDGE,
                           edgeTime(gpiod_edge_event_get_timestamp_ns(e), readAt)});
        }
        std::stable_sort(out.begin(), out.end(), [](const RawEdge& a, const RawEdge& b) { return a.time < b.time; });
        return out;
    }

    SteadyTime now() const override { return steadyNow(); }

    std::string describe() const override {
        std::string s = "gpiod " + chip_.name() + " inputs";
        for (const auto o : offsets_) s += " " + std::to_string(o);
        return s + notes_;
    }

private:
    static constexpr std::size_t kBufferedEvents = 64;

    // Every line an input with both edges, on the monotonic clock; with its bias unless `withBias` is false.
    static LineConfigPtr config(const std::vector<InputLineRequest>& requests, bool withBias) {
        LineConfigPtr lc(checked(gpiod_line_config_new(), "line config"));
        for (const auto& r : requests) {
            SettingsPtr s(checked(gpiod_line_settings_new(), "line settings"));
            gpiod_line_settings_set_direction(s.get(), GPIOD_LINE_DIRECTION_INPUT);
            gpiod_line_settings_set_edge_detection(s.get(), GPIOD_LINE_EDGE_BOTH);
            gpiod_line_settings_set_event_clock(s.get(), GPIOD_LINE_CLOCK_MONOTONIC);
            gpiod_line_settings_set_bias(s.get(), withBias ? biasOf(r.bias) : GPIOD_LINE_BIAS_AS_IS);
            gpiod_line_settings_set_debounce_period_us(s.get(), static_cast<unsigned long>(r.kernelDebounce.count()));
            const unsigned offset = r.offset;
            if (gpiod_line_config_add_line_settings(lc.get(), &offset, 1, s.get()) != 0)
                throw BoothError(ErrorKind::Device, "GPIO line " + std::to_string(offset),
                                 std::string("libgpiod: line config: ") + std::strerror(errno));
        }
        return lc;
    }

    Chip chip_;
    RequestPtr request_;
    EventBufferPtr events_;
    std::vector<unsigned> offsets_;
    std::string notes_;
};

class Gpiod2OutputLines final : public RawOutputLines {
public:
    Gpiod2OutputLines(const std::string& chip, const std::vector<OutputLineRequest>& requests,
                      const std::string& consumer)
        : chip_(chip) {
        LineConfigPtr lc(checked(gpiod_line_config_new(), "line config"));
        for (const auto& r : requests) {
            chip_.checkOffset(r.offset, r.label);
            SettingsPtr s(checked(gpiod_line_settings_new(), "line settings"));
            gpiod_line_settings_set_direction(s.get(), GPIOD_LINE_DIRECTION_OUTPUT);
            gpiod_line_settings_set_output_value(s.get(),
                                                 r.initialHigh ? GPIOD_LINE_VALUE_ACTIVE : GPIOD_LINE_VALUE_INACTIVE);
            const unsigned offset = r.offset;
            if (gpiod_line_config_add_line_settings(lc.get(), &offset, 1, s.get()) != 0)
                throw BoothError(ErrorKind::Device, chip_.where(r.offset, r.label),
                                 std::string("libgpiod: line config: ") + std::strerror(errno));
            offsets_.push_back(r.offset);
        }
        request_ = chip_.request(consumer, lc.get());
        if (!request_) chip_.fail(errno, requests);
    }

    void set(std::size_t line, bool high) override {
        if (line >= offsets_.size())
            throw BoothError(ErrorKind::Internal, "GPIO " + chip_.name(), "no output line " + std::to_string(line));
        if (gpiod_line_request_set_value(request_.get(), offsets_[line],
                                         high ? GPIOD_LINE_VALUE_ACTIVE : GPIOD_LINE_VALUE_INACTIVE) != 0)
            throw BoothError(ErrorKind::Device, chip_.where(offsets_[line], ""),
                             std::string("cannot set the line: ") + std::strerror(errno));
    }

    std::string describe() const override {
        std::string s = "gpiod " + chip_.name() + " outputs";
        for (const auto o : offsets_) s += " " + std::to_string(o);
        return s;
    }

private:
    Chip chip_;
    RequestPtr request_;
    std::vector<unsigned> offsets_;
};

}  // namespace

std::unique_ptr<RawInputLines> openGpiodInputLines(const std::string& chip, const std::vector<InputLineRequest>& lines,
                                                   const std::string& consumer) {
    return std::make_unique<Gpiod2InputLines>(chip, lines, consumer);
}

std::unique_ptr<RawOutputLines> openGpiodOutputLines(const std::string& chip,
                                                     const std::vector<OutputLineRequest>& lines,
                                                     const std::string& consumer) {
    return std::make_unique<Gpiod2OutputLines>(chip, lines, consumer);
}

bool gpiodChipAvailable(const std::string& chip, std::string* why) {
    errno = 0;
    if (gpiod_chip* c = openLookup(chip)) {
        gpiod_chip_close(c);
        return true;
    }
    if (why != nullptr) *why = "GPIO chip \"" + chip + "\": " + openFailure(errno ? errno : ENOENT);
    return false;
}

std::vector<GpioLineStatus> gpiodLineStatus(const std::string& chip, const std::vector<unsigned>& offsets,
                                            std::string* chipName) {
    Chip c(chip);  // throws Device naming the chip and why
    if (chipName != nullptr) *chipName = c.name();
    std::vector<GpioLineStatus> out;
    for (const unsigned offset : offsets) {
        GpioLineStatus st;
        st.offset = offset;
        // Line info only reads the kernel's view: nothing is requested, so a running booth is not disturbed.
        if (LineInfoPtr info{gpiod_chip_get_line_info(c.raw(), offset)}) {
            st.exists = true;
            st.used = gpiod_line_info_is_used(info.get());
            if (const char* user = gpiod_line_info_get_consumer(info.get())) st.consumer = user;
            if (const char* name = gpiod_line_info_get_name(info.get())) st.name = name;
            st.kernelDebounce = std::chrono::microseconds(gpiod_line_info_get_debounce_period_us(info.get()));
        }
        out.push_back(st);
    }
    return out;
}

std::string gpiodLibraryVersion() { return std::string("libgpiod ") + gpiod_api_version(); }

bool gpiodKernelDebounce() { return true; }

}  // namespace avatarbooth
