// Kitamura's top-down tile stage: map parsing, the 3-D generation rules of METHODS §3.3, its mesh and R(theta).
//
// Geometry: seen top-down (the 45-degree look of RPG maps) a point at depth z and height y shows on map row z - y,
// so a group whose top is at height T has its green tile of row r covering z in [r + T, r + 1 + T]. Decisions where
// the seed is open: a run with its own brown tiles is as tall as they are, hung from the group's top (a lower box of
// a group floats, as the seed notes); a run with no brown of its own (hidden, a pond rim, completed) reaches the
// group's bottom; a pond's floor is a box from the group's bottom up to its top minus the pond's depth.
#include "reveal/stage/tile_stage.h"

#include "common/error.h"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <tuple>
#include <sstream>

namespace avatarbooth::stage {

Tile TileMap::at(int c, int r) const {
    if (c < 0 || r < 0 || c >= width || r >= height) return Tile::Empty;
    return tiles[static_cast<std::size_t>(r * width + c)];
}
bool TileMap::edgeRight(int c, int r) const {
    if (c < 0 || r < 0 || c >= width || r >= height) return false;
    return cutRight[static_cast<std::size_t>(r * width + c)] != 0;
}
bool TileMap::edgeBelow(int c, int r) const {
    if (c < 0 || r < 0 || c >= width || r >= height) return false;
    return cutBelow[static_cast<std::size_t>(r * width + c)] != 0;
}

TileMap parseTileMap(std::string_view text, const std::string& sourceName) {
    struct Row {
        std::vector<Tile> tiles;
        std::vector<int> charColumn;  // 1-based character column of each tile
        std::vector<unsigned char> cutRight, cutBelow;
    };
    std::vector<Row> rows;
    bool pendingEdgeRow = false;
    int pendingEdgeLine = 0;
    auto fail = [&](int line, int column, const std::string& why) {
        throw BoothError(ErrorKind::BadConfig, sourceName + ":" + std::to_string(line) + ":" + std::to_string(column), why);
    };
    std::istringstream in{std::string(text)};
    std::string raw;
    int lineNo = 0;
    while (std::getline(in, raw)) {
        ++lineNo;
        std::string line = raw.substr(0, raw.find('#'));
        while (!line.empty() && (line.back() == ' ' || line.back() == '\r' || line.back() == '\t')) line.pop_back();
        if (line.empty()) continue;
        const bool edgeRow = line.find_first_not_of("- ") == std::string::npos;
        if (edgeRow) {
            if (rows.empty()) fail(lineNo, static_cast<int>(line.find('-')) + 1, "an edge row needs a tile row above it");
            Row& above = rows.back();
            for (std::size_t k = 0; k < line.size(); ++k) {
                if (line[k] != '-') continue;
                const auto it = std::find(above.charColumn.begin(), above.charColumn.end(), static_cast<int>(k) + 1);
                if (it == above.charColumn.end())
                    fail(lineNo, static_cast<int>(k) + 1, "edge mark '-' is not under a tile of the row above");
                above.cutBelow[static_cast<std::size_t>(it - above.charColumn.begin())] = 1;
            }
            pendingEdgeRow = true;
            pendingEdgeLine = lineNo;
            continue;
        }
        Row row;
        bool lastWasEdge = false;
        for (std::size_t k = 0; k < line.size(); ++k) {
            const char ch = line[k];
            const int column = static_cast<int>(k) + 1;
            if (ch == '|') {
                if (row.tiles.empty() || lastWasEdge) fail(lineNo, column, "edge mark '|' must stand between two tiles");
                row.cutRight.back() = 1;
                lastWasEdge = true;
                continue;
            }
            if (ch != '.' && ch != 'g' && ch != 'b' && ch != 'w' && ch != 'r' && ch != 'e')
                fail(lineNo, column,
                     std::string("unknown tile '") + ch + "' (use g green, b brown, w blue, r red, e beige, . empty, | and - edges)");
            row.tiles.push_back(static_cast<Tile>(ch));
            row.charColumn.push_back(column);
            row.cutRight.push_back(0);
            row.cutBelow.push_back(0);
            lastWasEdge = false;
        }
        if (lastWasEdge) fail(lineNo, static_cast<int>(line.size()), "edge mark '|' must stand between two tiles");
        rows.push_back(std::move(row));
        pendingEdgeRow = false;
    }
    if (pendingEdgeRow) fail(pendingEdgeLine, 1, "an edge row needs a tile row below it");
    TileMap map;
    map.height = static_cast<int>(rows.size());
    for (const Row& r : rows) map.width = std::max(map.width, static_cast<int>(r.tiles.size()));
    if (map.width == 0) fail(lineNo, 1, "the map has no tiles");
    const std::size_t n = static_cast<std::size_t>(map.width * map.height);
    map.tiles.assign(n, Tile::Empty);
    map.cutRight.assign(n, 0);
    map.cutBelow.assign(n, 0);
    for (int r = 0; r < map.height; ++r)
        for (std::size_t c = 0; c < rows[static_cast<std::size_t>(r)].tiles.size(); ++c) {
            const std::size_t i = static_cast<std::size_t>(r * map.width) + c;
            map.tiles[i] = rows[static_cast<std::size_t>(r)].tiles[c];
            map.cutRight[i] = rows[static_cast<std::size_t>(r)].cutRight[c];
            map.cutBelow[i] = rows[static_cast<std::size_t>(r)].cutBelow[c];
        }
    return map;
}

TileMap loadTileMap(const std::filesystem::path& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) throw BoothError(ErrorKind::BadInput, path.string(), "cannot read the tile map");
    std::ostringstream text;
    text << file.rdbuf();
    return parseTileMap(text.str(), path.string());
}

namespace {

// Connected components of one tile colour, 4-connected, not across edge marks. -1 where another colour.
std::vector<int> components(const TileMap& map, Tile colour, int& count) {
    std::vector<int> id(static_cast<std::size_t>(map.width * map.height), -1);
    count = 0;
    for (int r = 0; r < map.height; ++r)
        for (int c = 0; c < map.width; ++c) {
            if (map.at(c, r) != colour || id[static_cast<std::size_t>(r * map.width + c)] >= 0) continue;
            std::vector<std::pair<int, int>> stack{{c, r}};
            id[static_cast<std::size_t>(r * map.width + c)] = count;
            while (!stack.empty()) {
                const auto [x, y] = stack.back();
                stack.pop_back();
                const std::pair<int, int> next[4] = {{x + 1, y}, {x - 1, y}, {x, y + 1}, {x, y - 1}};
                for (const auto& [nx, ny] : next) {
                    if (map.at(nx, ny) != colour || id[static_cast<std::size_t>(ny * map.width + nx)] >= 0) continue;
                    const bool cut = nx != x ? map.edgeRight(std::min(x, nx), y) : map.edgeBelow(x, std::min(y, ny));
                    if (cut) continue;
                    id[static_cast<std::size_t>(ny * map.width + nx)] = count;
                    stack.emplace_back(nx, ny);
                }
            }
            ++count;
        }
    return id;
}

struct Run {
    int column, first, last;  // rows of green, inclusive
    int brown = 0;            // its own brown run below (0: none, or a pond wall)
    bool pondWall = false;
    bool rearFace = false;    // its brown continues as a face behind a nearer group (rear brown group rule)
};

}  // namespace

Stage buildStage(const TileMap& map) {
    Stage stage;
    const int w = map.width, h = map.height;
    auto idx = [w](int c, int r) { return static_cast<std::size_t>(r * w + c); };
    int groupCount = 0;
    const std::vector<int> group = components(map, Tile::Green, groupCount);
    auto groupAt = [&](int c, int r) { return map.at(c, r) == Tile::Green ? group[idx(c, r)] : -1; };
    std::vector<int> owner(group);  // green tiles: their group; brown tiles: the group whose front they are

    // Runs of green per column and group; the brown below each (cut by brown edges); ponds recognised.
    std::vector<std::vector<Run>> runs(static_cast<std::size_t>(groupCount));
    for (int c = 0; c < w; ++c)
        for (int r = 0; r < h; ++r) {
            const int g = groupAt(c, r);
            if (g < 0 || (r > 0 && groupAt(c, r - 1) == g && !map.edgeBelow(c, r - 1))) continue;
            Run run{c, r, r};
            while (groupAt(c, run.last + 1) == g && !map.edgeBelow(c, run.last)) ++run.last;
            int k = run.last + 1;
            while (map.at(c, k) == Tile::Brown && (k == run.last + 1 || !map.edgeBelow(c, k - 1))) ++k;
            run.brown = k - run.last - 1;
            if (run.brown > 0 && map.at(c, k) == Tile::Blue) {
                run.pondWall = true;
            } else {
                for (int b = run.last + 1; b < k; ++b) owner[idx(c, b)] = g;
            }
            runs[static_cast<std::size_t>(g)].push_back(run);
        }
    // Rear brown group (seed fig. 3.8): brown tiles form groups of their own (4-connected, cut by edge marks). A
    // brown front is one flat face: a column whose brown is interrupted by the green of a nearer group, while the same
    // brown group runs further down in other columns of the same plane (same group, same last green row), is that
    // face seen above the nearer group, so it reaches as low as the rest of the face and does not sit on the nearer
    // group. An edge mark that cuts the brown apart splits the face, and the cut part follows the stacking rule.
    int brownCount = 0;
    const std::vector<int> brownGroup = components(map, Tile::Brown, brownCount);
    {
        std::map<std::tuple<int, int, int>, int> lowest;  // (brown group, green group, last green row) -> lowest brown row
        for (int g = 0; g < groupCount; ++g)
            for (const Run& run : runs[static_cast<std::size_t>(g)]) {
                if (run.pondWall || run.brown == 0) continue;
                const int bottom = run.last + run.brown;
                for (int b = run.last + 1; b <= bottom; ++b) {
                    int& low = lowest.try_emplace({brownGroup[idx(run.column, b)], g, run.last}, bottom).first->second;
                    low = std::max(low, bottom);
                }
            }
        for (int g = 0; g < groupCount; ++g)
            for (Run& run : runs[static_cast<std::size_t>(g)]) {
                if (run.pondWall || run.brown == 0) continue;
                const int bottom = run.last + run.brown;
                const int below = groupAt(run.column, bottom + 1);
                if (below < 0 || below == g) continue;
                const auto it = lowest.find({brownGroup[idx(run.column, bottom)], g, run.last});
                if (it != lowest.end() && it->second > bottom) {
                    run.brown = it->second - run.last;
                    run.rearFace = true;
                }
            }
    }

    stage.groups.resize(static_cast<std::size_t>(groupCount));
    for (int g = 0; g < groupCount; ++g)
        for (const Run& run : runs[static_cast<std::size_t>(g)])
            if (!run.pondWall) stage.groups[static_cast<std::size_t>(g)].height = std::max(stage.groups[static_cast<std::size_t>(g)].height, run.brown);

    // Stacking: a group whose brown front ends on another group's green sits on that group's top.
    for (int g = 0; g < groupCount; ++g)
        for (const Run& run : runs[static_cast<std::size_t>(g)]) {
            if (run.pondWall || run.brown == 0 || run.rearFace) continue;
            const int below = groupAt(run.column, run.last + run.brown + 1);
            if (below >= 0 && below != g) stage.groups[static_cast<std::size_t>(g)].sitsOn = below;
        }
    std::vector<int> state(static_cast<std::size_t>(groupCount), 0);  // 0 new, 1 visiting, 2 done
    std::function<double(int)> topOf = [&](int g) -> double {
        StageGroup& sg = stage.groups[static_cast<std::size_t>(g)];
        if (state[static_cast<std::size_t>(g)] == 0) {
            state[static_cast<std::size_t>(g)] = 1;
            if (sg.sitsOn >= 0 && state[static_cast<std::size_t>(sg.sitsOn)] != 1) sg.base = topOf(sg.sitsOn);
            else sg.sitsOn = -1;  // a cycle of groups sitting on each other: this one stands on the ground
            state[static_cast<std::size_t>(g)] = 2;
        }
        return sg.base + sg.height;
    };
    for (int g = 0; g < groupCount; ++g) topOf(g);

    // Houses found before completion: a red group over a beige group; the green groups the walls stand on.
    struct House {
        int red = -1, beige = -1;
        cv::Rect roof, body;
    };
    std::vector<House> houses;
    int redCount = 0, beigeCount = 0;
    const std::vector<int> red = components(map, Tile::Red, redCount);
    const std::vector<int> beige = components(map, Tile::Beige, beigeCount);
    auto bounds = [&](const std::vector<int>& ids, int id) {
        cv::Rect box;
        bool any = false;
        for (int r = 0; r < h; ++r)
            for (int c = 0; c < w; ++c)
                if (ids[idx(c, r)] == id) {
                    box = any ? (box | cv::Rect(c, r, 1, 1)) : cv::Rect(c, r, 1, 1);
                    any = true;
                }
        return box;
    };
    // houseOn: for each red or beige tile of a house, the green group its walls stand on (-1: none).
    std::vector<int> houseOn(static_cast<std::size_t>(w * h), -1);
    for (int rr = 0; rr < redCount; ++rr) {
        House house;
        house.red = rr;
        house.roof = bounds(red, rr);
        for (int c = house.roof.x; c < house.roof.x + house.roof.width && house.beige < 0; ++c)
            if (map.at(c, house.roof.y + house.roof.height) == Tile::Beige)
                house.beige = beige[idx(c, house.roof.y + house.roof.height)];
        if (house.beige < 0) continue;  // a roof with no walls under it is not a house
        house.body = bounds(beige, house.beige);
        int standsOn = -1;
        for (int c = house.body.x; c < house.body.x + house.body.width; ++c) {
            const int g = groupAt(c, house.body.y + house.body.height);
            if (g >= 0 && (standsOn < 0 || stage.groups[static_cast<std::size_t>(g)].base +
                                                   stage.groups[static_cast<std::size_t>(g)].height >
                                               stage.groups[static_cast<std::size_t>(standsOn)].base +
                                                   stage.groups[static_cast<std::size_t>(standsOn)].height))
                standsOn = g;
        }
        for (int r = 0; r < h; ++r)
            for (int c = 0; c < w; ++c)
                if ((map.at(c, r) == Tile::Red && red[idx(c, r)] == rr) ||
                    (map.at(c, r) == Tile::Beige && beige[idx(c, r)] == house.beige))
                    houseOn[idx(c, r)] = standsOn;
        houses.push_back(house);
    }

    // Occlusion completion: a gap between two runs of a group in one column, hidden by tiles of groups sitting on it
    // or by a house standing on it (the ground goes on behind the house), belongs to the group.
    auto sitsOnGroup = [&](int other, int g) {
        for (int k = other; k >= 0; k = stage.groups[static_cast<std::size_t>(k)].sitsOn)
            if (stage.groups[static_cast<std::size_t>(k)].sitsOn == g) return true;
        return false;
    };
    for (int g = 0; g < groupCount; ++g) {
        auto& list = runs[static_cast<std::size_t>(g)];
        std::sort(list.begin(), list.end(), [](const Run& a, const Run& b) {
            return a.column != b.column ? a.column < b.column : a.first < b.first;
        });
        std::vector<Run> merged;
        for (const Run& run : list) {
            if (!merged.empty() && merged.back().column == run.column && !merged.back().pondWall) {
                bool hidden = true;
                for (int r = merged.back().last + 1; r < run.first && hidden; ++r) {
                    const int o = owner[idx(run.column, r)];
                    hidden = (o >= 0 && o != g && sitsOnGroup(o, g)) || houseOn[idx(run.column, r)] == g;
                }
                if (hidden) {
                    merged.back().last = run.last;
                    merged.back().brown = run.brown;
                    continue;
                }
            }
            merged.push_back(run);
        }
        list = merged;
    }

    // Boxes: one per run, side by side runs of the same rows and heights merged (W = horizontally connected green).
    for (int g = 0; g < groupCount; ++g) {
        const StageGroup& sg = stage.groups[static_cast<std::size_t>(g)];
        const double top = sg.base + sg.height;
        std::vector<StageBox> boxes;
        for (const Run& run : runs[static_cast<std::size_t>(g)]) {
            const double bottom = (run.brown > 0 && !run.pondWall) ? top - run.brown : sg.base;
            StageBox box;
            box.kind = StageBox::Kind::Ground;
            box.group = g;
            box.min = {run.column, bottom, run.first + top};
            box.max = {run.column + 1, top, run.last + 1 + top};
            auto same = std::find_if(boxes.begin(), boxes.end(), [&](const StageBox& b) {
                return b.max.x == box.min.x && b.min.y == box.min.y && b.min.z == box.min.z && b.max.z == box.max.z;
            });
            if (same != boxes.end()) same->max.x = box.max.x;
            else boxes.push_back(box);
        }
        stage.boxes.insert(stage.boxes.end(), boxes.begin(), boxes.end());
    }

    // Ponds: blue tiles under a brown run under green; as deep as the brown run; the floor a box in the group.
    int blueCount = 0;
    const std::vector<int> blue = components(map, Tile::Blue, blueCount);
    for (int b = 0; b < blueCount; ++b) {
        int c0 = w, c1 = -1, rFirstBrown = h, rLast = -1, depth = 0, g = -1;
        for (int r = 0; r < h; ++r)
            for (int c = 0; c < w; ++c) {
                if (blue[idx(c, r)] != b) continue;
                c0 = std::min(c0, c);
                c1 = std::max(c1, c);
                rLast = std::max(rLast, r);
                if (map.at(c, r - 1) == Tile::Brown) {
                    int k = r - 1, d = 0;
                    while (map.at(c, k) == Tile::Brown) --k, ++d;
                    if (groupAt(c, k) >= 0) {
                        g = groupAt(c, k);
                        depth = std::max(depth, d);
                        rFirstBrown = std::min(rFirstBrown, k + 1);
                    }
                } else if (groupAt(c, r - 1) >= 0) {
                    // Green straight above the water: a pond with no wall showing, i.e. no depth (the seed needs the
                    // brown for a deep pond): water level with the ground, filling the hole the blue would leave.
                    g = groupAt(c, r - 1);
                    rFirstBrown = std::min(rFirstBrown, r);
                }
            }
        if (g < 0) continue;  // blue with no green (or green-brown) rim above: not a pond
        const StageGroup& sg = stage.groups[static_cast<std::size_t>(g)];
        const double top = sg.base + sg.height;
        StageBox floor;
        floor.kind = StageBox::Kind::PondFloor;
        floor.group = g;
        floor.min = {c0, std::min(sg.base, top - depth), rFirstBrown + top};
        floor.max = {c1 + 1, top - depth, rLast + 1 + top};
        stage.boxes.push_back(floor);
    }

    // Houses: a red run over a beige run; on green ground the house takes that group's top.
    for (const House& found : houses) {
        const cv::Rect roof = found.roof, body = found.body;
        double base = 0.0;
        for (int c = body.x; c < body.x + body.width; ++c) {
            const int g = groupAt(c, body.y + body.height);
            if (g >= 0) base = std::max(base, stage.groups[static_cast<std::size_t>(g)].base + stage.groups[static_cast<std::size_t>(g)].height);
        }
        const double nhRed = roof.height;
        const double front = body.y + body.height + base;
        StageBox house;
        house.kind = StageBox::Kind::House;
        house.min = {body.x, base, front - nhRed};
        house.max = {body.x + body.width, base + body.height, front};
        stage.boxes.push_back(house);
        StageRoof prism;
        prism.min = {roof.x, house.max.y, front - nhRed};
        prism.max = {roof.x + roof.width, house.max.y + nhRed / std::sqrt(2.0), front};
        stage.roofs.push_back(prism);
    }
    return stage;
}

namespace {
// Palette texture columns (RGB): green, brown, blue, red, beige.
constexpr int kPalette[5][3] = {{96, 172, 72}, {140, 92, 52}, {64, 124, 220}, {200, 64, 52}, {232, 212, 172}};
enum PaletteIndex { kGreen, kBrown, kBlue, kRed, kBeige };
}  // namespace

Mesh stageMesh(const Stage& stage, double tileMm, cv::Mat& palette) {
    palette = cv::Mat(1, 5, CV_8UC3);
    for (int i = 0; i < 5; ++i)
        palette.at<cv::Vec3b>(0, i) = cv::Vec3b(static_cast<uchar>(kPalette[i][2]), static_cast<uchar>(kPalette[i][1]),
                                                static_cast<uchar>(kPalette[i][0]));
    Mesh mesh;
    glm::dvec3 lo(1e30), hi(-1e30);
    for (const StageBox& b : stage.boxes) {
        lo = glm::min(lo, b.min);
        hi = glm::max(hi, b.max);
    }
    for (const StageRoof& r : stage.roofs) {
        lo = glm::min(lo, r.min);
        hi = glm::max(hi, r.max);
    }
    const glm::dvec3 centre = stage.boxes.empty() ? glm::dvec3(0.0) : glm::dvec3((lo.x + hi.x) / 2, 0.0, (lo.z + hi.z) / 2);
    auto put = [&](glm::dvec3 p) { return (p - centre) * tileMm; };
    auto uv = [](int colour) { return glm::dvec2((colour + 0.5) / 5.0, 0.5); };
    // A planar polygon (3 or 4 corners, counter-clockwise seen from outside); degenerate faces are skipped.
    auto face = [&](std::initializer_list<glm::dvec3> corners, int colour) {
        std::vector<glm::dvec3> c(corners);
        if (glm::length(glm::cross(c[1] - c[0], c[2] - c[0])) < 1e-12) return;
        const auto first = static_cast<unsigned>(mesh.positions.size());
        for (const glm::dvec3& p : c) {
            mesh.positions.push_back(put(p));
            mesh.uvs.push_back(uv(colour));
        }
        for (unsigned k = 1; k + 1 < c.size(); ++k) mesh.triangles.emplace_back(first, first + k, first + k + 1);
    };
    for (const StageBox& b : stage.boxes) {
        const int top = b.kind == StageBox::Kind::PondFloor ? kBlue : b.kind == StageBox::Kind::House ? kBeige : kGreen;
        const int side = b.kind == StageBox::Kind::House ? kBeige : kBrown;
        const glm::dvec3 a = b.min, z = b.max;
        face({{a.x, z.y, a.z}, {a.x, z.y, z.z}, {z.x, z.y, z.z}, {z.x, z.y, a.z}}, top);    // +y
        face({{a.x, a.y, a.z}, {z.x, a.y, a.z}, {z.x, a.y, z.z}, {a.x, a.y, z.z}}, side);   // -y
        face({{a.x, a.y, z.z}, {z.x, a.y, z.z}, {z.x, z.y, z.z}, {a.x, z.y, z.z}}, side);   // +z (front)
        face({{z.x, a.y, a.z}, {a.x, a.y, a.z}, {a.x, z.y, a.z}, {z.x, z.y, a.z}}, side);   // -z
        face({{z.x, a.y, z.z}, {z.x, a.y, a.z}, {z.x, z.y, a.z}, {z.x, z.y, z.z}}, side);   // +x
        face({{a.x, a.y, a.z}, {a.x, a.y, z.z}, {a.x, z.y, z.z}, {a.x, z.y, a.z}}, side);   // -x
    }
    for (const StageRoof& r : stage.roofs) {
        const double zm = (r.min.z + r.max.z) / 2;
        const glm::dvec3 ridge0{r.min.x, r.max.y, zm}, ridge1{r.max.x, r.max.y, zm};
        face({{r.min.x, r.min.y, r.max.z}, {r.max.x, r.min.y, r.max.z}, ridge1, ridge0}, kRed);  // front slope
        face({{r.max.x, r.min.y, r.min.z}, {r.min.x, r.min.y, r.min.z}, ridge0, ridge1}, kRed);  // back slope
        face({{r.max.x, r.min.y, r.max.z}, {r.max.x, r.min.y, r.min.z}, ridge1}, kBeige);        // gable +x
        face({{r.min.x, r.min.y, r.min.z}, {r.min.x, r.min.y, r.max.z}, ridge0}, kBeige);        // gable -x
        face({{r.min.x, r.min.y, r.min.z}, {r.max.x, r.min.y, r.min.z}, {r.max.x, r.min.y, r.max.z},
              {r.min.x, r.min.y, r.max.z}}, kRed);  // underside
    }
    return mesh;
}

double blendR(double thetaDeg) {
    const double t = std::clamp(thetaDeg, -90.0, 90.0);
    const double a = std::abs(t);
    const double k = std::sqrt(2.0) - 1.0;
    if ((t >= 0.0 && t < 45.0) || t < -45.0) return k * a / 45.0 + 1.0;
    return k * (90.0 - a) / 45.0 + 1.0;  // 45 <= theta <= 90 and -45 <= theta < 0
}

glm::dmat4 blendTransform(double thetaDeg) {
    const glm::dvec3 xAxis(1.0, 0.0, 0.0);
    const glm::dmat4 toward = glm::rotate(glm::dmat4(1.0), glm::radians(45.0), xAxis);
    const glm::dmat4 back = glm::rotate(glm::dmat4(1.0), glm::radians(-45.0), xAxis);
    const glm::dmat4 stretch = glm::scale(glm::dmat4(1.0), glm::dvec3(1.0, blendR(thetaDeg), 1.0));
    // Applied to a point p as back * stretch * toward * p: rotate 45 degrees, scale y, rotate back.
    return back * stretch * toward;
}

}  // namespace avatarbooth::stage
