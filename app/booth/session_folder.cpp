// Writing the session folder: avatar.glb and avatar.usdz, the photos, overlays, previews, landmarks.json, the character, fit.json.
#include "booth/session_folder.h"

#include "booth/usdz.h"

#include "common/atomic_output.h"
#include "common/file_bytes.h"
#include "common/image_io.h"
#include "common/landmark_names.h"
#include "fit/export/glb.h"
#include "fit/parts/hair_part.h"
#include "render/mesh_renderer.h"
#include "render/previews.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::string photoExtension(const fs::path& p) {
    std::string ext = p.extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".jpeg" ? ".jpg" : (ext.empty() ? ".jpg" : ext);
}

nlohmann::json landmarksJson(const FitOutcome& o) {
    nlohmann::json landmarks;
    landmarks["pixel_convention"] = "pixel centres at integer coordinates";
    for (int k = 0; k < 68; ++k) {
        const auto& p = o.frontLandmarks.points[static_cast<std::size_t>(k)];
        landmarks["front"][landmarkName(k)] = {p.x, p.y};
    }
    landmarks["front_face_box"] = {o.frontLandmarks.face.x, o.frontLandmarks.face.y, o.frontLandmarks.face.width,
                                   o.frontLandmarks.face.height};
    for (const auto& [name, p] : o.sideLandmarks) landmarks["side"][name] = {p.x, p.y};
    landmarks["side_nose_points"] = o.sideNoseImageRight ? "image-right" : "image-left";
    landmarks["units_3d"] = "millimetres; y up, face along +z, x to the subject's left, origin between the ear holes";
    for (const auto& [name, p] : o.featurePoints) landmarks["points_3d"][name] = {p.x, p.y, p.z};
    return landmarks;
}

// fit.json: what went in, how the fit went (residuals, scales, each stage's time) and its warnings.
nlohmann::json fitReport(const FitOutcome& o, const SessionFolderContents& contents,
                         const std::vector<std::pair<std::string, double>>& writeStages) {
    nlohmann::json report;
    report["version"] = AVATARBOOTH_VERSION;
    const FitPhotoFiles& in = contents.photoFiles;
    report["inputs"] = {{"front", in.front.string()}, {"side", in.side.string()}, {"background", in.background.string()}};
    report["rbf"] = {{"kernel", rbfKernelName(o.rbf.kernel)}, {"unit_mm", o.rbf.unitMm},
                     {"gaussian_sigma", o.rbf.gaussianSigma}, {"regularisation", o.rbf.regularisation}};
    report["axis_scale"] = {o.fit.axisScale.x, o.fit.axisScale.y, o.fit.axisScale.z};
    report["measured_extents"] = {o.fit.measuredExtents.x, o.fit.measuredExtents.y, o.fit.measuredExtents.z};
    report["mm_per_pixel"] = {{"front", o.fit.front.mmPerPixel}, {"side", o.fit.side.mmPerPixel}};
    report["texture_seen_fraction"] = o.texture.seenFraction;
    // B, G, R, as the side photo's colours were scaled to the front's exposure (1 when too little skin was seen).
    report["texture_side_gain"] = {o.texture.sideGain[0], o.texture.sideGain[1], o.texture.sideGain[2]};
    report["texture_side_gain_texels"] = o.texture.sideGainTexels;
    // Texels (of the texture's size squared) repainted with skin: the photos' hair beside the face, their clothes
    // round the bottom of the neck.
    report["texture_skin_over_hair_texels"] = o.skinOverHairTexels;
    report["texture_skin_over_clothes_texels"] = o.skinOverClothesTexels;
    report["model_load_seconds"] = o.modelLoadSeconds;
    report["side_ear"] = {{"found", o.sideEar.found}, {"centre_px", {o.sideEar.centre.x, o.sideEar.centre.y}},
                          {"score", o.sideEar.score}, {"scale", o.sideEar.scale},
                          {"placed", o.fit.earsPlaced}, {"offset_mm", {o.fit.earOffsetMm.x, o.fit.earOffsetMm.y}},
                          {"shift_mm", {o.fit.earShiftMm.x, o.fit.earShiftMm.y}},
                          {"left_to_texture_mm", {o.fit.earLeftMm.x, o.fit.earLeftMm.y}}};
    report["side_eye"] = {{"found", o.sideEye.found}, {"centre_px", {o.sideEye.centre.x, o.sideEye.centre.y}},
                          {"contrast", o.sideEye.contrast},
                          {"left_to_texture_mm", {o.fit.eyeLeftMm.x, o.fit.eyeLeftMm.y}}};
    nlohmann::json stages = nlohmann::json::array();
    double total = 0.0;
    for (const auto& [name, seconds] : o.stageSeconds) {
        stages.push_back({{"stage", name}, {"seconds", seconds}});
        total += seconds;
    }
    for (const auto& [name, seconds] : writeStages) stages.push_back({{"stage", name}, {"seconds", seconds}});
    report["stages"] = stages;
    report["fit_seconds"] = total;
    nlohmann::json residuals = nlohmann::json::array();
    double worst = 0.0, sum = 0.0;
    for (const auto& r : o.fit.residuals) {
        residuals.push_back({{"name", r.name}, {"view", r.view}, {"measured_mm", {r.measured.x, r.measured.y}},
                             {"fitted_mm", {r.fitted.x, r.fitted.y}}, {"error_mm", r.errorMm}});
        worst = std::max(worst, r.errorMm);
        sum += r.errorMm * r.errorMm;
    }
    report["residuals"] = residuals;
    report["residual_rms_mm"] = o.fit.residuals.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(o.fit.residuals.size()));
    report["residual_max_mm"] = worst;
    {
        // What the hair analysis chose and the evidence it chose by (fit/face/hair_analysis.h): the operator's way to
        // see why a visitor got the hair the avatar wears.
        const HairEstimate& h = o.hair;
        const HairEvidence& e = h.evidence;
        const auto bgr = [](const cv::Vec3d& c) { return nlohmann::json{c[0], c[1], c[2]}; };
        const char* proxy = hairProxyName(h.style);
        report["hair"] = {{"style", toString(h.style)},
                          {"proxy", proxy ? nlohmann::json(proxy) : nlohmann::json(nullptr)},
                          {"colour_bgr", bgr(h.colour)},
                          {"skin_bgr", bgr(h.skinColour)},
                          {"beard", h.beard},
                          {"moustache", h.moustache},
                          {"evidence", {{"crown", e.crown}, {"hair_from_skin", e.hairFromSkin}, {"forehead_from_skin", e.foreheadFromSkin},
                                        {"crown_hue_shift_deg", e.crownHueShift}, {"crown_saturation", e.crownSaturation},
                                        {"hairline", e.hairline}, {"beside_face", e.besideFace},
                                        {"below_chin", e.belowChin}, {"behind_head", e.behindHead},
                                        {"down_the_back", e.downTheBack}, {"chin_darkening", e.chinDarkening},
                                        {"upper_lip_darkening", e.upperLipDarkening}, {"jaw_darkening", e.jawDarkening}}}};
        // Big hair's stretch to the photos' outlines, every 10 mm of height from the chin up (1: as the proxy came).
        nlohmann::json stretch = nlohmann::json::array();
        for (std::size_t i = 0; i < o.hairStretch.size(); i += 5) {
            const HairStretch& s = o.hairStretch[i];
            stretch.push_back({{"y_mm", s.y}, {"plus_x", s.plusX}, {"minus_x", s.minusX}, {"back", s.back}});
        }
        report["hair"]["stretch"] = stretch;
        if (o.hairLength.measured)  // a bob's length behind the head, to the side photo's
            report["hair"]["length_behind"] = {{"photo_bottom_mm", o.hairLength.photoBottom},
                                               {"avatar_bottom_mm", o.hairLength.avatarBottom},
                                               {"factor", o.hairLength.factor}};
        report["hair"]["forehead_shown_mm"] = o.foreheadShownMm;
        report["hair"]["trimmed_vertices"] = o.hairTrimmedVertices;
        report["hair"]["pulled_in_vertices"] = o.hairPulledInVertices;
        report["hair"]["tucked_behind_face_vertices"] = o.hairTuckedVertices;
    }
    if (!o.fit.modifierWeights.empty()) {
        // The first fitting step: the MakeHuman modifiers it used, and the targets' RMS before and after it.
        nlohmann::json modifiers = nlohmann::json::object();
        for (const auto& [name, weight] : o.fit.modifierWeights) modifiers[name] = weight;
        report["modifiers"] = modifiers;
        report["modifier_rms_mm"] = {o.fit.modifierRmsMm.first, o.fit.modifierRmsMm.second};
    }
    report["folds_removed"] = o.fit.foldsRemoved;
    report["warnings"] = o.warnings;
    if (contents.character)
        for (const auto& w : contents.character->warnings) report["warnings"].push_back("character: " + w);
    return report;
}

}  // namespace

std::vector<fs::path> writeSessionFolder(const FitOutcome& o, const SessionFolderContents& contents,
                                         const fs::path& folder, MeshRenderer& renderer) {
    StagedDirectory dir(folder, "fit.json");
    const fs::path s = dir.staging();
    std::vector<fs::path> written;
    const auto put = [&](const std::string& name, const std::string& bytes) {
        writeFileAtomically(s / name, bytes);
        written.push_back(folder / name);
    };
    const auto photo = [&](const char* name, const fs::path& file, const cv::Mat& image) {
        put(name + photoExtension(file), file.empty() ? encodeImage(image, ".jpg") : readFileBytes(file));
    };
    const auto t0 = Clock::now();
    put("avatar.glb", o.parts.empty() ? encodeGlb(o.fit.mesh, o.texture.texture, "avatar") : encodeGlb(o.parts));
    // The same avatar for iOS's AR Quick Look (the visitor's page offers both: booth/usdz.h).
    put("avatar.usdz", o.parts.empty() ? encodeUsdz(o.fit.mesh, o.texture.texture) : encodeUsdz(o.parts));
    // The photos themselves, as taken (personal data: the files are readable by the booth's user only).
    photo("front", contents.photoFiles.front, o.front);
    photo("side", contents.photoFiles.side, o.side);
    put("front_overlay.jpg", encodeImage(drawFrontOverlay(o), ".jpg"));
    put("side_overlay.jpg", encodeImage(drawSideOverlayWithRays(o), ".jpg"));
    const double exportSeconds = secondsSince(t0);

    const auto t1 = Clock::now();
    PreviewSet previews;
    if (o.parts.empty()) {
        renderer.upload(o.fit.mesh, o.texture.texture);
        previews = renderPreviews(renderer, o.fit.mesh, contents.previewSize, contents.previewAntialias);
    } else {
        renderer.upload(o.parts);
        previews = renderPreviews(renderer, o.parts, contents.previewSize, contents.previewAntialias);
    }
    put("preview_front.png", encodeImage(previews.front, ".png"));
    put("preview_side.png", encodeImage(previews.side, ".png"));
    put("preview_three_quarter.png", encodeImage(previews.threeQuarter, ".png"));
    // The character's picture too, for the printed card (print/card.h), which is made from the session alone.
    if (contents.character) {
        renderer.upload(contents.character->head.mesh, contents.character->head.texture);
        put("preview_character.png", encodeImage(renderThreeQuarterPreview(renderer, contents.character->head.mesh,
                                                                           contents.previewSize, contents.previewAntialias),
                                                 ".png"));
    }
    const double previewSeconds = secondsSince(t1);

    put("landmarks.json", landmarksJson(o).dump(2) + "\n");
    if (contents.character) {
        put("character.json", contents.character->json);
        put("character.glb", contents.character->glb);
    }
    const double characterSeconds = contents.character ? contents.character->makeSeconds : 0.0;
    // fit.json last: its presence marks a complete result.
    const std::vector<std::pair<std::string, double>> writeStages{
        {"export", exportSeconds}, {"previews", previewSeconds}, {"character", characterSeconds}};
    put("fit.json", fitReport(o, contents, writeStages).dump(2) + "\n");
    dir.commit();
    return written;
}

}  // namespace avatarbooth
