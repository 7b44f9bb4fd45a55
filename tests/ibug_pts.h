// The hand-placed 68 points of the iBUG / 300-W `.pts` files in the shared data (faces68), for the tests that
// compare landmarks with them.
#pragma once

#include <opencv2/core.hpp>

#include <array>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>

namespace avatarbooth::test {

// The points of a `.pts` file (1-based pixel coordinates) as 0-based (x, y); nothing when the file is missing or
// does not hold 68 points.
inline std::optional<std::array<cv::Point2d, 68>> readIbugPoints(const std::filesystem::path& file) {
    std::array<cv::Point2d, 68> p{};
    std::ifstream in(file);
    std::string line;
    std::size_t k = 0;
    bool inBlock = false;
    while (std::getline(in, line) && k < 68) {
        if (line.find('{') != std::string::npos) {
            inBlock = true;
            continue;
        }
        if (!inBlock) continue;
        std::istringstream s(line);
        double x = 0.0, y = 0.0;
        if (s >> x >> y) p[k++] = {x - 1.0, y - 1.0};
    }
    if (k != 68) return std::nullopt;
    return p;
}

}  // namespace avatarbooth::test
