// character.json and character.glb from a fit's front-photo analysis.
#include "reveal/character/character_outputs.h"

#include "reveal/character/character_modifiers.h"
#include "fit/export/glb.h"

#include <chrono>

namespace avatarbooth {

std::optional<cv::Point2d> earHoleInFrontPhoto(const HeadFit& fit, const std::map<std::string, cv::Point2d>& side) {
    const auto it = side.find("ear_hole");
    if (it == side.end()) return std::nullopt;
    const glm::dvec2 zy = fit.side.toHead(it->second);
    return fit.front.toPixel(glm::dvec2(0.0, zy.y));
}

CharacterOutputs makeCharacterOutputs(const cv::Mat& frontPhoto, const std::array<cv::Point2d, 68>& landmarks,
                                      const cv::Mat& frontMask, std::optional<cv::Point2d> earHole,
                                      const BaseHead& base, const CharacterSettings& settings) {
    const auto t0 = std::chrono::steady_clock::now();
    NaritaMappingInput input;
    input.landmarks = landmarks;
    input.mask = frontMask;
    input.earHole = earHole;
    const NaritaMapping mapping = mapNaritaPoints(input);
    const CharacterProportions proportions = computeProportions(mapping.points);
    const CharacterLook look = settings.coloursFromPhoto ? lookFromPhoto(frontPhoto, landmarks, frontMask) : CharacterLook{};
    CharacterHead head = makeCharacterHead(base, proportions, settings, look);

    nlohmann::json j = characterJson(mapping, proportions);
    nlohmann::json character;
    character["file"] = "character.glb";
    character["exaggeration"] = settings.exaggeration;
    character["colours"] = settings.coloursFromPhoto ? "photo" : "fixed";
    nlohmann::json applied = nlohmann::json::array();
    for (const SliderRange& s : sliderRanges())
        if (!settings.sliders || settings.sliders->count(std::string(s.key))) applied.push_back(s.key);
    character["sliders_applied"] = applied;
    for (const auto& [name, value] : std::map<std::string, const CharacterProportions*>{
             {"target", &head.target}, {"achieved", &head.achieved}, {"base_head", &head.base}}) {
        nlohmann::json ratios;
        for (std::size_t i = 0; i < value->r.size(); ++i) ratios["r" + std::to_string(i)] = value->r[i];
        ratios["eye_spacing"] = value->eyeSpacing;
        ratios["eye_tilt_deg"] = value->eyeTiltDeg;
        ratios["brow_tilt_deg"] = value->browTiltDeg;
        character[name] = ratios;
    }
    // The model's own sliders: MakeHuman's modifiers on the base head, by their names in its basis.
    nlohmann::json sliders = nlohmann::json::object();
    for (const auto& [name, weight] : head.modifiers) sliders[name] = weight;
    j["sliders"] = sliders;
    j["slider_convention"] = "MakeHuman modifier weights in [0, 1] on the base head's modifier basis (MakeHuman's "
                             "one-sided targets: 'nose/nose-trans-down' and 'nose/nose-trans-up' are the two ends of "
                             "MakeHuman's slider 'nose/nose-trans-down|up'); the shared ones hold the right and left "
                             "modifiers at one weight";
    nlohmann::json makehuman = nlohmann::json::object();
    for (const auto& [name, value] : makeHumanSliders(head.modifiers)) makehuman[name] = value;
    j["makehuman_modifiers"] = makehuman;
    j["makehuman_modifier_convention"] = "MakeHuman's two-sided sliders as a .mhm file writes them: upper end's weight "
                                         "minus the lower end's, in [-1, 1]";
    character["note"] = "target: the measured proportions exaggerated and clamped to the Narita slider ranges; "
                        "achieved: what the character head (the base head with the sliders' modifiers) measures "
                        "(front silhouette and feature vertices, the same mapping as the photo)";
    character["skin"] = "MakeHuman toon01 tinted by the skin colour, with painted hair, brows, eyes and mouth";
    j["character_head"] = character;

    CharacterOutputs out;
    out.json = j.dump(2) + "\n";
    out.glb = encodeGlb(head.mesh, head.texture, "character");
    out.warnings = mapping.warnings;
    out.warnings.insert(out.warnings.end(), head.warnings.begin(), head.warnings.end());
    out.head = std::move(head);
    out.makeSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

CharacterOutputs makeCharacterOutputs(const FitOutcome& o, const BaseHead& base, const CharacterSettings& settings) {
    return makeCharacterOutputs(o.front, o.frontLandmarks.points, o.frontMask, earHoleInFrontPhoto(o.fit, o.sideLandmarks),
                                base, settings);
}

}  // namespace avatarbooth
