// The MakeHuman synthetic visitor: the person drawn, the texture painted, the photos taken.
#include "sim/makehuman_visitor.h"

#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/face/profile.h"
#include "fit/head/modifier_basis.h"
#include "fit/head/surface_texels.h"
#include "fit/parts/hair_part.h"

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <random>
#include <set>

namespace avatarbooth {
namespace {

namespace fs = std::filesystem;

constexpr double kPi = 3.14159265358979323846;

using Rng = std::mt19937;

double uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }
bool chance(Rng& rng, double p) { return uniform(rng, 0.0, 1.0) < p; }
template <typename T>
const T& pick(Rng& rng, const std::vector<T>& items) {
    return items[std::uniform_int_distribution<std::size_t>(0, items.size() - 1)(rng)];
}

// A slider's modifiers share the name up to the last '-' ("nose/nose-trans-vert" for "-up" and "-down"; the head
// shapes "head/head-oval", "head/head-round", ... count as one slider), and the subject's left and right count as
// one (the right's name stands for both).
std::string sliderOf(const std::string& name) {
    std::string n = mirroredModifierName(name) < name ? mirroredModifierName(name) : name;
    const auto dash = n.rfind('-');
    return dash == std::string::npos ? n : n.substr(0, dash);
}

struct Colour {
    const char* name;
    cv::Vec3d bgr;
};

// Hair colours, and which are likely for whom (weights by ethnicity african, asian, caucasian; the old go grey).
struct HairColour {
    Colour colour;
    std::array<double, 3> likelihood;
};
const std::vector<HairColour>& hairColours() {
    static const std::vector<HairColour> colours = {
        {{"black", {18, 18, 22}}, {6, 6, 1}},
        {{"dark brown", {24, 34, 52}}, {2, 2, 3}},
        {{"brown", {34, 56, 88}}, {0.3, 0.5, 3}},
        {{"light brown", {62, 92, 132}}, {0, 0.2, 2}},
        {{"blond", {96, 152, 196}}, {0, 0.1, 1.5}},
        {{"red", {32, 66, 140}}, {0, 0, 0.6}},
    };
    return colours;
}
const std::vector<Colour>& greyHair() {
    static const std::vector<Colour> colours = {{"grey", {120, 122, 128}}, {"white", {196, 198, 204}},
                                                {"salt and pepper", {74, 76, 82}}};
    return colours;
}
const std::vector<HairColour>& irisColours() {
    static const std::vector<HairColour> colours = {
        {{"dark brown", {22, 34, 58}}, {6, 6, 2}},
        {{"brown", {32, 60, 100}}, {2, 2, 2}},
        {{"hazel", {46, 96, 118}}, {0, 0.2, 1}},
        {{"green", {70, 118, 86}}, {0, 0, 1}},
        {{"blue", {150, 112, 66}}, {0, 0, 2}},
        {{"grey", {128, 126, 114}}, {0, 0, 0.6}},
    };
    return colours;
}

const Colour& pickColour(Rng& rng, const std::vector<HairColour>& colours, int ethnicity) {
    double total = 0.0;
    for (const auto& c : colours) total += c.likelihood[static_cast<std::size_t>(ethnicity)];
    double at = uniform(rng, 0.0, total);
    for (const auto& c : colours) {
        at -= c.likelihood[static_cast<std::size_t>(ethnicity)];
        if (at <= 0.0) return c.colour;
    }
    return colours.back().colour;
}

// What the painter needs besides the skin: drawn with the person, from the same seed.
struct Look {
    cv::Vec3d hair{0, 0, 0}, brow{0, 0, 0}, iris{0, 0, 0};
    bool bald = false, balding = false;
    bool moustache = false, beard = false;  // painted: the upper lip; the chin and jaw
    cv::Vec3d beardColour{0, 0, 0};
    double hairlineFront = 108.0;  // height of the hairline over the forehead (head space, mm)
    double nape = -45.0;           // height of the hairline at the back
    double browWidth = 3.0;        // half-thickness of a brow stroke, mm
    cv::Scalar shirt{96, 110, 40};
    unsigned grainSeed = 1;
};

std::pair<MakeHumanPerson, Look> draw(const ModifierBasis& basis, unsigned seed) {
    Rng rng(seed * 2654435761u + 12345u);
    MakeHumanPerson p;
    Look look;
    look.grainSeed = seed;
    p.weights.assign(basis.modifiers.size(), 0.0);
    const auto set = [&](const std::string& name, double w) {
        const std::size_t k = basis.find(name);
        if (k == basis.modifiers.size())
            throw BoothError(ErrorKind::BadConfig, "modifier basis", "has no modifier '" + name + "' (is it MakeHuman's?)");
        p.weights[k] = std::clamp(w, 0.0, 1.0);
    };

    // --- Macro: sex, age, ethnicity, build. The default human is half male, 25 years, a third of each ethnicity,
    // average weight and muscle; a direction's weight 1 is the slider's end (male; 90 years; fully african; ...).
    // Sex, age group and ethnicity go round with the seed, so that any 18 seeds in a row hold every MakeHuman skin.
    const unsigned kind = seed % 18;
    const bool female = kind % 2 == 0;
    p.sex = female ? "female" : "male";
    set(female ? "macro/gender-female" : "macro/gender-male", uniform(rng, 0.55, 1.0));
    if (kind / 6 == 0) {
        p.age = "young";
        if (chance(rng, 0.4)) set("macro/age-child", uniform(rng, 0.0, 0.25));  // down to about 21 years
        else set("macro/age-old", uniform(rng, 0.0, 0.12));                     // up to about 33
    } else if (kind / 6 == 1) {
        p.age = "middleage";
        set("macro/age-old", uniform(rng, 0.25, 0.5));  // about 41 to 57 years
    } else {
        p.age = "old";
        set("macro/age-old", uniform(rng, 0.6, 0.95));  // about 64 to 87
    }
    static const std::vector<std::string> ethnicities = {"african", "asian", "caucasian"};
    const int ethnicity = static_cast<int>(kind / 2 % 3);
    p.ethnicity = ethnicities[static_cast<std::size_t>(ethnicity)];
    const double main = uniform(rng, 0.5, 1.0);
    set("macro/" + p.ethnicity, main);
    if (chance(rng, 0.3)) {
        const int other = (ethnicity + 1 + std::uniform_int_distribution<int>(0, 1)(rng)) % 3;
        set("macro/" + ethnicities[static_cast<std::size_t>(other)], uniform(rng, 0.0, std::min(0.3, 1.0 - main)));
    }
    set(chance(rng, 0.5) ? "macro/weight-min" : "macro/weight-max", uniform(rng, 0.0, 0.7));
    set(chance(rng, 0.5) ? "macro/muscle-min" : "macro/muscle-max", uniform(rng, 0.0, 0.7));
    set(chance(rng, 0.5) ? "macro/proportions-uncommon" : "macro/proportions-ideal", uniform(rng, 0.0, 0.8));

    // --- A handful of face sliders, each at one of its ends, the subject's left and right nearly alike; the ears
    // drawn apart so that every person has some (the fit holds them at the average).
    std::map<std::string, std::vector<std::string>> face, ears;
    for (const auto& m : basis.modifiers) {
        if (m.group == "macro") continue;
        (m.group == "ears" ? ears : face)[sliderOf(m.name)].push_back(m.name);
    }
    const auto drawSliders = [&](const std::map<std::string, std::vector<std::string>>& sliders, int count, double lo,
                                 double hi) {
        std::vector<std::string> keys;
        for (const auto& [key, names] : sliders) keys.push_back(key);
        std::shuffle(keys.begin(), keys.end(), rng);
        for (int i = 0; i < count && i < static_cast<int>(keys.size()); ++i) {
            const std::vector<std::string>& ends = sliders.at(keys[static_cast<std::size_t>(i)]);
            const std::string name = pick(rng, ends);
            const double w = uniform(rng, lo, hi);
            set(name, w);
            if (mirroredModifierName(name) != name) set(mirroredModifierName(name), w * uniform(rng, 0.9, 1.1));
        }
    };
    drawSliders(face, 8, 0.2, 0.65);
    drawSliders(ears, 2, 0.2, 0.7);

    // --- The skin of that age, sex and ethnicity; hair, brows and eyes.
    p.skin = p.age + "_" + p.ethnicity + "_" + p.sex;
    const bool old = p.age == "old", middle = p.age == "middleage";
    look.bald = !female && chance(rng, old ? 0.3 : middle ? 0.15 : 0.05);
    look.balding = !female && !look.bald && chance(rng, old ? 0.4 : middle ? 0.3 : 0.05);
    const bool grey = old ? chance(rng, 0.85) : middle && chance(rng, 0.35);
    const Colour hair = grey ? pick(rng, greyHair()) : pickColour(rng, hairColours(), ethnicity);
    look.hair = hair.bgr;
    p.hair = look.bald ? "bald" : look.balding ? std::string("balding, ") + hair.name : hair.name;
    // Brows darker than the hair (blond and grey brows still show against skin).
    look.brow = look.hair * 0.55 + cv::Vec3d(10, 12, 16);
    look.browWidth = female ? uniform(rng, 1.8, 2.4) : uniform(rng, 2.6, 3.4);
    look.hairlineFront = female ? uniform(rng, 100.0, 110.0) : uniform(rng, 104.0, old || middle ? 124.0 : 114.0);
    look.nape = female ? uniform(rng, -90.0, -60.0) : uniform(rng, -55.0, -35.0);
    // Shirts: the test head's green, and darker and lighter ones (a dark shirt on the dark backdrop is the
    // silhouette's hard case).
    static const std::vector<cv::Scalar> shirts = {{96, 110, 40}, {58, 58, 62}, {40, 40, 150}, {196, 200, 204},
                                                   {120, 72, 30}, {28, 28, 30}, {70, 140, 170}};
    look.shirt = pick(rng, shirts);
    const Colour& iris = pickColour(rng, irisColours(), ethnicity);
    look.iris = iris.bgr;
    p.eyes = iris.name;
    p.irisBgr = look.iris;
    p.browBgr = look.brow;

    // --- Issue 22's hair and beard, from a generator of their own, so that the people drawn before stay the same.
    Rng hairRng(seed * 40503u + 977u);
    p.hairStyle = look.bald || look.balding ? "none" : "short";
    if (p.hairStyle != "none") {
        // The style (a proxy over the painted scalp, when the base head has one): women's longer, men's mostly short.
        const double r = uniform(hairRng, 0.0, 1.0);
        p.hairStyle = female ? (r < 0.15 ? "short" : r < 0.45 ? "bob" : r < 0.8 ? "long" : "ponytail")
                             : (r < 0.8 ? "short" : r < 0.9 ? "bob" : r < 0.97 ? "long" : "ponytail");
    }
    p.hairColour = look.bald ? cv::Vec3d(0, 0, 0) : look.hair;
    p.beard = "none";
    if (!female && chance(hairRng, old || middle ? 0.35 : 0.25)) {
        look.moustache = true;
        look.beard = chance(hairRng, 0.65);
        p.beard = look.beard ? "full" : "moustache";
        // A beard of the hair's colour, a little darker (grey beards stay grey); the bald take a dark brown one.
        look.beardColour = look.bald ? cv::Vec3d(30, 40, 56) : look.hair * 0.85;
    }
    return {std::move(p), look};
}

// The hairline's height by the angle around the vertical axis (0 = the face, 90 = over the ear, 180 = the back),
// on MakeHuman's head (ear hole at the origin, the forehead's top about 105 mm above it, the ears' tops about 40).
double hairlineHeight(double azimuthDeg, const Look& look) {
    const double a = std::min(std::abs(azimuthDeg), 180.0);
    const double front = look.hairlineFront;
    const std::array<double, 8> angles = {0, 30, 55, 72, 85, 110, 150, 180};
    const std::array<double, 8> heights = {front, front - 6, front - 28, 46, 30, 34, 0.5 * (30 + look.nape), look.nape};
    for (std::size_t i = 0; i + 1 < angles.size(); ++i)
        if (a <= angles[i + 1]) {
            const double t = (a - angles[i]) / (angles[i + 1] - angles[i]);
            return heights[i] + t * (heights[i + 1] - heights[i]);
        }
    return heights.back();
}

cv::Vec3d mix(const cv::Vec3d& a, const cv::Vec3d& b, double t) { return a * (1.0 - t) + b * t; }

double smoothstep(double e0, double e1, double x) {
    const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
    return t * t * (3.0 - 2.0 * t);
}

double distanceToSegment(const glm::dvec2& p, const glm::dvec2& a, const glm::dvec2& b, double* along = nullptr) {
    const glm::dvec2 ab = b - a;
    const double t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12), 0.0, 1.0);
    if (along) *along = t;
    return glm::distance(p, a + t * ab);
}

// Paints eyes, brows and hair over the skin, texel by texel through the base head's surface (the texture follows
// the UVs, so the base head's positions say where each texel is on every person).
cv::Mat paintMakeHumanTexture(const BaseHead& base, const cv::Mat& skin, const Look& look) {
    const Mesh& mesh = base.mesh;
    const TexelMap map = mapTexels(mesh, skin.size());
    const SurfaceTexels texels = sampleSurfaceTexels(mesh, mesh.vertexNormals(), map);

    // Which triangles are an eyeball's (and whose), which an ear's: the vertices the ears' modifiers move.
    std::vector<int> eyeOf(mesh.triangles.size(), -1);
    std::vector<glm::dvec3> eyeCentre;
    for (std::size_t e = 0; e < base.rigidParts.size(); ++e) {
        std::set<std::uint32_t> part(base.rigidParts[e].begin(), base.rigidParts[e].end());
        glm::dvec3 c(0.0);
        for (const auto v : part) c += mesh.positions[v];
        eyeCentre.push_back(c / static_cast<double>(std::max<std::size_t>(1, part.size())));
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
            if (part.count(mesh.triangles[t].x) && part.count(mesh.triangles[t].y) && part.count(mesh.triangles[t].z))
                eyeOf[t] = static_cast<int>(e);
    }
    std::vector<bool> earVertex(mesh.positions.size(), false);
    if (base.modifiers)
        for (const auto& m : base.modifiers->modifiers)
            if (m.group == "ears")
                for (std::size_t i = 0; i < m.vertices.size(); ++i)
                    if (glm::length(glm::dvec3(m.offsets[i])) > 1.0) earVertex[m.vertices[i]] = true;
    const auto isEar = [&](int t) {
        const auto& tri = mesh.triangles[static_cast<std::size_t>(t)];
        return earVertex[tri.x] && earVertex[tri.y] && earVertex[tri.z];
    };

    // The beard's and moustache's regions, by the base head's landmarks (front view x, y): the moustache between the
    // nose's base and the upper lip, the beard from the mouth's corners down over the chin to the throat, in front of
    // the ears; the lips themselves stay bare.
    const auto feature = [&](int k) { return mesh.positions[base.frontFeatures.at(landmarkName(k))]; };
    std::vector<cv::Point2f> lips;
    for (int k = 48; k <= 59; ++k) lips.emplace_back(static_cast<float>(feature(k).x), static_cast<float>(feature(k).y));
    const double noseBaseY = feature(33).y, upperLipY = feature(51).y, mouthY = 0.5 * (feature(48).y + feature(54).y);
    const double mouthHalfWidth = 0.5 * std::abs(feature(54).x - feature(48).x);
    const double throatY = mesh.positions[base.sideFeatures.at("throat")].y;
    const double jawZ = 0.5 * (feature(4).z + feature(5).z);  // the beard's back edge, before the ears
    const auto beardAlpha = [&](const glm::dvec3& p) {
        const double lipDistance = cv::pointPolygonTest(lips, cv::Point2f(static_cast<float>(p.x), static_cast<float>(p.y)), true);
        if (lipDistance > -1.0) return 0.0;  // on the lips or their rim
        double a = 0.0;
        if (look.moustache && p.z > 0.0)
            a = std::max(a, (1.0 - smoothstep(noseBaseY - 3.0, noseBaseY, p.y)) * smoothstep(upperLipY - 2.0, upperLipY + 2.0, p.y) *
                                (1.0 - smoothstep(mouthHalfWidth + 2.0, mouthHalfWidth + 8.0, std::abs(p.x))));
        if (look.beard)
            a = std::max(a, (1.0 - smoothstep(mouthY - 4.0, mouthY + 4.0, p.y)) * smoothstep(throatY - 6.0, throatY + 6.0, p.y) *
                                smoothstep(jawZ - 25.0, jawZ - 10.0, p.z));
        return a;
    };

    std::array<glm::dvec2, 10> brow{};
    double browZ = 0.0;
    for (int k = 17; k <= 26; ++k) {
        const glm::dvec3& q = mesh.positions[base.frontFeatures.at(landmarkName(k))];
        brow[static_cast<std::size_t>(k - 17)] = {q.x, q.y};
        browZ += q.z / 10.0;
    }

    // The visible iris is about 5.8 mm across its radius, the pupil 2 mm, on an eyeball of radius r: angles from
    // the eye's axis (+z, where the head faces).
    Rng rng(look.grainSeed * 7919u + 5u);
    std::normal_distribution<double> grain(0.0, 1.0);
    cv::Mat texture = skin.clone();
    for (int y = 0; y < texture.rows; ++y)
        for (int x = 0; x < texture.cols; ++x) {
            const int t = map.triangle.at<int>(y, x);
            if (t < 0) continue;
            const cv::Vec3f pf = texels.position.at<cv::Vec3f>(y, x);
            const cv::Vec3f nf = texels.normal.at<cv::Vec3f>(y, x);
            const glm::dvec3 p(pf[0], pf[1], pf[2]);
            cv::Vec3b& out = texture.at<cv::Vec3b>(y, x);
            cv::Vec3d colour(out[0], out[1], out[2]);
            const int eye = eyeOf[static_cast<std::size_t>(t)];
            if (eye >= 0) {
                const glm::dvec3 d = p - eyeCentre[static_cast<std::size_t>(eye)];
                const double r = glm::length(d);
                const double angle = std::acos(std::clamp(d.z / std::max(r, 1e-9), -1.0, 1.0)) * 180.0 / kPi;
                const double iris = std::asin(std::min(1.0, 5.8 / r)) * 180.0 / kPi, pupil = std::asin(std::min(1.0, 2.1 / r)) * 180.0 / kPi;
                // Radial fibres and a darker rim, so the iris is no flat disc.
                const double around = std::atan2(d.y, d.x);
                const cv::Vec3d fibres = look.iris * (0.85 + 0.2 * std::sin(around * 23.0) * std::sin(around * 7.0 + 1.0));
                if (angle < pupil) colour = {12, 12, 14};
                else if (angle < iris) colour = mix(fibres, look.iris * 0.45, smoothstep(iris - 5.0, iris, angle));
                else colour = mix(colour, colour * 0.8, smoothstep(iris + 30.0, iris + 60.0, angle));  // shade toward the sides
            } else if (!isEar(t)) {
                // Brows: a stroke along 17-21 and 22-26 on the face, thinner towards the temples.
                if (nf[2] > 0.2f && std::abs(p.z - browZ) < 25.0) {
                    const glm::dvec2 q(p.x, p.y);
                    double best = 1e9;
                    for (const int start : {0, 5})
                        for (int k = start; k < start + 4; ++k) {
                            double along = 0.0;
                            const double dist = distanceToSegment(q, brow[static_cast<std::size_t>(k)], brow[static_cast<std::size_t>(k + 1)], &along);
                            // Landmarks 17 and 26 are the outer ends: the stroke thins there.
                            const double pos = (k - start + along) / 4.0;  // 0 at 17 or 22, 1 at 21 or 26
                            const double outer = start == 0 ? 1.0 - pos : pos;
                            best = std::min(best, dist / (look.browWidth * (1.0 - 0.45 * outer)));
                        }
                    const double alpha = 0.85 * (1.0 - smoothstep(0.7, 1.15, best));
                    if (alpha > 0.0) colour = mix(colour, look.brow * (1.0 + 0.12 * grain(rng)), alpha);
                }
                // Beard and moustache: dense short hair over the skin, with a grain.
                if (look.moustache) {
                    const double alpha = 0.9 * beardAlpha(p);
                    if (alpha > 0.0) colour = mix(colour, look.beardColour * (0.9 + 0.15 * grain(rng)), alpha);
                }
                // Hair above the hairline, a soft edge a few millimetres wide.
                if (!look.bald) {
                    const double azimuth = std::atan2(p.x, p.z) * 180.0 / kPi;
                    const double jitter = 1.5 * std::sin(azimuth * 0.9) + 1.0 * std::sin(azimuth * 2.3 + 1.3);
                    double alpha = smoothstep(0.0, 5.0, p.y - hairlineHeight(azimuth, look) - jitter);
                    // The balding keep a horseshoe: the sides and the back below the crown, nothing on top or in
                    // front of the ears.
                    if (look.balding)
                        alpha *= smoothstep(60.0, 80.0, std::abs(azimuth)) *
                                 (1.0 - smoothstep(-4.0, 4.0, p.y - (48.0 + 22.0 * smoothstep(90.0, 180.0, std::abs(azimuth)))));
                    if (alpha > 0.0) {
                        const double strands = 0.88 + 0.1 * std::sin(p.x * 1.7 + 3.0 * std::sin(p.z * 0.21)) *
                                                          std::sin(p.z * 1.3 + 2.0 * std::sin(p.x * 0.17));
                        colour = mix(colour, look.hair * (strands + 0.06 * grain(rng)), alpha);
                    }
                }
            }
            for (int c = 0; c < 3; ++c) out[c] = cv::saturate_cast<unsigned char>(colour[c]);
        }
    // The paint's colours, not the skin's, just outside each island: filtering at a seam must not show a line.
    padTextureBorders(texture, texels.covered, 4);
    return texture;
}

// The ear hole of a head by the profile analysis' own rule, as the base head places its own (makehuman_import.cpp).
glm::dvec3 earHoleOf(const BaseHead& base, const Mesh& mesh) {
    const auto at = [&](const char* name) { return mesh.positions[base.sideFeatures.at(name)]; };
    const auto profilePx = [](const glm::dvec3& p) { return cv::Point2d(p.z, -p.y); };  // side photo: z right, y down
    const cv::Point2d ear = estimateEarHole(profilePx(at("nasion")), profilePx(at("chin")), at("top_of_head").y - at("nose_tip").y);
    return {0.0, -ear.y, ear.x};
}

// The neck's end, where the shirt begins: 12 mm under the throat (the profile's cervical point, which the side
// photo must show), high enough that the collar hides most of the neck's cut (it runs along MakeHuman's quads and
// is closed by a fan: spiky over 20-25 mm), a little inside the neck at that height.
SyntheticNeck neckOf(const BaseHead& base, const Mesh& mesh) {
    double lowest = 1e300;
    for (const auto& p : mesh.positions) lowest = std::min(lowest, p.y);
    SyntheticNeck neck;
    neck.baseY = std::max(lowest + 6.0, mesh.positions[base.sideFeatures.at("throat")].y - 12.0);
    double halfWidth = 0.0, front = -1e300, back = 1e300;
    for (const auto& p : mesh.positions)
        if (std::abs(p.y - neck.baseY) < 3.0) {
            halfWidth = std::max(halfWidth, std::abs(p.x));
            front = std::max(front, p.z);
            back = std::min(back, p.z);
        }
    neck.halfWidth = halfWidth - 2.0;
    neck.frontZ = front - 2.0;
    neck.backZ = back + 2.0;
    return neck;
}

}  // namespace

MakeHumanPerson drawMakeHumanPerson(const ModifierBasis& basis, unsigned seed) { return draw(basis, seed).first; }

MakeHumanVisitor makeMakeHumanVisitor(const BaseHead& mh, MeshRenderer& renderer, const MakeHumanVisitorOptions& options) {
    if (!mh.modifiers || mh.modifiers->vertexCount != mh.mesh.positions.size())
        throw BoothError(ErrorKind::BadConfig, "base head", "has no modifier basis: the MakeHuman visitor needs MakeHuman's head");
    auto [person, look] = draw(*mh.modifiers, options.seed);
    fs::path skins = options.skinsDir;
    if (skins.empty()) {
        const fs::path dir = findMakeHumanBaseHead();
        if (dir.empty())
            throw BoothError(ErrorKind::BadConfig, "base_head", "the MakeHuman base head was not found, nor its skins");
        skins = dir / "skins";
    }
    const cv::Mat skin = readPhoto(skins / (person.skin + ".jpg"));

    MakeHumanVisitor out;
    SyntheticVisitor& v = out.photos;
    v.texture = paintMakeHumanTexture(mh, skin, look);
    v.truthMesh = mh.mesh;
    v.truthMesh.positions = mh.modifiers->apply(mh.mesh.positions, person.weights);
    SyntheticPhotoSetup setup;
    setup.mmPerPixel = options.mmPerPixel;
    setup.imageSize = options.imageSize;
    setup.sideNoseImageRight = options.sideNoseImageRight;
    setup.sideYawDeg = options.sideYawDeg;
    setup.lit = options.lit;
    setup.backdropSeed = options.seed;
    setup.target = {0.0, -35.0, 0.0};  // MakeHuman's head is a little taller above the ear hole than the test head
    setup.neck = neckOf(mh, v.truthMesh);
    setup.shirt = look.shirt;
    // The hair proxy of the drawn style on the person's head, in the hair's colour; without one (a base head made
    // without hair proxies) the painted scalp is all there is, a short cut.
    if (const auto style = hairStyleFromString(person.hairStyle); !options.hairProxies) {
        if (person.hairStyle != "none") person.hairStyle = "short";
    } else if (style && *style != HairStyle::None) {
        // Short hair is short02, fuller than the avatar's crop (short04): visitors' short hair stands off the scalp,
        // and the painted people without proxies are the crops.
        const char* proxy = *style == HairStyle::Short ? "short02" : hairProxyName(*style);
        if (auto part = placeHairPart(mh, v.truthMesh, proxy, person.hairColour)) setup.parts.push_back(std::move(*part));
        else person.hairStyle = "short";
    }
    photographSyntheticHead(v, mh, earHoleOf(mh, v.truthMesh), renderer, setup);
    out.person = std::move(person);
    return out;
}

void writeMakeHumanVisitorFolder(const MakeHumanVisitor& v, const BaseHead& mh, const fs::path& dir) {
    fs::create_directories(dir / "truth");
    const MakeHumanPerson& p = v.person;
    nlohmann::json j;
    j["sex"] = p.sex;
    j["age"] = p.age;
    j["ethnicity"] = p.ethnicity;
    j["skin"] = p.skin;
    j["hair"] = p.hair;
    j["eyes"] = p.eyes;
    j["hair_style"] = p.hairStyle;
    j["hair_colour_bgr"] = {p.hairColour[0], p.hairColour[1], p.hairColour[2]};
    j["beard"] = p.beard;
    j["modifiers"] = nlohmann::json::object();
    for (std::size_t k = 0; k < p.weights.size() && mh.modifiers && k < mh.modifiers->modifiers.size(); ++k)
        if (p.weights[k] != 0.0) j["modifiers"][mh.modifiers->modifiers[k].name] = p.weights[k];
    writeFileAtomically(dir / "truth" / "person.json", j.dump(2) + "\n");
    writeSyntheticVisitorFolder(v.photos, dir);  // its landmarks.json last: the folder is complete
}

}  // namespace avatarbooth
