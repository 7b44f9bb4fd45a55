// What a batch run works through: the sessions named by a folder of session folders or by a CSV manifest, and the
// deterministic split of them into shards for runs bigger than one machine.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace avatarbooth {

// One front/side pair to fit. `problem` is set when the input itself is broken (a malformed CSV row, an empty
// cell, a folder without a front photo): the item is then reported as failed with that reason, never fitted.
struct BatchItem {
    std::string id;  // unique in the run; names the output session folder (letters, digits, '.', '-', '_')
    std::filesystem::path front, side, background;  // background may be empty
    std::string source;                             // where the item came from, for messages: "pairs.csv:4", a folder
    std::string problem;                            // empty when the item can be fitted
    std::string problemKind;                        // "bad_row" or "missing_file" when problem is set
};

// The columns of a CSV manifest to read. Several side columns make one item per row and side column (FRMDB's
// pairs.csv has a profile with the nose to the left and one to the right): its id is then "<row id>-<column>".
struct ManifestColumns {
    std::string front = "front";
    std::vector<std::string> side = {"side"};
    std::string background;  // optional column; empty = none
    std::string id;          // column naming the session; empty = the first column of the header
};

// Reads a CSV manifest (RFC 4180: commas, double-quoted fields, "" inside quotes; a UTF-8 BOM and CRLF line ends
// are accepted). Paths in it are relative to the manifest's folder unless absolute. Throws BoothError(BadInput)
// naming the file when it cannot be read or has no header, and naming the column and the file when a column given
// in `columns` is missing from the header; a row that is broken (wrong number of fields, an empty path or id)
// becomes an item with `problem` set, naming the file and line.
std::vector<BatchItem> readCsvManifest(const std::filesystem::path& csv, const ManifestColumns& columns);

// A folder of recorded session folders (DESIGN.md "Formats"): each sub-folder holds front.* and side.* (jpg, jpeg or
// png) and optionally background.*; its name is the session id. Sub-folders are taken in name order; hidden ones
// (names starting with '.') are ignored. A sub-folder without a front or side photo becomes an item with `problem`.
// Throws BoothError(BadInput) when the folder cannot be listed.
std::vector<BatchItem> readSessionFolders(const std::filesystem::path& folder);

// A folder (readSessionFolders) or a CSV file (readCsvManifest), by what `input` is.
std::vector<BatchItem> readBatchInput(const std::filesystem::path& input, const ManifestColumns& columns);

// Checks that ids are unique; throws BoothError(BadInput) naming both sources of the first duplicate.
void requireUniqueIds(const std::vector<BatchItem>& items);

// "I/N" with 1 <= I <= N: the I-th of N shards.
struct Shard {
    int index = 1;
    int count = 1;
};

// Parses "I/N"; throws BoothError(BadConfig, "--shard", ...) when it is not of that form or out of range.
Shard parseShard(const std::string& text);

// The shard (1..count) a session id belongs to: FNV-1a 64 of the id's bytes, modulo count, plus one. It depends on
// the id alone, so adding or removing other rows never moves a session to another shard, and every machine of a job
// array computes the same split without talking to the others.
int shardOf(const std::string& id, int count);
std::uint64_t stableIdHash(const std::string& id);

// The items of one shard, in input order.
std::vector<BatchItem> selectShard(const std::vector<BatchItem>& items, const Shard& shard);

}  // namespace avatarbooth
