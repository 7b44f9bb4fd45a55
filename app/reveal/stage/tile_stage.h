// Kitamura's top-down tile stage (METHODS §3.3): the tile-map text format, its 3-D boxes, houses, ponds, and R(theta).
#pragma once

#include "fit/head/mesh.h"

#include <glm/glm.hpp>
#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace avatarbooth::stage {

// One tile colour. The characters are those of the map file.
enum class Tile : char {
    Empty = '.',
    Green = 'g',  // top faces
    Brown = 'b',  // front faces
    Blue = 'w',   // ponds (water)
    Red = 'r',    // roofs
    Beige = 'e',  // house walls
};

// The map as the operator drew it. Text format (one map row per line, row 0 at the top, as seen top-down):
//   g green  b brown  w blue  r red  e beige  . empty      (one character per tile)
//   `|` between two tiles of a row: an edge mark between them (cuts their connection)
//   a line of only `-` and spaces between two tile rows: each `-` under a tile of the row above cuts that tile from
//     the one below it (the `-` must stand in the same character column as the tile)
//   `#` starts a comment (to the end of the line); blank lines are ignored; short rows are padded with empty tiles.
struct TileMap {
    int width = 0, height = 0;
    std::vector<Tile> tiles;             // row-major
    std::vector<unsigned char> cutRight;  // edge between (c, r) and (c + 1, r)
    std::vector<unsigned char> cutBelow;  // edge between (c, r) and (c, r + 1)

    Tile at(int c, int r) const;  // Empty outside the map
    bool edgeRight(int c, int r) const;
    bool edgeBelow(int c, int r) const;
};

// Parses the text format. Throws BoothError(BadConfig, "NAME:LINE:COLUMN", why) on an unknown character, a
// misplaced `|` or `-`, or a map with no tiles.
TileMap parseTileMap(std::string_view text, const std::string& sourceName = "tile map");
// Reads and parses a file (BoothError(BadInput) when it cannot be read).
TileMap loadTileMap(const std::filesystem::path& path);

// An axis-aligned box in tile units: x to the right (map columns), y up, z towards the viewer (down the map).
struct StageBox {
    enum class Kind { Ground, PondFloor, House };
    Kind kind = Kind::Ground;
    int group = -1;  // the green group it belongs to (-1 for houses)
    glm::dvec3 min{0.0}, max{0.0};
    bool operator==(const StageBox&) const = default;
};
// A house roof: a triangular prism along x over [min.x, max.x], base [min.z, max.z] at y = min.y, ridge at max.y.
struct StageRoof {
    glm::dvec3 min{0.0}, max{0.0};
};
// A group of connected green tiles and where it ended up.
struct StageGroup {
    int height = 0;     // tiles: the highest box's brown count
    double base = 0.0;  // tiles: the top of the group it sits on, 0 on the ground
    int sitsOn = -1;    // that group, or -1
};
struct Stage {
    std::vector<StageGroup> groups;
    std::vector<StageBox> boxes;
    std::vector<StageRoof> roofs;
};

// The generation rules of METHODS §3.3 (rules the seed leaves open are decided and written in tile_stage.cpp):
// groups of green tiles (edges cut them); per column, a box whose depth is its run of green tiles and whose own
// height is the brown run below it; a group's top is at its highest box; a group whose brown front ends on another
// group's green sits on it, unless that brown belongs to a brown group (brown tiles, cut by edges) that runs further
// down in the same front plane: then it is the rear face seen above a nearer group and reaches as low as the rest;
// tiles of a group sitting on this one, or of a house standing on it, that hide a gap in this one's columns are taken
// as this one's (occlusion completion, ground behind houses); green-brown-blue in a column is a pond as deep as its
// brown run, green-blue a pond level with the ground; a red run over a beige run is a house with a Nh_red / sqrt(2)
// roof.
Stage buildStage(const TileMap& map);

// The stage as a triangle mesh in millimetres (`tileMm` per tile, centred on x and z, ground at y = 0), coloured
// through `palette` (filled with a small texture of the tile colours; pass it to MeshRenderer::upload).
Mesh stageMesh(const Stage& stage, double tileMm, cv::Mat& palette);

// Kitamura's view-dependent stretch factor R(theta) (eq. 3.2), theta in degrees between the view vector and the
// ground, in [-90, 90] (values beyond are clamped): the two branches exactly as the seed gives them.
double blendR(double thetaDeg);
// The deformation to apply to the stage for a view at theta: rotate 45 degrees about X, scale Y by R(theta), rotate
// back by -45 degrees (a 4x4 to multiply stage positions by, about the origin).
glm::dmat4 blendTransform(double thetaDeg);

}  // namespace avatarbooth::stage
