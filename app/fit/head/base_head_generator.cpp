// The built-in base head, made by code.
//
// How it is made: the head is an implicit solid, a smooth union (polynomial smooth-min) of ellipsoids —
// cranium, face mass, chin, brow ridge, cheeks, nose bridge and tip, alae, lips, eyeballs, ears, a neck —
// with the eye sockets carved out by a smooth difference. Its surface is sampled on a latitude/longitude grid
// of rays from a centre inside the head (the outermost crossing of each ray, refined by bisection), which
// gives a closed mesh whose UVs are the grid itself: u = longitude (seam at the back of the head), v = latitude,
// so the texture covers the whole head including ears, back and neck. The grid is denser around the face
// (cubic spacing), where the features and the texture detail are.
//
// Feature vertices: the 68 iBUG landmarks are designed as front-view (x, y) positions of an average adult face
// (the table below, millimetres, eye line at y = 6); each is cast along -z onto the surface and takes the
// nearest vertex. Profile landmarks are placed likewise on the mid-sagittal line. Contour vertices are found on
// the mesh's own outlines (findContourVertices).
//
// How to make another: change the ellipsoids (proportions follow METHODS §5) or the landmark table and run
// `avatarbooth make-base-head -o DIR`, which writes base_head.glb and base_head.features.json; or model a head in
// any tool, export a glb with UVs and write a feature file in the same format by hand; point the config's
// [head] base_mesh / base_features at them.
#include "fit/head/base_head.h"
#include "common/landmark_names.h"
#include "fit/head/head_views.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <memory>

namespace avatarbooth {
namespace {

constexpr double kPi = 3.14159265358979323846;

double smoothMin(double a, double b, double k) {
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

double smoothMax(double a, double b, double k) { return -smoothMin(-a, -b, k); }

// Approximate signed distance to an axis-aligned ellipsoid (exact on the axes; good enough for smooth unions).
double ellipsoid(const glm::dvec3& p, const glm::dvec3& centre, const glm::dvec3& radii) {
    const glm::dvec3 q = p - centre;
    const double k0 = glm::length(q / radii);
    const double k1 = glm::length(q / (radii * radii));
    if (k1 < 1e-12) return -std::min({radii.x, radii.y, radii.z});
    return k0 * (k0 - 1.0) / k1;
}

// Signed distance to a capsule: the segment a-b thickened by radius r.
double capsule(const glm::dvec3& p, const glm::dvec3& a, const glm::dvec3& b, double r) {
    const glm::dvec3 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
    return glm::distance(p, a + t * ab) - r;
}

// A vertical elliptic cylinder from y0 to y1, rounded at the ends.
double neck(const glm::dvec3& p) {
    const glm::dvec3 c(0.0, 0.0, -12.0);
    const double rx = 52.0, rz = 55.0;
    const double k = std::sqrt(((p.x - c.x) / rx) * ((p.x - c.x) / rx) + ((p.z - c.z) / rz) * ((p.z - c.z) / rz));
    const double radial = (k - 1.0) * std::min(rx, rz);
    const double y0 = -175.0, y1 = -40.0;
    const double vertical = std::max(y0 - p.y, p.y - y1);
    return std::max(radial, vertical);
}

// The head solid: negative inside, positive outside (millimetres, origin between the ear holes).
double headField(const glm::dvec3& p) {
    const glm::dvec3 mirrored(std::abs(p.x), p.y, p.z);  // the head is symmetric: features on the +x side
    double d = ellipsoid(p, {0, 25, -5}, {76, 97, 97});                              // cranium
    d = smoothMin(d, ellipsoid(p, {0, -30, 22}, {63, 70, 68}), 15.0);               // face and jaw mass
    d = smoothMin(d, ellipsoid(p, {0, -88, 62}, {30, 24, 28}), 12.0);               // chin
    d = smoothMin(d, neck(p), 20.0);                                                 // neck
    d = smoothMin(d, ellipsoid(p, {0, 26, 76}, {58, 13, 20}), 10.0);                // brow ridge
    d = smoothMin(d, ellipsoid(mirrored, {40, -22, 58}, {26, 24, 26}), 12.0);       // cheeks
    d = smoothMin(d, capsule(p, {0, 4, 83}, {0, -29, 100}, 8.0), 5.0);             // nose bridge: straight, from below the nasion dip
    d = smoothMin(d, ellipsoid(p, {0, -33, 98}, {14, 11, 13}), 5.0);                // nose tip
    d = smoothMin(d, ellipsoid(mirrored, {13, -38, 88}, {8, 7, 8}), 4.0);           // alae (nostril wings)
    d = smoothMin(d, ellipsoid(p, {0, -57, 86}, {25, 7, 10}), 4.0);                 // upper lip
    d = smoothMin(d, ellipsoid(p, {0, -70, 84}, {22, 7, 10}), 4.0);                 // lower lip
    d = smoothMax(d, -ellipsoid(mirrored, {32, 8, 96}, {18, 12, 16}), 6.0);         // eye sockets
    d = smoothMin(d, ellipsoid(mirrored, {32, 6, 70}, {12.5, 12.5, 12.5}), 2.0);    // eyeballs
    d = smoothMin(d, ellipsoid(mirrored, {78, -5, -8}, {13, 31, 18}), 5.0);         // ears
    return d;
}

// Rays start here, inside the head, low enough that the neck and the underside of the nose are seen from it.
const glm::dvec3 kRayCentre(0.0, -20.0, 0.0);
constexpr double kMaxRay = 280.0;

// Distance along dir from origin to the outermost crossing of the surface: march inwards from outside the head
// to the first point inside (thinnest parts, the ears, are far thicker than the step), then bisect.
double outermostCrossing(const glm::dvec3& origin, const glm::dvec3& dir) {
    constexpr double step = 1.5;
    double t = kMaxRay;
    while (t > 0.0 && headField(origin + t * dir) >= 0.0) t -= step;
    if (t <= 0.0) throw std::logic_error("base head: ray never inside the head");
    double lo = t, hi = t + step;
    for (int i = 0; i < 30; ++i) {
        const double mid = 0.5 * (lo + hi);
        (headField(origin + mid * dir) < 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

// Grid spacing: s in [-1, 1] -> angle fraction, denser near 0 (the face).
double denseNearZero(double s, double linearShare) { return linearShare * s + (1.0 - linearShare) * s * s * s; }

constexpr int kColumns = 128;  // longitude steps
constexpr int kRows = 76;      // latitude steps (pole to pole)

// iBUG 68-point positions of the designed average face, front view (x to the subject's left, y up), mm.
// Index order as iBUG: jaw 0-16 (from the image's left), brows 17-26, nose 27-35, eyes 36-47, mouth 48-67.
constexpr std::array<std::array<double, 2>, 68> kLandmarkDesign = {{
    {-68, 5},   {-67, -15}, {-65, -35}, {-61, -55}, {-54, -73}, {-44, -88}, {-32, -100}, {-17, -108}, {0, -111},
    {17, -108}, {32, -100}, {44, -88},  {54, -73},  {61, -55},  {65, -35},  {67, -15},   {68, 5},
    {-52, 26},  {-43, 33},  {-32, 35},  {-21, 33},  {-11, 29},                                   // right brow
    {11, 29},   {21, 33},   {32, 35},   {43, 33},   {52, 26},                                    // left brow
    {0, 12},    {0, -4},    {0, -19},   {0, -33},                                                // nose bridge
    {-14, -41}, {-7, -44},  {0, -46},   {7, -44},   {14, -41},                                   // nostrils
    {-45, 6},   {-38, 11},  {-27, 11},  {-19, 5},   {-27, 1},   {-38, 1},                        // right eye
    {19, 5},    {27, 11},   {38, 11},   {45, 6},    {38, 1},    {27, 1},                         // left eye
    {-25, -64}, {-16, -58}, {-6, -55},  {0, -56},   {6, -55},   {16, -58},  {25, -64},           // upper lip
    {16, -71},  {7, -74},   {0, -75},   {-7, -74},  {-16, -71},                                  // lower lip
    {-21, -64}, {-8, -62},  {0, -62},   {8, -62},   {21, -64},  {8, -66},   {0, -66},  {-8, -66} // inner lips
}};

// Profile landmarks of the designed head: (y, z) on the mid-sagittal line where known by design; the rest are
// found on the outline (top_of_head, back_of_head: extremes).
struct ProfileDesign {
    const char* name;
    double y;
};
constexpr std::array<ProfileDesign, 9> kProfileDesign = {{
    {"forehead", 60},   {"glabella", 26},   {"nasion", 12},  {"nose_tip", -33}, {"subnasale", -46},
    {"upper_lip", -57}, {"lower_lip", -70}, {"chin", -96},   {"throat", -140},
}};

std::uint32_t nearestVertex(const Mesh& mesh, const glm::dvec3& p, const std::vector<bool>& taken) {
    std::uint32_t best = 0;
    double bestD = std::numeric_limits<double>::max();
    for (std::uint32_t i = 0; i < mesh.positions.size(); ++i) {
        if (taken[i]) continue;
        const double d = glm::distance(mesh.positions[i], p);
        if (d < bestD) {
            bestD = d;
            best = i;
        }
    }
    return best;
}

// The first surface point met by a ray along -view from far in front of the head.
glm::dvec3 castFromFront(double a, double b, View view) {
    const glm::dvec3 start = view == View::Front ? glm::dvec3(a, b, 250.0) : glm::dvec3(0.0, b, 250.0);
    const glm::dvec3 dir(0.0, 0.0, -1.0);
    double t = 0.0;
    while (t < 500.0 && headField(start + t * dir) > 0.0) t += 0.5;
    double lo = t - 0.5, hi = t;
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (headField(start + mid * dir) > 0.0 ? lo : hi) = mid;
    }
    return start + hi * dir;
}

BaseHead generate() {
    BaseHead head;
    Mesh& mesh = head.mesh;
    // Vertex (i, j): column i in [0, kColumns] (the last column repeats the first with u = 1: the UV seam at the
    // back), row j in [0, kRows] from the bottom pole (j = 0) to the top pole.
    for (int j = 0; j <= kRows; ++j) {
        const double s = 2.0 * j / kRows - 1.0;
        const double lat = 0.5 * kPi * denseNearZero(s, 0.6);
        for (int i = 0; i <= kColumns; ++i) {
            const double t = 2.0 * i / kColumns - 1.0;  // -1 .. 1, 0 = the face (+z)
            const double lon = kPi * denseNearZero(t, 0.55);
            glm::dvec3 dir(std::cos(lat) * std::sin(lon), std::sin(lat), std::cos(lat) * std::cos(lon));
            if (j == 0 || j == kRows) dir = glm::dvec3(0.0, j == 0 ? -1.0 : 1.0, 0.0);
            mesh.positions.push_back(kRayCentre + outermostCrossing(kRayCentre, dir) * dir);
            mesh.uvs.emplace_back(static_cast<double>(i) / kColumns, 1.0 - static_cast<double>(j) / kRows);
        }
    }
    const auto index = [](int i, int j) { return static_cast<std::uint32_t>(j * (kColumns + 1) + i); };
    for (int j = 0; j < kRows; ++j) {
        for (int i = 0; i < kColumns; ++i) {
            const std::uint32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1), d = index(i, j + 1);
            // Counter-clockwise from outside: longitude grows towards +x (the subject's left), latitude upwards.
            if (j != 0) mesh.triangles.emplace_back(a, b, c);
            if (j != kRows - 1) mesh.triangles.emplace_back(a, c, d);
        }
    }

    std::vector<bool> taken(mesh.positions.size(), false);
    // Pole and seam duplicates must never become feature vertices (their twins would stay behind).
    for (int j = 0; j <= kRows; ++j) taken[index(kColumns, j)] = true;
    for (int i = 0; i <= kColumns; ++i) taken[index(i, 0)] = taken[index(i, kRows)] = true;

    for (std::size_t k = 0; k < kLandmarkDesign.size(); ++k) {
        const glm::dvec3 surface = castFromFront(kLandmarkDesign[k][0], kLandmarkDesign[k][1], View::Front);
        const std::uint32_t v = nearestVertex(mesh, surface, taken);
        taken[v] = true;
        head.frontFeatures[landmarkName(static_cast<int>(k))] = v;
    }
    // Mid-sagittal vertices: column kColumns / 2 is longitude 0, i.e. x = 0.
    std::vector<bool> offMidline(mesh.positions.size(), true);
    for (int j = 1; j < kRows; ++j) offMidline[index(kColumns / 2, j)] = false;
    for (const auto& p : kProfileDesign)
        head.sideFeatures[p.name] = nearestVertex(mesh, castFromFront(0.0, p.y, View::Side), offMidline);
    head.sideFeatures["top_of_head"] = index(kColumns / 2, kRows - 1);
    // Back of the head: the midline vertex furthest back above the ears.
    std::uint32_t back = index(0, kRows / 2);  // column 0 is longitude -180 degrees: the back midline
    for (int j = kRows / 2; j < kRows; ++j)
        if (mesh.positions[index(0, j)].z < mesh.positions[back].z) back = index(0, j);
    head.sideFeatures["back_of_head"] = back;

    head.earHoleCentre = glm::dvec3(0.0);
    head.frontContour = findContourVertices(mesh, head.eyeMidpoint(), 0, defaultFrontContourAngles());
    head.sideContour = findContourVertices(mesh, head.earHoleCentre, 1, defaultSideContourAngles());
    return head;
}

}  // namespace

std::shared_ptr<const BaseHead> sharedBuiltinBaseHead() {
    static const std::shared_ptr<const BaseHead> head = std::make_shared<const BaseHead>(generate());
    return head;
}

const BaseHead& builtinBaseHead() { return *sharedBuiltinBaseHead(); }

}  // namespace avatarbooth
