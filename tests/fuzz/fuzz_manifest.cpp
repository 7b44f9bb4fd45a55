// libFuzzer target: the CSV manifest reader of `avatarbooth batch` (batch/batch_input readCsvManifest and what the
// batch command does with its items next: the unique-id check and the shard split).
//
// Input layout: one flags byte, then the manifest's bytes. The flags pick the columns asked for (so the fuzzer
// reaches the id, background and several-sides paths, and the "no such column" errors) and where the file lies.
// Every input must give items or a BoothError; the items must keep the promises batch_input.h makes (an id that is
// a safe folder name, and either a problem or a front and a side path), or the target traps.
#include "fuzz_files.h"

#include "batch/batch_input.h"
#include "common/error.h"

#include <cstddef>
#include <cstdint>
#include <string>

namespace {

constexpr std::uint8_t kIdColumn = 1;          // --id-column id (else the first column names the session)
constexpr std::uint8_t kBackground = 2;        // --background-column background
constexpr std::uint8_t kTwoSides = 4;          // --side-column left --side-column right (one item per side)
constexpr std::uint8_t kByInput = 8;           // through readBatchInput (what `batch INPUT` calls)
constexpr std::uint8_t kNonUtf8Folder = 16;    // the manifest in a folder whose name is not UTF-8
constexpr std::uint8_t kShardsShift = 5;       // bits 5-7: split into 1..8 shards

// What batch_input.h promises of an id: it names a folder under the output folder, so it is not empty, uses only
// letters, digits, '-', '_', '.', and does not start with '.' (no hidden folder, no "." or "..").
bool safeFolderName(const std::string& id) {
    if (id.empty() || id.front() == '.') return false;
    for (const char c : id) {
        const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' ||
                        c == '_' || c == '.';
        if (!ok) return false;
    }
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace avatarbooth;
    static const fuzz::ScratchDir root("manifest");
    if (size < 1) return 0;
    const std::uint8_t flags = data[0];
    const auto folder = root.path() / ((flags & kNonUtf8Folder) ? "sessions\xff\xfe" : "sessions");
    fuzz::clearFolder(folder);
    const auto csv = folder / "pairs.csv";
    fuzz::writeBytes(csv, data + 1, size - 1);

    ManifestColumns columns;
    if (flags & kIdColumn) columns.id = "id";
    if (flags & kBackground) columns.background = "background";
    if (flags & kTwoSides) columns.side = {"left", "right"};
    const int shards = ((flags >> kShardsShift) & 7) + 1;

    std::vector<BatchItem> items;
    try {
        items = (flags & kByInput) ? readBatchInput(csv, columns) : readCsvManifest(csv, columns);
    } catch (const BoothError&) {
        return 0;
    }
    for (const auto& item : items) {
        if (!safeFolderName(item.id)) __builtin_trap();
        if (item.source.empty()) __builtin_trap();
        if (item.problem.empty() ? (item.front.empty() || item.side.empty()) : item.problemKind.empty())
            __builtin_trap();
    }
    try {
        requireUniqueIds(items);
    } catch (const BoothError&) {
    }
    // Every item lands in exactly one shard.
    std::size_t inShards = 0;
    for (int s = 1; s <= shards; ++s) inShards += selectShard(items, Shard{s, shards}).size();
    if (inShards != items.size()) __builtin_trap();
    return 0;
}
