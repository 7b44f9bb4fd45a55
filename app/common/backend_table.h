// The backends of one device kind as a table in the order "auto" tries them: choosing one by name or by probing.
//
// Each kind (drivers/camera/camera_backends.h, drivers/display/display_backends.h, drivers/gpio/button_backends.h)
// owns one constant table of {name, probe, open}; the factories, the config's allowed words, `avatarbooth check`
// and `run`'s "simulated booth" decision all read that one table, so "auto" has one set of rules. The tables are
// constant arrays of function pointers: nothing registers itself at start-up (libcamera's rule).
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace avatarbooth {

// What a backend's probe found out, without taking the device (check can run next to a running booth).
struct BackendProbe {
    bool usable = false;
    // Usable: what it found, for the log ("V4L2 camera /dev/video0 (UVC Camera) found"; may be empty); else why
    // it cannot be used here ("no DRM device ...").
    std::string text;
    // The device it found, for backends that look for one (a camera node or id); "" = the configured one.
    std::string device;
};

// One backend of a kind: its word in the configuration, its probe, and how it opens (`Open` is the kind's own
// function pointer type, as each kind opens with other arguments).
template <typename Settings, typename Open>
struct Backend {
    std::string_view name;
    BackendProbe (*probe)(const Settings&);
    Open open;
};

// A backend "auto" passed over, and why.
struct PassedBackend {
    std::string name;
    std::string why;
};

template <typename Entry>
struct BackendChoice {
    const Entry* backend = nullptr;     // the one chosen; null when no backend of the table is usable
    BackendProbe probe;                 // its probe's result
    std::vector<PassedBackend> passed;  // the earlier ones, in table order, with their reasons
};

// The entry named `name`, or null.
template <typename Entry>
const Entry* findBackend(std::span<const Entry> table, std::string_view name) {
    for (const Entry& e : table)
        if (e.name == name) return &e;
    return nullptr;
}

// "auto": probes the entries from `from` on in table order and takes the first usable one.
template <typename Entry, typename Settings>
BackendChoice<Entry> probeBackends(std::span<const Entry> table, const Settings& settings, std::size_t from = 0) {
    BackendChoice<Entry> choice;
    for (std::size_t i = from; i < table.size(); ++i) {
        BackendProbe probe = table[i].probe(settings);
        if (probe.usable) {
            choice.backend = &table[i];
            choice.probe = std::move(probe);
            return choice;
        }
        choice.passed.push_back({std::string(table[i].name), std::move(probe.text)});
    }
    return choice;
}

// The words the configuration allows: "auto", then the table's names in order.
template <typename Entry>
std::vector<std::string> backendWords(std::span<const Entry> table) {
    std::vector<std::string> words{"auto"};
    for (const Entry& e : table) words.emplace_back(e.name);
    return words;
}

// The same words for a message: "auto, kms, window or headless".
template <typename Entry>
std::string backendWordList(std::span<const Entry> table) {
    const std::vector<std::string> words = backendWords(table);
    std::string out;
    for (std::size_t i = 0; i < words.size(); ++i) out += (i == 0 ? "" : i + 1 == words.size() ? " or " : ", ") + words[i];
    return out;
}

// Why "auto" passed over the earlier backends: "kms: no DRM device ...; window: $DISPLAY is not set".
inline std::string passedOver(const std::vector<PassedBackend>& passed) {
    std::string out;
    for (const PassedBackend& p : passed) out += (out.empty() ? "" : "; ") + p.name + ": " + p.why;
    return out;
}

// Why "auto" chose as it did: why the earlier backends were passed over, or what the first one found when none was.
template <typename Entry>
std::string autoWhy(const BackendChoice<Entry>& choice) {
    return choice.passed.empty() ? choice.probe.text : passedOver(choice.passed);
}

// The "auto" part of a start-up description: "auto" or "auto: " + autoWhy.
template <typename Entry>
std::string autoReason(const BackendChoice<Entry>& choice) {
    const std::string why = autoWhy(choice);
    return why.empty() ? std::string("auto") : "auto: " + why;
}

}  // namespace avatarbooth
