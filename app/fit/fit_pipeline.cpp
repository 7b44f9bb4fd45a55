// The photo-to-head pipeline: stages, timings, error attribution, the session folder.
#include "fit/fit_pipeline.h"

#include "reveal/character/character_outputs.h"
#include "common/atomic_output.h"
#include "common/error.h"
#include "common/image_io.h"
#include "fit/export/glb.h"
#include "fit/face/profile.h"
#include "fit/face/silhouette.h"
#include "render/previews.h"

#include <opencv2/imgproc.hpp>

#include <chrono>
#include <ctime>
#include <fstream>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Processor time used by the whole process so far (every thread), in seconds.
double processCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Runs one stage, timing it, and names the photo in any error that does not name a file yet.
template <typename Out, typename F>
auto stage(Out& out, const StageListener& listener, const char* name, const fs::path& photo, F&& work) {
    if (listener) listener(name);
    const auto t0 = Clock::now();
    const double cpu0 = processCpuSeconds();
    const auto record = [&] {
        out.stageSeconds.emplace_back(name, secondsSince(t0));
        out.stageCpuSeconds.emplace_back(name, processCpuSeconds() - cpu0);
    };
    try {
        if constexpr (std::is_void_v<decltype(work())>) {
            work();
            record();
        } else {
            auto result = work();
            record();
            return result;
        }
    } catch (const BoothError& e) {
        if (!e.where().empty() || photo.empty()) throw;
        throw BoothError(e.kind(), photo.string(), e.what());
    } catch (const cv::Exception& e) {
        throw BoothError(ErrorKind::Internal, photo.string(), std::string(name) + " failed in OpenCV: " + e.what());
    }
}

std::string readBytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw BoothError(ErrorKind::BadInput, path.string(), "cannot be read");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::string photoExtension(const fs::path& p) {
    std::string ext = p.extension().string();
    for (auto& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return ext == ".jpeg" ? ".jpg" : (ext.empty() ? ".jpg" : ext);
}

}  // namespace

FitPipeline::FitPipeline(FitSettings settings, const BaseHead& base) : settings_(std::move(settings)), base_(base) {
    const auto t0 = Clock::now();
    detector_ = std::make_unique<LandmarkDetector>(settings_.landmarkModel);
    // The texture step's per-UV-layout tables, built here with the other one-off loading, not for the first visitor.
    prepareTexture(base_.mesh, settings_.texture);
    modelLoadSeconds_ = secondsSince(t0);
}

FitPipeline::FitPipeline(const FitPipeline& shareFrom, std::unique_ptr<LandmarkDetector> detector)
    : settings_(shareFrom.settings_), base_(shareFrom.base_), detector_(std::move(detector)),
      modelLoadSeconds_(shareFrom.modelLoadSeconds_) {}

FitPipeline::~FitPipeline() = default;

std::unique_ptr<FitPipeline> FitPipeline::forAnotherThread() const {
    return std::unique_ptr<FitPipeline>(new FitPipeline(*this, detector_->sharingModel()));
}

FitOutcome FitPipeline::fit(const FitInputs& inputs) const {
    const auto t0 = Clock::now();
    const double cpu0 = processCpuSeconds();
    const cv::Mat front = readPhoto(inputs.front);
    const cv::Mat side = readPhoto(inputs.side);
    const cv::Mat background = inputs.background.empty() ? cv::Mat() : readPhoto(inputs.background);
    if (!background.empty() && background.size() != front.size())
        throw BoothError(ErrorKind::BadInput, inputs.background.string(),
                         "the background plate is " + std::to_string(background.cols) + "x" + std::to_string(background.rows) +
                             " but the front photo is " + std::to_string(front.cols) + "x" + std::to_string(front.rows));
    const double readSeconds = secondsSince(t0), readCpuSeconds = processCpuSeconds() - cpu0;
    FitOutcome out = fit(front, side, background, inputs);
    out.stageSeconds.insert(out.stageSeconds.begin(), {"read_photos", readSeconds});
    out.stageCpuSeconds.insert(out.stageCpuSeconds.begin(), {"read_photos", readCpuSeconds});
    return out;
}

FrontAnalysis FitPipeline::analyseFront(const cv::Mat& front, const cv::Mat& background, const FitInputs& names,
                                        const StageListener& listener) const {
    FrontAnalysis a;
    a.photo = front;
    a.background = background;
    a.landmarks = stage(a, listener, "front_landmarks", names.front, [&] { return detector_->detect(front); });
    a.mask = stage(a, listener, "front_silhouette", names.front,
                   [&] { return segmentPerson(front, background, a.landmarks.face); });
    return a;
}

FitOutcome FitPipeline::fit(const cv::Mat& front, const cv::Mat& side, const cv::Mat& background,
                            const FitInputs& names, const StageListener& listener, const FrontAnalysis* ahead) const {
    FitOutcome out;
    out.front = front;
    out.side = side;
    out.background = background;
    if (!background.empty() && background.size() != side.size())
        throw BoothError(ErrorKind::BadInput, names.side.string(), "the side photo and the background plate differ in size");

    // The front's analysis made ahead counts only for these very pixels (a retaken front photo is analysed anew).
    const bool useAhead = ahead != nullptr && ahead->photo.data == front.data && ahead->photo.size() == front.size() &&
                          ahead->background.data == background.data;
    const FrontAnalysis frontAnalysis = useAhead ? *ahead : analyseFront(front, background, names, listener);
    out.frontLandmarks = frontAnalysis.landmarks;
    out.frontMask = frontAnalysis.mask;
    out.stageSeconds = frontAnalysis.stageSeconds;
    out.stageCpuSeconds = frontAnalysis.stageCpuSeconds;
    if (useAhead)
        for (auto* list : {&out.stageSeconds, &out.stageCpuSeconds})
            for (auto& [name, seconds] : *list) name += "_ahead";  // not on this fit's clock
    if (out.frontLandmarks.facesFound > 1)
        out.warnings.push_back(std::to_string(out.frontLandmarks.facesFound) +
                               " faces in the front photo; the largest was used");
    const SideAnalysis sideAnalysis = stage(out, listener, "side_profile", names.side, [&] { return analyzeSidePhoto(side, background); });
    out.sideMask = sideAnalysis.mask;
    out.sideNoseImageRight = sideAnalysis.noseImageRight;
    for (const auto& p : sideAnalysis.landmarks) out.sideLandmarks[p.name] = p.px;
    for (const auto& w : sideAnalysis.warnings) out.warnings.push_back("side photo: " + w);

    PhotoMeasurements m;
    for (int k = 0; k < 68; ++k) m.frontPoints[landmarkName(k)] = out.frontLandmarks.points[static_cast<std::size_t>(k)];
    m.frontMask = out.frontMask;
    m.sidePoints = out.sideLandmarks;
    m.sideMask = out.sideMask;
    m.sideNoseImageRight = out.sideNoseImageRight;
    out.fit = stage(out, listener, "head_fit", names.side, [&] { return fitHead(base_, m, settings_.head); });
    for (const auto& w : out.fit.warnings) out.warnings.push_back(w);
    out.texture = stage(out, listener, "texture", fs::path(), [&] {
        return textureFromPhotos(out.fit.mesh, out.fit, front, out.frontMask, side, out.sideMask, settings_.texture);
    });
    return out;
}

namespace {

// The silhouette's outline and the contour rays (METHODS §1 step 4) drawn on a copy of a photo.
cv::Mat drawOutlineAndRays(const cv::Mat& photo, const cv::Mat& mask,
                           const std::vector<std::pair<cv::Point2d, cv::Point2d>>& rays) {
    cv::Mat canvas = photo.clone();
    std::vector<std::vector<cv::Point>> contours;
    cv::findContours(mask.clone(), contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
    cv::drawContours(canvas, contours, -1, cv::Scalar(255, 255, 0), 2, cv::LINE_AA);
    for (const auto& [from, to] : rays) {
        cv::line(canvas, from, to, cv::Scalar(0, 220, 255), 1, cv::LINE_AA);
        cv::circle(canvas, to, 4, cv::Scalar(0, 140, 255), cv::FILLED, cv::LINE_AA);
    }
    return canvas;
}

}  // namespace

cv::Mat drawFrontOverlay(const FitOutcome& o) {
    cv::Mat canvas = drawOutlineAndRays(o.front, o.frontMask, o.fit.frontRays);
    cv::rectangle(canvas, o.frontLandmarks.face, cv::Scalar(255, 0, 255), 1);
    for (const auto& p : o.frontLandmarks.points) cv::circle(canvas, p, 2, cv::Scalar(0, 255, 0), cv::FILLED, cv::LINE_AA);
    return canvas;
}

cv::Mat drawSideOverlayWithRays(const FitOutcome& o) {
    cv::Mat canvas = drawOutlineAndRays(o.side, o.sideMask, o.fit.sideRays);
    for (const auto& [name, p] : o.sideLandmarks) {
        cv::circle(canvas, p, 4, cv::Scalar(0, 255, 0), cv::FILLED, cv::LINE_AA);
        cv::putText(canvas, name, p + cv::Point2d(o.sideNoseImageRight ? 6 : -6 - 7.0 * static_cast<double>(name.size()), 4),
                    cv::FONT_HERSHEY_SIMPLEX, 0.4, cv::Scalar(0, 255, 0), 1, cv::LINE_AA);
    }
    return canvas;
}

std::vector<fs::path> FitPipeline::write(const FitOutcome& o, const FitInputs& inputs, const fs::path& outDir,
                                         MeshRenderer& renderer, const CharacterOutputs* madeCharacter) const {
    StagedDirectory dir(outDir, "fit.json");
    const fs::path s = dir.staging();
    std::vector<fs::path> written;
    const auto put = [&](const std::string& name, const std::string& bytes) {
        writeFileAtomically(s / name, bytes);
        written.push_back(outDir / name);
    };
    const auto t0 = Clock::now();
    put("avatar.glb", encodeGlb(o.fit.mesh, o.texture.texture, "avatar"));
    // The photos themselves, as taken (personal data: the files are readable by the booth's user only).
    put("front" + photoExtension(inputs.front), inputs.front.empty() ? encodeImage(o.front, ".jpg") : readBytes(inputs.front));
    put("side" + photoExtension(inputs.side), inputs.side.empty() ? encodeImage(o.side, ".jpg") : readBytes(inputs.side));
    put("front_overlay.jpg", encodeImage(drawFrontOverlay(o), ".jpg"));
    put("side_overlay.jpg", encodeImage(drawSideOverlayWithRays(o), ".jpg"));
    const double exportSeconds = secondsSince(t0);

    const auto t1 = Clock::now();
    renderer.upload(o.fit.mesh, o.texture.texture);
    const PreviewSet previews = renderPreviews(renderer, o.fit.mesh, settings_.previewSize);
    put("preview_front.png", encodeImage(previews.front, ".png"));
    put("preview_side.png", encodeImage(previews.side, ".png"));
    put("preview_three_quarter.png", encodeImage(previews.threeQuarter, ".png"));
    const double previewSeconds = secondsSince(t1);

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
    for (const auto& [name, v] : base_.frontFeatures) {
        const auto& p = o.fit.mesh.positions[v];
        landmarks["points_3d"][name] = {p.x, p.y, p.z};
    }
    for (const auto& [name, v] : base_.sideFeatures) {
        const auto& p = o.fit.mesh.positions[v];
        landmarks["points_3d"][name] = {p.x, p.y, p.z};
    }
    put("landmarks.json", landmarks.dump(2) + "\n");

    // Character maker (issue 6, app/character/): Narita's proportions and the stylised character head.
    const auto tCharacter = Clock::now();
    CharacterOutputs madeHere;
    if (settings_.characterEnabled && !madeCharacter) madeHere = makeCharacter(o);
    const CharacterOutputs& character = madeCharacter ? *madeCharacter : madeHere;
    if (settings_.characterEnabled) {
        put("character.json", character.json);
        put("character.glb", character.glb);
    }
    const double characterSeconds = secondsSince(tCharacter);

    nlohmann::json report;
    report["version"] = AVATARBOOTH_VERSION;
    report["inputs"] = {{"front", inputs.front.string()}, {"side", inputs.side.string()},
                        {"background", inputs.background.string()}};
    report["rbf"] = {{"kernel", rbfKernelName(settings_.head.rbf.kernel)}, {"unit_mm", settings_.head.rbf.unitMm},
                     {"gaussian_sigma", settings_.head.rbf.gaussianSigma}, {"regularisation", settings_.head.rbf.regularisation}};
    report["axis_scale"] = {o.fit.axisScale.x, o.fit.axisScale.y, o.fit.axisScale.z};
    report["mm_per_pixel"] = {{"front", o.fit.front.mmPerPixel}, {"side", o.fit.side.mmPerPixel}};
    report["texture_seen_fraction"] = o.texture.seenFraction;
    report["model_load_seconds"] = modelLoadSeconds_;
    nlohmann::json stages = nlohmann::json::array();
    double total = 0.0;
    for (const auto& [name, seconds] : o.stageSeconds) {
        stages.push_back({{"stage", name}, {"seconds", seconds}});
        total += seconds;
    }
    stages.push_back({{"stage", "export"}, {"seconds", exportSeconds}});
    stages.push_back({{"stage", "previews"}, {"seconds", previewSeconds}});
    stages.push_back({{"stage", "character"}, {"seconds", characterSeconds}});
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
    report["warnings"] = o.warnings;
    for (const auto& w : character.warnings) report["warnings"].push_back("character: " + w);
    // fit.json last: its presence marks a complete result.
    put("fit.json", report.dump(2) + "\n");
    dir.commit();
    return written;
}

CharacterOutputs FitPipeline::makeCharacter(const FitOutcome& o) const {
    if (!settings_.characterEnabled) return {};
    return makeCharacterOutputs(o.front, o.frontLandmarks.points, o.frontMask,
                                earHoleInFrontPhoto(o.fit, o.sideLandmarks), base_, settings_.character);
}

}  // namespace avatarbooth
