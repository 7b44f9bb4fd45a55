// The hair part (hair_part.h).
#include "fit/parts/hair_part.h"

#include "common/booth_lights.h"
#include "common/error.h"
#include "common/landmark_names.h"
#include "common/smoothstep.h"
#include "fit/parts/avatar_parts.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <utility>
#include <string>
#include <vector>

namespace avatarbooth {

namespace {

// Landmark k's feature vertex on the fitted head.
const glm::dvec3& featureOn(const BaseHead& base, const Mesh& fittedHead, int k) {
    const auto it = base.frontFeatures.find(landmarkName(k));
    if (it == base.frontFeatures.end() || it->second >= fittedHead.positions.size())
        throw BoothError(ErrorKind::Internal, "hair part", "the base head has no feature vertex " + landmarkName(k));
    return fittedHead.positions[it->second];
}

}  // namespace

double jawTopDepth(const BaseHead& base, const Mesh& fittedHead) {
    return 0.5 * (featureOn(base, fittedHead, 0).z + featureOn(base, fittedHead, 16).z);
}

void keepFaceClear(Mesh& hair, const BaseHead& base, const Mesh& fittedHead, const FaceClearance& clearance) {
    double browY = featureOn(base, fittedHead, 17).y;
    for (int k = 18; k <= 26; ++k) browY = std::min(browY, featureOn(base, fittedHead, k).y);
    browY += std::max(clearance.above, 0.0);
    const double sideZ = jawTopDepth(base, fittedHead);
    for (glm::dvec3& p : hair.positions) {
        if (p.z <= sideZ) continue;
        // 0 from `ramp` over the brows up, 1 from the brows down, smooth between (no crease in a strand).
        const double t = std::clamp((browY + clearance.ramp - p.y) / clearance.ramp, 0.0, 1.0);
        // Ahead of the plane, depth is compressed into `depth` millimetres, keeping its order: the strands stay
        // layered as they were, not collapsed onto one flat wall.
        const double ahead = p.z - sideZ;
        const double kept = clearance.depth * (1.0 - std::exp(-ahead / clearance.depth));
        p.z -= smoothstep(t) * (ahead - kept);
    }
}

namespace {

// 1 where the photo shows hair (grown by `grow` pixels) or no person (it says nothing of hair there), 0 on the
// person's skin and clothes, blurred by `sigma` pixels.
cv::Mat hairOrUnknownShare(const cv::Mat& hair, const cv::Mat& person, int grow, double sigma) {
    cv::Mat keep;
    cv::dilate(hair, keep, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * grow + 1, 2 * grow + 1)));
    keep.setTo(255, person == 0);
    cv::Mat share;
    keep.convertTo(share, CV_32F, 1.0 / 255.0);
    cv::GaussianBlur(share, share, cv::Size(), sigma, sigma, cv::BORDER_REPLICATE);
    return share;
}

// The nearest of a set of points within `reach` of a query (a grid of reach-sized cells).
class NearestVertex {
public:
    NearestVertex(const std::vector<glm::dvec3>& points, double reach) : points_(points), reach_(reach) {
        for (std::uint32_t v = 0; v < points.size(); ++v) cells_[cellOf(points[v])].push_back(v);
    }
    std::optional<std::uint32_t> operator()(const glm::dvec3& p) const {
        const auto c = cellOf(p);
        std::optional<std::uint32_t> nearest;
        double best = reach_;
        for (int dx = -1; dx <= 1; ++dx)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dz = -1; dz <= 1; ++dz) {
                    const auto it = cells_.find({c[0] + dx, c[1] + dy, c[2] + dz});
                    if (it == cells_.end()) continue;
                    for (const auto v : it->second) {
                        const double d = glm::distance(p, points_[v]);
                        if (d <= best) best = d, nearest = v;
                    }
                }
        return nearest;
    }

private:
    std::array<int, 3> cellOf(const glm::dvec3& p) const {
        return {static_cast<int>(std::floor(p.x / reach_)), static_cast<int>(std::floor(p.y / reach_)),
                static_cast<int>(std::floor(p.z / reach_))};
    }
    const std::vector<glm::dvec3>& points_;
    double reach_;
    std::map<std::array<int, 3>, std::vector<std::uint32_t>> cells_;
};

// A CV_32F image's value at the pixel nearest `px`, or `beyond` outside the image.
double valueAt(const cv::Mat& image, const cv::Point2d& px, double beyond) {
    const int x = static_cast<int>(std::lround(px.x)), y = static_cast<int>(std::lround(px.y));
    if (x < 0 || y < 0 || x >= image.cols || y >= image.rows) return beyond;
    return static_cast<double>(image.at<float>(y, x));
}

}  // namespace

int trimShortHairToPhotos(Mesh& hair, const Mesh& fittedHead, const HairPhotoMasks& photos, const HairTrim& trim) {
    const auto checked = [](const cv::Mat& hairMask, const cv::Mat& person, const char* which) {
        if (hairMask.empty() || person.empty()) return false;
        if (hairMask.type() != CV_8U || person.type() != CV_8U || hairMask.size() != person.size())
            throw BoothError(ErrorKind::Internal, "hair part",
                             std::string("trimShortHairToPhotos: the ") + which + " photo's masks are not CV_8U of one size");
        return true;
    };
    if (!checked(photos.frontHair, photos.frontPerson, "front") || !checked(photos.sideHair, photos.sidePerson, "side") ||
        photos.front.mmPerPixel <= 0.0 || photos.side.mmPerPixel <= 0.0 || fittedHead.positions.empty())
        return 0;
    const auto shareOf = [&](const cv::Mat& h, const cv::Mat& person, const PhotoFrame& frame) {
        return hairOrUnknownShare(h, person, static_cast<int>(std::lround(trim.lenient / frame.mmPerPixel)),
                                  std::max(0.5, trim.spread / frame.mmPerPixel));
    };
    const cv::Mat frontShare = shareOf(photos.frontHair, photos.frontPerson, photos.front);
    const cv::Mat sideShare = shareOf(photos.sideHair, photos.sidePerson, photos.side);
    const std::vector<glm::dvec3> normals = fittedHead.vertexNormals();
    const NearestVertex nearestOnHead(fittedHead.positions, trim.reach);

    // Each hair vertex's share of skin round its spot on the head (0 for the crown and for hair hanging free).
    std::vector<double> skin(hair.positions.size(), 0.0);
    for (std::size_t i = 0; i < hair.positions.size(); ++i) {
        const auto spot = nearestOnHead(hair.positions[i]);
        if (!spot) continue;
        const glm::dvec3& q = fittedHead.positions[*spot];
        const glm::dvec3& n = normals[*spot];
        if (n.y > 0.85) continue;  // the crown: both photos see it edge-on
        // The photo that sees the spot most squarely, read a little inside its outline where it sees it edge-on.
        double share = 1.0;
        if (n.z > std::abs(n.x)) {
            const glm::dvec3 at = q - trim.inside * glm::dvec3(n.x, n.y, 0.0);
            share = valueAt(frontShare, photos.front.toPixel({at.x, at.y}), 1.0);
        } else {
            const glm::dvec3 at = q - trim.inside * glm::dvec3(0.0, n.y, n.z);
            share = valueAt(sideShare, photos.side.toPixel({at.z, at.y}), 1.0);
        }
        skin[i] = std::clamp((0.7 - share) / 0.4, 0.0, 1.0);  // from none at a share of 0.7 to all at 0.3
    }
    // Strands go with their neighbours along the hair's surface: a lone vertex kept among cut ones (a pixel of
    // shade taken for hair) stood out as a stray wisp.
    std::vector<std::vector<std::uint32_t>> neighbours(hair.positions.size());
    for (const glm::uvec3& t : hair.triangles)
        for (int k = 0; k < 3; ++k) {
            neighbours[t[k]].push_back(t[(k + 1) % 3]);
            neighbours[t[k]].push_back(t[(k + 2) % 3]);
        }
    for (int round = 0; round < trim.smoothRounds; ++round) {
        std::vector<double> next(skin.size());
        for (std::size_t i = 0; i < skin.size(); ++i) {
            double sum = skin[i];
            for (const auto j : neighbours[i]) sum += skin[j];
            next[i] = sum / static_cast<double>(neighbours[i].size() + 1);
        }
        skin.swap(next);
    }
    // A strand card (a small connected piece of the hair's mesh) that is cut at all goes whole: cut in part, its
    // rest stood out of the skin as slivers (FRMDB 003's fade).
    std::vector<std::uint32_t> piece(hair.positions.size());
    for (std::uint32_t i = 0; i < piece.size(); ++i) piece[i] = i;
    const auto root = [&](std::uint32_t i) {
        while (piece[i] != i) i = piece[i] = piece[piece[i]];
        return i;
    };
    for (const glm::uvec3& t : hair.triangles)
        for (int k = 1; k < 3; ++k) piece[root(t[k])] = root(t[0]);
    // And a card that reaches out of either photo's outline goes: short hair lies inside the outlines (the head fit
    // followed them, hair included), so a card out there stands where the photos show no hair (FRMDB 002's over the
    // nape and the temple, some hanging free of the head, where the trim above does not look).
    cv::Mat frontOff, sideOff;  // pixels off the person, to the nearest pixel on them
    cv::distanceTransform(photos.frontPerson == 0, frontOff, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    cv::distanceTransform(photos.sidePerson == 0, sideOff, cv::DIST_L2, cv::DIST_MASK_PRECISE);
    const auto outsideMm = [](const cv::Mat& off, const PhotoFrame& frame, const glm::dvec2& at) {
        return valueAt(off, frame.toPixel(at), std::numeric_limits<double>::infinity()) * frame.mmPerPixel;
    };
    struct PieceCut {
        int cut = 0, total = 0;
        bool outside = false;
    };
    std::map<std::uint32_t, PieceCut> cutOfPiece;
    for (std::uint32_t i = 0; i < hair.positions.size(); ++i) {
        PieceCut& c = cutOfPiece[root(i)];
        c.cut += skin[i] > trim.cut;
        ++c.total;
        const glm::dvec3& p = hair.positions[i];
        c.outside = c.outside || outsideMm(frontOff, photos.front, {p.x, p.y}) > trim.outside ||
                    outsideMm(sideOff, photos.side, {p.z, p.y}) > trim.outside;
    }
    std::vector<std::uint32_t> trimmed;
    for (std::uint32_t i = 0; i < hair.positions.size(); ++i) {
        const PieceCut& c = cutOfPiece[root(i)];
        if (skin[i] > trim.cut || (c.total <= trim.cardVertices && (c.cut > 0 || c.outside))) trimmed.push_back(i);
    }
    if (!trimmed.empty()) hair = withoutVertices(hair, trimmed);
    return static_cast<int>(trimmed.size());
}

int pullShortHairIntoOutlines(Mesh& hair, const Mesh& fittedHead, const HairPhotoMasks& photos, const HairPull& pull) {
    const auto usable = [](const cv::Mat& person) { return !person.empty() && person.type() == CV_8U; };
    if (!usable(photos.frontPerson) || !usable(photos.sidePerson) || photos.front.mmPerPixel <= 0.0 ||
        photos.side.mmPerPixel <= 0.0 || fittedHead.positions.empty())
        return 0;
    // Signed distances to each photo's outline, in millimetres, out of the person positive.
    const auto signedDistance = [](const cv::Mat& person, double mmPerPixel) {
        cv::Mat out, in;
        cv::distanceTransform(person == 0, out, cv::DIST_L2, cv::DIST_MASK_PRECISE);
        cv::distanceTransform(person != 0, in, cv::DIST_L2, cv::DIST_MASK_PRECISE);
        return cv::Mat((out - in) * mmPerPixel);
    };
    const cv::Mat frontDistance = signedDistance(photos.frontPerson, photos.front.mmPerPixel);
    const cv::Mat sideDistance = signedDistance(photos.sidePerson, photos.side.mmPerPixel);
    const std::vector<glm::dvec3> normals = fittedHead.vertexNormals();
    const NearestVertex nearestOnHead(fittedHead.positions, pull.reach);
    // How far along the normal a point is past where the view's outline (plus the margin) lies: its distance out
    // of it over the part of n in the view's plane (to first order; a spot the view sees edge-on moves it the most).
    const auto past = [&](const cv::Mat& distance, const PhotoFrame& frame, const glm::dvec2& at, const glm::dvec2& nInView) {
        const cv::Point2d px = frame.toPixel(at);
        if (px.x < -0.5 || px.y < -0.5 || px.x > distance.cols - 0.5 || px.y > distance.rows - 0.5)
            return std::numeric_limits<double>::infinity();
        cv::Mat sample;  // bilinear between pixel centres, the border replicated
        cv::getRectSubPix(distance, cv::Size(1, 1), cv::Point2f(static_cast<float>(px.x), static_cast<float>(px.y)), sample);
        const double d = sample.at<float>(0, 0);
        return (d - pull.margin) / std::max(glm::length(nInView), 0.3);
    };
    int moved = 0;
    for (glm::dvec3& p : hair.positions) {
        const auto spot = nearestOnHead(p);
        if (!spot) continue;
        const glm::dvec3& n = normals[*spot];
        const double offset = glm::dot(p - fittedHead.positions[*spot], n);
        const double beyond = std::max(past(frontDistance, photos.front, {p.x, p.y}, {n.x, n.y}),
                                       past(sideDistance, photos.side, {p.z, p.y}, {n.z, n.y}));
        // The offset the outline allows here, and the soft limit under it: offsets within `band` of it and past it
        // are compressed into the band (z' = a - b + b tanh((z - a + b) / b)), the haircut's layers in order.
        const double allowed = offset - beyond, b = pull.band;
        if (!std::isfinite(allowed) || offset <= allowed - b) continue;
        double wanted = allowed - b + b * std::tanh((offset - allowed + b) / b);
        wanted = std::max(wanted, std::min(offset, pull.minOffset));
        if (wanted >= offset) continue;
        p -= (offset - wanted) * n;
        moved += offset - wanted > 1.0;
    }
    return moved;
}

double foreheadShownMm(const cv::Mat& hair, const std::array<cv::Point2d, 68>& points, const PhotoFrame& front,
                       double margin) {
    if (hair.empty() || hair.type() != CV_8U || front.mmPerPixel <= 0.0) return 0.0;
    const int run = std::max(1, static_cast<int>(std::lround(2.0 / front.mmPerPixel)));
    // The middle brow points from left to right in the photo.
    const cv::Point2d& a = points[19].x <= points[24].x ? points[19] : points[24];
    const cv::Point2d& b = points[19].x <= points[24].x ? points[24] : points[19];
    const int x0 = static_cast<int>(std::lround(a.x)), x1 = static_cast<int>(std::lround(b.x));
    std::vector<double> shown;
    for (int x = std::max(x0, 0); x <= std::min(x1, hair.cols - 1); ++x) {
        // The brows' height at this column: the line between the middle brow points.
        const double t = x1 > x0 ? static_cast<double>(x - x0) / (x1 - x0) : 0.0;
        const int brow = static_cast<int>(std::lround(a.y + t * (b.y - a.y)));
        int inHair = 0;
        for (int y = std::min(brow, hair.rows - 1); y >= 0; --y) {
            inHair = hair.at<std::uint8_t>(y, x) ? inHair + 1 : 0;
            if (inHair == run) {
                shown.push_back((brow - (y + run - 1)) * front.mmPerPixel);
                break;
            }
        }
    }
    // Most columns must find a hairline: a bald or shaven crown has none, and then nothing is said.
    if (shown.size() * 2 < static_cast<std::size_t>(std::max(x1 - x0 + 1, 1))) return 0.0;
    std::nth_element(shown.begin(), shown.begin() + static_cast<std::ptrdiff_t>(shown.size() / 2), shown.end());
    return std::max(0.0, shown[shown.size() / 2] - margin);
}

namespace {

// The side-on maps tuckEarsUnderHair works on: per side (+x, -x), a value per cell of `cell` mm over a window in
// z (columns, from behind to ahead) and y (rows, from below).
struct SideMaps {
    double z0, y0, cell;
    int cols, rows;
    std::array<cv::Mat, 2> map;  // CV_64F

    SideMaps(double z0_, double z1, double y0_, double y1, double cell_, double fill)
        : z0(z0_), y0(y0_), cell(cell_), cols(static_cast<int>(std::ceil((z1 - z0_) / cell_))),
          rows(static_cast<int>(std::ceil((y1 - y0_) / cell_))) {
        for (cv::Mat& m : map) m = cv::Mat(rows, cols, CV_64F, cv::Scalar(fill));
    }
    // Each cell's centre a triangle covers seen from the side, with the triangle's |x| there (triangles across the
    // middle are over the crown, the face or the nape, not beside an ear).
    template <class Visit>
    void rasterise(const Mesh& mesh, Visit visit) {
        for (const glm::uvec3& t : mesh.triangles) {
            const glm::dvec3& a = mesh.positions[t[0]];
            const glm::dvec3& b = mesh.positions[t[1]];
            const glm::dvec3& c = mesh.positions[t[2]];
            if ((a.x > 0.0) != (b.x > 0.0) || (a.x > 0.0) != (c.x > 0.0)) continue;
            const int side = a.x > 0.0 ? 0 : 1;
            const double det = (b.z - a.z) * (c.y - a.y) - (c.z - a.z) * (b.y - a.y);
            if (std::abs(det) < 1e-12) continue;  // edge-on from the side: its neighbours cover it
            const int c0 = std::max(0, static_cast<int>(std::floor((std::min({a.z, b.z, c.z}) - z0) / cell)));
            const int c1 = std::min(cols - 1, static_cast<int>(std::floor((std::max({a.z, b.z, c.z}) - z0) / cell)));
            const int r0 = std::max(0, static_cast<int>(std::floor((std::min({a.y, b.y, c.y}) - y0) / cell)));
            const int r1 = std::min(rows - 1, static_cast<int>(std::floor((std::max({a.y, b.y, c.y}) - y0) / cell)));
            for (int r = r0; r <= r1; ++r)
                for (int col = c0; col <= c1; ++col) {
                    const double z = z0 + (col + 0.5) * cell, y = y0 + (r + 0.5) * cell;
                    const double u = ((z - a.z) * (c.y - a.y) - (c.z - a.z) * (y - a.y)) / det;
                    const double v = ((b.z - a.z) * (y - a.y) - (z - a.z) * (b.y - a.y)) / det;
                    if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
                    visit(side, r, col, std::abs(a.x + u * (b.x - a.x) + v * (c.x - a.x)));
                }
        }
    }
    // The cell holding (z, y), or nothing outside the window.
    std::optional<std::pair<int, int>> cellOf(double z, double y) const {
        const int col = static_cast<int>(std::floor((z - z0) / cell)), r = static_cast<int>(std::floor((y - y0) / cell));
        if (col < 0 || col >= cols || r < 0 || r >= rows) return std::nullopt;
        return std::pair{r, col};
    }
};

}  // namespace

int tuckEarsUnderHair(Mesh& head, const Mesh& hair, double jawZ, const EarTuck& tuck) {
    const double z0 = -tuck.behind, z1 = std::min(tuck.ahead, jawZ), y0 = -tuck.below, y1 = tuck.above;
    if (z1 <= z0 || tuck.cell <= 0.0) return 0;
    const double inf = std::numeric_limits<double>::infinity();
    // The side of the head without its ears: the head's outermost |x| over each cell, opened (a minimum, then a
    // maximum over a disc wider than an ear), on a map reaching past the window so that the disc finds the head
    // round the ear everywhere in it.
    const double reach = tuck.skullOpening;
    SideMaps skull(z0 - reach, z1 + reach, y0 - reach, y1 + reach, tuck.cell, 0.0);
    skull.rasterise(head, [&](int side, int r, int col, double x) {
        double& m = skull.map[static_cast<std::size_t>(side)].at<double>(r, col);
        m = std::max(m, x);
    });
    const int radius = static_cast<int>(std::lround(reach / tuck.cell));
    const cv::Mat disc = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * radius + 1, 2 * radius + 1));
    for (cv::Mat& m : skull.map) {
        m.setTo(inf, m == 0.0);  // no head seen there: leave it out of the minimum
        // In single precision (a micrometre is plenty), which OpenCV's morphology runs several times faster with
        // a disc this wide (README, "How near the fit comes", speed).
        cv::Mat single;
        m.convertTo(single, CV_32F);
        cv::morphologyEx(single, single, cv::MORPH_OPEN, disc);
        single.convertTo(m, CV_64F);
        m.setTo(0.0, m == inf);
    }
    // The hair's innermost |x| over each cell, of the hair that lies outside the skull or nearly: MakeHuman's bob02
    // has layers deep inside the fitted head beside the ears (20-30 mm under the skin on FRMDB 008), which no one
    // sees, and the head pressed in under them showed as a dent down the cheek.
    SideMaps inner(z0, z1, y0, y1, tuck.cell, inf);
    inner.rasterise(hair, [&](int side, int r, int col, double x) {
        const double z = z0 + (col + 0.5) * tuck.cell, y = y0 + (r + 0.5) * tuck.cell;
        const auto s = skull.cellOf(z, y);
        if (s && x < skull.map[static_cast<std::size_t>(side)].at<double>(s->first, s->second) - tuck.hiddenDepth) return;
        double& m = inner.map[static_cast<std::size_t>(side)].at<double>(r, col);
        m = std::min(m, x);
    });
    int moved = 0;
    for (glm::dvec3& p : head.positions) {
        if (p.z < z0 || p.z >= z1 || p.y < y0 || p.y >= y1) continue;
        const auto c = inner.cellOf(p.z, p.y);
        const auto s = skull.cellOf(p.z, p.y);
        if (!c || !s) continue;
        const std::size_t side = p.x > 0.0 ? 0 : 1;
        const double limit = inner.map[side].at<double>(c->first, c->second) - tuck.clearance;
        if (std::abs(p.x) <= limit || limit <= 0.0) continue;  // under the hair already, or no hair over it
        // Only what stands out of the head's side (the ear) goes under the hair; the side itself stays.
        const double to = std::max(limit, std::min(std::abs(p.x), skull.map[side].at<double>(s->first, s->second)));
        if (to >= std::abs(p.x)) continue;
        p.x = std::copysign(to, p.x);
        ++moved;
    }
    return moved;
}

namespace {

// The run of mask pixels along `row` that holds column `through` (or the nearest run to it), as [first, last]
// columns; nothing when the row is empty or outside the mask.
std::optional<std::pair<int, int>> runThrough(const cv::Mat& mask, int row, int through) {
    if (row < 0 || row >= mask.rows) return std::nullopt;
    const auto* m = mask.ptr<std::uint8_t>(row);
    through = std::clamp(through, 0, mask.cols - 1);
    int at = -1;
    for (int d = 0; d < mask.cols && at < 0; ++d) {
        if (through - d >= 0 && m[through - d]) at = through - d;
        else if (through + d < mask.cols && m[through + d]) at = through + d;
    }
    if (at < 0) return std::nullopt;
    int first = at, last = at;
    while (first > 0 && m[first - 1]) --first;
    while (last + 1 < mask.cols && m[last + 1]) ++last;
    return std::pair{first, last};
}

// Where a mesh crosses the plane at height y, its extreme +x, -x and -z (NaN when it does not cross it).
std::array<double, 3> sliceExtent(const Mesh& mesh, double y) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    std::array<double, 3> e{nan, nan, nan};
    const auto add = [&](const glm::dvec3& p) {
        if (std::isnan(e[0])) e = {p.x, p.x, p.z};
        else e = {std::max(e[0], p.x), std::min(e[1], p.x), std::min(e[2], p.z)};
    };
    for (const glm::uvec3& t : mesh.triangles)
        for (int i = 0; i < 3; ++i) {
            const glm::dvec3& a = mesh.positions[t[i]];
            const glm::dvec3& b = mesh.positions[t[(i + 1) % 3]];
            if ((a.y - y) * (b.y - y) > 0.0 || a.y == b.y) continue;
            add(a + (b - a) * ((y - a.y) / (b.y - a.y)));
        }
    return e;
}

// The stretch that takes hair reaching `avatar` beyond a head edge at `head` to `photo` (all along one direction,
// outwards positive); NaN where the hair does not stand out.
double stretchTo(double head, double avatar, double photo, const HairSilhouetteFit& o) {
    if (!(avatar - head > o.stands)) return std::numeric_limits<double>::quiet_NaN();
    return std::clamp((photo - head) / (avatar - head), o.minStretch, o.maxStretch);
}

}  // namespace

std::vector<HairStretch> fitHairToSilhouettes(Mesh& hair, const Mesh& fittedHead, const PhotoFrame& front,
                                              const cv::Mat& frontMask, const PhotoFrame& side, const cv::Mat& sideMask,
                                              double chinY, const HairSilhouetteFit& o) {
    if (frontMask.empty() || sideMask.empty() || frontMask.type() != CV_8U || sideMask.type() != CV_8U)
        throw BoothError(ErrorKind::Internal, "hair part", "fitting the hair to the silhouettes needs both 8-bit masks");
    glm::dvec3 lo, hi;
    fittedHead.bounds(lo, hi);
    double top = hi.y;
    for (const glm::dvec3& p : hair.positions) top = std::max(top, p.y);
    const int bands = std::max(1, static_cast<int>(std::ceil((top - chinY) / o.band)));
    const double nan = std::numeric_limits<double>::quiet_NaN();
    // Per band: the head's edges (+x, -x, back), the avatar's (head and hair), the stretches.
    struct Band {
        double headPlus = -1e9, headMinus = 1e9, headBack = 1e9;
        double plus = -1e9, minus = 1e9, back = 1e9;
        double k[3] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                       std::numeric_limits<double>::quiet_NaN()};
    };
    std::vector<Band> b(static_cast<std::size_t>(bands));
    for (int i = 0; i < bands; ++i) {
        Band& x = b[static_cast<std::size_t>(i)];
        const double y = chinY + (i + 0.5) * o.band;
        const auto head = sliceExtent(fittedHead, y), strands = sliceExtent(hair, y);
        if (!std::isnan(head[0])) x.headPlus = head[0], x.headMinus = head[1], x.headBack = head[2];
        x.plus = x.headPlus, x.minus = x.headMinus, x.back = x.headBack;
        if (!std::isnan(strands[0]))
            x.plus = std::max(x.plus, strands[0]), x.minus = std::min(x.minus, strands[1]), x.back = std::min(x.back, strands[2]);
    }
    const double midZ = 0.5 * (lo.z + hi.z);
    for (int i = 0; i < bands; ++i) {
        Band& x = b[static_cast<std::size_t>(i)];
        if (x.headPlus < x.headMinus) continue;  // the head's slice is empty here (over the skull: the hair's crown)
        const double y = chinY + (i + 0.5) * o.band;
        const cv::Point2d f = front.toPixel({0.0, y});
        if (const auto run = runThrough(frontMask, static_cast<int>(std::lround(f.y)), static_cast<int>(std::lround(f.x)))) {
            double a = front.toHead({static_cast<double>(run->first), f.y}).x, c = front.toHead({static_cast<double>(run->second), f.y}).x;
            if (a > c) std::swap(a, c);
            x.k[0] = stretchTo(x.headPlus, x.plus, c, o);
            x.k[1] = stretchTo(-x.headMinus, -x.minus, -a, o);
        }
        if (!o.behind) continue;
        const cv::Point2d s = side.toPixel({midZ, y});
        if (const auto run = runThrough(sideMask, static_cast<int>(std::lround(s.y)), static_cast<int>(std::lround(s.x)))) {
            const double a = side.toHead({static_cast<double>(run->first), s.y}).x, c = side.toHead({static_cast<double>(run->second), s.y}).x;
            x.k[2] = stretchTo(-x.headBack, -x.back, -std::min(a, c), o);
        }
    }
    // Smoothed along the height (a Gaussian over the bands that measured a stretch), and the head's edges with it.
    const double sigma = o.smooth / o.band;
    const int reach = static_cast<int>(std::ceil(3.0 * sigma));
    std::vector<HairStretch> out(static_cast<std::size_t>(bands));
    std::vector<std::array<double, 3>> edge(static_cast<std::size_t>(bands));
    for (int i = 0; i < bands; ++i) {
        std::array<double, 3> k{}, kw{}, e{}, ew{};
        for (int j = std::max(0, i - reach); j <= std::min(bands - 1, i + reach); ++j) {
            const Band& x = b[static_cast<std::size_t>(j)];
            const double w = std::exp(-0.5 * (j - i) * (j - i) / (sigma * sigma));
            const double edges[3] = {x.headPlus, -x.headMinus, -x.headBack};
            for (int c = 0; c < 3; ++c) {
                if (!std::isnan(x.k[c])) k[c] += w * x.k[c], kw[c] += w;
                if (x.headPlus >= x.headMinus) e[c] += w * edges[c], ew[c] += w;
            }
        }
        HairStretch& h = out[static_cast<std::size_t>(i)];
        h.y = chinY + (i + 0.5) * o.band;
        // Over the skull's top the head's slices shrink to nothing and their edges say little: the stretch fades out
        // over the top `crown` millimetres of the head (stretched there, the crown's hair sank under the scalp).
        const double u = std::clamp((hi.y - h.y - o.crown * 0.25) / (o.crown * 0.75), 0.0, 1.0);
        const double fade = smoothstep(u);
        double* ks[3] = {&h.plusX, &h.minusX, &h.back};
        for (int c = 0; c < 3; ++c) {
            *ks[c] = 1.0 + fade * ((kw[c] > 1e-6 ? k[c] / kw[c] : 1.0) - 1.0);
            edge[static_cast<std::size_t>(i)][static_cast<std::size_t>(c)] = ew[c] > 1e-6 ? e[c] / ew[c] : nan;
        }
    }
    // Bands over the head's top have no edge: they keep the top-most edge below them.
    for (std::size_t i = 1; i < edge.size(); ++i)
        for (std::size_t c = 0; c < 3; ++c)
            if (std::isnan(edge[i][c])) edge[i][c] = edge[i - 1][c];
    for (glm::dvec3& p : hair.positions) {
        const double t = std::clamp((p.y - chinY) / o.band - 0.5, 0.0, static_cast<double>(bands - 1));
        const std::size_t i = static_cast<std::size_t>(std::floor(t));
        const std::size_t j = std::min(i + 1, out.size() - 1);
        const double f = t - static_cast<double>(i);
        const auto lerp = [&](double a, double c) { return a + f * (c - a); };
        const double k[3] = {lerp(out[i].plusX, out[j].plusX), lerp(out[i].minusX, out[j].minusX), lerp(out[i].back, out[j].back)};
        double e[3];
        for (std::size_t c = 0; c < 3; ++c) e[c] = lerp(edge[i][c], edge[j][c]);
        if (std::isnan(e[0])) continue;
        // Outwards along +x, -x and -z: beyond the head's edge the hair's distance from it is scaled.
        if (p.x > e[0]) p.x = e[0] + k[0] * (p.x - e[0]);
        if (-p.x > e[1]) p.x = -(e[1] + k[1] * (-p.x - e[1]));
        if (-p.z > e[2]) p.z = -(e[2] + k[2] * (-p.z - e[2]));
    }
    return out;
}

HairLength fitHairLengthBehind(Mesh& hair, const Mesh& fittedHead, const PhotoFrame& side, const cv::Mat& sideHair,
                               double jawZ, const HairLengthFit& o) {
    HairLength out;
    if (sideHair.empty() || sideHair.type() != CV_8U || hair.positions.empty() || fittedHead.positions.empty() ||
        o.step <= 0.0 || side.mmPerPixel <= 0.0)
        return out;
    glm::dvec3 headLo, headHi;
    fittedHead.bounds(headLo, headHi);
    // The band behind the head: from the hair part's back to behindZ; the hair part's lowest point in it.
    double back = std::numeric_limits<double>::infinity(), avatarBottom = std::numeric_limits<double>::infinity();
    for (const glm::dvec3& p : hair.positions)
        if (p.z < o.behindZ) back = std::min(back, p.z), avatarBottom = std::min(avatarBottom, p.y);
    if (!std::isfinite(back) || avatarBottom >= 0.0) return out;
    // The photo's hair, height by height down from the ear holes: the share of the band that is hair.
    const auto share = [&](double y) {
        int hairy = 0, read = 0;
        for (double z = back; z <= o.behindZ; z += o.step) {
            const cv::Point2d px = side.toPixel({z, y});
            const int c = static_cast<int>(std::lround(px.x)), r = static_cast<int>(std::lround(px.y));
            if (c < 0 || r < 0 || c >= sideHair.cols || r >= sideHair.rows) continue;
            ++read;
            hairy += sideHair.at<std::uint8_t>(r, c) != 0;
        }
        return read > 0 ? static_cast<double>(hairy) / read : 0.0;
    };
    double photoBottom = std::numeric_limits<double>::quiet_NaN();
    for (double y = 0.0, sinceHair = 0.0; y >= headLo.y - o.gap && sinceHair < o.gap; y -= o.step) {
        if (share(y) >= o.rowShare) {
            photoBottom = y;
            sinceHair = 0.0;
        } else {
            sinceHair += o.step;
        }
    }
    if (std::isnan(photoBottom)) return out;  // no hair behind the head under the ear holes (or none read)
    out.measured = true;
    out.photoBottom = std::max(photoBottom, headLo.y);
    out.avatarBottom = avatarBottom;
    out.factor = std::clamp(out.photoBottom / avatarBottom, o.minFactor, o.maxFactor);
    if (out.factor == 1.0) return out;
    const double fade = std::max(jawZ - o.behindZ, 1e-6);
    for (glm::dvec3& p : hair.positions) {
        if (p.y >= 0.0) continue;
        const double t = std::clamp((jawZ - p.z) / fade, 0.0, 1.0);  // 1 behind behindZ, 0 from the jaw's top on
        p.y *= 1.0 + (out.factor - 1.0) * smoothstep(t);
    }
    return out;
}

int tuckHairBehindTheFace(Mesh& hair, const PhotoFrame& side, const cv::Mat& sideHair, const SideFaceClearance& o) {
    if (sideHair.empty() || hair.positions.empty() || o.step <= 0.0 || side.mmPerPixel <= 0.0 || o.topY <= o.bottomY)
        return 0;
    if (sideHair.type() != CV_8U)
        throw BoothError(ErrorKind::Internal, "", "tuckHairBehindTheFace: the side photo's hair pixels are not 8-bit");
    glm::dvec3 lo, hi;
    hair.bounds(lo, hi);
    // The photo's hair edge, height by height: going back from frontZ, where the first run of hair begins.
    const int rows = static_cast<int>(std::floor((o.topY - o.bottomY) / o.step)) + 1;
    std::vector<double> edge(static_cast<std::size_t>(rows), std::numeric_limits<double>::quiet_NaN());
    const int runSteps = std::max(1, static_cast<int>(std::lround(o.run / o.step)));
    for (int i = 0; i < rows; ++i) {
        const double y = o.bottomY + i * o.step;
        int inRun = 0;
        for (double z = o.frontZ; z >= lo.z; z -= o.step) {
            inRun = inMask(sideHair, side.toPixel({z, y})) ? inRun + 1 : 0;
            if (inRun == runSteps) {
                edge[static_cast<std::size_t>(i)] = z + (runSteps - 1) * o.step;
                break;
            }
        }
    }
    // Smoothed along the height over the rows that show hair (a Gaussian's weights, renormalised).
    std::vector<double> smooth(edge.size(), std::numeric_limits<double>::quiet_NaN());
    const int reach = static_cast<int>(std::ceil(3.0 * o.smooth / o.step));
    for (int i = 0; i < rows; ++i) {
        if (std::isnan(edge[static_cast<std::size_t>(i)])) continue;
        double sum = 0.0, weights = 0.0;
        for (int j = std::max(0, i - reach); j <= std::min(rows - 1, i + reach); ++j) {
            const double e = edge[static_cast<std::size_t>(j)];
            if (std::isnan(e)) continue;
            const double d = (j - i) * o.step / std::max(o.smooth, 1e-6);
            const double w = std::exp(-0.5 * d * d);
            sum += w * e;
            weights += w;
        }
        smooth[static_cast<std::size_t>(i)] = sum / weights;
    }
    const double band = std::max(o.band, 1e-6);
    int moved = 0;
    for (glm::dvec3& p : hair.positions) {
        const double sideways = smoothstep((std::abs(p.x) - o.innerX) / std::max(o.sideRamp, 1e-6));
        if (sideways <= 0.0 || p.y < o.bottomY || p.y > o.topY) continue;
        const double e = smooth[static_cast<std::size_t>(std::clamp(static_cast<int>(std::lround((p.y - o.bottomY) / o.step)), 0, rows - 1))] - o.margin;
        if (std::isnan(e) || p.z <= e - band) continue;
        const double ends = std::min(p.y - o.bottomY, o.topY - p.y) / std::max(o.ramp, 1e-6);
        const double tucked = e - band + band * std::tanh((p.z - e + band) / band);
        const double z = p.z + sideways * smoothstep(ends) * (tucked - p.z);
        if (p.z - z > 1.0) ++moved;
        p.z = z;
    }
    return moved;
}

const char* hairProxyName(HairStyle style) {
    switch (style) {
        case HairStyle::None: return nullptr;
        case HairStyle::Short: return "short04";
        case HairStyle::Bob: return "bob02";
        case HairStyle::Long: return "long01";
        case HairStyle::Ponytail: return "ponytail01";
    }
    return nullptr;
}

bool isHairStyleProxy(const HeadProxy& proxy) { return proxy.name == "hair"; }

const HeadProxy* findHairProxy(const BaseHead& base, std::string_view proxyName) {
    const std::string source = "proxies/hair/" + std::string(proxyName);
    for (const HeadProxy& p : base.proxies)
        if (isHairStyleProxy(p) && p.source == source) return &p;
    return nullptr;
}

cv::Vec3d hairPaint(const cv::Vec3d& seen) {
    const double light = booth_lights::meanLightSeenOnSphere();
    return {std::min(255.0, seen[0] / light), std::min(255.0, seen[1] / light), std::min(255.0, seen[2] / light)};
}

std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, const HairEstimate& hair) {
    const char* name = hairProxyName(hair.style);
    return name == nullptr ? std::nullopt : placeHairPart(base, fittedHead, name, hairPaint(hair.colour));
}

std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, std::string_view proxyName,
                                        const cv::Vec3d& colour) {
    const HeadProxy* proxy = findHairProxy(base, proxyName);
    if (proxy == nullptr) return std::nullopt;
    // The avatar is a bust cut under the chin: long hair ends where the neck does, not in the air at waist height
    // (which also made every preview frame a head a third of its size).
    glm::dvec3 lo, hi;
    fittedHead.bounds(lo, hi);
    return placeProxyPart(*proxy, fittedHead, &colour, lo.y);
}

}  // namespace avatarbooth
