// Reading batch inputs (CSV manifests, folders of session folders) and splitting them into shards.
#include "batch/batch_input.h"

#include "common/error.h"

#include <algorithm>
#include <fstream>
#include <map>
#include <sstream>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

// One CSV record: its fields and the line it started on (1-based).
struct CsvRecord {
    std::vector<std::string> fields;
    int line = 0;
};

// RFC 4180 records; a quoted field may span lines. An unterminated quote is an error naming the line it opened on.
std::vector<CsvRecord> parseCsv(const std::string& text, const fs::path& file) {
    std::vector<CsvRecord> records;
    std::size_t i = 0;
    if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) i = 3;  // UTF-8 byte order mark (spreadsheet exports)
    int line = 1;
    while (i < text.size()) {
        CsvRecord rec;
        rec.line = line;
        std::string field;
        bool endOfRecord = false;
        while (!endOfRecord) {
            field.clear();
            if (i < text.size() && text[i] == '"') {
                const int openedOn = line;
                ++i;
                for (;;) {
                    if (i >= text.size())
                        throw BoothError(ErrorKind::BadInput, file.string() + ":" + std::to_string(openedOn),
                                         "a quoted field is never closed");
                    if (text[i] == '"') {
                        if (i + 1 < text.size() && text[i + 1] == '"') {
                            field += '"';
                            i += 2;
                            continue;
                        }
                        ++i;
                        break;
                    }
                    if (text[i] == '\n') ++line;
                    field += text[i++];
                }
                // Anything between the closing quote and the separator is kept as written (lenient, like most readers).
                while (i < text.size() && text[i] != ',' && text[i] != '\n' && text[i] != '\r') field += text[i++];
            } else {
                while (i < text.size() && text[i] != ',' && text[i] != '\n' && text[i] != '\r') field += text[i++];
            }
            rec.fields.push_back(field);
            if (i >= text.size()) {
                endOfRecord = true;
            } else if (text[i] == ',') {
                ++i;
            } else {
                if (text[i] == '\r') ++i;
                if (i < text.size() && text[i] == '\n') ++i;
                ++line;
                endOfRecord = true;
            }
        }
        // Blank lines separate nothing: skip them.
        if (rec.fields.size() == 1 && rec.fields[0].empty()) continue;
        records.push_back(std::move(rec));
    }
    return records;
}

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t");
    if (b == std::string::npos) return "";
    const auto e = s.find_last_not_of(" \t");
    return s.substr(b, e - b + 1);
}

// Session ids name folders: keep them to a portable set of characters (anything else, including bytes of non-UTF-8
// names, becomes '_') so that an id can never climb out of the output folder.
std::string safeId(const std::string& raw) {
    std::string id;
    for (const char c : raw) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                        c == '_' || c == '.';
        id += ok ? c : '_';
    }
    if (!id.empty() && id.front() == '.') id.front() = '_';  // no hidden folders, no "." or ".."
    return id;
}

fs::path resolve(const fs::path& base, const std::string& cell) {
    const fs::path p(cell);
    return p.is_absolute() ? p : base / p;
}

// The photo named `stem`.* in a session folder (jpg, jpeg or png, any case); empty when there is none.
fs::path findPhoto(const fs::path& folder, const std::string& stem) {
    static const char* const kExtensions[] = {".jpg", ".jpeg", ".png", ".JPG", ".JPEG", ".PNG"};
    for (const char* ext : kExtensions) {
        const fs::path p = folder / (stem + ext);
        std::error_code ec;
        if (fs::exists(p, ec)) return p;
    }
    return {};
}

}  // namespace

std::vector<BatchItem> readCsvManifest(const fs::path& csv, const ManifestColumns& columns) {
    std::error_code ec;
    if (!fs::is_regular_file(csv, ec)) throw BoothError(ErrorKind::BadInput, csv.string(), "manifest not found or not a file");
    std::ifstream in(csv, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadInput, csv.string(), "cannot read the manifest");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    const std::vector<CsvRecord> records = parseCsv(buffer.str(), csv);
    if (records.empty()) throw BoothError(ErrorKind::BadInput, csv.string(), "the manifest is empty (no header row)");

    const CsvRecord& header = records.front();
    std::map<std::string, std::size_t> index;
    std::string names;
    for (std::size_t k = 0; k < header.fields.size(); ++k) {
        const std::string name = trim(header.fields[k]);
        index.emplace(name, k);
        names += (names.empty() ? "" : ", ") + name;
    }
    const auto column = [&](const std::string& name, const char* option) {
        const auto it = index.find(name);
        if (it == index.end())
            throw BoothError(ErrorKind::BadInput, csv.string() + ":" + std::to_string(header.line),
                             "no column '" + name + "' (" + option + ") in the header; the columns are: " + names);
        return it->second;
    };
    if (columns.side.empty()) throw BoothError(ErrorKind::BadConfig, "--side-column", "name at least one side column");
    const std::size_t frontCol = column(columns.front, "--front-column");
    std::vector<std::size_t> sideCols;
    for (const auto& s : columns.side) sideCols.push_back(column(s, "--side-column"));
    const bool hasBackground = !columns.background.empty();
    const std::size_t backgroundCol = hasBackground ? column(columns.background, "--background-column") : 0;
    const std::size_t idCol = columns.id.empty() ? 0 : column(columns.id, "--id-column");
    const fs::path base = csv.has_parent_path() ? csv.parent_path() : fs::path(".");

    std::vector<BatchItem> items;
    for (std::size_t r = 1; r < records.size(); ++r) {
        const CsvRecord& rec = records[r];
        const std::string where = csv.filename().string() + ":" + std::to_string(rec.line);
        const std::string rowId = rec.fields.size() > idCol ? safeId(trim(rec.fields[idCol])) : "";
        for (std::size_t s = 0; s < sideCols.size(); ++s) {
            BatchItem item;
            item.source = where;
            const std::string baseId = rowId.empty() ? "line" + std::to_string(rec.line) : rowId;
            item.id = sideCols.size() > 1 ? baseId + "-" + safeId(columns.side[s]) : baseId;
            const auto cell = [&](std::size_t col) { return col < rec.fields.size() ? trim(rec.fields[col]) : std::string(); };
            if (rec.fields.size() != header.fields.size()) {
                item.problemKind = "bad_row";
                item.problem = csv.string() + ":" + std::to_string(rec.line) + ": the row has " +
                               std::to_string(rec.fields.size()) + " fields, the header " +
                               std::to_string(header.fields.size());
            } else if (rowId.empty()) {
                item.problemKind = "bad_row";
                item.problem = csv.string() + ":" + std::to_string(rec.line) + ": the id column is empty";
            } else if (cell(frontCol).empty() || cell(sideCols[s]).empty()) {
                item.problemKind = "bad_row";
                item.problem = csv.string() + ":" + std::to_string(rec.line) + ": column '" +
                               (cell(frontCol).empty() ? columns.front : columns.side[s]) + "' is empty";
            }
            if (item.problem.empty()) {
                item.front = resolve(base, cell(frontCol));
                item.side = resolve(base, cell(sideCols[s]));
                if (hasBackground && !cell(backgroundCol).empty()) item.background = resolve(base, cell(backgroundCol));
            }
            items.push_back(std::move(item));
        }
    }
    return items;
}

std::vector<BatchItem> readSessionFolders(const fs::path& folder) {
    std::vector<fs::path> subfolders;
    std::error_code ec;
    fs::directory_iterator it(folder, ec);
    if (ec) throw BoothError(ErrorKind::BadInput, folder.string(), "cannot list the folder: " + ec.message());
    for (const auto& entry : it) {
        const std::string name = entry.path().filename().string();
        if (name.empty() || name.front() == '.') continue;
        if (entry.is_directory(ec)) subfolders.push_back(entry.path());
    }
    std::sort(subfolders.begin(), subfolders.end());
    std::vector<BatchItem> items;
    for (const auto& sub : subfolders) {
        BatchItem item;
        item.id = safeId(sub.filename().string());
        item.source = sub.string();
        item.front = findPhoto(sub, "front");
        item.side = findPhoto(sub, "side");
        item.background = findPhoto(sub, "background");
        if (item.front.empty() || item.side.empty()) {
            item.problemKind = "missing_file";
            item.problem = sub.string() + ": no " + std::string(item.front.empty() ? "front" : "side") +
                           ".jpg/.jpeg/.png in the session folder";
        }
        items.push_back(std::move(item));
    }
    return items;
}

std::vector<BatchItem> readBatchInput(const fs::path& input, const ManifestColumns& columns) {
    std::error_code ec;
    if (fs::is_directory(input, ec)) return readSessionFolders(input);
    if (fs::exists(input, ec)) return readCsvManifest(input, columns);
    throw BoothError(ErrorKind::BadInput, input.string(), "no such folder or manifest");
}

void requireUniqueIds(const std::vector<BatchItem>& items) {
    std::map<std::string, const BatchItem*> seen;
    for (const auto& item : items) {
        const auto [it, fresh] = seen.emplace(item.id, &item);
        if (!fresh)
            throw BoothError(ErrorKind::BadInput, item.source,
                             "session id '" + item.id + "' is also used by " + it->second->source +
                                 " (ids name the output folders; choose another --id-column)");
    }
}

Shard parseShard(const std::string& text) {
    const auto slash = text.find('/');
    int index = 0, count = 0;
    try {
        std::size_t used = 0;
        if (slash == std::string::npos) throw std::invalid_argument("no slash");
        index = std::stoi(text.substr(0, slash), &used);
        if (used != slash) throw std::invalid_argument("junk");
        count = std::stoi(text.substr(slash + 1), &used);
        if (used != text.size() - slash - 1) throw std::invalid_argument("junk");
    } catch (const std::exception&) {
        throw BoothError(ErrorKind::BadConfig, "--shard", "'" + text + "' is not of the form I/N (e.g. 2/4)");
    }
    if (count < 1 || index < 1 || index > count)
        throw BoothError(ErrorKind::BadConfig, "--shard", "'" + text + "': need 1 <= I <= N");
    return {index, count};
}

std::uint64_t stableIdHash(const std::string& id) {
    std::uint64_t h = 14695981039346656037ull;  // FNV-1a 64-bit offset basis
    for (const unsigned char c : id) {
        h ^= c;
        h *= 1099511628211ull;  // FNV-1a 64-bit prime
    }
    return h;
}

int shardOf(const std::string& id, int count) {
    return static_cast<int>(stableIdHash(id) % static_cast<std::uint64_t>(count)) + 1;
}

std::vector<BatchItem> selectShard(const std::vector<BatchItem>& items, const Shard& shard) {
    std::vector<BatchItem> out;
    for (const auto& item : items)
        if (shardOf(item.id, shard.count) == shard.index) out.push_back(item);
    return out;
}

}  // namespace avatarbooth
