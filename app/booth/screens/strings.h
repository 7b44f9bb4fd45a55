// The on-screen strings, English and Japanese, from the one strings file (app/assets/strings.toml).
#pragma once

#include "booth/screens/text_renderer.h"

#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace avatarbooth {

// Every key the screens look up. Loading checks that each exists in every language.
std::span<const std::string_view> requiredStringKeys();

class StringTable {
public:
    // Reads the strings file: one table per language ([en], [ja]) of keys (dotted keys nest: `hint.step_back`)
    // to strings. Throws BoothError(BadConfig) naming the file, the line and the key when the file cannot be read
    // or parsed, a value is not a string, a language table is missing, a required key is missing in a language,
    // or a key exists in one language and not the other.
    static StringTable load(const std::filesystem::path& file);

    // The strings file the booth ships: $AVATARBOOTH_ASSET_DIR/strings.toml, else ../share/avatarbooth next to
    // the executable's folder, else the source tree's app/assets (a development build), else
    // /usr/share/avatarbooth. Throws BoothError(BadConfig) listing the places looked at when none exists.
    static std::filesystem::path defaultFile();

    // The string for a key; throws BoothError(Internal) for a key the file does not have (load() checked the
    // required ones).
    const std::string& get(Language language, std::string_view key) const;

    bool has(Language language, std::string_view key) const;

    // get() with "{name}" placeholders replaced by their values.
    std::string format(Language language, std::string_view key,
                       std::initializer_list<std::pair<std::string_view, std::string>> values) const;

    // All keys of a language, sorted.
    std::vector<std::string> keys(Language language) const;

    const std::filesystem::path& file() const { return file_; }

private:
    std::filesystem::path file_;
    std::map<std::string, std::string, std::less<>> strings_[2];
};

}  // namespace avatarbooth
