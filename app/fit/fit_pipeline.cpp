// The photo-to-head pipeline: steps, timings, which photo an error is about, cancellation between steps.
#include "fit/fit_pipeline.h"

#include "fit/parts/hair_part.h"
#include "fit/parts/part_colours.h"

#include "common/error.h"
#include "common/image_io.h"
#include "fit/face/profile.h"
#include "fit/face/silhouette.h"
#include "fit/head/ears.h"

#include <opencv2/imgproc.hpp>

#include <chrono>
#include <ctime>
#include <tuple>

namespace avatarbooth {
namespace fs = std::filesystem;

namespace {

// Under big hair, how far outside the shaped head an outline crossing on hair may lie and still count: about what
// short hair adds to the skull's outline.
constexpr double kBigHairOutlineSlackMm = 15.0;
// Clothes are repainted with skin from this far under the chin down (NeckClothes::topY), fading in above it: the
// throat under the chin is in shadow, and a beard grows there.
constexpr double kNeckClothesUnderChinMm = 25.0;
// ... and behind the ears from this far under the ear's middle, under the lobe.
constexpr double kNeckClothesUnderEarMm = 40.0;
// Hair tucked behind the face is read down to this far under the chin: the fade at the bottom of the heights read
// (SideFaceClearance::ramp) lies under it, and a lock's end beside the jaw goes back with the rest.
constexpr double kTuckUnderChinMm = 15.0;

// Where the side of the face begins on the fitted head, for the hair beside it (the texture's repaint and the hair
// part's tuck): |x| of the eyes' outer corners (ibug 36 and 45) and the brows' top (17-26).
struct FaceSide {
    double innerX = 0.0, browsTopY = 0.0;
};

FaceSide faceSide(const BaseHead& base, const Mesh& fitted) {
    const auto at = [&](int k) { return fitted.positions[base.frontFeatures.at(landmarkName(k))]; };
    FaceSide f;
    f.innerX = 0.5 * (std::abs(at(36).x) + std::abs(at(45).x));
    f.browsTopY = -1e9;
    for (int k = 17; k <= 26; ++k) f.browsTopY = std::max(f.browsTopY, at(k).y);
    return f;
}

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Processor time used by the whole process so far (every thread), in seconds.
double processCpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The photo each step looks at, for the error that says which to take again (the head fit and the texture use both).
FitPhoto photoOf(FitStep step) {
    switch (step) {
        case FitStep::FrontLandmarks:
        case FitStep::FrontSilhouette: return FitPhoto::Front;
        case FitStep::SideProfile: return FitPhoto::Side;
        default: return FitPhoto::Both;
    }
}

const std::string& nameOf(FitPhoto photo, const FitPhotoNames& names) {
    static const std::string none;
    return photo == FitPhoto::Front ? names.front : photo == FitPhoto::Side ? names.side : none;
}

// Runs one step, timing it: stops first when asked to, tells the listener, and turns any error into a FitError
// about the step's photo (or the photo the error itself names), with that photo's name where the error has none.
template <typename Out, typename F>
auto runStep(Out& out, const FitControl& control, FitStep step, const FitPhotoNames& names, F&& work) {
    if (control.cancel.cancelled()) throw FitCancelled();
    if (control.listener) control.listener(step);
    const auto t0 = Clock::now();
    const double cpu0 = processCpuSeconds();
    const auto record = [&] {
        out.stageSeconds.emplace_back(toString(step), secondsSince(t0));
        out.stageCpuSeconds.emplace_back(toString(step), processCpuSeconds() - cpu0);
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
    } catch (const FitError& e) {
        throw FitError(e, nameOf(e.photo(), names));
    } catch (const BoothError& e) {
        throw FitError(e, photoOf(step), nameOf(photoOf(step), names));
    } catch (const cv::Exception& e) {
        throw FitError(ErrorKind::Internal, photoOf(step), FitFault::Other, nameOf(photoOf(step), names),
                       std::string(toString(step)) + " failed in OpenCV: " + e.what());
    }
}

}  // namespace

FitPipeline::FitPipeline(FitSettings settings, const BaseHead& base) : settings_(std::move(settings)), base_(base) {
    const auto t0 = Clock::now();
    detector_ = std::make_unique<LandmarkDetector>(settings_.landmarkModel);
    // The eyes' and brows' landmarks: the front photo registers them, the side photo lands there through the depth.
    std::vector<std::uint32_t> eyesAndBrows;
    for (int k = 17; k <= 47; ++k)
        if (k <= 26 || k >= 36)
            if (const auto it = base_.frontFeatures.find(landmarkName(k)); it != base_.frontFeatures.end())
                eyesAndBrows.push_back(it->second);
    textureTables_ = std::make_shared<const TextureTables>(base_.mesh, settings_.texture, base_.skin, eyesAndBrows);
    frontalCheck_ = std::make_shared<FrontalFaceCheck>();
    earTemplate_ = std::make_shared<const EarTemplate>(makeEarTemplate(base_));
    modelLoadSeconds_ = secondsSince(t0);
    // OpenCV fills its 8-bit CIELAB tables at the first such conversion (0.13 s of one core here), which the hair
    // analysis makes: here, while the kiosk's attract screen runs, not in the first visitor's fit (and not counted
    // as the model's loading, which it is not).
    cv::Mat lab;
    cv::cvtColor(cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(128)), lab, cv::COLOR_BGR2Lab);
}

FitPipeline::FitPipeline(const FitPipeline& shareFrom, std::unique_ptr<LandmarkDetector> detector)
    : settings_(shareFrom.settings_), base_(shareFrom.base_), detector_(std::move(detector)),
      textureTables_(shareFrom.textureTables_), frontalCheck_(shareFrom.frontalCheck_), earTemplate_(shareFrom.earTemplate_),
      modelLoadSeconds_(shareFrom.modelLoadSeconds_) {}

FitPipeline::~FitPipeline() = default;

std::unique_ptr<FitPipeline> FitPipeline::forAnotherThread() const {
    return std::unique_ptr<FitPipeline>(new FitPipeline(*this, detector_->sharingModel()));
}

FitOutcome FitPipeline::fit(const FitPhotoFiles& files, const FitControl& control) const {
    const FitPhotoNames names = FitPhotoNames::of(files);
    const auto read = [](const fs::path& file, FitPhoto photo) {
        try {
            return readPhoto(file);
        } catch (const BoothError& e) {
            throw FitError(e, photo, file.string());
        }
    };
    struct {
        std::vector<std::pair<std::string, double>> stageSeconds, stageCpuSeconds;
    } reading;
    const auto [front, side, background] = runStep(reading, control, FitStep::ReadPhotos, names, [&] {
        const cv::Mat f = read(files.front, FitPhoto::Front), s = read(files.side, FitPhoto::Side);
        const cv::Mat b = files.background.empty() ? cv::Mat() : read(files.background, FitPhoto::Both);
        if (!b.empty() && b.size() != f.size())
            throw FitError(ErrorKind::BadInput, FitPhoto::Both, FitFault::Other, names.background,
                           "the background plate is " + std::to_string(b.cols) + "x" + std::to_string(b.rows) +
                               " but the front photo is " + std::to_string(f.cols) + "x" + std::to_string(f.rows));
        return std::tuple{f, s, b};
    });
    FitOutcome out = fit(front, side, background, names, control);
    out.stageSeconds.insert(out.stageSeconds.begin(), reading.stageSeconds.front());
    out.stageCpuSeconds.insert(out.stageCpuSeconds.begin(), reading.stageCpuSeconds.front());
    return out;
}

FrontAnalysis FitPipeline::analyseFront(const cv::Mat& front, const cv::Mat& background, const FitPhotoNames& names,
                                        const FitControl& control) const {
    FrontAnalysis a;
    a.photo = front;
    a.background = background;
    a.landmarks = runStep(a, control, FitStep::FrontLandmarks, names, [&] { return detector_->detect(front); });
    a.mask = runStep(a, control, FitStep::FrontSilhouette, names,
                     [&] { return segmentPerson(front, background, a.landmarks.face); });
    return a;
}

FitOutcome FitPipeline::fit(const cv::Mat& front, const cv::Mat& side, const cv::Mat& background,
                            const FitPhotoNames& names, const FitControl& control, const FrontAnalysis* ahead) const {
    FitOutcome out;
    out.front = front;
    out.side = side;
    out.background = background;
    out.rbf = settings_.head.rbf;
    out.modelLoadSeconds = modelLoadSeconds_;
    if (!background.empty() && background.size() != side.size())
        throw FitError(ErrorKind::BadInput, FitPhoto::Side, FitFault::Other, names.side,
                       "the side photo and the background plate differ in size");

    // The front's analysis made ahead counts only for these very pixels (a retaken front photo is analysed anew).
    const bool useAhead = ahead != nullptr && ahead->photo.data == front.data && ahead->photo.size() == front.size() &&
                          ahead->background.data == background.data;
    const FrontAnalysis frontAnalysis = useAhead ? *ahead : analyseFront(front, background, names, control);
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
    const SideAnalysis sideAnalysis =
        runStep(out, control, FitStep::SideProfile, names, [&] {
        SideOptions options;
        options.frontalCheck = frontalCheck_.get();
        options.landmarkDetector = detector_.get();
        return analyseSidePhoto(side, background, options);
    });
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
    out.fit = runStep(out, control, FitStep::HeadFit, names, [&] {
        // The hair first: with big hair the outline above and behind the face is the hair's, not the skull's.
        HeadFitOptions head = settings_.head;
        try {
            HairPhotos hp{front, out.frontMask, out.frontLandmarks.points, side, out.sideMask, out.sideLandmarks,
                          out.sideNoseImageRight};
            out.hair = estimateHair(hp);
            if (isBigHair(out.hair.style)) {
                m.frontHair = hairPixels(front, out.frontMask, out.hair);
                m.sideHair = hairPixels(side, out.sideMask, out.hair);
                if (head.hairOutlineSlackMm <= 0.0) head.hairOutlineSlackMm = kBigHairOutlineSlackMm;
            }
        } catch (const std::exception& e) {  // no hair is better than no avatar
            out.hair = HairEstimate{};
            out.warnings.push_back(std::string("hair analysis: ") + e.what());
        }
        {
            std::vector<ProfilePoint> profile;
            for (const auto& [name, px] : out.sideLandmarks) profile.push_back({name, px});
            // (The side photo's hair pixels count in the head fit only with big hair; the texture takes them too.)
            if (m.sideHair.empty() && out.hair.style != HairStyle::None) m.sideHair = hairPixels(side, out.sideMask, out.hair);
            out.sideEar = locateEar(side, out.sideMask, m.sideHair, profile, out.sideNoseImageRight, *earTemplate_);
            if (out.sideEar.found) m.sideEar = out.sideEar.centre;
            out.sideEye = locateSideEye(side, out.sideMask, m.sideHair, profile, out.sideNoseImageRight);
            if (out.sideEye.found) m.sideEye = out.sideEye.centre;
        }
        return fitHead(base_, m, head);
    });
    for (const auto& w : out.fit.warnings) out.warnings.push_back(w);
    for (const auto* features : {&base_.frontFeatures, &base_.sideFeatures})
        for (const auto& [name, v] : *features) out.featurePoints.emplace_back(name, out.fit.mesh.positions[v]);
    // The photos' hair, for the texture's exposure match (skin against skin) and the short hair's trim.
    if (out.hair.style != HairStyle::None && m.frontHair.empty()) m.frontHair = hairPixels(front, out.frontMask, out.hair);
    out.texture = runStep(out, control, FitStep::Texture, names, [&] {
        PhotoTexture texture = textureFromPhotos(out.fit.mesh, out.fit, front, out.frontMask, side, out.sideMask,
                                                 settings_.texture, *textureTables_, ColourMatchMasks{m.frontHair, m.sideHair});
        if (hairCoversEars(out.hair.style)) {
            // Long hair or a bob beside the face: the hair part leaves the cheeks bare, so the photo's hair on them goes.
            const auto at = [&](int k) { return out.fit.mesh.positions[base_.frontFeatures.at(landmarkName(k))]; };
            const FaceSide face = faceSide(base_, out.fit.mesh);
            FaceSides sides;
            sides.innerX = face.innerX;
            sides.topY = face.browsTopY;
            sides.bottomY = out.hair.beard ? at(30).y : at(8).y;
            // The head's origin lies between the ear holes; the ear reaches about 15 mm ahead of its middle.
            sides.frontOfZ = (out.fit.earsPlaced ? out.fit.earMiddleMm.z : 0.0) + 15.0;
            out.skinOverHairTexels = skinOverHairBesideFace(texture, out.fit.mesh, out.fit, ColourMatchMasks{m.frontHair, m.sideHair},
                                                            sides, settings_.texture, *textureTables_);
        }
        if (out.hair.skinLab[0] > 0.0) {  // the hair analysis measured the skin (none known when it failed)
            // Clothes round the bottom of the neck (a hood, a collar): the bust's neck shows skin there.
            NeckClothes neck;
            neck.skinLab = out.hair.skinLab;
            neck.topY = out.fit.mesh.positions[base_.frontFeatures.at(landmarkName(8))].y - kNeckClothesUnderChinMm;
            // Behind the ears, from under the lobes (the head's origin lies between the ear holes).
            const glm::dvec3 ear = out.fit.earsPlaced ? out.fit.earMiddleMm : glm::dvec3(0.0);
            neck.backTopY = ear.y - kNeckClothesUnderEarMm;
            neck.frontZ = ear.z + kNeckClothesUnderEarMm;
            neck.backZ = ear.z - 0.5 * kNeckClothesUnderEarMm;
            neck.keepHairBehind = isBigHair(out.hair.style);
            out.skinOverClothesTexels = skinOverClothesOnNeck(texture, out.fit.mesh, out.fit, ColourMatchMasks{m.frontHair, m.sideHair},
                                                              neck, settings_.texture, *textureTables_);
        }
        return texture;
    });
    out.partColours = measurePartColours(front, out.frontLandmarks);
    out.parts = placeParts(base_, out.fit.mesh, out.texture.texture, out.partColours);
    if (auto hair = placeHairPart(base_, out.fit.mesh, out.hair)) {
        // A bob as long behind the head as the side photo shows it, before its outline is fitted. (Long hair runs
        // past the bust's cut in the photos, and where it lies over the shoulders the band behind the neck shows
        // clothes: read there, it shortened long01 by a tenth on every long-haired FRMDB pair.)
        if (out.hair.style == HairStyle::Bob)
            out.hairLength = fitHairLengthBehind(hair->mesh, out.fit.mesh, out.fit.side, m.sideHair, jawTopDepth(base_, out.fit.mesh));
        // Big hair is as full as the photos show it (short hair is in the head's own outline already).
        if (isBigHair(out.hair.style)) {
            HairSilhouetteFit follow;
            follow.behind = out.hair.style != HairStyle::Ponytail;
            out.hairStretch = fitHairToSilhouettes(hair->mesh, out.fit.mesh, out.fit.front, out.frontMask, out.fit.side,
                                                   out.sideMask, out.fit.mesh.positions[base_.frontFeatures.at(landmarkName(8))].y,
                                                   follow);
        }
        // The photo showed the face (its landmarks were all found): the avatar's hair leaves it clear too.
        // bob02's fringe falls to the brows; a visitor whose forehead shows has none (FRMDB 008: the fringe made a
        // helmet of his parted curls). long01's and ponytail01's hair starts at the top of the forehead already:
        // pushed back there, their strand cards' ends showed as steps (007).
        FaceClearance clear;
        if (out.hair.style == HairStyle::Bob) clear.above = foreheadShownMm(m.frontHair, out.frontLandmarks.points, out.fit.front);
        out.foreheadShownMm = clear.above;
        keepFaceClear(hair->mesh, base_, out.fit.mesh, clear);
        if (out.hair.style == HairStyle::Short) {
            HairPhotoMasks masks{m.frontHair, out.frontMask, m.sideHair, out.sideMask, out.fit.front, out.fit.side};
            if (settings_.trimShortHair && cv::norm(out.hair.hairLab - out.hair.skinLab) >= kTrimMinHairSkinContrast)
                out.hairTrimmedVertices = trimShortHairToPhotos(hair->mesh, out.fit.mesh, masks);
            out.hairPulledInVertices = pullShortHairIntoOutlines(hair->mesh, out.fit.mesh, masks);
        }
        // The fitted head's ears stand out further than those MakeHuman's styles were made over (under the hair as
        // placed: tucked under what then goes behind the face, the ear's top stays under the temple's hair and the
        // head's side round the ear keeps its shape).
        if (hairCoversEars(out.hair.style)) {
            for (AvatarPart& part : out.parts)
                if (part.name == "head") tuckEarsUnderHair(part.mesh, hair->mesh, jawTopDepth(base_, out.fit.mesh));
            // Long hair and a bob hang over the ears; where the side photo shows the side of the face bare, the
            // hair goes behind it.
            const auto at = [&](int k) { return out.fit.mesh.positions[base_.frontFeatures.at(landmarkName(k))]; };
            const FaceSide face = faceSide(base_, out.fit.mesh);
            SideFaceClearance clearSide;
            clearSide.innerX = face.innerX;
            clearSide.frontZ = 0.5 * (at(36).z + at(45).z);
            clearSide.topY = face.browsTopY;
            clearSide.bottomY = at(8).y - kTuckUnderChinMm;
            out.hairTuckedVertices = tuckHairBehindTheFace(hair->mesh, out.fit.side, m.sideHair, clearSide);
        }
        out.parts.push_back(std::move(*hair));
    }
    // The brows onto the photo's own (which the texture shows where the fit put dlib's brow points): dlib puts them on
    // a brow's upper half, about 1.5 mm over its middle (the FRMDB overlays).
    std::vector<glm::dvec2> browPoints;
    for (int k = 17; k <= 26; ++k) browPoints.push_back(out.fit.front.toHead(out.frontLandmarks.points[static_cast<std::size_t>(k)]));
    for (AvatarPart& part : out.parts)
        if (part.name == "eyebrows") alignToPoints(part, out.fit.mesh, browPoints, 1.5);
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

}  // namespace avatarbooth
