// Every table and key of booth.toml, and the default file and Markdown reference rendered from them.
#include "config/config_schema.h"

#include "drivers/camera/camera_backends.h"
#include "drivers/display/display_backends.h"
#include "drivers/gpio/button_backends.h"
#include "reveal/character/proportions.h"
#include "fit/head/rbf.h"

#include <charconv>
#include <chrono>
#include <cmath>
#include <set>
#include <sstream>
#include <type_traits>

namespace avatarbooth {
namespace {

// A key's field in BoothConfig, written once and used for reading (const) and writing: FIELD(camera.device) for a
// plain table's key, ELEMENT(buttons.buttons[i].offset) for a key of a Repeated table's i-th element.
#define FIELD(expr) [](auto& c) -> auto& { return c.expr; }
#define ELEMENT(expr) [](auto& c, std::size_t i) -> auto& { return c.expr; }

template <typename Ref, typename C>
decltype(auto) at(const Ref& ref, C& c, std::size_t i) {
    if constexpr (std::is_invocable_v<const Ref&, C&, std::size_t>) return ref(c, i);
    else return ref(c);
}

std::string asText(const std::string& s) { return s; }
std::string asText(const std::filesystem::path& p) { return p.string(); }

template <typename Ref>
ConfigKey textKey(std::string table, std::string name, ConfigType type, Ref ref, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = type, .doc = std::move(doc)};
    k.get = [ref](const BoothConfig& c, std::size_t i) { return ConfigValue(asText(at(ref, c, i))); };
    k.set = [ref](BoothConfig& c, std::size_t i, const ConfigValue& v) { at(ref, c, i) = std::get<std::string>(v); };
    return k;
}
template <typename Ref>
ConfigKey text(std::string table, std::string name, Ref ref, std::string doc) {
    return textKey(std::move(table), std::move(name), ConfigType::String, ref, std::move(doc));
}
template <typename Ref>
ConfigKey path(std::string table, std::string name, Ref ref, std::string doc) {
    return textKey(std::move(table), std::move(name), ConfigType::Path, ref, std::move(doc));
}

template <typename Ref>
ConfigKey choice(std::string table, std::string name, Ref ref, std::vector<std::string> choices, std::string doc) {
    ConfigKey k = textKey(std::move(table), std::move(name), ConfigType::Choice, ref, std::move(doc));
    k.choices = std::move(choices);
    return k;
}

// A device kind's `backend` key: the words are the kind's backend table's names after "auto" (so the file accepts
// exactly what the factories open), and the doc lists them after what "auto" does.
template <typename Ref, std::size_t N>
ConfigKey backendChoice(std::string table, Ref ref, const std::array<std::string_view, N>& backends,
                        const std::string& autoDoes) {
    std::vector<std::string> words{"auto"};
    for (const std::string_view name : backends) words.emplace_back(name);
    std::string doc = "\"auto\" (" + autoDoes + ")";
    for (std::size_t i = 1; i < words.size(); ++i) doc += ", \"" + words[i] + "\"";
    return choice(std::move(table), "backend", ref, std::move(words), doc + ".");
}

template <typename Ref>
ConfigKey flag(std::string table, std::string name, Ref ref, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::Bool, .doc = std::move(doc)};
    k.get = [ref](const BoothConfig& c, std::size_t i) { return ConfigValue(static_cast<bool>(at(ref, c, i))); };
    k.set = [ref](BoothConfig& c, std::size_t i, const ConfigValue& v) { at(ref, c, i) = std::get<bool>(v); };
    return k;
}

template <typename Ref>
ConfigKey integer(std::string table, std::string name, Ref ref, long long lo, long long hi, std::string doc,
                  long long step = 1) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::Integer,
                .min = static_cast<double>(lo), .max = static_cast<double>(hi), .step = step, .doc = std::move(doc)};
    k.get = [ref](const BoothConfig& c, std::size_t i) { return ConfigValue(static_cast<long long>(at(ref, c, i))); };
    k.set = [ref](BoothConfig& c, std::size_t i, const ConfigValue& v) {
        auto& field = at(ref, c, i);
        field = static_cast<std::remove_reference_t<decltype(field)>>(std::get<long long>(v));
    };
    return k;
}

template <typename Ref>
ConfigKey number(std::string table, std::string name, Ref ref, double lo, double hi, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::Number, .min = lo, .max = hi,
                .doc = std::move(doc)};
    k.get = [ref](const BoothConfig& c, std::size_t i) { return ConfigValue(static_cast<double>(at(ref, c, i))); };
    k.set = [ref](BoothConfig& c, std::size_t i, const ConfigValue& v) { at(ref, c, i) = std::get<double>(v); };
    return k;
}

// A std::chrono::duration field given in seconds; rounded to the field's own tick (milliseconds), so 0.29 s is
// 290 ms and not 289.
template <typename Ref>
ConfigKey seconds(std::string table, std::string name, Ref ref, double lo, double hi, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::Seconds, .min = lo, .max = hi,
                .doc = std::move(doc)};
    k.get = [ref](const BoothConfig& c, std::size_t i) {
        return ConfigValue(std::chrono::duration<double>(at(ref, c, i)).count());
    };
    k.set = [ref](BoothConfig& c, std::size_t i, const ConfigValue& v) {
        auto& field = at(ref, c, i);
        field = std::chrono::round<std::remove_reference_t<decltype(field)>>(std::chrono::duration<double>(std::get<double>(v)));
    };
    return k;
}

// A retention age (std::chrono::seconds) given in `Unit`s (hours, days).
template <typename Unit, typename Ref>
ConfigKey age(std::string table, std::string name, Ref ref, double lo, double hi, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::Number, .min = lo, .max = hi,
                .doc = std::move(doc)};
    k.get = [ref](const BoothConfig& c, std::size_t i) {
        return ConfigValue(std::chrono::duration<double, Unit>(at(ref, c, i)).count());
    };
    k.set = [ref](BoothConfig& c, std::size_t i, const ConfigValue& v) {
        const double s = std::get<double>(v) * static_cast<double>(Unit::num) / static_cast<double>(Unit::den);
        at(ref, c, i) = std::chrono::seconds(static_cast<long long>(std::llround(s)));
    };
    return k;
}

// A choice stored as an enum: `name` and `parse` translate.
template <typename Ref, typename Name, typename Parse>
ConfigKey enumChoice(std::string table, std::string name, Ref ref, std::vector<std::string> choices, Name toName,
                     Parse parse, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::Choice,
                .choices = std::move(choices), .doc = std::move(doc)};
    k.get = [ref, toName](const BoothConfig& c, std::size_t i) { return ConfigValue(std::string(toName(at(ref, c, i)))); };
    k.set = [ref, parse](BoothConfig& c, std::size_t i, const ConfigValue& v) { at(ref, c, i) = parse(std::get<std::string>(v)); };
    return k;
}

// A list of words, each one of `choices`, none twice, at least `minCount`; `get`/`set` translate to the field.
template <typename Get, typename Set>
ConfigKey words(std::string table, std::string name, std::vector<std::string> choices, std::size_t minCount, Get get,
                Set set, std::string doc) {
    ConfigKey k{.table = std::move(table), .name = std::move(name), .type = ConfigType::WordList,
                .choices = std::move(choices), .minCount = minCount, .doc = std::move(doc)};
    k.get = [get](const BoothConfig& c, std::size_t) { return ConfigValue(get(c)); };
    k.set = [set](BoothConfig& c, std::size_t, const ConfigValue& v) { set(c, std::get<std::vector<std::string>>(v)); };
    return k;
}

std::vector<std::string> sliderKeys() {
    std::vector<std::string> keys;
    for (const SliderRange& r : sliderRanges()) keys.emplace_back(r.key);
    return keys;
}

std::vector<std::string> styleNames() {
    std::vector<std::string> names;
    for (const AvatarStyle s : {AvatarStyle::Photo, AvatarStyle::Character, AvatarStyle::Toon}) names.emplace_back(toString(s));
    return names;
}

// [character] sliders: unset means all of them; a set is listed in sliderRanges() order.
ConfigKey characterSliders() {
    return words(
        "character", "sliders", sliderKeys(), 0,
        [](const BoothConfig& c) {
            const auto& chosen = c.character.settings.sliders;
            std::vector<std::string> out;
            for (const std::string& key : sliderKeys())
                if (!chosen || chosen->count(key)) out.push_back(key);
            return out;
        },
        [](BoothConfig& c, const std::vector<std::string>& v) {
            auto& sliders = c.character.settings.sliders;
            sliders = std::set<std::string>(v.begin(), v.end());
            if (sliders->size() == sliderRanges().size()) sliders.reset();  // all of them: the default
        },
        "The sliders that move the character; one left out keeps the base head's value ([] = none of them).");
}

ConfigKey revealStyles() {
    return words(
        "reveal", "styles", styleNames(), 1,
        [](const BoothConfig& c) {
            std::vector<std::string> out;
            for (const AvatarStyle s : c.reveal.styles) out.emplace_back(toString(s));
            return out;
        },
        [](BoothConfig& c, const std::vector<std::string>& v) {
            c.reveal.styles.clear();
            for (const std::string& w : v) c.reveal.styles.push_back(*parseAvatarStyle(w));  // checked: a choice
        },
        "The styles side by side, most important first (the first is drawn largest, in the middle; the next left of "
        "it, the next right): \"photo\" (the photo-fitted head), \"character\", \"toon\" (Kitamura's two-view "
        "drawing, made from the photos while the reveal already shows). Not given, \"character\" is left out while "
        "[character] is disabled; listed while it is disabled, it is an error.");
}

const char* biasName(LineBias bias) {
    switch (bias) {
        case LineBias::PullUp: return "pull-up";
        case LineBias::PullDown: return "pull-down";
        case LineBias::Disabled: return "disabled";
        case LineBias::AsIs: return "as-is";
    }
    return "?";
}
LineBias parseBias(const std::string& word) {
    if (word == "pull-down") return LineBias::PullDown;
    if (word == "disabled") return LineBias::Disabled;
    if (word == "as-is") return LineBias::AsIs;
    return LineBias::PullUp;  // the only other choice the schema lets through
}

std::vector<std::string> buttonNames() {
    std::vector<std::string> names;
    for (const Button b : {Button::Start, Button::Retake, Button::Service}) names.emplace_back(toString(b));
    return names;
}

ConfigKey lockCombo() {
    ConfigKey k{.table = "flow", .name = "lock_combo", .type = ConfigType::ButtonCombo,
                .doc = "The operator menu opens when exactly these buttons (joined by +) are held together for "
                       "lock_hold_s; a booth with a Service button inside the cabinet can use \"service\" alone."};
    k.get = [](const BoothConfig& c, std::size_t) {
        std::string combo;
        for (const Button b : c.flow.lockCombo) combo += (combo.empty() ? "" : "+") + std::string(toString(b));
        return ConfigValue(combo);
    };
    k.set = [](BoothConfig& c, std::size_t, const ConfigValue& v) {
        std::vector<Button> lock;
        std::stringstream in(std::get<std::string>(v));
        for (std::string word; std::getline(in, word, '+');) {
            const std::optional<Button> b = parseButton(word);
            if (!b) throw ConfigValueRejected{"\"" + word + "\" is not a button (start, retake, service; joined by +)"};
            lock.push_back(*b);
        }
        if (lock.empty()) throw ConfigValueRejected{"name at least one button"};
        c.flow.lockCombo = lock;
    };
    return k;
}

std::vector<ConfigTable> makeTables() {
    std::vector<ConfigTable> t;
    t.push_back({.name = "fit",
                 .doc = "The photo-to-head pipeline.",
                 .check = [](const BoothConfig& c) -> std::optional<ConfigProblem> {
                     if (c.fit.baseMesh.empty() == c.fit.baseFeatures.empty()) return std::nullopt;
                     return ConfigProblem{c.fit.baseMesh.empty() ? "base_features" : "base_mesh",
                                          "give both base_mesh and base_features, or neither"};
                 }});
    t.push_back({.name = "camera",
                 .doc = "The camera: which stack, the preview and photo sizes, the simulated camera, reopening after a "
                        "camera went away.",
                 .check = [](const BoothConfig& c) -> std::optional<ConfigProblem> {
                     if (c.camera.reopenMaxDelaySeconds >= c.camera.reopenFirstDelaySeconds) return std::nullopt;
                     return ConfigProblem{"reopen_max_delay_s", "must not be shorter than reopen_first_delay_s"};
                 }});
    t.push_back({.name = "buttons",
                 .doc = "The arcade buttons and their lamps on the GPIO chip, or the simulated ones.",
                 .check = [](const BoothConfig& c) -> std::optional<ConfigProblem> {
                     std::set<unsigned> lines;
                     for (const auto& b : c.buttons.buttons)
                         if (!lines.insert(b.offset).second)
                             return ConfigProblem{"button", "line " + std::to_string(b.offset) + " is used twice"};
                     for (const auto& l : c.buttons.lamps)
                         if (!lines.insert(l.offset).second)
                             return ConfigProblem{"lamp", "line " + std::to_string(l.offset) + " is used twice"};
                     return std::nullopt;
                 }});
    t.push_back({.name = "buttons.button",
                 .kind = ConfigTableKind::Repeated,
                 .doc = "One table per button (given at all, they replace the default buttons). Defaults: start on "
                        "BCM 17 (header pin 11), retake on BCM 27 (pin 13), each wired to ground.",
                 .count = [](const BoothConfig& c) { return c.buttons.buttons.size(); },
                 .reset = [](BoothConfig& c, std::size_t n) { c.buttons.buttons.assign(n, ButtonSettings{}); }});
    t.push_back({.name = "buttons.lamp",
                 .kind = ConfigTableKind::Repeated,
                 .doc = "One table per lamp (given at all, they replace the default lamps). Defaults: BCM 22 (pin 15) "
                        "the start button's lamp, 23 (pin 16) the retake button's, 24 (pin 18) the flash.",
                 .count = [](const BoothConfig& c) { return c.buttons.lamps.size(); },
                 .reset = [](BoothConfig& c, std::size_t n) { c.buttons.lamps.assign(n, LampSettings{}); }});
    t.push_back({.name = "buttons.keys",
                 .kind = ConfigTableKind::StringMap,
                 .doc = "Keyboard keys (X11 key names) that press a button while the development window is open: "
                        "key = \"button\". Given at all, the table replaces the default keys.",
                 .map = [](BoothConfig& c) -> std::map<std::string, std::string>& { return c.buttons.keys; },
                 .valueChoices = buttonNames()});
    t.push_back({.name = "display", .doc = "The screen: which backend, the panel's rotation and size."});
    t.push_back({.name = "screen", .doc = "What the screens show: language, fonts, strings, button sides."});
    t.push_back({.name = "flow",
                 .doc = "The visitor flow's timing and the operator lock. Durations in seconds.",
                 .check = [](const BoothConfig& c) -> std::optional<ConfigProblem> {
                     if (c.flow.thanksMinTime <= c.flow.thanksTime) return std::nullopt;
                     return ConfigProblem{"thanks_min_time_s", "must not be longer than thanks_time_s"};
                 }});
    t.push_back({.name = "guidance", .doc = "How the guide screens place the visitor."});
    t.push_back({.name = "guidance.oval",
                 .doc = "The face oval of the guide screens, as fractions of the camera frame (the screen draws the "
                        "same oval)."});
    t.push_back({.name = "sessions",
                 .doc = "Kept sessions. Photos of visitors are personal data: the folder is readable by the booth's "
                        "user only, and photos are deleted after photo_retention_hours.",
                 .check = [](const BoothConfig& c) -> std::optional<ConfigProblem> {
                     const auto& s = c.sessions;
                     if (s.sessionRetention.count() == 0 || s.photoRetention.count() == 0 ||
                         s.sessionRetention >= s.photoRetention)
                         return std::nullopt;
                     return ConfigProblem{"session_retention_days",
                                          "sessions would be deleted before their photos' retention ends"};
                 }});
    t.push_back({.name = "animation", .doc = "The avatar's turn on the reveal and attract screens."});
    t.push_back({.name = "character",
                 .doc = "The character avatar: the base head with MakeHuman's own sliders set to the visitor's "
                        "proportions (Narita), in a flat toon skin; written as character.json + character.glb "
                        "in every session when enabled."});
    t.push_back({.name = "reveal", .doc = "The avatar styles on the reveal and attract screens."});
    t.push_back({.name = "stage", .doc = "Kitamura's tile stage under the avatars on the attract and reveal screens."});
    t.push_back({.name = "share",
                 .doc = "The visitor's own page (`avatarbooth share`, off by default: nothing listens unless enabled): "
                        "the thanks screen shows a QR code of the session's page, which shows the avatar turning, "
                        "with AR and downloads. The README's \"Take it home\" section sets up the hotspot.",
                 .check = [](const BoothConfig& c) -> std::optional<ConfigProblem> {
                     const ShareSettings& s = c.share;
                     if (s.tlsCertificate.empty() != s.tlsKey.empty())
                         return ConfigProblem{s.tlsCertificate.empty() ? "tls_key" : "tls_certificate",
                                              "give both tls_certificate and tls_key, or neither"};
                     const auto retention = c.sessions.sessionRetention;
                     if (s.enabled && retention.count() > 0 && s.pageLifetime > retention)
                         return ConfigProblem{"page_lifetime_days",
                                              "a page cannot outlive its session: longer than [sessions] "
                                              "session_retention_days"};
                     return std::nullopt;
                 }});
    t.push_back({.name = "print",
                 .doc = "The printed card (off by default): Keep prints the visitor's three styles, the short code and "
                        "the QR code of their page through a CUPS queue. The README's \"Take it home\" section sets up "
                        "the printer."});
    t.push_back({.name = "sound",
                 .doc = "The booth's sounds: a beep on each number of the countdown, the shutter, a chime at the "
                        "reveal. On when the booth has a sound card."});
    return t;
}

void addFitKeys(std::vector<ConfigKey>& k) {
    // [fit]
    k.push_back(path("fit", "landmark_model", FIELD(fit.settings.landmarkModel),
                     "dlib's 68-point shape predictor (Debian: libdlib-data). It was trained on iBUG 300-W, whose terms "
                     "exclude commercial use: a commercial booth needs a model trained on data it may use."));
    k.push_back(path("fit", "base_mesh", FIELD(fit.baseMesh),
                     "Your own base head instead of the MakeHuman head the booth ships: a glb with UVs (`avatarbooth "
                     "make-base-head --from-makehuman DIR -o OUT` writes the shipped one to start from); \"\" = the "
                     "MakeHuman head."));
    k.push_back(path("fit", "base_features", FIELD(fit.baseFeatures),
                     "The feature file of base_mesh; give both or neither."));
    k.push_back(enumChoice(
        "fit", "rbf_kernel", FIELD(fit.settings.head.rbf.kernel), {"ntt", "tps", "gaussian"},
        [](RbfKernel r) { return rbfKernelName(r); }, [](const std::string& s) { return parseRbfKernel(s); },
        "RBF kernel of the warp: \"ntt\" (the paper's f(r) = 1/(r+1)), \"tps\" (thin-plate spline with an affine "
        "part), \"gaussian\"."));
    k.push_back(number("fit", "rbf_unit_mm", FIELD(fit.settings.head.rbf.unitMm), 1.0, 500.0,
                       "The RBF's distance r is measured in units of this many millimetres."));
    k.push_back(number("fit", "rbf_regularisation", FIELD(fit.settings.head.rbf.regularisation), 0.0, 10.0,
                       "Ridge added to the RBF system's diagonal: 0 makes the warp pass through every measured point "
                       "exactly (the paper's way); more lets conflicting nearby points give way instead of folding "
                       "the surface."));
    k.push_back(number("fit", "modifier_regularisation", FIELD(fit.settings.head.modifiers.regularisation), 0.0,
                       1.0e6,
                       "How strongly the first fitting step keeps the MakeHuman modifiers at the average head (square "
                       "millimetres of error a modifier at full weight must remove)."));
    k.push_back(integer("fit", "texture_size", FIELD(fit.settings.texture.size), 256, 4096,
                        "The avatar's texture, texels per side."));
    k.push_back(integer("fit", "preview_size", FIELD(fit.previewSize), 64, 4096,
                        "The preview renders of a session, pixels per side."));
}

void addCameraKeys(std::vector<ConfigKey>& k) {
    // [camera]
    k.push_back(backendChoice("camera", FIELD(camera.backend), kCameraBackendNames,
                              "a V4L2 camera if there is one, else libcamera, else the simulated camera"));
    k.push_back(text("camera", "device", FIELD(camera.device),
                     "v4l2: \"/dev/video0\" or a stable /dev/v4l/by-id/... name; libcamera: the camera id from "
                     "`avatarbooth check`; \"\" = the first one found."));
    k.push_back(integer("camera", "preview_width", FIELD(camera.previewWidth), 64, 8192,
                        "The preview stream's wanted width (the nearest the camera offers is used)."));
    k.push_back(integer("camera", "preview_height", FIELD(camera.previewHeight), 64, 8192,
                        "The preview stream's wanted height."));
    k.push_back(number("camera", "preview_fps", FIELD(camera.previewFps), 1.0, 240.0,
                       "The preview stream's wanted frame rate."));
    k.push_back(integer("camera", "still_width", FIELD(camera.stillWidth), 0, 16384,
                        "The photo's width; 0 (with still_height 0) = the largest the camera offers."));
    k.push_back(integer("camera", "still_height", FIELD(camera.stillHeight), 0, 16384, "The photo's height."));
    k.push_back(integer("camera", "still_warmup_frames", FIELD(camera.stillWarmupFrames), 0, 100,
                        "Frames dropped after switching to the still format while exposure settles."));
    k.push_back(integer("camera", "buffer_count", FIELD(camera.bufferCount), 2, 32,
                        "Driver buffers for streaming (V4L2 buffers, libcamera requests)."));
    k.push_back(path("camera", "sim_folder", FIELD(camera.simFolder),
                     "sim: replay this recorded session folder (front.*, side.*, optional background.*); \"\" = the "
                     "synthetic visitor the booth makes itself."));
    k.push_back(number("camera", "sim_fps", FIELD(camera.simFps), 1.0, 240.0, "sim: frames per second."));
    k.push_back(flag("camera", "sim_real_time", FIELD(camera.simRealTime),
                     "sim: frames come in real time (false: as fast as they are asked for, for tests)."));
    k.push_back(integer("camera", "sim_noise", FIELD(camera.simNoise), 0, 64,
                        "sim: sensor noise added to preview frames, grey levels (0 = identical frames)."));
    k.push_back(number("camera", "reopen_first_delay_s", FIELD(camera.reopenFirstDelaySeconds), 0.01, 60.0,
                       "A camera that went away is reopened after this delay, doubling up to reopen_max_delay_s."));
    k.push_back(number("camera", "reopen_max_delay_s", FIELD(camera.reopenMaxDelaySeconds), 0.01, 600.0,
                       "The longest delay between reopening attempts."));
}

void addButtonsKeys(std::vector<ConfigKey>& k) {
    // [buttons]
    k.push_back(backendChoice("buttons", FIELD(buttons.backend), kButtonBackendNames,
                              "the GPIO chip when it exists, else simulated"));
    k.push_back(text("buttons", "chip", FIELD(buttons.chip),
                     "The GPIO chip by label (\"pinctrl-bcm2711\"), name (\"gpiochip0\"), path or number."));
    k.push_back(integer("buttons", "debounce_ms", FIELD(buttons.debounceMs), 0, 1000,
                        "Edges closer than this are one press (contact bounce), milliseconds; 0 turns debouncing off."));
    k.push_back(text("buttons", "consumer", FIELD(buttons.consumer),
                     "The name the lines are requested under (what `gpioinfo` shows)."));
    k.push_back(path("buttons", "timeline", FIELD(buttons.timeline),
                     "sim: a scripted button timeline file (\"at 2.0s press start\"), see drivers/gpio/README.md; "
                     "\"\" = no scripted presses."));
    // [[buttons.button]]
    ConfigKey buttonName = choice("buttons.button", "name", ELEMENT(buttons.buttons[i].name), buttonNames(),
                                  "The button: \"start\", \"retake\" or \"service\".");
    buttonName.required = true;
    k.push_back(buttonName);
    k.push_back(integer("buttons.button", "offset", ELEMENT(buttons.buttons[i].offset), 0, 1023,
                        "The line offset on the chip (the BCM number on a Raspberry Pi)."));
    k.push_back(flag("buttons.button", "active_low", ELEMENT(buttons.buttons[i].activeLow),
                     "Pressed reads low (the button connects the line to ground)."));
    k.push_back(enumChoice(
        "buttons.button", "bias", ELEMENT(buttons.buttons[i].bias), {"pull-up", "pull-down", "disabled", "as-is"},
        biasName, parseBias, "The pull resistor asked of the GPIO controller."));
    // [[buttons.lamp]]
    ConfigKey lampName = choice("buttons.lamp", "name", ELEMENT(buttons.lamps[i].name), {"start", "retake", "flash"},
                                "The lamp: \"start\" / \"retake\" (the buttons' lamps) or \"flash\".");
    lampName.required = true;
    k.push_back(lampName);
    k.push_back(integer("buttons.lamp", "offset", ELEMENT(buttons.lamps[i].offset), 0, 1023,
                        "The line offset on the chip."));
    k.push_back(flag("buttons.lamp", "active_low", ELEMENT(buttons.lamps[i].activeLow),
                     "The lamp lights with the line low (many relay boards)."));
}

void addDisplayKeys(std::vector<ConfigKey>& k) {
    // [display]
    k.push_back(backendChoice("display", FIELD(display.backend), kDisplayBackendNames,
                              "KMS when a screen is connected, else a window when $DISPLAY is set, else KMS waiting "
                              "for a screen when a DRM device has a connector, else headless"));
    k.push_back(integer("display", "rotation", FIELD(display.rotation), 0, 270,
                        "Degrees the picture is turned clockwise for the panel (portrait panels: 90 or 270).", 90));
    k.push_back(integer("display", "width", FIELD(display.width), 64, 8192,
                        "Width for the window and headless backends (KMS uses the screen's own mode)."));
    k.push_back(integer("display", "height", FIELD(display.height), 64, 8192,
                        "Height for the window and headless backends."));
    k.push_back(path("display", "drm_device", FIELD(display.drmDevice),
                     "kms: the DRM device; \"\" = the first /dev/dri/card* with a connected screen."));
    k.push_back(text("display", "connector", FIELD(display.connector),
                     "kms: the connector (\"HDMI-A-1\", \"DSI-1\"); \"\" = the first connected one."));
    k.push_back(integer("display", "every_nth_frame", FIELD(display.everyNthFrame), 0, 1000000,
                        "headless: write every N-th frame as a PNG into frames_dir (0 = none)."));
    k.push_back(path("display", "frames_dir", FIELD(display.framesDir), "headless: where those frames go."));
    k.push_back(text("display", "window_title", FIELD(display.windowTitle), "window: the window's title."));
}

void addScreenKeys(std::vector<ConfigKey>& k) {
    // [screen]
    k.push_back(enumChoice(
        "screen", "language", FIELD(screen.language), {"en", "ja"}, [](Language l) { return languageCode(l); },
        [](const std::string& s) { return parseLanguage(s); }, "The screens' language: \"en\" or \"ja\"."));
    k.push_back(path("screen", "font_regular", FIELD(screen.fonts.regular),
                     "Latin text; \"\" = DejaVu Sans (fonts-dejavu-core)."));
    k.push_back(path("screen", "font_bold", FIELD(screen.fonts.bold),
                     "Latin titles; \"\" = DejaVu Sans Bold (fonts-dejavu-core)."));
    k.push_back(path("screen", "font_japanese", FIELD(screen.fonts.japanese),
                     "Japanese text; \"\" = VL Gothic (fonts-vlgothic), else IPAGothic (fonts-ipafont-gothic)."));
    k.push_back(path("screen", "strings_file", FIELD(screen.stringsFile),
                     "The screens' strings; \"\" = the strings.toml the booth ships."));
    k.push_back(flag("screen", "start_button_on_left", FIELD(screen.startButtonOnLeft),
                     "The Start (keep) button is left of the Retake button, as the visitor sees them."));
}

void addFlowKeys(std::vector<ConfigKey>& k) {
    // [flow]
    k.push_back(seconds("flow", "countdown_s", FIELD(flow.countdown), 1.0, 10.0, "Countdown before each photo."));
    k.push_back(seconds("flow", "steady_s", FIELD(flow.steadyOk), 0.0, 10.0,
                        "The guide counts down by itself once its hint has said \"hold still\" this long."));
    k.push_back(seconds("flow", "guide_absent_timeout_s", FIELD(flow.guideAbsentTimeout), 2.0, 600.0,
                        "Back to the attract screen when nobody was seen this long in a guide."));
    k.push_back(seconds("flow", "guide_max_time_s", FIELD(flow.guideMaxTime), 5.0, 3600.0,
                        "Back to the attract screen after this long in a guide anyway."));
    k.push_back(seconds("flow", "capture_timeout_s", FIELD(flow.captureTimeout), 1.0, 120.0,
                        "No photo this long after the capture command: the capture failed (back to the guide)."));
    k.push_back(seconds("flow", "processing_timeout_s", FIELD(flow.processingTimeout), 5.0, 600.0,
                        "A fit still running after this long is cancelled and the session discarded."));
    k.push_back(seconds("flow", "reveal_timeout_s", FIELD(flow.revealTimeout), 5.0, 3600.0,
                        "The reveal waits this long for keep or retake; then the session is discarded (never kept "
                        "unasked)."));
    k.push_back(seconds("flow", "retake_choice_timeout_s", FIELD(flow.retakeChoiceTimeout), 2.0, 600.0,
                        "The \"which photo?\" question goes back to the reveal after this long."));
    k.push_back(seconds("flow", "thanks_time_s", FIELD(flow.thanksTime), 1.0, 600.0,
                        "The thanks screen shows the session's code (or that it could not be saved) this long."));
    k.push_back(seconds("flow", "thanks_min_time_s", FIELD(flow.thanksMinTime), 0.0, 600.0,
                        "... and ignores the Start button this long, so the code is not skipped by the next visitor."));
    k.push_back(seconds("flow", "thanks_saving_limit_s", FIELD(flow.thanksSavingLimit), 1.0, 3600.0,
                        "While the kept session is still being written the thanks screen says \"saving\" and waits "
                        "for its code, at most this long (then back to attract; the write goes on)."));
    k.push_back(seconds("flow", "camera_lost_timeout_s", FIELD(flow.cameraLostTimeout), 1.0, 3600.0,
                        "A session whose camera was lost is given up after this long."));
    k.push_back(seconds("flow", "press_guard_s", FIELD(flow.pressGuard), 0.0, 5.0,
                        "Presses this soon after a screen changed are ignored (a double press does not act twice)."));
    k.push_back(lockCombo());
    k.push_back(seconds("flow", "lock_hold_s", FIELD(flow.lockHold), 1.0, 60.0,
                        "How long lock_combo is held to open the operator menu."));
    k.push_back(seconds("flow", "operator_timeout_s", FIELD(flow.operatorTimeout), 10.0, 3600.0,
                        "The operator menu closes after this long without a press."));
}

void addGuidanceKeys(std::vector<ConfigKey>& k) {
    // [guidance.oval]
    k.push_back(number("guidance.oval", "centre_x", FIELD(guidance.oval.centreX), 0.1, 0.9,
                       "The oval's centre, fraction of the frame's width."));
    k.push_back(number("guidance.oval", "centre_y", FIELD(guidance.oval.centreY), 0.1, 0.9,
                       "The oval's centre, fraction of the frame's height."));
    k.push_back(number("guidance.oval", "height", FIELD(guidance.oval.height), 0.2, 1.0,
                       "The head's outline (hair to chin), fraction of the frame's height."));
    k.push_back(number("guidance.oval", "aspect", FIELD(guidance.oval.aspect), 0.4, 1.2, "The oval's width / height."));
}

void addSessionsKeys(std::vector<ConfigKey>& k) {
    // [sessions]
    k.push_back(path("sessions", "directory", FIELD(sessions.directory),
                     "Where kept sessions live, one folder per code (created readable by the booth's user only)."));
    k.push_back(age<std::ratio<3600>>("sessions", "photo_retention_hours", FIELD(sessions.photoRetention), 0.0,
                                      24.0 * 3650, "Photos are deleted this long after the session was kept (0 = never)."));
    k.push_back(age<std::ratio<86400>>("sessions", "session_retention_days", FIELD(sessions.sessionRetention), 0.0,
                                       3650.0, "The whole session is deleted this long after it was kept (0 = never)."));
    k.push_back(integer("sessions", "code_length", FIELD(sessions.codeLength), 4, 12,
                        "Characters in a session's code (the visitor's key to their avatar)."));
}

void addAnimationKeys(std::vector<ConfigKey>& k) {
    // [animation]
    k.push_back(enumChoice(
        "animation", "style", FIELD(animation.style), {"limited", "full"},
        [](AnimationStyle s) { return animationStyleName(s); },
        [](const std::string& s) { return s == "full" ? AnimationStyle::Full : AnimationStyle::Limited; },
        "\"limited\" (Kitamura's limited animation) or \"full\" (every frame)."));
    k.push_back(number("animation", "fps", FIELD(animation.fps), 1.0, 120.0, "Frames per second of the turn."));
    k.push_back(integer("animation", "inbetween_omissions", FIELD(animation.inbetweenOmissions), 0, 100,
                        "N_io: in-betweens omitted where the motion is fastest."));
    k.push_back(number("animation", "hold_fraction", FIELD(animation.holdFraction), 0.0, 0.9,
                       "N_hf: the share of the frames held."));
}

void addCharacterKeys(std::vector<ConfigKey>& k) {
    // [character]
    k.push_back(flag("character", "enabled", FIELD(character.enabled),
                     "Make the character in every fit (character.json + character.glb in the session)."));
    k.push_back(number("character", "exaggeration", FIELD(character.settings.exaggeration), 0.0, 3.0,
                       "1: the measured proportions; above 1 exaggerates each away from the base head's (caricature), "
                       "below 1 tones down."));
    k.push_back(characterSliders());
    k.push_back(enumChoice(
        "character", "colours", FIELD(character.settings.coloursFromPhoto), {"photo", "fixed"},
        [](bool fromPhoto) { return fromPhoto ? "photo" : "fixed"; },
        [](const std::string& s) { return s == "photo"; },
        "\"photo\": skin and hair colours sampled from the front photo; \"fixed\": the built-in palette."));
    k.push_back(integer("character", "texture_size", FIELD(character.settings.textureSize), 64, 4096,
                        "Edge of the painted (flat-colour) texture in texels."));
}

void addRevealKeys(std::vector<ConfigKey>& k) {
    // [reveal]
    k.push_back(revealStyles());
    k.push_back(integer("reveal", "toon_colours", FIELD(reveal.toonColours), 2, 16, "Flat colours of the toon drawing."));
    k.push_back(integer("reveal", "toon_strip_frames", FIELD(reveal.toonStripFrames), 2, 360,
                        "Frames of the toon's turntable strip kept in the session (toon/turntable_NNN.png)."));
}

void addStageKeys(std::vector<ConfigKey>& k) {
    // [stage]
    k.push_back(flag("stage", "enabled", FIELD(stage.enabled), "Show the tile stage under the avatars."));
    k.push_back(path("stage", "map", FIELD(stage.map),
                     "The tile map (format in the shipped stage.map); \"\" = the one the booth ships. A relative path "
                     "is taken from the folder of this file; a mistake in the map stops the booth with MAP:LINE:COLUMN."));
    {
        ConfigKey sweep = number("stage", "sweep_s", FIELD(stage.sweepSeconds), 2.0, 600.0,
                                 "One camera sweep: the top-down look (45 degrees), down to low_angle_deg (ordinary "
                                 "3-D), and back.");
        sweep.type = ConfigType::Seconds;
        k.push_back(std::move(sweep));
    }
    k.push_back(number("stage", "low_angle_deg", FIELD(stage.lowAngleDeg), 0.0, 44.0,
                       "The camera's elevation in degrees at the ordinary 3-D end of the sweep."));
}

void addShareKeys(std::vector<ConfigKey>& k) {
    // [share]
    k.push_back(flag("share", "enabled", FIELD(share.enabled),
                     "Give every kept session its page and show its QR code on the thanks screen; `avatarbooth share` "
                     "(avatarbooth-share.service) serves the pages."));
    {
        ConfigKey listen = text("share", "listen", FIELD(share.listen),
                                "ADDRESS:PORT the page server listens on (an IPv6 address in brackets); the default "
                                "is the booth's own NetworkManager hotspot.");
        const auto store = listen.set;
        listen.set = [store](BoothConfig& c, std::size_t i, const ConfigValue& v) {
            if (!parseListenAddress(std::get<std::string>(v)))
                throw ConfigValueRejected{"\"" + std::get<std::string>(v) + "\" is not ADDRESS:PORT (port 1-65535)"};
            store(c, i, v);
        };
        k.push_back(std::move(listen));
    }
    {
        ConfigKey base = text("share", "base_url", FIELD(share.baseUrl),
                              "The URL phones reach the server by (in the QR code), e.g. \"http://booth.example\"; "
                              "\"\" = http://LISTEN (https:// with a certificate).");
        const auto store = base.set;
        base.set = [store](BoothConfig& c, std::size_t i, const ConfigValue& v) {
            const std::string& url = std::get<std::string>(v);
            const bool scheme = url.rfind("http://", 0) == 0 || url.rfind("https://", 0) == 0;
            if (!url.empty() && (!scheme || url.find_first_of(" \t\"<>?#") != std::string::npos))
                throw ConfigValueRejected{"\"" + url + "\" is not an http:// or https:// URL without query"};
            // The QR code gets denser with every character: a short URL scans from further away.
            if (url.size() > 100) throw ConfigValueRejected{"longer than 100 characters (the QR code would be too dense)"};
            store(c, i, v);
        };
        k.push_back(std::move(base));
    }
    k.push_back(age<std::ratio<86400>>("share", "page_lifetime_days", FIELD(share.pageLifetime), 0.04, 3650.0,
                                       "A page answers this long after its session was kept (at most the session's "
                                       "retention); afterwards it answers like an unknown page."));
    k.push_back(flag("share", "downloads", FIELD(share.offerDownloads),
                     "The page offers avatar.glb, avatar.usdz, the preview image and the turning picture (turntable.webp) for "
                     "download."));
    k.push_back(flag("share", "photos", FIELD(share.offerPhotos),
                     "The page also offers the visitor's two photos while they are kept (personal data: only with "
                     "the visitors' consent)."));
    k.push_back(path("share", "tls_certificate", FIELD(share.tlsCertificate),
                     "HTTPS: the operator's certificate (PEM, readable by the service); \"\" = plain HTTP."));
    k.push_back(path("share", "tls_key", FIELD(share.tlsKey), "HTTPS: the certificate's private key (PEM)."));
    k.push_back(integer("share", "workers", FIELD(share.workers), 1, 64,
                        "Requests served at once; as many more connections wait, the rest wait in the kernel."));
    k.push_back(seconds("share", "read_timeout_s", FIELD(share.readTimeout), 1.0, 60.0,
                        "A connection silent for this long is closed (a slow or stalled client); whole seconds."));
}

void addPrintKeys(std::vector<ConfigKey>& k) {
    // [print]
    k.push_back(flag("print", "enabled", FIELD(print.enabled),
                     "Keep prints a card of the session (its styles, code and QR code) on the CUPS queue."));
    {
        ConfigKey queue = text("print", "queue", FIELD(print.queue),
                               "The CUPS queue (`lpstat -p` lists them); \"\" = the CUPS server's default queue.");
        const auto store = queue.set;
        queue.set = [store](BoothConfig& c, std::size_t i, const ConfigValue& v) {
            const std::string& name = std::get<std::string>(v);
            // CUPS refuses these in a queue's name (lpadmin(8)); a typo is caught here rather than at the first keep.
            if (name.find_first_of(" \t/#\\\"'") != std::string::npos || name.size() > 127)
                throw ConfigValueRejected{"\"" + name + "\" is not a CUPS queue name (no spaces, /, # or quotes)"};
            store(c, i, v);
        };
        k.push_back(std::move(queue));
    }
    k.push_back(number("print", "width_mm", FIELD(print.widthMm), 50.0, 300.0,
                       "The card's width in millimetres (100 x 148: the postcard photo printers take)."));
    k.push_back(number("print", "height_mm", FIELD(print.heightMm), 50.0, 300.0, "The card's height in millimetres."));
    k.push_back(integer("print", "dpi", FIELD(print.dpi), 72, 1200,
                        "The resolution the card's pictures are placed at (text and the QR code are vectors)."));
    k.push_back(text("print", "media", FIELD(print.media),
                     "The printer's own name for the paper (\"Postcard\", \"w284h420\"; `lpoptions -p QUEUE -l` lists "
                     "them); \"\" = the card's size as a custom size (\"Custom.100x148mm\")."));
    k.push_back(flag("print", "front_photo", FIELD(print.frontPhoto),
                     "The visitor's front photo on the card too (personal data on paper)."));
    k.push_back(text("print", "title", FIELD(print.title), "The line across the card's top (\"\" = none)."));
    k.push_back(integer("print", "copies", FIELD(print.copies), 1, 10, "Cards printed per kept session."));
}

void addSoundKeys(std::vector<ConfigKey>& k) {
    // [sound]
    k.push_back(flag("sound", "enabled", FIELD(sound.enabled),
                     "Sounds when the booth has a sound card (false: silent whatever it has)."));
    k.push_back(integer("sound", "volume", FIELD(sound.volume), 0, 100,
                        "Loudness of the booth's sounds, percent of their own level (the card's mixer is left as "
                        "it is: set it once with alsamixer)."));
    k.push_back(text("sound", "device", FIELD(sound.device),
                     "The ALSA output (`aplay -L` lists them): \"default\" (the first sound card), \"hw:1\", ...; "
                     "\"file:FILE=/tmp/booth.wav,FORMAT=wav\" records the sounds instead."));
}

std::vector<ConfigKey> makeKeys() {
    std::vector<ConfigKey> k;
    addFitKeys(k);
    addCameraKeys(k);
    addButtonsKeys(k);
    addDisplayKeys(k);
    addScreenKeys(k);
    addFlowKeys(k);
    addGuidanceKeys(k);
    addSessionsKeys(k);
    addAnimationKeys(k);
    addCharacterKeys(k);
    addRevealKeys(k);
    addStageKeys(k);
    addShareKeys(k);
    addPrintKeys(k);
    addSoundKeys(k);
    return k;
}

#undef FIELD
#undef ELEMENT

// ---- rendering -----------------------------------------------------------------------------------------------

constexpr std::size_t kWidth = 116;  // the repository's line length

std::string quoted(const std::string& s) {
    std::string out = "\"";
    for (const char ch : s) {
        if (ch == '"' || ch == '\\') out += '\\';
        out += ch;
    }
    return out + "\"";
}

// "# "-prefixed lines of at most kWidth characters.
std::string comment(const std::string& text) {
    std::string out, line;
    std::istringstream words(text);
    for (std::string w; words >> w;) {
        if (!line.empty() && 2 + line.size() + 1 + w.size() > kWidth) {
            out += "# " + line + "\n";
            line.clear();
        }
        line += (line.empty() ? "" : " ") + w;
    }
    if (!line.empty()) out += "# " + line + "\n";
    return out;
}

std::string bareOrQuoted(const std::string& key) {
    const bool bare = !key.empty() && key.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
                                                            "0123456789_-") == std::string::npos;
    return bare ? key : quoted(key);
}

std::vector<const ConfigKey*> keysOf(const std::string& table) {
    std::vector<const ConfigKey*> keys;
    for (const ConfigKey& k : configKeys())
        if (k.table == table) keys.push_back(&k);
    return keys;
}

std::string decimal(double v) {
    std::ostringstream s;
    s << v;
    return s.str();
}

// "key = value\n"; a list too long for one line continues on lines indented under its first element.
std::string keyLine(const std::string& key, const ConfigValue& value) {
    const std::string line = key + " = " + tomlValue(value);
    const auto* list = std::get_if<std::vector<std::string>>(&value);
    if (!list || line.size() <= kWidth) return line + "\n";
    const std::string indent(key.size() + 4, ' ');
    std::string out = key + " = [", current = out;
    for (std::size_t i = 0; i < list->size(); ++i) {
        const std::string word = quoted((*list)[i]) + (i + 1 < list->size() ? "," : "]");
        if (current.size() > indent.size() && current.size() + 1 + word.size() > kWidth) {
            out += "\n" + indent;
            current = indent;
        } else if (i) {
            out += " ";
            current += " ";
        }
        out += word;
        current += word;
    }
    return out + "\n";
}

std::string typeName(ConfigType t) {
    switch (t) {
        case ConfigType::String: return "string";
        case ConfigType::Path: return "path";
        case ConfigType::Bool: return "bool";
        case ConfigType::Integer: return "integer";
        case ConfigType::Number: return "number";
        case ConfigType::Seconds: return "seconds";
        case ConfigType::Choice: return "choice";
        case ConfigType::ButtonCombo: return "buttons";
        case ConfigType::WordList: return "list";
    }
    return "?";
}

std::string allowed(const ConfigKey& k) {
    switch (k.type) {
        case ConfigType::Integer:
            if (k.step > 1) {
                std::string s;
                for (auto v = static_cast<long long>(k.min); v <= static_cast<long long>(k.max); v += k.step)
                    s += (s.empty() ? "" : ", ") + std::to_string(v);
                return s;
            }
            return std::to_string(static_cast<long long>(k.min)) + " – " + std::to_string(static_cast<long long>(k.max));
        case ConfigType::Number:
        case ConfigType::Seconds: return decimal(k.min) + " – " + decimal(k.max);
        case ConfigType::Choice: {
            std::string s;
            for (const auto& c : k.choices) s += (s.empty() ? "" : ", ") + std::string("`") + quoted(c) + "`";
            return s;
        }
        case ConfigType::ButtonCombo: return "`start`, `retake`, `service` joined by `+`";
        case ConfigType::WordList: {
            std::string s;
            for (const auto& c : k.choices) s += (s.empty() ? "" : ", ") + std::string("`") + quoted(c) + "`";
            return s + "; none twice" + (k.minCount ? ", at least " + std::to_string(k.minCount) : std::string());
        }
        default: return "";
    }
}

std::string cell(std::string s) {
    std::string out;
    for (const char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
    return out;
}

}  // namespace

const std::vector<ConfigTable>& configTables() {
    static const std::vector<ConfigTable> tables = makeTables();
    return tables;
}

const std::vector<ConfigKey>& configKeys() {
    static const std::vector<ConfigKey> keys = makeKeys();
    return keys;
}

std::string tomlValue(const ConfigValue& value) {
    if (const bool* b = std::get_if<bool>(&value)) return *b ? "true" : "false";
    if (const long long* i = std::get_if<long long>(&value)) return std::to_string(*i);
    if (const std::string* s = std::get_if<std::string>(&value)) return quoted(*s);
    if (const auto* list = std::get_if<std::vector<std::string>>(&value)) {
        std::string s = "[";
        for (std::size_t i = 0; i < list->size(); ++i) s += (i ? ", " : "") + quoted((*list)[i]);
        return s + "]";
    }
    // The shortest digits that read back as the same double, with a '.' so TOML reads a float.
    char buffer[64];
    const double d = std::get<double>(value);
    const auto end = std::to_chars(buffer, buffer + sizeof buffer, d).ptr;
    std::string s(buffer, end);
    if (s.find_first_of(".eEn") == std::string::npos) s += ".0";
    return s;
}

std::string renderDefaultConfig() {
    const BoothConfig defaults;
    std::string out =
        comment("avatarbooth configuration: the reference of every key, each set to its default.") + "#\n" +
        comment("Installed as /etc/avatarbooth/booth.toml; `avatarbooth run --config FILE` reads another. Every key "
                "may be left out (the default below applies); an unknown key, a wrong type or a value out of range "
                "stops the booth with the file, line and key named, so a typo never passes silently. "
                "`avatarbooth config --check FILE` checks a file.") +
        comment("Generated by `avatarbooth config --print-default` from app/config/config_schema.cpp.");
    for (const ConfigTable& table : configTables()) {
        const std::vector<const ConfigKey*> keys = keysOf(table.name);
        switch (table.kind) {
            case ConfigTableKind::Table:
                out += "\n[" + table.name + "]\n" + comment(table.doc);
                for (const ConfigKey* k : keys) out += comment(k->doc) + keyLine(k->name, k->get(defaults, 0));
                break;
            case ConfigTableKind::Repeated: {
                out += "\n" + comment(table.doc);
                for (const ConfigKey* k : keys) out += comment(k->name + ": " + k->doc);
                for (std::size_t i = 0; i < table.count(defaults); ++i) {
                    out += (i ? "\n" : "") + std::string("[[") + table.name + "]]\n";
                    for (const ConfigKey* k : keys) out += k->name + " = " + tomlValue(k->get(defaults, i)) + "\n";
                }
                break;
            }
            case ConfigTableKind::StringMap: {
                out += "\n[" + table.name + "]\n" + comment(table.doc);
                BoothConfig copy;
                for (const auto& [key, value] : table.map(copy)) out += bareOrQuoted(key) + " = " + quoted(value) + "\n";
                break;
            }
        }
    }
    return out;
}

std::string renderConfigReference() {
    BoothConfig defaults;
    std::string out;
    for (const ConfigTable& table : configTables()) {
        const bool repeated = table.kind == ConfigTableKind::Repeated;
        out += std::string(out.empty() ? "" : "\n") + "**`" + (repeated ? "[[" : "[") + table.name +
               (repeated ? "]]" : "]") + "`** " + table.doc + "\n";
        const std::vector<const ConfigKey*> keys = keysOf(table.name);
        if (table.kind == ConfigTableKind::StringMap) {
            std::string lines, choices;
            for (const auto& [key, value] : table.map(defaults))
                lines += (lines.empty() ? "" : ", ") + std::string("`") + bareOrQuoted(key) + " = " + quoted(value) + "`";
            for (const auto& c : table.valueChoices) choices += (choices.empty() ? "" : ", ") + std::string("`") + quoted(c) + "`";
            out += "Default: " + lines + ". Values: " + choices + ".\n";
            continue;
        }
        if (keys.empty()) continue;
        out += "\n| key | type | default | allowed | meaning |\n|---|---|---|---|---|\n";
        for (const ConfigKey* k : keys) {
            std::string value;
            const std::size_t n = repeated ? table.count(defaults) : 1;
            for (std::size_t i = 0; i < n; ++i)
                value += (i ? ", " : "") + std::string("`") + tomlValue(k->get(defaults, i)) + "`";
            if (k->required) value = "required (" + value + ")";
            out += "| `" + k->name + "` | " + typeName(k->type) + " | " + cell(value) + " | " + cell(allowed(*k)) + " | " +
                   cell(k->doc) + " |\n";
        }
    }
    return out;
}

}  // namespace avatarbooth
