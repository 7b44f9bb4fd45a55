// The synthetic visitor: front and side photos of a head whose shape and landmarks are known exactly, so that
// fitting can be checked against ground truth and the booth can be demonstrated without a camera.
//
// The head is the base head deformed by a smooth analytic warp (per-axis scaling, a wider or narrower jaw, a
// longer or shorter nose, a fuller back of the head, a longer chin) whose form differs from the fit's RBF warp,
// so that the fit cannot recover it exactly by construction. Its face is painted procedurally in texture space
// (skin, hair cap, brows, eyes with iris and pupil, lips, nostrils) and lit by the renderer, well enough that
// dlib's face detector and landmark predictor find it. sim/makehuman_visitor.h makes MakeHuman people and takes
// their photos the same way (photographSyntheticHead).
#pragma once

#include "fit/head/base_head.h"
#include "fit/head/mesh.h"
#include "fit/parts/avatar_part.h"
#include "render/mesh_renderer.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace avatarbooth {

struct SyntheticVisitorOptions {
    unsigned seed = 1;              // picks the warp's coefficients (seed 0: no warp, the base head itself)
    double mmPerPixel = 0.6;        // orthographic scale of both photos
    cv::Size imageSize{972, 720};
    bool sideNoseImageRight = true; // which way the profile faces in the side photo
    int textureSize = 1024;
    // false: the photos show the painted colours exactly, without shading (to check texturing against the paint).
    bool lit = true;
};

struct SyntheticVisitor {
    cv::Mat front, side;   // the photos (BGR), the head composited on a backdrop with shoulders
    cv::Mat background;    // the empty booth: the same backdrop without the person
    cv::Mat texture;       // the painted face texture (base head UVs)
    Mesh truthMesh;        // the visitor's head: the base head's topology, warped positions
    RenderCamera frontCamera, sideCamera;
    // Ground-truth 2-D landmarks in photo pixels (pixel centres at +0.5): the warped feature vertices projected.
    std::map<std::string, cv::Point2d> frontLandmarks;  // ibug_00 .. ibug_67
    std::map<std::string, cv::Point2d> sideLandmarks;   // profile names (nose_tip, chin, ...)
};

// Where the head mesh's neck ends (head space, millimetres): the photos draw a shirt from there down. The defaults
// are the built-in head's.
struct SyntheticNeck {
    double baseY = -150.0;     // the shirt's top edge: above the neck mesh's lowest vertices, so that no gap shows
    double halfWidth = 48.0;   // of the neck there (front view)
    double frontZ = 40.0, backZ = -60.0;  // the neck's front and back there (side view)
};

// How the synthetic photos are taken: orthographic front and side views of the head on a cloth backdrop, shoulders
// below.
struct SyntheticPhotoSetup {
    double mmPerPixel = 0.6;
    cv::Size imageSize{972, 720};
    bool sideNoseImageRight = true;
    // The side camera's angle from the front, degrees: 90 a true profile, less a visitor who has not turned far
    // enough (60: both eyes show), more one turned past the profile (the back of the head shows more). The
    // visitor turns whole, shoulders with the head.
    double sideYawDeg = 90.0;
    bool lit = true;
    unsigned backdropSeed = 1;           // the backdrop's folds
    glm::dvec3 target{0.0, -45.0, 0.0};  // at the image centre: the head in the upper middle, shoulders below
    SyntheticNeck neck;
    cv::Scalar shirt{96, 110, 40};       // BGR
    // Drawn with the head (the hair proxy on the person's head), in head space.
    std::vector<AvatarPart> parts;
};

// Renders v.truthMesh with v.texture from the front and the side, composites both on the backdrop (v.front, v.side,
// v.background, the cameras) and projects the ground truth: base's feature vertices on v.truthMesh (same
// topology), and `earHole` (head space) as the side photo's "ear_hole".
void photographSyntheticHead(SyntheticVisitor& v, const BaseHead& base, const glm::dvec3& earHole, MeshRenderer& renderer,
                             const SyntheticPhotoSetup& setup);

// The warp applied to base-head points for a given seed.
glm::dvec3 syntheticWarp(const glm::dvec3& p, unsigned seed);

// The procedural face texture for a base head (depends only on the base head).
cv::Mat paintSyntheticFace(const BaseHead& base, int textureSize);

SyntheticVisitor makeSyntheticVisitor(const BaseHead& base, MeshRenderer& renderer,
                                      const SyntheticVisitorOptions& options = {});

// Writes a recorded session folder: front.jpg, side.jpg, background.png and truth/ (head.glb with the texture,
// landmarks.json with the ground-truth points and cameras).
void writeSyntheticVisitorFolder(const SyntheticVisitor& visitor, const std::filesystem::path& dir);

// The default synthetic visitor's folder in `dir`, made (about 2 s and 200 MB: a render) only when it is missing or
// was left incomplete. Returns `dir`.
std::filesystem::path ensureSyntheticVisitorFolder(const std::filesystem::path& dir);

}  // namespace avatarbooth
