// Narita's ratios, the tilts, the sliders and character.json.
#include "reveal/character/proportions.h"

#include "common/error.h"

#include <algorithm>
#include <cmath>

namespace avatarbooth {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;


// |X sin θ| and |X cos θ|, θ the angle between the face line `line` and X: X's components across and along it.
double across(const cv::Point2d& X, const cv::Point2d& line) { return std::abs(line.cross(X)) / cv::norm(line); }
double along(const cv::Point2d& X, const cv::Point2d& line) { return std::abs(line.dot(X)) / cv::norm(line); }

cv::Point2d centre(const std::array<cv::Point2d, 10>& e, std::size_t first) {
    cv::Point2d sum(0.0, 0.0);
    for (std::size_t i = first; i < first + 5; ++i) sum += e[i];
    return sum * 0.2;
}

// The angle of inner->outer against the face line, positive when the outer end is higher (further from the
// chin). `outwards` is the face line's direction on that side, `up` the face's up.
double tiltDeg(const cv::Point2d& inner, const cv::Point2d& outer, const cv::Point2d& outwards, const cv::Point2d& up) {
    const cv::Point2d d = outer - inner;
    return std::atan2(d.dot(up), d.dot(outwards)) * kRadToDeg;
}

// Slider ranges. The middle of each is about what the built-in base head (an average adult face) measures with
// this mapping (r0 1.29, r1 0.50, r2 0.144, r3 0.120, r4 0.342, r5 0.133, r6 0.221, r7 0.378, eye spacing 0.359,
// eye tilt -0.6 deg, brow tilt -3.7 deg); the half-widths cover what real faces measure with room for stylised
// characters. Measured on the 8 FRMDB people fitted in the booth's way (../shared/data/frmdb): r0 0.89-1.44,
// r1 0.34-0.61, r2 0.11-0.16, r3 0.01-0.13, r4 0.31-0.43, r5 0.06-0.12, r6 0.18-0.26, r7 0.31-0.44; on the
// faces68 photos r0 up to 1.71 and brow tilts down to -28 deg. Temples are on the silhouette (ears or hair
// included), so l_f0 is wider than the face across the cheekbones and the ratios are correspondingly smaller than
// on a drawn character; and r1, by the seed's formula, mostly shows how asymmetric the silhouette is at eye height
// (a parting, hair over one side), hence its wide range.
constexpr std::array<SliderRange, 11> kSliders = {{
    {"face_aspect", "r0", 0.8, 1.8, "face height / face width (2 x chin to face line / temple to temple)"},
    {"eye_position", "r1", 0.25, 0.75, "where the pair of eyes sits between the temples (0.5: centred)"},
    {"eye_size", "r2", 0.06, 0.22, "eye width along the face line / face width"},
    {"ear_position", "r3", 0.0, 0.25, "ear top's distance from the face line / face width"},
    {"ear_size", "r4", 0.15, 0.55, "ear height across the face line / face width"},
    {"brow_position", "r5", 0.02, 0.2, "brow inner ends' distance from the face line / face width"},
    {"nose_position", "r6", 0.1, 0.34, "nose tip's distance from the face line / face width"},
    {"mouth_position", "r7", 0.22, 0.54, "mouth centre's distance from the face line / face width"},
    {"eye_spacing", "eye_spacing", 0.2, 0.52, "distance between the eye centres along the face line / face width"},
    {"eye_tilt", "eye_tilt_deg", -15.0, 15.0, "eye corners' tilt in degrees, + = outer corners up"},
    {"brow_tilt", "brow_tilt_deg", -30.0, 22.0, "brows' tilt in degrees, + = outer ends up"},
}};

}  // namespace

CharacterProportions computeProportions(const NaritaPoints& P) {
    CharacterProportions out;
    const cv::Point2d line = P.f[1] - P.f[0];
    out.lf0 = cv::norm(line);
    if (!(out.lf0 > 0.0)) throw BoothError(ErrorKind::NoFace, "", "character proportions: the temples coincide");
    const double w = out.lf0;
    out.lf1 = 2.0 * across(P.f[2] - P.f[0], line);
    out.r[0] = out.lf1 / w;
    const cv::Point2d eyeR = centre(P.e, 0), eyeL = centre(P.e, 5);
    out.r[1] = (along(eyeR - P.f[0], line) + along(eyeL - P.f[0], line)) / (2.0 * w);
    out.r[2] = (along(P.e[1] - P.e[0], line) + along(P.e[6] - P.e[5], line)) / (2.0 * w);
    out.r[3] = (across(P.a[0] - P.f[0], line) + across(P.a[2] - P.f[0], line)) / (2.0 * w);
    out.r[4] = (across(P.a[1] - P.a[0], line) + across(P.a[3] - P.a[2], line)) / (2.0 * w);
    out.r[5] = (across(P.b[0] - P.f[0], line) + across(P.b[1] - P.f[0], line)) / (2.0 * w);
    out.r[6] = across(P.n - P.f[0], line) / w;
    out.r[7] = across(P.m - P.f[0], line) / w;
    out.eyeSpacing = along(eyeL - eyeR, line) / w;

    const cv::Point2d u = line * (1.0 / w);
    cv::Point2d up(u.y, -u.x);
    if ((P.f[2] - P.f[0]).dot(up) > 0.0) up = -up;
    out.eyeTiltDeg = 0.5 * (tiltDeg(P.e[1], P.e[0], -u, up) + tiltDeg(P.e[6], P.e[5], u, up));
    out.browTiltDeg = 0.5 * (tiltDeg(P.b[0], P.browOuter[0], -u, up) + tiltDeg(P.b[1], P.browOuter[1], u, up));
    return out;
}

const std::array<SliderRange, 11>& sliderRanges() { return kSliders; }

double proportionQuantity(const CharacterProportions& p, std::string_view q) {
    if (q.size() == 2 && q[0] == 'r' && q[1] >= '0' && q[1] <= '7') return p.r[static_cast<std::size_t>(q[1] - '0')];
    if (q == "eye_spacing") return p.eyeSpacing;
    if (q == "eye_tilt_deg") return p.eyeTiltDeg;
    if (q == "brow_tilt_deg") return p.browTiltDeg;
    throw BoothError(ErrorKind::Internal, "", "unknown character quantity '" + std::string(q) + "'");
}

void setProportionQuantity(CharacterProportions& p, std::string_view q, double value) {
    if (q.size() == 2 && q[0] == 'r' && q[1] >= '0' && q[1] <= '7') {
        p.r[static_cast<std::size_t>(q[1] - '0')] = value;
        return;
    }
    if (q == "eye_spacing") p.eyeSpacing = value;
    else if (q == "eye_tilt_deg") p.eyeTiltDeg = value;
    else if (q == "brow_tilt_deg") p.browTiltDeg = value;
    else throw BoothError(ErrorKind::Internal, "", "unknown character quantity '" + std::string(q) + "'");
}

double sliderFromValue(const SliderRange& range, double value) {
    return std::clamp((value - range.lo) / (range.hi - range.lo), 0.0, 1.0);
}

double valueFromSlider(const SliderRange& range, double slider) {
    return range.lo + std::clamp(slider, 0.0, 1.0) * (range.hi - range.lo);
}

std::map<std::string, double> slidersOf(const CharacterProportions& p) {
    std::map<std::string, double> out;
    for (const SliderRange& s : kSliders) out[std::string(s.key)] = sliderFromValue(s, proportionQuantity(p, s.quantity));
    return out;
}

CharacterProportions clampToSliderRanges(CharacterProportions p) {
    for (const SliderRange& s : kSliders)
        setProportionQuantity(p, s.quantity, std::clamp(proportionQuantity(p, s.quantity), s.lo, s.hi));
    return p;
}

nlohmann::json characterJson(const NaritaMapping& mapping, const CharacterProportions& p) {
    nlohmann::json j;
    j["method"] = "Narita 2010: 21 feature points -> face width and height, ratios r0..r7 (METHODS.md section 2)";
    j["pixel_convention"] = "front photo pixels, pixel centres at integer coordinates";
    for (const auto& [name, q] : mapping.points.named()) j["points"][name] = {q.x, q.y};
    j["point_sources"] = {
        {"Pf0, Pf1", "temples on the eye line: right " + mapping.templeSource[0] + ", left " + mapping.templeSource[1] +
                         " (silhouette: its edge outwards from the eye centre; face contour: the jaw landmarks' contour "
                         "where the silhouette fell short)"},
        {"Pf2", "ibug_08"},
        {"Pe0..Pe4", "ibug_36, ibug_39, mid(ibug_37, ibug_38), ibug_41, ibug_40"},
        {"Pe5..Pe9", "ibug_45, ibug_42, mid(ibug_43, ibug_44), ibug_46, ibug_47"},
        {"Pb0, Pb1", "ibug_21, ibug_22"},
        {"Pn", "ibug_30"},
        {"Pm", "mid(ibug_62, ibug_66)"},
        {"brow_outer_right, brow_outer_left", "ibug_17, ibug_26"},
        {"Pa0, Pa1", "right ear top and bottom: " + mapping.earSource[0] + " (points on the " +
                         mapping.earPointSource[0] + ", " + mapping.earPointSource[1] + ")"},
        {"Pa2, Pa3", "left ear top and bottom: " + mapping.earSource[1] + " (points on the " +
                         mapping.earPointSource[2] + ", " + mapping.earPointSource[3] + ")"},
        {"ear_hole", mapping.earHoleSource}};
    j["lengths_px"] = {{"l_f0", p.lf0}, {"l_f1", p.lf1}};
    for (std::size_t i = 0; i < p.r.size(); ++i) j["ratios"]["r" + std::to_string(i)] = p.r[i];
    j["extras"] = {{"eye_spacing", p.eyeSpacing}, {"eye_tilt_deg", p.eyeTiltDeg}, {"brow_tilt_deg", p.browTiltDeg}};
    nlohmann::json sliders = nlohmann::json::object();
    for (const SliderRange& s : kSliders) {
        const double value = proportionQuantity(p, s.quantity);
        sliders[std::string(s.key)] = {{"value", sliderFromValue(s, value)},
                                       {"quantity", std::string(s.quantity)},
                                       {"measured", value},
                                       {"range", {s.lo, s.hi}},
                                       {"meaning", std::string(s.meaning)}};
    }
    j["narita_sliders"] = sliders;
    j["narita_slider_convention"] = "value = clamp((measured - range[0]) / (range[1] - range[0]), 0, 1)";
    j["warnings"] = mapping.warnings;
    return j;
}

}  // namespace avatarbooth
