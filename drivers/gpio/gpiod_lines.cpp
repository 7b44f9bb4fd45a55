// libgpiod 1.6 backend of the raw GPIO lines (Debian bookworm); gpiod2_lines.cpp is the 2.x one, and
// drivers/gpio/CMakeLists.txt compiles one of the two, by pkg-config's version.
//
// What libgpiod 2.x changes (gpiod2_lines.cpp implements the same functions with it):
// chips open by path only (gpiod_chip_open; labels come from gpiod_chip_get_info, so lookup by label means
// scanning /dev/gpiochip*); gpiod_chip_get_line + gpiod_line_request_* are replaced by gpiod_line_settings
// (direction, edge detection, bias, active-low, and a kernel debounce period) + gpiod_line_config +
// gpiod_request_config (consumer) → gpiod_chip_request_lines, returning one gpiod_line_request for all lines;
// values become enum gpiod_line_value; edge events are read into a gpiod_edge_event_buffer from
// gpiod_line_request_read_edge_events on the request's single fd, each event naming its line offset; the
// timestamp is in ns, CLOCK_MONOTONIC by default. The header is then gpiod.h 2.x (pkg-config libgpiod >= 2).
#include "drivers/gpio/gpiod_lines.h"

#include "common/error.h"

#include <gpiod.h>
#include <poll.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <ctime>

namespace avatarbooth {
namespace {

using std::chrono::nanoseconds;

std::string chipsPresent() {
    std::string list;
    if (gpiod_chip_iter* iter = gpiod_chip_iter_new()) {
        gpiod_chip* chip = nullptr;
        gpiod_foreach_chip(iter, chip) {
            list += (list.empty() ? "" : ", ") + std::string(gpiod_chip_name(chip)) + " [" + gpiod_chip_label(chip) +
                    "] (" + std::to_string(gpiod_chip_num_lines(chip)) + " lines)";
        }
        gpiod_chip_iter_free(iter);
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

// An open chip, closed (releasing its requested lines) on destruction.
class Chip {
public:
    explicit Chip(const std::string& descr) {
        errno = 0;
        chip_ = gpiod_chip_open_lookup(descr.c_str());
        if (chip_ == nullptr)
            throw BoothError(ErrorKind::Device, "GPIO chip \"" + descr + "\"", openFailure(errno ? errno : ENOENT));
        name_ = std::string(gpiod_chip_name(chip_)) + " [" + gpiod_chip_label(chip_) + "]";
    }
    ~Chip() { gpiod_chip_close(chip_); }
    Chip(const Chip&) = delete;
    Chip& operator=(const Chip&) = delete;

    const std::string& name() const { return name_; }
    gpiod_chip* raw() const { return chip_; }

    // The line at `offset`, or a Device error naming the chip's range.
    gpiod_line* line(unsigned offset, const std::string& label) {
        gpiod_line* l = gpiod_chip_get_line(chip_, offset);
        if (l == nullptr) {
            const unsigned n = gpiod_chip_num_lines(chip_);
            throw BoothError(ErrorKind::Device, where(offset, label),
                             offset >= n ? "no such line: the chip has " + std::to_string(n) + " lines (0-" +
                                               std::to_string(n == 0 ? 0 : n - 1) + ")"
                                         : std::string("cannot get the line: ") + std::strerror(errno));
        }
        return l;
    }

    std::string where(unsigned offset, const std::string& label) const {
        return "GPIO " + name_ + " line " + std::to_string(offset) + (label.empty() ? "" : " (" + label + ")");
    }

    // Requests `l`; on failure a Device error saying why (see fail()).
    void request(gpiod_line* l, const gpiod_line_request_config& config, int defaultValue, unsigned offset,
                 const std::string& label) {
        if (gpiod_line_request(l, &config, defaultValue) != 0) fail(l, errno, offset, label);
    }

    // A Device error for a failed request (errno `err`), naming the line's current user when it is busy.
    [[noreturn]] void fail(gpiod_line* l, int err, unsigned offset, const std::string& label) {
        if (err == EBUSY) {
            gpiod_line_update(l);
            const char* user = gpiod_line_consumer(l);
            throw BoothError(ErrorKind::Device, where(offset, label),
                             std::string("the line is already in use") +
                                 (user != nullptr && *user ? " by \"" + std::string(user) + "\"" : std::string()) +
                                 " (another program or a device-tree overlay holds it; see `gpioinfo`)");
        }
        throw BoothError(ErrorKind::Device, where(offset, label),
                         std::string("cannot request the line: ") + std::strerror(err));
    }

private:
    gpiod_chip* chip_ = nullptr;
    std::string name_;
};

int biasFlags(LineBias bias) {
    switch (bias) {
        case LineBias::AsIs: return 0;
        case LineBias::PullUp: return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_UP;
        case LineBias::PullDown: return GPIOD_LINE_REQUEST_FLAG_BIAS_PULL_DOWN;
        case LineBias::Disabled: return GPIOD_LINE_REQUEST_FLAG_BIAS_DISABLE;
    }
    return 0;
}

SteadyTime steadyNow() { return std::chrono::steady_clock::now(); }

// Kernels before 5.7 stamp edges with CLOCK_REALTIME, later ones with CLOCK_MONOTONIC (steady_clock here). A
// stamp far from the monotonic now is taken as realtime and replaced by the time of reading.
SteadyTime edgeTime(const timespec& ts, SteadyTime readAt) {
    const SteadyTime t{nanoseconds(static_cast<long long>(ts.tv_sec) * 1'000'000'000LL + ts.tv_nsec)};
    const auto distance = t > readAt ? t - readAt : readAt - t;
    return distance > std::chrono::seconds(60) ? readAt : std::min(t, readAt);
}

class GpiodInputLines final : public RawInputLines {
public:
    GpiodInputLines(const std::string& chip, const std::vector<InputLineRequest>& requests,
                    const std::string& consumer)
        : chip_(chip) {
        for (const auto& r : requests) {
            gpiod_line* l = chip_.line(r.offset, r.label);
            gpiod_line_request_config config{consumer.c_str(), GPIOD_LINE_REQUEST_EVENT_BOTH_EDGES, biasFlags(r.bias)};
            if (gpiod_line_request(l, &config, 0) != 0) {
                const int err = errno;
                if (config.flags == 0 || (err != EINVAL && err != EOPNOTSUPP)) chip_.fail(l, err, r.offset, r.label);
                // Kernels before 5.5 and some controllers refuse a bias: use the line as it is and say so.
                config.flags = 0;
                chip_.request(l, config, 0, r.offset, r.label);
                notes_ += " (line " + std::to_string(r.offset) + ": bias refused, needs an external resistor)";
            }
            lines_.push_back(l);
            fds_.push_back(gpiod_line_event_get_fd(l));
            offsets_.push_back(r.offset);
        }
    }

    std::vector<bool> levels() override {
        std::vector<bool> out;
        for (std::size_t i = 0; i < lines_.size(); ++i) {
            const int v = gpiod_line_get_value(lines_[i]);
            if (v < 0)
                throw BoothError(ErrorKind::Device, chip_.where(offsets_[i], ""),
                                 std::string("cannot read the line: ") + std::strerror(errno));
            out.push_back(v != 0);
        }
        return out;
    }

    std::vector<RawEdge> waitEdges(SteadyTime deadline) override {
        std::vector<RawEdge> out;
        std::vector<pollfd> fds;
        for (const int fd : fds_) fds.push_back({fd, POLLIN | POLLPRI, 0});
        const auto left = deadline - steadyNow();
        // Round up so that a wake-up for the end of a debounce window does not come a fraction of a ms early.
        const auto ms = std::chrono::ceil<std::chrono::milliseconds>(std::max(left, nanoseconds::zero())).count();
        const int ready = ::poll(fds.data(), static_cast<nfds_t>(fds.size()), static_cast<int>(ms));
        if (ready < 0) {
            if (errno == EINTR) return out;
            throw BoothError(ErrorKind::Device, "GPIO " + chip_.name(),
                             std::string("waiting for button edges failed: ") + std::strerror(errno));
        }
        if (ready == 0) return out;
        const SteadyTime readAt = steadyNow();
        for (std::size_t i = 0; i < fds.size(); ++i) {
            if ((fds[i].revents & (POLLIN | POLLPRI)) == 0) continue;
            gpiod_line_event events[16];
            const int n = gpiod_line_event_read_fd_multiple(fds[i].fd, events, 16);
            if (n < 0)
                throw BoothError(ErrorKind::Device, chip_.where(offsets_[i], ""),
                                 std::string("reading edge events failed: ") + std::strerror(errno));
            for (int k = 0; k < n; ++k)
                out.push_back({i, events[k].event_type == GPIOD_LINE_EVENT_RISING_EDGE, edgeTime(events[k].ts, readAt)});
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
    Chip chip_;
    std::vector<gpiod_line*> lines_;
    std::vector<int> fds_;
    std::vector<unsigned> offsets_;
    std::string notes_;
};

class GpiodOutputLines final : public RawOutputLines {
public:
    GpiodOutputLines(const std::string& chip, const std::vector<OutputLineRequest>& requests,
                     const std::string& consumer)
        : chip_(chip) {
        for (const auto& r : requests) {
            gpiod_line* l = chip_.line(r.offset, r.label);
            const gpiod_line_request_config config{consumer.c_str(), GPIOD_LINE_REQUEST_DIRECTION_OUTPUT, 0};
            chip_.request(l, config, r.initialHigh ? 1 : 0, r.offset, r.label);
            lines_.push_back(l);
            offsets_.push_back(r.offset);
        }
    }

    void set(std::size_t line, bool high) override {
        if (line >= lines_.size()) throw BoothError(ErrorKind::Internal, "GPIO " + chip_.name(), "no output line " + std::to_string(line));
        if (gpiod_line_set_value(lines_[line], high ? 1 : 0) != 0)
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
    std::vector<gpiod_line*> lines_;
    std::vector<unsigned> offsets_;
};

}  // namespace

std::unique_ptr<RawInputLines> openGpiodInputLines(const std::string& chip, const std::vector<InputLineRequest>& lines,
                                                   const std::string& consumer) {
    return std::make_unique<GpiodInputLines>(chip, lines, consumer);
}

std::unique_ptr<RawOutputLines> openGpiodOutputLines(const std::string& chip,
                                                     const std::vector<OutputLineRequest>& lines,
                                                     const std::string& consumer) {
    return std::make_unique<GpiodOutputLines>(chip, lines, consumer);
}

bool gpiodChipAvailable(const std::string& chip, std::string* why) {
    errno = 0;
    gpiod_chip* c = gpiod_chip_open_lookup(chip.c_str());
    if (c != nullptr) {
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
        // gpiod_chip_get_line only looks the line up: nothing is requested, so a running booth is not disturbed.
        if (gpiod_line* l = gpiod_chip_get_line(c.raw(), offset)) {
            st.exists = true;
            gpiod_line_update(l);
            st.used = gpiod_line_is_used(l);
            if (const char* user = gpiod_line_consumer(l)) st.consumer = user;
            if (const char* name = gpiod_line_name(l)) st.name = name;
        }
        out.push_back(st);
    }
    return out;
}

std::string gpiodLibraryVersion() { return std::string("libgpiod ") + gpiod_version_string(); }

// The v1 uAPI that 1.6 speaks has no debounce attribute.
bool gpiodKernelDebounce() { return false; }

}  // namespace avatarbooth
