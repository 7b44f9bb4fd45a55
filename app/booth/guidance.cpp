// Hints for the front and side guides, and the cheap preview analyses behind them.
#include "booth/guidance.h"

#include "common/error.h"
#include "fit/face/landmarks68.h"
#include "fit/face/profile.h"
#include "fit/face/silhouette.h"

#include <opencv2/imgproc.hpp>

#include <cmath>

namespace avatarbooth {

cv::Rect2d ovalBox(const FaceOval& oval, cv::Size frame) {
    const double h = oval.height * frame.height, w = oval.aspect * h;
    return {oval.centreX * frame.width - 0.5 * w, oval.centreY * frame.height - 0.5 * h, w, h};
}

Hint frontHint(const FrontObservation& obs, const GuidanceSettings& s) {
    if (!obs.face || obs.face->width <= 0 || obs.face->height <= 0 || obs.frame.height <= 0) return Hint::NoFace;
    const cv::Rect2d oval = ovalBox(s.oval, obs.frame);
    const cv::Rect2d& f = *obs.face;
    const double size = f.height / (s.faceToOval * oval.height);
    if (size < 1.0 - s.sizeTolerance) return Hint::StepCloser;
    if (size > 1.0 + s.sizeTolerance) return Hint::StepBack;
    const double dx = (f.x + 0.5 * f.width) - (oval.x + 0.5 * oval.width);
    const double dy = (f.y + 0.5 * f.height) - (oval.y + (0.5 + s.faceBelowCentre) * oval.height);
    if (std::abs(dx) > s.centreToleranceX * oval.height || std::abs(dy) > s.centreToleranceY * oval.height)
        return Hint::MoveToCentre;
    if (obs.landmarks) {
        const auto& p = *obs.landmarks;
        const cv::Point2d eyeL = p[36], eyeR = p[45];
        const double eyes = cv::norm(eyeR - eyeL);
        if (eyes > 0.0) {
            const double yaw = noseOffsetYaw(p);
            const double roll = std::atan2(eyeR.y - eyeL.y, eyeR.x - eyeL.x) * 180.0 / CV_PI;
            if (std::abs(yaw) > s.maxYaw || std::abs(roll) > s.maxRollDegrees) return Hint::LookAtCamera;
        }
    }
    return Hint::HoldStill;
}

Hint sideHint(const SideObservation& obs) {
    if (!obs.personSeen) return Hint::TurnRight;
    if (obs.frontalFace) return std::abs(obs.frontalYaw) > kHalfTurnedYaw ? Hint::TurnMore : Hint::TurnRight;
    if (!obs.profileSeen) return obs.faceLooked && !obs.faceShows ? Hint::FaceHidden : Hint::TurnMore;
    if (obs.turnedBack) return Hint::TurnBack;
    if (obs.turnedShort) return Hint::TurnMore;
    return Hint::HoldStill;
}

PreviewAnalyser::PreviewAnalyser(const LandmarkDetector* detector, Options options)
    : detector_(detector), options_(std::move(options)) {
    const std::filesystem::path dir = options_.cascadeDir.empty()
                                          ? std::filesystem::path(AVATARBOOTH_DEFAULT_CASCADE_DIR)
                                          : options_.cascadeDir;
    // The LBP "improved" cascade: as reliable as Haar on booth photos and about 4x faster (see face/profile.cpp).
    const std::filesystem::path candidates[] = {
        dir.parent_path() / "lbpcascades" / "lbpcascade_frontalface_improved.xml",
        dir / "lbpcascade_frontalface_improved.xml", dir / "haarcascade_frontalface_alt2.xml"};
    for (const auto& c : candidates) {
        std::error_code ec;
        if (std::filesystem::is_regular_file(c, ec) && cascade_.load(c.string())) return;
    }
    throw BoothError(ErrorKind::BadConfig, dir.string(),
                     "no frontal-face cascade (lbpcascade_frontalface_improved.xml or haarcascade_frontalface_alt2.xml)"
                     " found; install opencv-data");
}

PreviewAnalyser::~PreviewAnalyser() = default;

std::vector<cv::Rect> PreviewAnalyser::frontalFaces(const cv::Mat& grey, int minSize, int maxSize) {
    std::vector<cv::Rect> faces;
    cascade_.detectMultiScale(grey, faces, 1.1, 4, 0, cv::Size(minSize, minSize), cv::Size(maxSize, maxSize));
    std::sort(faces.begin(), faces.end(), [](const cv::Rect& a, const cv::Rect& b) { return a.area() > b.area(); });
    return faces;
}

FrontObservation PreviewAnalyser::observeFront(const cv::Mat& bgr) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw BoothError(ErrorKind::BadInput, "preview", "expected a non-empty BGR frame");
    FrontObservation obs;
    obs.frame = bgr.size();
    // The face box comes from the LBP cascade on a 320 px copy (about 4x cheaper than dlib's HOG detector on the
    // 640 px copy it needs for booth faces); the 68-point predictor then runs in that box (about 3 ms).
    const double scale = std::min(1.0, 320.0 / bgr.cols);
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    cv::resize(grey, grey, {}, scale, scale, cv::INTER_AREA);
    cv::equalizeHist(grey, grey);
    const auto faces = frontalFaces(grey, std::max(24, grey.rows / 8), grey.rows);
    if (faces.empty()) return obs;
    const cv::Rect& f = faces.front();
    obs.face = cv::Rect2d(f.x / scale, f.y / scale, f.width / scale, f.height / scale);
    if (detector_) {
        const cv::Rect box(cvRound(obs.face->x), cvRound(obs.face->y), cvRound(obs.face->width),
                           cvRound(obs.face->height));
        obs.landmarks = detector_->landmarksIn(bgr, box);
    }
    return obs;
}

SideObservation PreviewAnalyser::observeSide(const cv::Mat& bgr, const cv::Mat& plate) {
    if (bgr.empty() || bgr.type() != CV_8UC3)
        throw BoothError(ErrorKind::BadInput, "preview", "expected a non-empty BGR frame");
    SideObservation obs;
    const double scale = std::min(1.0, static_cast<double>(options_.sideHeight) / bgr.rows);
    cv::Mat small, smallPlate;
    cv::resize(bgr, small, {}, scale, scale, cv::INTER_AREA);
    if (!plate.empty()) cv::resize(plate, smallPlate, small.size(), 0, 0, cv::INTER_AREA);

    cv::Mat grey;
    cv::cvtColor(small, grey, cv::COLOR_BGR2GRAY);
    cv::equalizeHist(grey, grey);
    if (const auto faces = frontalFaces(grey, std::max(24, grey.rows / 8), grey.rows); !faces.empty()) {
        obs.personSeen = obs.frontalFace = true;
        if (detector_) {
            const cv::Rect& f = faces.front();
            obs.frontalYaw = noseOffsetYaw(detector_->landmarksIn(small, f));
        }
        return obs;  // no need for the outline: the visitor has not turned far yet
    }
    cv::Mat mask;
    try {
        mask = segmentPerson(small, smallPlate);
    } catch (const BoothError& e) {
        if (e.kind() == ErrorKind::NoFace) return obs;  // nobody in front of the camera
        throw;
    }
    obs.personSeen = true;
    std::vector<cv::Point2d> outline;
    for (const auto& p : largestOutline(mask)) outline.emplace_back(p.x, p.y);
    const ProfileFit right = fitProfile(outline, true), left = fitProfile(outline, false);
    const bool profile = right.ok || left.ok;
    if (!profile && !detector_) return obs;
    // The ear's folds are a few pixels wide at the preview's size, and a face there is below dlib's 80 px: the turn
    // and the face are read on the frame itself.
    cv::Mat frameMask;
    cv::resize(mask, frameMask, bgr.size(), 0, 0, cv::INTER_NEAREST);
    if (!profile) {
        // dlib's detector costs about 4x the cascade, so it runs only where the outline cannot say which way the
        // visitor should turn (analyseSidePhoto does the same).
        obs.faceLooked = true;
        obs.faceShows = faceOnPerson(*detector_, bgr, frameMask).has_value();
        return obs;
    }
    obs.noseImageRight = profileFacesRight(right, left);
    const ProfileFit& fit = obs.noseImageRight ? right : left;  // one with a nose: `profile`
    obs.noseProminence = fit.noseProminence;
    obs.profileSeen = true;
    std::vector<ProfilePoint> landmarks = fit.landmarks;
    for (auto& p : landmarks) p.px = p.px / scale;
    const ProfileTurn turn = estimateProfileTurn(bgr, frameMask, landmarks, obs.noseImageRight);
    if (turn.known) obs.turnDegrees = turn.degrees;
    obs.turnedBack = turn.pastProfile;
    // The detector only where the eye and the ear already say "well short": a profile costs no more.
    if (detector_ && turnedShortCues(turn)) obs.turnedShort = faceOnPerson(*detector_, bgr, frameMask).has_value();
    return obs;
}

PreviewAnalysed PreviewAnalyser::analyse(Photo photo, const cv::Mat& bgr, const GuidanceSettings& settings,
                                         FlowTime t) {
    if (photo == Photo::Front) {
        const FrontObservation obs = observeFront(bgr);
        return {photo, frontHint(obs, settings), obs.face.has_value(), t};
    }
    const SideObservation obs = observeSide(bgr);
    return {photo, sideHint(obs), obs.personSeen, t};
}

}  // namespace avatarbooth
