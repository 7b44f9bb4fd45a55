// The schema of booth.toml: every table and key once, with its type, range or choices, one line of doc, and how its
// value is read from and written into BoothConfig.
//
// It is the one source of truth about the file: the parser (booth_config.cpp) reads and validates through it, and
// the documented default file (`avatarbooth config --print-default`, kept as app/assets/booth.toml) and the
// README's reference table (`avatarbooth config --reference`) are rendered from it. The default values themselves
// are the settings structs' own initialisers, read through each key's get() from a default-constructed
// BoothConfig, so a default cannot be written down twice and differ.
#pragma once

#include "config/booth_config.h"

#include <cstddef>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace avatarbooth {

enum class ConfigType {
    String,       // any text
    Path,         // a file or folder name ("" = the documented fallback)
    Bool,         // true / false
    Integer,      // a whole number in [min, max] (and a multiple of `step` when step > 1)
    Number,       // a number in [min, max]
    Seconds,      // a duration in seconds (fractions allowed), in [min, max]
    Choice,       // one of `choices`
    ButtonCombo,  // button names joined by "+" ("start+retake")
    WordList,     // a list of words in brackets, each one of `choices`, none twice, at least `minCount` of them
};

// A key's value as TOML holds it: bool, integer, floating point, string or a list of strings.
using ConfigValue = std::variant<bool, long long, double, std::string, std::vector<std::string>>;

// Thrown by a key's set() for a value its type and range allow but the setting does not (a combo naming no
// button); the parser adds the file, line and key.
struct ConfigValueRejected {
    std::string what;
};

// A rule across keys that failed: the key blamed (its line is named) and why.
struct ConfigProblem {
    std::string key;
    std::string what;
};

enum class ConfigTableKind {
    Table,      // [name]: keys of its own
    Repeated,   // [[name]]: a list of tables, each with the same keys; given at all, it replaces the default list
    StringMap,  // [name]: free "key" = "value" lines
};

struct ConfigTable {
    std::string name{};  // dotted: "camera", "guidance.oval", "buttons.button"
    ConfigTableKind kind = ConfigTableKind::Table;
    std::string doc{};
    // Repeated: the number of elements, and replacing the list by n default elements.
    std::function<std::size_t(const BoothConfig&)> count{};
    std::function<void(BoothConfig&, std::size_t)> reset{};
    // StringMap: the map, and the words its values may be (empty: any).
    std::function<std::map<std::string, std::string>&(BoothConfig&)> map{};
    std::vector<std::string> valueChoices{};
    // Checked once the table (with its sub-tables) is read: a rule across its keys.
    std::function<std::optional<ConfigProblem>(const BoothConfig&)> check{};
};

struct ConfigKey {
    std::string table{};  // the ConfigTable's name
    std::string name{};
    ConfigType type = ConfigType::String;
    double min = 0;                     // Integer, Number, Seconds
    double max = 0;
    long long step = 1;                 // Integer: allowed values are min, min + step, ... max
    std::vector<std::string> choices{};   // Choice, WordList
    std::size_t minCount = 0;           // WordList: the fewest words
    std::string doc{};
    bool required = false;              // keys of Repeated tables that every element must give
    // The value in a configuration (element: the index in a Repeated table, else 0), and storing a value that has
    // passed the type and range checks.
    std::function<ConfigValue(const BoothConfig&, std::size_t element)> get{};
    std::function<void(BoothConfig&, std::size_t element, const ConfigValue&)> set{};
};

// In file order: a table's keys come before its sub-tables.
const std::vector<ConfigTable>& configTables();
const std::vector<ConfigKey>& configKeys();

// The documented default configuration as a TOML file (what `avatarbooth config --print-default` prints).
std::string renderDefaultConfig();

// The reference of every key as Markdown tables (what `avatarbooth config --reference` prints; in the README).
std::string renderConfigReference();

// A value written as TOML writes it (strings quoted and escaped, floating point with a '.' and all its digits, a
// list of strings in brackets on one line).
std::string tomlValue(const ConfigValue& value);

}  // namespace avatarbooth
