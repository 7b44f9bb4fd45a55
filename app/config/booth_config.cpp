// Reading booth.toml strictly into the parts' settings structs (toml++ stays inside this file).
#include "config/booth_config.h"

#include "character/proportions.h"
#include "common/error.h"
#include "head/rbf.h"
#include "stage/tile_stage.h"

#include <toml++/toml.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

namespace avatarbooth {
namespace {

// One table of the file being read. Each read marks its key as known; finish() then reports any key nobody read,
// which is how a misspelt key becomes an error instead of a silently ignored line.
class Table {
public:
    Table(const toml::table* table, std::string path, const std::string& file, int line)
        : table_(table), path_(std::move(path)), file_(file), line_(line) {}

    // A nested table (absent: an empty one, so every default stays).
    Table sub(const std::string& key) {
        const toml::node* n = take(key);
        if (!n) return Table(nullptr, qualified(key), file_, line_);
        if (!n->is_table()) fail(n, key, "expected a table ([" + qualified(key) + "])");
        return Table(n->as_table(), qualified(key), file_, static_cast<int>(n->source().begin.line));
    }

    void read(const std::string& key, std::string& out) {
        if (const toml::node* n = take(key)) {
            if (!n->is_string()) fail(n, key, "expected a string in quotes");
            out = n->as_string()->get();
        }
    }
    void read(const std::string& key, std::filesystem::path& out) {
        std::string s = out.string();
        read(key, s);
        out = s;
    }
    void read(const std::string& key, bool& out) {
        if (const toml::node* n = take(key)) {
            if (!n->is_boolean()) fail(n, key, "expected true or false");
            out = n->as_boolean()->get();
        }
    }
    template <typename Int>
        requires std::is_integral_v<Int>
    void read(const std::string& key, Int& out, long long lo, long long hi) {
        if (const toml::node* n = take(key)) {
            if (!n->is_integer()) fail(n, key, "expected a whole number");
            const long long v = n->as_integer()->get();
            if (v < lo || v > hi) fail(n, key, "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " + std::to_string(v));
            out = static_cast<Int>(v);
        }
    }
    void read(const std::string& key, double& out, double lo, double hi) {
        if (const toml::node* n = take(key)) {
            if (!n->is_number()) fail(n, key, "expected a number");
            const double v = n->is_integer() ? static_cast<double>(n->as_integer()->get()) : n->as_floating_point()->get();
            if (!(v >= lo && v <= hi)) fail(n, key, "must be between " + num(lo) + " and " + num(hi) + ", got " + num(v));
            out = v;
        }
    }
    // A duration given in seconds (fractions allowed).
    template <typename Rep, typename Period>
    void readSeconds(const std::string& key, std::chrono::duration<Rep, Period>& out, double lo, double hi) {
        double s = std::chrono::duration<double>(out).count();
        read(key, s, lo, hi);
        out = std::chrono::duration_cast<std::chrono::duration<Rep, Period>>(std::chrono::duration<double>(s));
    }
    // One of a fixed set of words.
    void readChoice(const std::string& key, std::string& out, const std::vector<std::string>& choices) {
        if (const toml::node* n = take(key)) {
            if (!n->is_string()) fail(n, key, "expected one of " + list(choices));
            const std::string v = n->as_string()->get();
            if (std::find(choices.begin(), choices.end(), v) == choices.end())
                fail(n, key, "\"" + v + "\" is not one of " + list(choices));
            out = v;
        }
    }
    // An array of words, each one of `choices`, none twice; at least `minCount` of them.
    bool readWords(const std::string& key, std::vector<std::string>& out, const std::vector<std::string>& choices,
                   std::size_t minCount) {
        const toml::node* n = take(key);
        if (!n) return false;
        const toml::array* a = n->as_array();
        if (!a) fail(n, key, "expected a list in brackets of " + list(choices));
        std::vector<std::string> words;
        for (const toml::node& e : *a) {
            if (!e.is_string()) fail(&e, key, "expected words in quotes, each one of " + list(choices));
            const std::string v = e.as_string()->get();
            if (std::find(choices.begin(), choices.end(), v) == choices.end())
                fail(&e, key, "\"" + v + "\" is not one of " + list(choices));
            if (std::find(words.begin(), words.end(), v) != words.end()) fail(&e, key, "\"" + v + "\" is listed twice");
            words.push_back(v);
        }
        if (words.size() < minCount) fail(n, key, "name at least " + std::to_string(minCount) + " of " + list(choices));
        out = words;
        return true;
    }
    // An array of tables ([[key]]), each handed to `each` as a Table of its own.
    template <typename Each>
    bool readTables(const std::string& key, Each each) {
        const toml::node* n = take(key);
        if (!n) return false;
        const toml::array* a = n->as_array();
        if (!a || !a->is_array_of_tables()) fail(n, key, "expected tables ([[" + qualified(key) + "]])");
        int index = 0;
        for (const toml::node& e : *a) {
            Table t(e.as_table(), qualified(key) + "[" + std::to_string(index++) + "]", file_, static_cast<int>(e.source().begin.line));
            each(t);
            t.finish();
        }
        return true;
    }
    // Every key of a table of strings (key = "value").
    bool readStringMap(const std::string& key, std::map<std::string, std::string>& out) {
        const toml::node* n = take(key);
        if (!n) return false;
        if (!n->is_table()) fail(n, key, "expected a table of \"key\" = \"value\" lines");
        out.clear();
        for (const auto& [k, v] : *n->as_table()) {
            if (!v.is_string()) fail(&v, key + "." + std::string(k.str()), "expected a string in quotes");
            out[std::string(k.str())] = v.as_string()->get();
        }
        return true;
    }

    [[noreturn]] void fail(const toml::node* n, const std::string& key, const std::string& what) const {
        const int line = n ? static_cast<int>(n->source().begin.line) : line_;
        throw BoothError(ErrorKind::BadConfig, file_ + ":" + std::to_string(line), qualified(key) + ": " + what);
    }
    [[noreturn]] void failHere(const std::string& key, const std::string& what) const { fail(nodeOf(key), key, what); }

    // Reports the first key that no read asked for.
    void finish() const {
        if (!table_) return;
        for (const auto& [k, v] : *table_)
            if (!known_.count(std::string(k.str())))
                fail(&v, std::string(k.str()), std::string(v.is_table() ? "unknown table" : "unknown key") +
                                                    " (see the reference booth.toml for the keys there are)");
    }

    const std::string& path() const { return path_; }

private:
    const toml::node* take(const std::string& key) {
        known_.insert(key);
        return table_ ? table_->get(key) : nullptr;
    }
    const toml::node* nodeOf(const std::string& key) const { return table_ ? table_->get(key) : nullptr; }
    std::string qualified(const std::string& key) const { return path_.empty() ? key : path_ + "." + key; }
    static std::string num(double v) {
        std::ostringstream s;
        s << v;
        return s.str();
    }
    static std::string list(const std::vector<std::string>& v) {
        std::string s;
        for (std::size_t i = 0; i < v.size(); ++i) s += (i ? (i + 1 == v.size() ? " or \"" : ", \"") : "\"") + v[i] + "\"";
        return s;
    }

    const toml::table* table_;
    std::string path_;
    const std::string& file_;
    int line_;
    std::set<std::string> known_;
};

void readFit(Table t, FitConfig& fit) {
    FitSettings& s = fit.settings;
    t.read("landmark_model", s.landmarkModel);
    t.read("base_mesh", fit.baseMesh);
    t.read("base_features", fit.baseFeatures);
    std::string kernel = rbfKernelName(s.head.rbf.kernel);
    t.readChoice("rbf_kernel", kernel, {"ntt", "tps", "gaussian"});
    s.head.rbf.kernel = parseRbfKernel(kernel);
    t.read("rbf_unit_mm", s.head.rbf.unitMm, 1.0, 500.0);
    t.read("texture_size", s.texture.size, 256, 4096);
    t.read("preview_size", s.previewSize, 64, 4096);
    if (fit.baseMesh.empty() != fit.baseFeatures.empty())
        t.failHere(fit.baseMesh.empty() ? "base_features" : "base_mesh", "give both base_mesh and base_features, or neither");
    t.finish();
}

void readCamera(Table t, CameraSettings& c) {
    t.readChoice("backend", c.backend, {"auto", "v4l2", "libcamera", "sim"});
    t.read("device", c.device);
    t.read("preview_width", c.previewWidth, 64, 8192);
    t.read("preview_height", c.previewHeight, 64, 8192);
    t.read("preview_fps", c.previewFps, 1.0, 240.0);
    t.read("still_width", c.stillWidth, 0, 16384);
    t.read("still_height", c.stillHeight, 0, 16384);
    t.read("still_warmup_frames", c.stillWarmupFrames, 0, 100);
    t.read("buffer_count", c.bufferCount, 2, 32);
    t.read("sim_folder", c.simFolder);
    t.read("sim_fps", c.simFps, 1.0, 240.0);
    t.read("sim_real_time", c.simRealTime);
    t.read("sim_noise", c.simNoise, 0, 64);
    t.read("reopen_first_delay_s", c.reopenFirstDelaySeconds, 0.01, 60.0);
    t.read("reopen_max_delay_s", c.reopenMaxDelaySeconds, 0.01, 600.0);
    if (c.reopenMaxDelaySeconds < c.reopenFirstDelaySeconds)
        t.failHere("reopen_max_delay_s", "must not be shorter than reopen_first_delay_s");
    t.finish();
}

LineBias parseBias(Table& t, const std::string& word) {
    if (word == "pull-up") return LineBias::PullUp;
    if (word == "pull-down") return LineBias::PullDown;
    if (word == "disabled") return LineBias::Disabled;
    if (word == "as-is") return LineBias::AsIs;
    t.failHere("bias", "unknown bias \"" + word + "\"");
}

void readButtons(Table t, GpioSettings& g) {
    t.readChoice("backend", g.backend, {"auto", "gpiod", "sim"});
    t.read("chip", g.chip);
    t.read("debounce_ms", g.debounceMs, 0, 1000);
    t.read("consumer", g.consumer);
    t.read("timeline", g.timeline);
    std::vector<ButtonSettings> buttons;
    if (t.readTables("button", [&](Table& b) {
            ButtonSettings s;
            s.name.clear();
            b.readChoice("name", s.name, {"start", "retake", "service"});
            if (s.name.empty()) b.failHere("name", "every [[buttons.button]] needs a name");
            b.read("offset", s.offset, 0, 1023);
            b.read("active_low", s.activeLow);
            std::string bias = "pull-up";
            b.readChoice("bias", bias, {"pull-up", "pull-down", "disabled", "as-is"});
            s.bias = parseBias(b, bias);
            buttons.push_back(s);
        }))
        g.buttons = buttons;
    std::vector<LampSettings> lamps;
    if (t.readTables("lamp", [&](Table& l) {
            LampSettings s;
            l.readChoice("name", s.name, {"start", "retake", "flash"});
            if (s.name.empty()) l.failHere("name", "every [[buttons.lamp]] needs a name");
            l.read("offset", s.offset, 0, 1023);
            l.read("active_low", s.activeLow);
            lamps.push_back(s);
        }))
        g.lamps = lamps;
    std::set<unsigned> lines;
    for (const auto& b : g.buttons)
        if (!lines.insert(b.offset).second) t.failHere("button", "line " + std::to_string(b.offset) + " is used twice");
    for (const auto& l : g.lamps)
        if (!lines.insert(l.offset).second) t.failHere("lamp", "line " + std::to_string(l.offset) + " is used twice");
    t.readStringMap("keys", g.keys);
    t.finish();
}

void readDisplay(Table t, DisplaySettings& d) {
    t.readChoice("backend", d.backend, {"auto", "kms", "window", "headless"});
    t.read("rotation", d.rotation, 0, 270);
    if (d.rotation % 90 != 0) t.failHere("rotation", "must be 0, 90, 180 or 270");
    t.read("width", d.width, 64, 8192);
    t.read("height", d.height, 64, 8192);
    t.read("drm_device", d.drmDevice);
    t.read("connector", d.connector);
    t.read("every_nth_frame", d.everyNthFrame, 0, 1000000);
    t.read("frames_dir", d.framesDir);
    t.read("window_title", d.windowTitle);
    t.finish();
}

void readScreen(Table t, ScreenSettings& s) {
    std::string language = languageCode(s.language);
    t.readChoice("language", language, {"en", "ja"});
    s.language = parseLanguage(language);
    t.read("font_regular", s.fonts.regular);
    t.read("font_bold", s.fonts.bold);
    t.read("font_japanese", s.fonts.japanese);
    t.read("strings_file", s.stringsFile);
    t.read("start_button_on_left", s.startButtonOnLeft);
    t.finish();
}

void readFlow(Table t, BoothSettings& f) {
    t.readSeconds("countdown_s", f.countdown, 1.0, 10.0);
    t.readSeconds("steady_s", f.steadyOk, 0.0, 10.0);
    t.readSeconds("guide_absent_timeout_s", f.guideAbsentTimeout, 2.0, 600.0);
    t.readSeconds("guide_max_time_s", f.guideMaxTime, 5.0, 3600.0);
    t.readSeconds("capture_timeout_s", f.captureTimeout, 1.0, 120.0);
    t.readSeconds("processing_timeout_s", f.processingTimeout, 5.0, 600.0);
    t.readSeconds("reveal_timeout_s", f.revealTimeout, 5.0, 3600.0);
    t.readSeconds("retake_choice_timeout_s", f.retakeChoiceTimeout, 2.0, 600.0);
    t.readSeconds("thanks_time_s", f.thanksTime, 1.0, 600.0);
    t.readSeconds("thanks_min_time_s", f.thanksMinTime, 0.0, 600.0);
    t.readSeconds("camera_lost_timeout_s", f.cameraLostTimeout, 1.0, 3600.0);
    t.readSeconds("press_guard_s", f.pressGuard, 0.0, 5.0);
    t.readSeconds("lock_hold_s", f.lockHold, 1.0, 60.0);
    t.readSeconds("operator_timeout_s", f.operatorTimeout, 10.0, 3600.0);
    if (f.thanksMinTime > f.thanksTime) t.failHere("thanks_min_time_s", "must not be longer than thanks_time_s");
    // The lock: the names of the buttons held together.
    std::vector<std::string> names;
    for (const Button b : f.lockCombo) names.push_back(toString(b));
    std::string combo;
    for (std::size_t i = 0; i < names.size(); ++i) combo += (i ? "+" : "") + names[i];
    t.read("lock_combo", combo);
    std::vector<Button> lock;
    std::stringstream in(combo);
    for (std::string word; std::getline(in, word, '+');) {
        if (word == "start") lock.push_back(Button::Start);
        else if (word == "retake") lock.push_back(Button::Retake);
        else if (word == "service") lock.push_back(Button::Service);
        else t.failHere("lock_combo", "\"" + word + "\" is not a button (start, retake, service; joined by +)");
    }
    if (lock.empty()) t.failHere("lock_combo", "name at least one button");
    f.lockCombo = lock;
    t.finish();
}

void readGuidance(Table t, GuidanceSettings& g) {
    Table oval = t.sub("oval");
    oval.read("centre_x", g.oval.centreX, 0.1, 0.9);
    oval.read("centre_y", g.oval.centreY, 0.1, 0.9);
    oval.read("height", g.oval.height, 0.2, 1.0);
    oval.read("aspect", g.oval.aspect, 0.4, 1.2);
    oval.finish();
    t.finish();
}

void readSessions(Table t, SessionStoreSettings& s) {
    t.read("directory", s.directory);
    double photoHours = std::chrono::duration<double, std::ratio<3600>>(s.photoRetention).count();
    t.read("photo_retention_hours", photoHours, 0.0, 24.0 * 3650);
    s.photoRetention = std::chrono::seconds(static_cast<long long>(std::llround(photoHours * 3600.0)));
    double sessionDays = std::chrono::duration<double, std::ratio<86400>>(s.sessionRetention).count();
    t.read("session_retention_days", sessionDays, 0.0, 3650.0);
    s.sessionRetention = std::chrono::seconds(static_cast<long long>(std::llround(sessionDays * 86400.0)));
    if (s.sessionRetention.count() != 0 && s.photoRetention.count() != 0 && s.sessionRetention < s.photoRetention)
        t.failHere("session_retention_days", "sessions would be deleted before their photos' retention ends");
    t.read("code_length", s.codeLength, 4, 12);
    t.finish();
}

void readAnimation(Table t, AnimationSettings& a) {
    std::string style = animationStyleName(a.style);
    t.readChoice("style", style, {"limited", "full"});
    a.style = style == "full" ? AnimationStyle::Full : AnimationStyle::Limited;
    t.read("fps", a.fps, 1.0, 120.0);
    t.read("inbetween_omissions", a.inbetweenOmissions, 0, 100);
    t.read("hold_fraction", a.holdFraction, 0.0, 0.9);
    t.finish();
}

void readCharacter(Table t, FitSettings& f) {
    t.read("enabled", f.characterEnabled);
    t.read("exaggeration", f.character.exaggeration, 0.0, 3.0);
    std::vector<std::string> all;
    for (const SliderRange& r : sliderRanges()) all.emplace_back(r.key);
    std::vector<std::string> sliders(all);
    if (f.character.sliders) sliders.assign(f.character.sliders->begin(), f.character.sliders->end());
    if (t.readWords("sliders", sliders, all, 0)) {
        f.character.sliders = std::set<std::string>(sliders.begin(), sliders.end());
        if (f.character.sliders->size() == all.size()) f.character.sliders.reset();  // all of them: the default
    }
    std::string colours = f.character.coloursFromPhoto ? "photo" : "fixed";
    t.readChoice("colours", colours, {"photo", "fixed"});
    f.character.coloursFromPhoto = colours == "photo";
    t.read("texture_size", f.character.textureSize, 64, 4096);
    t.finish();
}

void readReveal(Table t, RevealSettings& r, bool characterEnabled) {
    std::vector<std::string> words;
    for (const AvatarStyle s : r.styles) words.emplace_back(toString(s));
    if (t.readWords("styles", words, {"photo", "character", "toon"}, 1)) {
        r.styles.clear();
        for (const auto& w : words) r.styles.push_back(*parseAvatarStyle(w));
        // Listed, yet no fit would make it: it would silently never show.
        if (r.shows(AvatarStyle::Character) && !characterEnabled)
            t.failHere("styles", "\"character\" is listed but [character] enabled = false (remove it here, or enable it)");
    } else if (!characterEnabled) {
        std::erase(r.styles, AvatarStyle::Character);  // the default list, without what is switched off
    }
    t.read("toon_colours", r.toonColours, 2, 16);
    t.read("toon_strip_frames", r.toonStripFrames, 2, 360);
    t.finish();
}

void readStage(Table t, StageSettings& s) {
    t.read("enabled", s.enabled);
    t.read("map", s.map);
    t.read("sweep_s", s.sweepSeconds, 2.0, 600.0);
    t.read("low_angle_deg", s.lowAngleDeg, 0.0, 44.0);
    t.finish();
}

}  // namespace

BoothConfig parseBoothConfig(const std::string& text, const std::string& name) {
    toml::table root;
    try {
        root = toml::parse(text, name);
    } catch (const toml::parse_error& e) {
        throw BoothError(ErrorKind::BadConfig, name + ":" + std::to_string(e.source().begin.line),
                         std::string("not valid TOML: ") + std::string(e.description()));
    }
    BoothConfig config;
    config.file = name;
    Table top(&root, "", name, 1);
    readFit(top.sub("fit"), config.fit);
    readCamera(top.sub("camera"), config.camera);
    readButtons(top.sub("buttons"), config.buttons);
    readDisplay(top.sub("display"), config.display);
    readScreen(top.sub("screen"), config.screen);
    readFlow(top.sub("flow"), config.flow);
    readGuidance(top.sub("guidance"), config.guidance);
    readSessions(top.sub("sessions"), config.sessions);
    readAnimation(top.sub("animation"), config.animation);
    readCharacter(top.sub("character"), config.fit.settings);
    readReveal(top.sub("reveal"), config.reveal, config.fit.settings.characterEnabled);
    readStage(top.sub("stage"), config.stage);
    top.finish();
    // A map given in the file is relative to the file (as an operator writes it next to booth.toml).
    if (!config.stage.map.empty() && config.stage.map.is_relative())
        config.stage.map = std::filesystem::path(name).parent_path() / config.stage.map;
    // The operator's map is read now, so a mistake in it stops the booth at start-up with the map's
    // file:line:column, like a mistake in this file.
    if (config.stage.enabled && !config.stage.map.empty()) {
        try {
            (void)stage::buildStage(stage::loadTileMap(config.stage.map));
        } catch (const BoothError& e) {
            throw BoothError(ErrorKind::BadConfig, e.where(), std::string("[stage] map: ") + e.what());
        }
    }
    // The screen draws the oval the guidance measures against: one setting, two users.
    config.screen.oval = config.guidance.oval;
    return config;
}

BoothConfig loadBoothConfig(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadInput, file.string(), "cannot read the configuration file");
    std::stringstream text;
    text << in.rdbuf();
    BoothConfig config = parseBoothConfig(text.str(), file.string());
    config.file = file;
    return config;
}

std::shared_ptr<const BaseHead> configuredBaseHead(const FitConfig& fit) {
    if (fit.baseMesh.empty()) return std::shared_ptr<const BaseHead>(&builtinBaseHead(), [](const BaseHead*) {});
    return std::make_shared<const BaseHead>(loadBaseHead(fit.baseMesh, fit.baseFeatures));
}

}  // namespace avatarbooth
