// The toon's editable correspondence file: parsing, writing, and rebuilding a model's pairs from it.
#include "reveal/toon/toon_correspondence.h"

#include "common/error.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>

namespace avatarbooth::toon {

namespace {

constexpr int kMinPoints = 3;  // fewer cannot outline an area

std::vector<std::string_view> fieldsOf(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t k = 0;
    while (k < line.size()) {
        while (k < line.size() && (line[k] == ' ' || line[k] == '\t')) ++k;
        const std::size_t start = k;
        while (k < line.size() && line[k] != ' ' && line[k] != '\t') ++k;
        if (k > start) out.push_back(line.substr(start, k - start));
    }
    return out;
}

}  // namespace

CorrespondenceFile parseCorrespondence(std::string_view text, const std::string& sourceName) {
    CorrespondenceFile file;
    auto fail = [&](int line, int field, const std::string& why) {
        throw BoothError(ErrorKind::BadConfig, sourceName + ":" + std::to_string(line) + ":" + std::to_string(field), why);
    };
    std::istringstream in{std::string(text)};
    std::string raw;
    int lineNo = 0;
    bool sawHeader = false;
    std::set<std::size_t> listed;
    CorrespondenceFile::Entry* current = nullptr;  // the last `match`, for its `point` lines
    auto finishMatch = [&] {
        if (current && !current->pointsA.empty() && static_cast<int>(current->pointsA.size()) < kMinPoints)
            fail(current->line, 1, "a match with outline points needs at least " + std::to_string(kMinPoints) +
                                       " (it has " + std::to_string(current->pointsA.size()) + "); give none for automatic");
        current = nullptr;
    };
    while (std::getline(in, raw)) {
        ++lineNo;
        const std::string line = raw.substr(0, raw.find('#'));
        const std::vector<std::string_view> f = fieldsOf(line);
        if (f.empty() || (f.size() == 1 && f[0] == "\r")) continue;  // blank (a CRLF file's blank lines too)
        auto expectCount = [&](std::size_t n, const char* usage) {
            if (f.size() != n)
                fail(lineNo, static_cast<int>(std::min(f.size(), n)) + 1,  // the first missing or extra field
                     std::string("expected `") + usage + "` (" + std::to_string(n - 1) + " numbers), got " +
                         std::to_string(f.size() - 1));
        };
        auto index = [&](std::size_t k, const char* what) -> std::size_t {
            std::string_view s = f[k];
            if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
            std::size_t v = 0;
            const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
            if (ec != std::errc() || end != s.data() + s.size())
                fail(lineNo, static_cast<int>(k) + 1, std::string(what) + " '" + std::string(s) + "' is not a region number (0, 1, 2, ...)");
            return v;
        };
        auto number = [&](std::size_t k, const char* what) -> double {
            std::string_view s = f[k];
            if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
            double v = 0.0;
            const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
            if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(v))
                fail(lineNo, static_cast<int>(k) + 1, std::string(what) + " '" + std::string(s) + "' is not a number");
            return v;
        };
        const std::string_view key = f[0];
        if (!sawHeader) {
            if (key != "toon-correspondence") fail(lineNo, 1, "the file must start with `toon-correspondence 1`");
            expectCount(2, "toon-correspondence 1");
            if (index(1, "version") != 1) fail(lineNo, 2, "only version 1 is known");
            sawHeader = true;
            continue;
        }
        if (key == "point") {
            if (!current) fail(lineNo, 1, "`point` must follow a `match` line (or another `point`)");
            expectCount(5, "point AX AY BX BY");
            current->pointsA.emplace_back(number(1, "AX"), number(2, "AY"));
            current->pointsB.emplace_back(number(3, "BX"), number(4, "BY"));
            continue;
        }
        finishMatch();
        if (key == "regions") {
            if (file.regionsLine) fail(lineNo, 1, "`regions` given twice (first on line " + std::to_string(file.regionsLine) + ")");
            expectCount(3, "regions NA NB");
            file.regionsA = index(1, "NA");
            file.regionsB = index(2, "NB");
            file.regionsLine = lineNo;
        } else if (key == "match" || key == "unmatched") {
            if (!file.regionsLine) fail(lineNo, 1, "`regions NA NB` must come before the first match");
            CorrespondenceFile::Entry e;
            e.line = lineNo;
            if (key == "match") {
                expectCount(3, "match A B");
                e.a = index(1, "front region A");
                e.b = index(2, "side region B");
                if (*e.b >= file.regionsB)
                    fail(lineNo, 3, "side region " + std::to_string(*e.b) + " is out of range (regions 0.." +
                                        std::to_string(static_cast<long>(file.regionsB) - 1) + ")");
            } else {
                expectCount(2, "unmatched A");
                e.a = index(1, "front region A");
            }
            if (e.a >= file.regionsA)
                fail(lineNo, 2, "front region " + std::to_string(e.a) + " is out of range (regions 0.." +
                                    std::to_string(static_cast<long>(file.regionsA) - 1) + ")");
            if (!listed.insert(e.a).second)
                fail(lineNo, 2, "front region " + std::to_string(e.a) + " is listed twice");
            file.entries.push_back(e);
            if (key == "match") current = &file.entries.back();
        } else if (key == "forbid") {
            if (!file.regionsLine) fail(lineNo, 1, "`regions NA NB` must come before the first forbid");
            expectCount(3, "forbid A B");
            CorrespondenceFile::Forbid fb{index(1, "front region A"), index(2, "side region B"), lineNo};
            if (fb.a >= file.regionsA) fail(lineNo, 2, "front region " + std::to_string(fb.a) + " is out of range");
            if (fb.b >= file.regionsB) fail(lineNo, 3, "side region " + std::to_string(fb.b) + " is out of range");
            file.forbidden.push_back(fb);
        } else {
            fail(lineNo, 1, "unknown record '" + std::string(key) + "' (regions, match, point, unmatched, forbid)");
        }
    }
    finishMatch();
    if (!sawHeader) fail(lineNo, 1, "empty file: it must start with `toon-correspondence 1`");
    if (!file.regionsLine) fail(lineNo, 1, "no `regions NA NB` line");
    for (const auto& fb : file.forbidden)
        for (const auto& e : file.entries)
            if (e.a == fb.a && e.b && *e.b == fb.b)
                fail(fb.line, 1, "pair " + std::to_string(fb.a) + " " + std::to_string(fb.b) + " is forbidden but matched on line " +
                                     std::to_string(e.line));
    return file;
}

CorrespondenceFile loadCorrespondence(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadInput, path.string(), "cannot read the correspondence file");
    std::ostringstream text;
    text << in.rdbuf();
    return parseCorrespondence(text.str(), path.string());
}

std::string formatCorrespondence(const ToonModel& model) {
    std::ostringstream out;
    char buf[160];
    out << "toon-correspondence 1\n"
           "# Edit and read back with `avatarbooth toon --correspondence FILE` (format in app/toon/toon_correspondence.h).\n"
           "# match A B: front region A with side region B; point AX AY BX BY: corresponding outline points (pixels from\n"
           "# each region's centroid, in order round the outline; delete them all for automatic); unmatched A;\n"
           "# forbid A B: never pair them when A is matched automatically (A with no match/unmatched line).\n";
    std::snprintf(buf, sizeof buf, "regions %zu %zu\n", model.regionsA.regions.size(), model.regionsB.regions.size());
    out << buf;
    auto describe = [&](const Region& r) {
        std::snprintf(buf, sizeof buf, "%s at (%.0f, %.0f), %.0f px, rgb %.2f %.2f %.2f",
                      r.label < 0 ? "silhouette" : "region", r.centroid.x, r.centroid.y, r.area, r.colour[0],
                      r.colour[1], r.colour[2]);
        return std::string(buf);
    };
    for (std::size_t i = 0; i < model.regionsB.regions.size(); ++i)
        out << "# side " << i << ": " << describe(model.regionsB.regions[i]) << "\n";
    for (std::size_t a = 0; a < model.regionsA.regions.size(); ++a) {
        out << "\n# front " << a << ": " << describe(model.regionsA.regions[a]) << "\n";
        const auto it = std::find_if(model.pairs.begin(), model.pairs.end(), [a](const PlacedPair& p) { return p.regionA == a; });
        if (it == model.pairs.end()) {
            out << "unmatched " << a << "\n";
            continue;
        }
        out << "match " << a << " " << it->regionB << "\n";
        const ContourCorrespondence& cc = model.contours[static_cast<std::size_t>(it - model.pairs.begin())];
        for (std::size_t k = 0; k < cc.a.size(); ++k) {
            // %.17g round-trips a double exactly: reading the file back changes nothing.
            std::snprintf(buf, sizeof buf, "point %.17g %.17g %.17g %.17g\n", cc.a[k].x, cc.a[k].y, cc.b[k].x, cc.b[k].y);
            out << buf;
        }
    }
    return out.str();
}

void applyCorrespondence(ToonModel& model, const CorrespondenceFile& file, const std::string& sourceName) {
    const std::size_t na = model.regionsA.regions.size(), nb = model.regionsB.regions.size();
    if (file.regionsA != na || file.regionsB != nb)
        throw BoothError(ErrorKind::BadConfig, sourceName + ":" + std::to_string(file.regionsLine),
                         "the file is for " + std::to_string(file.regionsA) + " front and " + std::to_string(file.regionsB) +
                             " side regions, these drawings have " + std::to_string(na) + " and " + std::to_string(nb) +
                             " (was it written from other photos or settings?)");
    std::vector<const CorrespondenceFile::Entry*> entryOf(na, nullptr);
    for (const auto& e : file.entries) entryOf[e.a] = &e;
    std::vector<PlacedPair> pairs;
    std::vector<ContourCorrespondence> contours;
    for (std::size_t a = 0; a < na; ++a) {
        const Region& ra = model.regionsA.regions[a];
        std::optional<std::size_t> b;
        if (entryOf[a]) {
            b = entryOf[a]->b;
        } else {
            double best = 0.0;
            for (std::size_t j = 0; j < nb; ++j) {
                const bool banned = std::any_of(file.forbidden.begin(), file.forbidden.end(),
                                                [&](const auto& fb) { return fb.a == a && fb.b == j; });
                if (banned) continue;
                const double s = regionSimilarity(ra, model.regionsB.regions[j], model.viewA.direction, model.viewB.direction);
                if (s > best) {
                    best = s;
                    b = j;
                }
            }
        }
        if (!b) continue;
        const Region& rb = model.regionsB.regions[*b];
        pairs.push_back(placePair(ra, rb, a, *b, model.viewA, model.viewB));
        if (entryOf[a] && !entryOf[a]->pointsA.empty()) {
            contours.push_back({entryOf[a]->pointsA, entryOf[a]->pointsB});
        } else {
            contours.push_back(correspondContours(ra, rb));
        }
    }
    // Silhouette backdrops (label -1) first: the renderer draws the first backdropPairs pairs behind everything.
    std::vector<std::size_t> order(pairs.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
    std::stable_partition(order.begin(), order.end(),
                          [&](std::size_t k) { return model.regionsA.regions[pairs[k].regionA].label < 0; });
    model.pairs.clear();
    model.contours.clear();
    model.backdropPairs = 0;
    for (std::size_t k : order) {
        model.pairs.push_back(pairs[k]);
        model.contours.push_back(contours[k]);
        if (model.regionsA.regions[pairs[k].regionA].label < 0) ++model.backdropPairs;
    }
}

}  // namespace avatarbooth::toon
