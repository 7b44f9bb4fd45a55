// Loading and checking the strings file (TOML, one table per language).
#include "booth/screens/strings.h"

#include "common/error.h"
#include "common/executable_dir.h"

#include <toml++/toml.h>

#include <unistd.h>

#include <array>
#include <cstdlib>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

constexpr std::array<std::string_view, 2> kLanguageTables = {"en", "ja"};

constexpr std::string_view kRequired[] = {
    "title",
    "attract.subtitle",
    "attract.press",
    "guide.front.step",
    "guide.side.step",
    "guide.press_now",
    "hint.none",
    "hint.no_face",
    "hint.step_closer",
    "hint.step_back",
    "hint.move_to_centre",
    "hint.look_at_camera",
    "hint.turn_right",
    "hint.turn_more",
    "hint.turn_back",
    "hint.face_hidden",
    "hint.hold_still",
    "processing.title",
    "stage.read_photos",
    "stage.front_landmarks",
    "stage.front_silhouette",
    "stage.side_profile",
    "stage.head_fit",
    "stage.texture",
    "stage.working",
    "reveal.title",
    "reveal.keep",
    "reveal.retake",
    "retake.title",
    "retake.front",
    "retake.side",
    "thanks.title",
    "thanks.code_label",
    "thanks.instructions",
    "thanks.saving",
    "thanks.scan",
    "error.camera_lost.title",
    "error.camera_lost.body",
    "error.capture_failed",
    "error.fit.no_face",
    "error.fit.not_profile",
    "error.fit.turn_more",
    "error.fit.turn_back",
    "error.fit.face_hidden",
    "error.fit.mismatch",
    "error.fit.other",
    "error.save_failed",
    "operator.title",
    "operator.item.last_codes",
    "operator.item.free_disk",
    "operator.item.exit",
    "operator.help",
    "operator.back",
    "operator.no_sessions",
    "operator.sessions",
    "operator.free",
    "operator.freed",
    "operator.printer",
    "operator.camera_ok",
    "operator.camera_lost",
};

std::string where(const fs::path& file, const toml::source_region& src, std::string_view key) {
    return file.string() + ":" + std::to_string(src.begin.line) + ": " + std::string(key);
}

void flatten(const fs::path& file, const toml::table& table, const std::string& prefix,
             std::map<std::string, std::string, std::less<>>& out) {
    for (const auto& [k, node] : table) {
        const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
        if (const auto* sub = node.as_table()) {
            flatten(file, *sub, key, out);
        } else if (const auto* s = node.as_string()) {
            out.emplace(key, s->get());
        } else {
            throw BoothError(ErrorKind::BadConfig, where(file, node.source(), key), "must be a string");
        }
    }
}

}  // namespace

std::span<const std::string_view> requiredStringKeys() { return kRequired; }

StringTable StringTable::load(const fs::path& file) {
    StringTable t;
    t.file_ = file;
    toml::table root;
    try {
        root = toml::parse_file(file.string());
    } catch (const toml::parse_error& e) {
        throw BoothError(ErrorKind::BadConfig, file.string() + ":" + std::to_string(e.source().begin.line),
                         std::string(e.description()));
    }
    for (std::size_t l = 0; l < kLanguageTables.size(); ++l) {
        const auto* table = root[kLanguageTables[l]].as_table();
        if (!table)
            throw BoothError(ErrorKind::BadConfig, file.string(),
                             "no [" + std::string(kLanguageTables[l]) + "] table of strings");
        flatten(file, *table, "", t.strings_[l]);
        for (std::string_view key : kRequired)
            if (!t.strings_[l].count(key))
                throw BoothError(ErrorKind::BadConfig, file.string() + ": [" + std::string(kLanguageTables[l]) + "]",
                                 "missing string '" + std::string(key) + "'");
    }
    for (std::size_t l = 0; l < kLanguageTables.size(); ++l) {
        const auto& other = t.strings_[1 - l];
        for (const auto& [key, value] : t.strings_[l])
            if (!other.count(key))
                throw BoothError(ErrorKind::BadConfig,
                                 file.string() + ": [" + std::string(kLanguageTables[1 - l]) + "]",
                                 "missing string '" + key + "' (it exists in [" + std::string(kLanguageTables[l]) +
                                     "])");
    }
    return t;
}

fs::path StringTable::defaultFile() {
    std::vector<fs::path> places;
    if (const char* env = std::getenv("AVATARBOOTH_ASSET_DIR"); env && *env) places.emplace_back(env);
    if (const fs::path exe = executableDir(); !exe.empty())
        places.push_back(exe.parent_path() / "share" / "avatarbooth");
    places.push_back(fs::path(__FILE__).parent_path().parent_path().parent_path() / "assets");  // the source tree
    places.emplace_back("/usr/share/avatarbooth");
    std::string looked;
    for (const auto& p : places) {
        std::error_code ec;
        if (fs::is_regular_file(p / "strings.toml", ec)) return p / "strings.toml";
        looked += (looked.empty() ? "" : ", ") + (p / "strings.toml").string();
    }
    throw BoothError(ErrorKind::BadConfig, "strings.toml", "the strings file was not found (looked at " + looked + ")");
}

const std::string& StringTable::get(Language language, std::string_view key) const {
    const auto& table = strings_[language == Language::Japanese ? 1 : 0];
    const auto it = table.find(key);
    if (it == table.end())
        throw BoothError(ErrorKind::Internal, file_.string(),
                         "no string '" + std::string(key) + "' for language " + languageCode(language));
    return it->second;
}

bool StringTable::has(Language language, std::string_view key) const {
    return strings_[language == Language::Japanese ? 1 : 0].count(key) > 0;
}

std::string StringTable::format(Language language, std::string_view key,
                                std::initializer_list<std::pair<std::string_view, std::string>> values) const {
    std::string s = get(language, key);
    for (const auto& [name, value] : values) {
        const std::string token = "{" + std::string(name) + "}";
        for (std::size_t at = s.find(token); at != std::string::npos; at = s.find(token, at + value.size()))
            s.replace(at, token.size(), value);
    }
    return s;
}

std::vector<std::string> StringTable::keys(Language language) const {
    std::vector<std::string> out;
    for (const auto& [k, v] : strings_[language == Language::Japanese ? 1 : 0]) out.push_back(k);
    return out;
}

}  // namespace avatarbooth
