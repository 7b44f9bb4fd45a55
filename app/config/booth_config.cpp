// Reading booth.toml strictly into the parts' settings structs, as config_schema.cpp describes every key (toml++
// stays inside this file).
#include "config/booth_config.h"

#include "common/error.h"
#include "config/config_schema.h"
#include "reveal/stage/tile_stage.h"

#include <toml++/toml.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

namespace avatarbooth {
namespace {

// Every mistake found in the file so far, with the line it is on (the order they are reported in).
using Mistakes = std::vector<std::pair<int, BoothError>>;

// One table of the file being read. Each read marks its key as known; finish() then reports any key nobody read,
// which is how a misspelt key becomes an error instead of a silently ignored line. A mistake is recorded and the
// reading goes on (the key keeps its default), so that one pass finds every mistake in the file.
class Table {
public:
    Table(const toml::table* table, std::string path, const std::string& file, int line, Mistakes& mistakes)
        : table_(table), path_(std::move(path)), file_(file), line_(line), mistakes_(mistakes) {}

    // A nested table (absent, or a mistake: an empty one, so every default stays).
    Table sub(const std::string& key) {
        const toml::node* n = take(key);
        if (n && !n->is_table()) refuse(n, key, "expected a table ([" + qualified(key) + "])");
        if (!n || !n->is_table()) return Table(nullptr, qualified(key), file_, line_, mistakes_);
        return Table(n->as_table(), qualified(key), file_, static_cast<int>(n->source().begin.line), mistakes_);
    }

    // The key's value, checked against its type, range and choices (nothing when the key is absent or wrong).
    std::optional<ConfigValue> value(const ConfigKey& k) {
        const toml::node* n = take(k.name);
        if (!n) return std::nullopt;
        switch (k.type) {
            case ConfigType::String:
            case ConfigType::Path:
            case ConfigType::ButtonCombo:
                if (!n->is_string()) return refuse(n, k.name, "expected a string in quotes");
                return n->as_string()->get();
            case ConfigType::Choice: {
                if (!n->is_string()) return refuse(n, k.name, "expected one of " + list(k.choices));
                const std::string v = n->as_string()->get();
                if (std::find(k.choices.begin(), k.choices.end(), v) == k.choices.end())
                    return refuse(n, k.name, "\"" + v + "\" is not one of " + list(k.choices));
                return v;
            }
            case ConfigType::Bool:
                if (!n->is_boolean()) return refuse(n, k.name, "expected true or false");
                return n->as_boolean()->get();
            case ConfigType::Integer: {
                if (!n->is_integer()) return refuse(n, k.name, "expected a whole number");
                const long long v = n->as_integer()->get();
                const auto lo = static_cast<long long>(k.min), hi = static_cast<long long>(k.max);
                if (k.step > 1 && (v < lo || v > hi || (v - lo) % k.step != 0)) {
                    std::vector<std::string> allowed;
                    for (long long a = lo; a <= hi; a += k.step) allowed.push_back(std::to_string(a));
                    std::string words;
                    for (std::size_t i = 0; i < allowed.size(); ++i)
                        words += (i ? (i + 1 == allowed.size() ? " or " : ", ") : "") + allowed[i];
                    return refuse(n, k.name, "must be " + words);
                }
                if (v < lo || v > hi)
                    return refuse(n, k.name, "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " + std::to_string(v));
                return v;
            }
            case ConfigType::Number:
            case ConfigType::Seconds: {
                if (!n->is_number()) return refuse(n, k.name, "expected a number");
                const double v = n->is_integer() ? static_cast<double>(n->as_integer()->get()) : n->as_floating_point()->get();
                if (!(v >= k.min && v <= k.max))
                    return refuse(n, k.name, "must be between " + num(k.min) + " and " + num(k.max) + ", got " + num(v));
                return v;
            }
            case ConfigType::WordList: {
                const toml::array* a = n->as_array();
                if (!a) return refuse(n, k.name, "expected a list in brackets of " + list(k.choices));
                std::vector<std::string> words;
                for (const toml::node& e : *a) {
                    if (!e.is_string()) return refuse(&e, k.name, "expected words in quotes, each one of " + list(k.choices));
                    const std::string v = e.as_string()->get();
                    if (std::find(k.choices.begin(), k.choices.end(), v) == k.choices.end())
                        return refuse(&e, k.name, "\"" + v + "\" is not one of " + list(k.choices));
                    if (std::find(words.begin(), words.end(), v) != words.end())
                        return refuse(&e, k.name, "\"" + v + "\" is listed twice");
                    words.push_back(v);
                }
                if (words.size() < k.minCount)
                    return refuse(n, k.name, "name at least " + std::to_string(k.minCount) + " of " + list(k.choices));
                return words;
            }
        }
        return refuse(n, k.name, "has a type the schema does not know");
    }

    // An array of tables ([[key]]): one Table per element (nothing when the key is absent or wrong).
    std::optional<std::vector<Table>> tables(const std::string& key) {
        const toml::node* n = take(key);
        if (!n) return std::nullopt;
        const toml::array* a = n->as_array();
        if (!a || !a->is_array_of_tables()) return refuse(n, key, "expected tables ([[" + qualified(key) + "]])");
        std::vector<Table> out;
        for (const toml::node& e : *a)
            out.emplace_back(e.as_table(), qualified(key) + "[" + std::to_string(out.size()) + "]", file_,
                             static_cast<int>(e.source().begin.line), mistakes_);
        return out;
    }
    // Every key of a table of strings (key = "value"), each value one of `choices` unless that is empty.
    bool readStringMap(const std::string& key, std::map<std::string, std::string>& out, const std::vector<std::string>& choices) {
        const toml::node* n = take(key);
        if (!n) return false;
        if (!n->is_table()) {
            refuse(n, key, "expected a table of \"key\" = \"value\" lines");
            return false;
        }
        out.clear();
        for (const auto& [k, v] : *n->as_table()) {
            const std::string name = key + "." + std::string(k.str());
            if (!v.is_string()) {
                refuse(&v, name, "expected a string in quotes");
                continue;
            }
            const std::string value = v.as_string()->get();
            if (!choices.empty() && std::find(choices.begin(), choices.end(), value) == choices.end()) {
                refuse(&v, name, "\"" + value + "\" is not one of " + list(choices));
                continue;
            }
            out[std::string(k.str())] = value;
        }
        return true;
    }

    // Records "FILE:LINE: table.key: what" (the line of `n`, else the table's); nothing, for the caller to return.
    std::nullopt_t refuse(const toml::node* n, const std::string& key, const std::string& what) const {
        const int line = n ? static_cast<int>(n->source().begin.line) : line_;
        mistakes_.emplace_back(line, BoothError(ErrorKind::BadConfig, file_ + ":" + std::to_string(line),
                                                qualified(key) + ": " + what));
        return std::nullopt;
    }
    void refuseHere(const std::string& key, const std::string& what) const { refuse(nodeOf(key), key, what); }
    std::size_t mistakesSoFar() const { return mistakes_.size(); }

    // Reports every key that no read asked for.
    void finish() const {
        if (!table_) return;
        for (const auto& [k, v] : *table_)
            if (!known_.count(std::string(k.str())))
                refuse(&v, std::string(k.str()), std::string(v.is_table() ? "unknown table" : "unknown key") +
                                                      " (see the reference booth.toml for the keys there are)");
    }

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
    Mistakes& mistakes_;
    std::set<std::string> known_;
};

// The schema table's parent ("" for a top-level table) and its own name within it.
std::string parentOf(const std::string& table) {
    const auto dot = table.rfind('.');
    return dot == std::string::npos ? "" : table.substr(0, dot);
}
std::string leafOf(const std::string& table) { return table.substr(table.rfind('.') + 1); }

void readTable(Table& t, const std::string& name, const ConfigTable* schema, BoothConfig& config, std::size_t element);

// The sub-tables the schema puts under `parent`, in schema order.
void readChildren(Table& t, const std::string& parent, BoothConfig& config) {
    for (const ConfigTable& child : configTables()) {
        if (parentOf(child.name) != parent) continue;
        const std::string key = leafOf(child.name);
        switch (child.kind) {
            case ConfigTableKind::Table: {
                Table sub = t.sub(key);
                readTable(sub, child.name, &child, config, 0);
                break;
            }
            case ConfigTableKind::Repeated:
                if (auto elements = t.tables(key)) {
                    child.reset(config, elements->size());
                    for (std::size_t i = 0; i < elements->size(); ++i) readTable((*elements)[i], child.name, &child, config, i);
                }
                break;
            case ConfigTableKind::StringMap: t.readStringMap(key, child.map(config), child.valueChoices); break;
        }
    }
}

// One table: its keys, its sub-tables, the schema's rule across them, then any key left over is an error. The rule
// is checked only when the table's own keys were right: with one of them wrong (and left at its default) it would
// blame a key that is not the mistake.
void readTable(Table& t, const std::string& name, const ConfigTable* schema, BoothConfig& config, std::size_t element) {
    const std::size_t mistakesBefore = t.mistakesSoFar();
    for (const ConfigKey& k : configKeys()) {
        if (k.table != name) continue;
        if (const std::optional<ConfigValue> v = t.value(k)) {
            try {
                k.set(config, element, *v);
            } catch (const ConfigValueRejected& rejected) {
                t.refuseHere(k.name, rejected.what);
            }
        } else if (k.required) {
            t.refuseHere(k.name, "every [[" + name + "]] needs a " + k.name);
        }
    }
    readChildren(t, name, config);
    if (schema && schema->check && t.mistakesSoFar() == mistakesBefore)
        if (const std::optional<ConfigProblem> problem = schema->check(config)) t.refuseHere(problem->key, problem->what);
    t.finish();
}

}  // namespace

BoothConfig parseBoothConfig(const std::string& text, const std::string& name) {
    toml::table root;
    try {
        root = toml::parse(text, name);
    } catch (const toml::parse_error& e) {
        // toml++ stops at the first syntax error: the one mistake there is to report.
        throw ConfigErrors({BoothError(ErrorKind::BadConfig, name + ":" + std::to_string(e.source().begin.line),
                                       std::string("not valid TOML: ") + std::string(e.description()))});
    }
    BoothConfig config;
    config.file = name;
    Mistakes mistakes;
    Table top(&root, "", name, 1, mistakes);
    readTable(top, "", nullptr, config, 0);
    const auto lineOf = [&](const char* key) {
        const toml::node* n = root.at_path(key).node();
        return n ? static_cast<int>(n->source().begin.line) : 0;
    };
    // [reveal] styles and [character] enabled: a style listed that no fit would make would silently never show;
    // not listed at all, the default list drops what is switched off. (With a mistake already found the two may
    // be defaults standing in for what the file meant: not checked then.)
    if (mistakes.empty() && !config.character.enabled && config.reveal.shows(AvatarStyle::Character)) {
        if (const int line = lineOf("reveal.styles"))
            mistakes.emplace_back(line, BoothError(ErrorKind::BadConfig, name + ":" + std::to_string(line),
                                                   "reveal.styles: \"character\" is listed but [character] enabled "
                                                   "= false (remove it here, or enable it)"));
        std::erase(config.reveal.styles, AvatarStyle::Character);
    }
    // A map given in the file is relative to the file (as an operator writes it next to booth.toml).
    if (!config.stage.map.empty() && config.stage.map.is_relative())
        config.stage.map = std::filesystem::path(name).parent_path() / config.stage.map;
    // The operator's map is read now, so a mistake in it stops the booth at start-up with the map's
    // file:line:column, like a mistake in this file.
    if (config.stage.enabled && !config.stage.map.empty()) {
        try {
            (void)stage::buildStage(stage::loadTileMap(config.stage.map));
        } catch (const BoothError& e) {
            mistakes.emplace_back(lineOf("stage.map"),
                                  BoothError(ErrorKind::BadConfig, e.where(), std::string("[stage] map: ") + e.what()));
        }
    }
    if (!mistakes.empty()) {
        std::stable_sort(mistakes.begin(), mistakes.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
        std::vector<BoothError> inOrder;
        for (auto& [line, mistake] : mistakes) inOrder.push_back(std::move(mistake));
        throw ConfigErrors(std::move(inOrder));
    }
    // The screen draws the oval the guidance measures against: one setting, two users.
    config.screen.oval = config.guidance.oval;
    return config;
}

namespace {

// The first mistake's message without its "FILE:LINE: " (BoothError puts it back), then the others, one a line.
std::string listed(const std::vector<BoothError>& mistakes) {
    const BoothError& first = mistakes.at(0);
    std::string out = std::string(first.what()).substr(first.where().empty() ? 0 : first.where().size() + 2);
    for (std::size_t i = 1; i < mistakes.size(); ++i) out += "\n" + std::string(mistakes[i].what());
    return out;
}

}  // namespace

ConfigErrors::ConfigErrors(std::vector<BoothError> mistakes)
    : BoothError(ErrorKind::BadConfig, mistakes.at(0).where(), listed(mistakes)), mistakes_(std::move(mistakes)) {}

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
    if (fit.baseMesh.empty()) return productBaseHead();
    return std::make_shared<const BaseHead>(loadBaseHead(fit.baseMesh, fit.baseFeatures));
}

}  // namespace avatarbooth
