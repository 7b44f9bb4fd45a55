// The toon's editable correspondence file: which front region pairs with which side region, and their outline points.
#pragma once

#include "reveal/toon/toon_billboard.h"

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace avatarbooth::toon {

// Text format (one record a line; `#` starts a comment to the end of the line; blank lines ignored; fields separated
// by spaces; region numbers are indices into ToonModel::regionsA (front) and regionsB (side), from 0):
//   toon-correspondence 1       first record: the format and its version
//   regions NA NB               how many front and side regions the file was written for (must equal the model's)
//   match A B                   front region A pairs with side region B (overrides the automatic match)
//   point AX AY BX BY           an outline point of the preceding `match`: AX AY on A's outline and BX BY on B's, as
//                               pixel offsets from each region's centroid, in each drawing's pixels. The points of a
//                               match, in order round the outline, replace the automatic correspondence; the
//                               billboard's outline is interpolated segment by segment between them. None: automatic
//                               (principal axes aligned, nearest points). When given, at least 3.
//   unmatched A                 front region A pairs with nothing
//   forbid A B                  A never pairs with B; a front region with no `match` or `unmatched` line is matched
//                               automatically (METHODS §3.2 similarity) among the side regions not forbidden to it
// `avatarbooth toon --write-correspondence F` writes the automatic result: a `match` with all its points or an
// `unmatched` for every front region; `--correspondence F` reads an edited copy back.
struct CorrespondenceFile {
    std::size_t regionsA = 0, regionsB = 0;
    int regionsLine = 0;
    struct Entry {
        std::size_t a = 0;
        std::optional<std::size_t> b;  // nullopt: unmatched
        std::vector<cv::Point2d> pointsA, pointsB;
        int line = 0;
    };
    std::vector<Entry> entries;  // one per front region at most
    struct Forbid {
        std::size_t a = 0, b = 0;
        int line = 0;
    };
    std::vector<Forbid> forbidden;
};

// Throws BoothError(BadConfig, "NAME:LINE:FIELD", why) on an unknown record, a bad or missing number, a `point` with
// no `match` before it, a front region listed twice, a match with 1 or 2 points, a pair both matched and forbidden.
CorrespondenceFile parseCorrespondence(std::string_view text, const std::string& sourceName = "correspondence");
// Reads and parses a file (BoothError(BadInput) when it cannot be read).
CorrespondenceFile loadCorrespondence(const std::filesystem::path& path);

// The model's pairs and outline points in the text format (with comments naming each region's colour and place).
std::string formatCorrespondence(const ToonModel& model);

// Rebuilds the model's pairs from the file: listed matches (placed by Algorithm 1, outlines from the file's points or
// automatic), unmatched regions dropped, the rest matched automatically avoiding forbidden pairs. Pairs whose front
// region is a silhouette backdrop (label -1) stay first and drawn behind. Throws BoothError(BadConfig, "NAME:LINE",
// why) when the region counts differ from the model's or a region number is out of range.
void applyCorrespondence(ToonModel& model, const CorrespondenceFile& file, const std::string& sourceName = "correspondence");

}  // namespace avatarbooth::toon
