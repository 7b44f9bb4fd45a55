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

    // The key's value, checked against its type, range and choices (nothing when the key is absent).
    std::optional<ConfigValue> value(const ConfigKey& k) {
        const toml::node* n = take(k.name);
        if (!n) return std::nullopt;
        switch (k.type) {
            case ConfigType::String:
            case ConfigType::Path:
            case ConfigType::ButtonCombo:
                if (!n->is_string()) fail(n, k.name, "expected a string in quotes");
                return n->as_string()->get();
            case ConfigType::Choice: {
                if (!n->is_string()) fail(n, k.name, "expected one of " + list(k.choices));
                const std::string v = n->as_string()->get();
                if (std::find(k.choices.begin(), k.choices.end(), v) == k.choices.end())
                    fail(n, k.name, "\"" + v + "\" is not one of " + list(k.choices));
                return v;
            }
            case ConfigType::Bool:
                if (!n->is_boolean()) fail(n, k.name, "expected true or false");
                return n->as_boolean()->get();
            case ConfigType::Integer: {
                if (!n->is_integer()) fail(n, k.name, "expected a whole number");
                const long long v = n->as_integer()->get();
                const auto lo = static_cast<long long>(k.min), hi = static_cast<long long>(k.max);
                if (k.step > 1 && (v < lo || v > hi || (v - lo) % k.step != 0)) {
                    std::vector<std::string> allowed;
                    for (long long a = lo; a <= hi; a += k.step) allowed.push_back(std::to_string(a));
                    std::string words;
                    for (std::size_t i = 0; i < allowed.size(); ++i)
                        words += (i ? (i + 1 == allowed.size() ? " or " : ", ") : "") + allowed[i];
                    fail(n, k.name, "must be " + words);
                }
                if (v < lo || v > hi)
                    fail(n, k.name, "must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " + std::to_string(v));
                return v;
            }
            case ConfigType::Number:
            case ConfigType::Seconds: {
                if (!n->is_number()) fail(n, k.name, "expected a number");
                const double v = n->is_integer() ? static_cast<double>(n->as_integer()->get()) : n->as_floating_point()->get();
                if (!(v >= k.min && v <= k.max))
                    fail(n, k.name, "must be between " + num(k.min) + " and " + num(k.max) + ", got " + num(v));
                return v;
            }
            case ConfigType::WordList: {
                const toml::array* a = n->as_array();
                if (!a) fail(n, k.name, "expected a list in brackets of " + list(k.choices));
                std::vector<std::string> words;
                for (const toml::node& e : *a) {
                    if (!e.is_string()) fail(&e, k.name, "expected words in quotes, each one of " + list(k.choices));
                    const std::string v = e.as_string()->get();
                    if (std::find(k.choices.begin(), k.choices.end(), v) == k.choices.end())
                        fail(&e, k.name, "\"" + v + "\" is not one of " + list(k.choices));
                    if (std::find(words.begin(), words.end(), v) != words.end())
                        fail(&e, k.name, "\"" + v + "\" is listed twice");
                    words.push_back(v);
                }
                if (words.size() < k.minCount)
                    fail(n, k.name, "name at least " + std::to_string(k.minCount) + " of " + list(k.choices));
                return words;
            }
        }
        fail(n, k.name, "has a type the schema does not know");
    }

    // An array of tables ([[key]]): one Table per element (nothing when the key is absent).
    std::optional<std::vector<Table>> tables(const std::string& key) {
        const toml::node* n = take(key);
        if (!n) return std::nullopt;
        const toml::array* a = n->as_array();
        if (!a || !a->is_array_of_tables()) fail(n, key, "expected tables ([[" + qualified(key) + "]])");
        std::vector<Table> out;
        for (const toml::node& e : *a)
            out.emplace_back(e.as_table(), qualified(key) + "[" + std::to_string(out.size()) + "]", file_,
                             static_cast<int>(e.source().begin.line));
        return out;
    }
    // Every key of a table of strings (key = "value"), each value one of `choices` unless that is empty.
    bool readStringMap(const std::string& key, std::map<std::string, std::string>& out, const std::vector<std::string>& choices) {
        const toml::node* n = take(key);
        if (!n) return false;
        if (!n->is_table()) fail(n, key, "expected a table of \"key\" = \"value\" lines");
        out.clear();
        for (const auto& [k, v] : *n->as_table()) {
            const std::string name = key + "." + std::string(k.str());
            if (!v.is_string()) fail(&v, name, "expected a string in quotes");
            const std::string value = v.as_string()->get();
            if (!choices.empty() && std::find(choices.begin(), choices.end(), value) == choices.end())
                fail(&v, name, "\"" + value + "\" is not one of " + list(choices));
            out[std::string(k.str())] = value;
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

// One table: its keys, its sub-tables, the schema's rule across them, then any key left over is an error.
void readTable(Table& t, const std::string& name, const ConfigTable* schema, BoothConfig& config, std::size_t element) {
    for (const ConfigKey& k : configKeys()) {
        if (k.table != name) continue;
        if (const std::optional<ConfigValue> v = t.value(k)) {
            try {
                k.set(config, element, *v);
            } catch (const ConfigValueRejected& rejected) {
                t.failHere(k.name, rejected.what);
            }
        } else if (k.required) {
            t.failHere(k.name, "every [[" + name + "]] needs a " + k.name);
        }
    }
    readChildren(t, name, config);
    if (schema && schema->check)
        if (const std::optional<ConfigProblem> problem = schema->check(config)) t.failHere(problem->key, problem->what);
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
    readTable(top, "", nullptr, config, 0);
    // [reveal] styles and [character] enabled: a style listed that no fit would make would silently never show;
    // not listed at all, the default list drops what is switched off.
    if (!config.character.enabled && config.reveal.shows(AvatarStyle::Character)) {
        if (const toml::node* styles = root.at_path("reveal.styles").node())
            throw BoothError(ErrorKind::BadConfig, name + ":" + std::to_string(styles->source().begin.line),
                             "reveal.styles: \"character\" is listed but [character] enabled = false (remove it "
                             "here, or enable it)");
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
    if (fit.baseMesh.empty()) return sharedBuiltinBaseHead();
    return std::make_shared<const BaseHead>(loadBaseHead(fit.baseMesh, fit.baseFeatures));
}

}  // namespace avatarbooth
