// Side-photo analysis on the sample data: the 8 frmdb people in both profile directions (order and plausibility,
// overlays for a person to look at), their front photos refused, and the scan's side renders against landmarks
// taken from the scan's mesh and projected with the renders' exact cameras.
#include "common/error.h"
#include "fit/fit_error.h"
#include "fit/face/landmarks68.h"
#include "fit/face/profile.h"
#include "test_paths.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <array>
#include <chrono>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>
#include <string>

namespace {

using avatarbooth::analyseSidePhoto;
using avatarbooth::profilePoint;
using avatarbooth::SideAnalysis;
namespace fs = std::filesystem;

fs::path scanDir() { return avatarbooth::test::sharedData() / "scan_lee_perry_smith"; }

// The anatomical order along the face, top to bottom (glabella and nasion may share a height).
void expectAnatomicalOrder(const SideAnalysis& a) {
    const char* order[] = {"top_of_head", "forehead", "glabella", "nasion", "nose_tip", "subnasale",
                           "upper_lip",   "lower_lip", "chin",    "throat"};
    for (std::size_t k = 1; k < std::size(order); ++k) {
        const double above = profilePoint(a.landmarks, order[k - 1]).y;
        const double below = profilePoint(a.landmarks, order[k]).y;
        if (std::string(order[k]) == "nasion")
            EXPECT_LE(above, below) << order[k - 1] << " should not be below " << order[k];
        else
            EXPECT_LT(above, below) << order[k - 1] << " should be above " << order[k];
    }
}

// The nose tip is the face's most forward point: no outline point between the forehead and the chin is further
// forward (1 px of slack for the outline's pixel steps).
void expectNoseMostForward(const SideAnalysis& a) {
    const double sign = a.noseImageRight ? 1.0 : -1.0;
    const cv::Point2d nose = profilePoint(a.landmarks, "nose_tip");
    const double top = profilePoint(a.landmarks, "forehead").y, bottom = profilePoint(a.landmarks, "chin").y;
    double mostForward = -1e9;
    for (const auto& p : a.outline)
        if (p.y >= top && p.y <= bottom) mostForward = std::max(mostForward, sign * p.x);
    EXPECT_GE(sign * nose.x + 1.0, mostForward);
}

TEST(ProfileData, FrmdbProfilesBothDirections) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const fs::path dir = avatarbooth::test::scratchDir("profile_frmdb");
    double total = 0.0;
    int count = 0;
    for (int person = 1; person <= 8; ++person) {
        const std::string id = cv::format("%03d", person);
        // Img_13: the nose points image-left; Img_53: image-right.
        for (const auto& [shot, right] : {std::pair<std::string, bool>{"Img_13", false}, {"Img_53", true}}) {
            SCOPED_TRACE(id + "/" + shot);
            const cv::Mat bgr = cv::imread((avatarbooth::test::sharedData() / "frmdb" / id / (shot + ".jpg")).string());
            ASSERT_FALSE(bgr.empty());
            SideAnalysis a;
            const auto t0 = std::chrono::steady_clock::now();
            try {
                a = analyseSidePhoto(bgr);
            } catch (const avatarbooth::BoothError& e) {
                ADD_FAILURE() << "refused: " << e.what();
                continue;
            }
            total += avatarbooth::test::millisecondsSince(t0);
            ++count;
            cv::Mat overlay = bgr.clone();
            avatarbooth::drawSideOverlay(overlay, a);
            cv::imwrite((dir / (id + "_" + shot + ".png")).string(), overlay);

            EXPECT_EQ(a.noseImageRight, right);
            ASSERT_EQ(a.landmarks.size(), std::size(avatarbooth::kProfileLandmarkNames));
            expectAnatomicalOrder(a);
            expectNoseMostForward(a);
            // Scale and depth order: the nose tip lies well below the top of the head (faces are about 200 px
            // tall here), and back of the head, ear hole and nasion follow each other from back to front.
            const double V = profilePoint(a.landmarks, "nose_tip").y - profilePoint(a.landmarks, "top_of_head").y;
            EXPECT_GT(V, 100.0);
            const double sign = right ? 1.0 : -1.0;
            EXPECT_LT(sign * profilePoint(a.landmarks, "back_of_head").x,
                      sign * profilePoint(a.landmarks, "ear_hole").x);
            EXPECT_LT(sign * profilePoint(a.landmarks, "ear_hole").x, sign * profilePoint(a.landmarks, "nasion").x);
            for (const auto& w : a.warnings) std::cout << "[ " << id << "/" << shot << " ] warning: " << w << "\n";
        }
    }
    if (count) std::cout << "[ frmdb ] mean side analysis time " << total / count << " ms per 972x544 photo\n";
}

// Every frmdb view as a side photo (Img_13/53 profiles, Img_23 turned about 65-75 degrees, Img_33 fronts, Img_43
// about 35-60 degrees): what the analysis makes of it, with dlib's points for half-turned faces as the pipeline
// gives them. The profiles fit; a front is a front view; a half-turned frontal face (the 45-degree views the
// cascade sees) is told to turn more.
TEST(ProfileData, EveryFrmdbViewAsASidePhoto) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    static const avatarbooth::LandmarkDetector detector(AVATARBOOTH_DEFAULT_DLIB_MODEL);
    avatarbooth::SideOptions options;
    options.landmarkDetector = &detector;
    int turnMore = 0;
    for (int person = 1; person <= 8; ++person)
        for (const char* shot : {"Img_13", "Img_23", "Img_33", "Img_43", "Img_53"}) {
            const std::string id = cv::format("%03d", person);
            SCOPED_TRACE(id + "/" + shot);
            const cv::Mat bgr = cv::imread((avatarbooth::test::sharedData() / "frmdb" / id / (std::string(shot) + ".jpg")).string());
            ASSERT_FALSE(bgr.empty());
            const std::string name(shot);
            try {
                const SideAnalysis a = analyseSidePhoto(bgr, cv::Mat(), options);
                std::cout << "[ " << id << "/" << shot << " ] accepted; eye " << a.turn.eyeBehind << " V behind the outline, turn "
                          << a.turn.degrees << " degrees; ear "
                          << (a.turn.ear.found ? cv::format("%.2f V behind the nose tip (%.3f of the head), folds %.2f",
                                                            a.turn.ear.front, a.turn.ear.front / a.turn.ear.headLength,
                                                            a.turn.ear.fold)
                                               : std::string("not found"))
                          << (a.turn.pastProfile ? ": past the profile" : "") << "\n";
                EXPECT_NE(name, "Img_33") << "a front accepted";
                EXPECT_FALSE(a.turn.pastProfile) << "none of frmdb's views is turned past the profile";
            } catch (const avatarbooth::FitError& e) {
                std::cout << "[ " << id << "/" << shot << " ] refused: " << e.what() << "\n";
                EXPECT_TRUE(name != "Img_13" && name != "Img_53") << "a profile refused: " << e.what();
                if (name == "Img_33") {
                    EXPECT_EQ(e.fault(), avatarbooth::FitFault::NotProfile) << e.what();
                }
                if (e.fault() == avatarbooth::FitFault::TurnMore) {
                    EXPECT_TRUE(name == "Img_23" || name == "Img_43") << e.what();
                    turnMore += name == "Img_43";
                }
            }
        }
    // Measured 2026-12-04: 5 of the 8: 004, 005, 006 and 007 by the cascade's face and its dlib points, 002 (whose
    // outline has no nose) by dlib's detector finding its face looking aside (it was "a front view"); 001, 003 and
    // 008 (about 60, 40 and 50 degrees; no frontal face found) pass as profiles, as they did before.
    std::cout << "[ frmdb ] Img_43 told to turn more: " << turnMore << " of 8\n";
    EXPECT_GE(turnMore, 5);
}

TEST(ProfileData, FrmdbFrontsAreRefusedAsFrontViews) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    for (int person = 1; person <= 8; ++person) {
        const std::string id = cv::format("%03d", person);
        SCOPED_TRACE(id);
        const cv::Mat bgr = cv::imread((avatarbooth::test::sharedData() / "frmdb" / id / "Img_33.jpg").string());
        ASSERT_FALSE(bgr.empty());
        try {
            (void)analyseSidePhoto(bgr);
            ADD_FAILURE() << "a front photo was accepted as a profile";
        } catch (const avatarbooth::BoothError& e) {
            EXPECT_EQ(e.kind(), avatarbooth::ErrorKind::Mismatch) << e.what();
            EXPECT_NE(std::string(e.what()).find("front view, not a profile"), std::string::npos) << e.what();
        }
        // For the log: what the silhouette alone (no face detector) makes of the front photo.
        avatarbooth::SideOptions silhouetteOnly;
        silhouetteOnly.rejectFrontViews = false;
        try {
            (void)analyseSidePhoto(bgr, cv::Mat(), silhouetteOnly);
            std::cout << "[ " << id << "/Img_33 ] silhouette alone: accepted (the face detector refuses it)\n";
        } catch (const avatarbooth::BoothError& e) {
            std::cout << "[ " << id << "/Img_33 ] silhouette alone: refused (" << e.what() << ")\n";
        }
    }
}

// ------------------------------------------------------------------------------ the scan: truth from the mesh

struct Camera {
    cv::Matx33d K, R;
    cv::Vec3d t;
    // Pixel coordinates with pixel centres at integers (the cameras file puts them at integer + 0.5).
    cv::Point2d project(const cv::Vec3d& X) const {
        const cv::Vec3d c = R * X + t;
        return {K(0, 0) * c[0] / c[2] + K(0, 2) - 0.5, K(1, 1) * c[1] / c[2] + K(1, 2) - 0.5};
    }
};

Camera loadCamera(const std::string& view) {
    std::ifstream in(scanDir() / "renders" / "LeePerrySmith_cameras.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    Camera cam;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            cam.K(r, c) = j["K"][r][c].get<double>();
            cam.R(r, c) = j["views"][view]["R"][r][c].get<double>();
        }
    for (int r = 0; r < 3; ++r) cam.t[r] = j["views"][view]["t"][r].get<double>();
    return cam;
}

struct ObjMesh {
    std::vector<cv::Vec3d> v;
    std::vector<std::array<int, 3>> f;
};

ObjMesh loadObj(const fs::path& file) {
    ObjMesh m;
    std::ifstream in(file);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream ss(line);
        std::string tag;
        ss >> tag;
        if (tag == "v") {
            cv::Vec3d p;
            ss >> p[0] >> p[1] >> p[2];
            m.v.push_back(p);
        } else if (tag == "f") {
            std::array<int, 3> tri{};
            for (int& idx : tri) {
                std::string corner;
                ss >> corner;
                idx = std::stoi(corner.substr(0, corner.find('/'))) - 1;
            }
            m.f.push_back(tri);
        }
    }
    return m;
}

// Where the mesh crosses the plane x = x0: the mid-sagittal profile as a cloud of points.
std::vector<cv::Vec3d> sagittalProfile(const ObjMesh& m, double x0) {
    std::vector<cv::Vec3d> out;
    for (const auto& tri : m.f)
        for (int e = 0; e < 3; ++e) {
            const cv::Vec3d a = m.v[static_cast<std::size_t>(tri[static_cast<std::size_t>(e)])];
            const cv::Vec3d b = m.v[static_cast<std::size_t>(tri[static_cast<std::size_t>((e + 1) % 3)])];
            if ((a[0] - x0) * (b[0] - x0) > 0.0 || a[0] == b[0]) continue;
            const double s = (x0 - a[0]) / (b[0] - a[0]);
            out.push_back(a + (b - a) * s);
        }
    return out;
}

// Ground truth in scan units (y up, face along +z), each with its definition:
//   nose_tip     the mesh's most forward vertex;
//   top_of_head  its highest vertex;
//   chin         the most forward point of the mid-sagittal profile 0.9-1.7 units below the nose tip (lips end
//                about 0.8 below it, the jaw turns under about 1.8 below);
//   nasion       the most backward point of the face's profile (z > 1) 0.4-1.1 units above the nose tip;
//   back_of_head the most backward point of the profile between 0.3 above the nose tip and 0.5 below the top.
std::map<std::string, cv::Vec3d> meshLandmarks() {
    const ObjMesh mesh = loadObj(scanDir() / "LeePerrySmith.obj");
    std::map<std::string, cv::Vec3d> t;
    cv::Vec3d nose = mesh.v.front(), top = mesh.v.front();
    for (const auto& p : mesh.v) {
        if (p[2] > nose[2]) nose = p;
        if (p[1] > top[1]) top = p;
    }
    t["nose_tip"] = nose;
    t["top_of_head"] = top;
    const auto profile = sagittalProfile(mesh, nose[0]);
    auto pick = [&](double yLo, double yHi, double zMin, bool forward) {
        cv::Vec3d best(0, 0, forward ? -1e9 : 1e9);
        for (const auto& p : profile)
            if (p[1] >= yLo && p[1] <= yHi && p[2] >= zMin && (forward ? p[2] > best[2] : p[2] < best[2])) best = p;
        return best;
    };
    t["chin"] = pick(nose[1] - 1.7, nose[1] - 0.9, -1e9, true);
    t["nasion"] = pick(nose[1] + 0.4, nose[1] + 1.1, 1.0, false);
    cv::Vec3d back(0, 0, 1e9);
    for (const auto& p : profile)
        if (p[1] >= nose[1] + 0.3 && p[1] <= top[1] - 0.5 && p[2] < back[2]) back = p;
    t["back_of_head"] = back;
    return t;
}

void checkScanProfile(const std::string& view, bool noseRight) {
    const cv::Mat bgr = cv::imread((scanDir() / "renders" / ("LeePerrySmith_" + view + "_rgb.png")).string());
    ASSERT_FALSE(bgr.empty());
    const auto t0 = std::chrono::steady_clock::now();
    const SideAnalysis a = analyseSidePhoto(bgr);
    const double ms = avatarbooth::test::millisecondsSince(t0);
    EXPECT_EQ(a.noseImageRight, noseRight);
    cv::Mat overlay = bgr.clone();
    avatarbooth::drawSideOverlay(overlay, a);
    const Camera cam = loadCamera(view);
    const auto truth = meshLandmarks();
    std::map<std::string, cv::Point2d> px;
    for (const auto& [name, X] : truth) {
        px[name] = cam.project(X);
        cv::drawMarker(overlay, px[name], cv::Scalar(255, 0, 0), cv::MARKER_CROSS, 14, 2);
    }
    cv::imwrite((avatarbooth::test::scratchDir("profile_scan_" + view) / "overlay.png").string(), overlay);

    const double headHeight = px["chin"].y - px["top_of_head"].y;
    std::cout << "[ scan " << view << " ] " << ms << " ms, head height " << headHeight << " px\n";
    for (const auto& [name, truthPx] : px) {
        const cv::Point2d found = profilePoint(a.landmarks, name);
        const double err = cv::norm(found - truthPx);
        std::cout << "    " << name << ": error " << err << " px = " << 100.0 * err / headHeight
                  << "% of head height (dx " << found.x - truthPx.x << ", dy " << found.y - truthPx.y << ")\n";
        if (name == "top_of_head") {
            // The crown is flat: its outline stays within a pixel of its highest row over about 40 px, so where
            // along it the highest point lies is a matter of a pixel's rounding. Its height is what counts.
            EXPECT_LE(std::abs(found.y - truthPx.y), 0.02 * headHeight) << name;
            EXPECT_LE(std::abs(found.x - truthPx.x), 0.08 * headHeight) << name;
        } else {
            EXPECT_LE(err, 0.04 * headHeight) << name << " at " << found << ", truth " << truthPx;
        }
    }
    expectAnatomicalOrder(a);
}

TEST(ProfileData, ScanRightProfileMatchesMeshLandmarks) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    checkScanProfile("yaw+090", true);
    // Ear hole: marked by hand on the +090 render (the opening behind the tragus) at (466, 652); the estimate is a
    // proportion rule (profile.cpp), expected within 6% of the head height here.
    const cv::Mat bgr = cv::imread((scanDir() / "renders" / "LeePerrySmith_yaw+090_rgb.png").string());
    const SideAnalysis a = analyseSidePhoto(bgr);
    const double headHeight = profilePoint(a.landmarks, "chin").y - profilePoint(a.landmarks, "top_of_head").y;
    const double err = cv::norm(profilePoint(a.landmarks, "ear_hole") - cv::Point2d(466, 652));
    std::cout << "    ear_hole (hand-marked): error " << err << " px = " << 100.0 * err / headHeight << "%\n";
    EXPECT_LE(err, 0.06 * headHeight);
}

TEST(ProfileData, ScanLeftProfileMatchesMeshLandmarks) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    checkScanProfile("yaw-090", false);
}

TEST(ProfileData, ScanFrontIsRefusedAsFrontView) {
    AVATARBOOTH_REQUIRE_SHARED_DATA();
    const cv::Mat bgr = cv::imread((scanDir() / "renders" / "LeePerrySmith_yaw+000_rgb.png").string());
    ASSERT_FALSE(bgr.empty());
    try {
        (void)analyseSidePhoto(bgr);
        ADD_FAILURE() << "the scan's front render was accepted as a profile";
    } catch (const avatarbooth::BoothError& e) {
        EXPECT_EQ(e.kind(), avatarbooth::ErrorKind::Mismatch) << e.what();
    }
}

}  // namespace
