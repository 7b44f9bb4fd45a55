// The generic base head that every visitor's head is fitted from (METHODS §1): a closed mesh with UVs over the
// whole head, and the feature vertices the fit moves onto measured positions.
#pragma once

#include "fit/head/mesh.h"
#include "fit/head/modifier_basis.h"
#include "fit/parts/head_proxy.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace avatarbooth {

// A vertex on the head's outline seen from the front (or the side), found by a ray from the view's centre
// (eye midpoint for the front, ear hole for the side) at an angle in degrees, counter-clockwise from the
// image's +x (subject's left in the front view, the face direction +z in the side view), y up.
struct ContourVertex {
    double angleDeg = 0.0;
    std::uint32_t vertex = 0;
};

struct BaseHead {
    Mesh mesh;
    // Feature vertices for the front photo's landmarks, keyed by landmark name ("ibug_00" .. "ibug_67").
    std::map<std::string, std::uint32_t> frontFeatures;
    // Feature vertices for the side photo's profile landmarks (nose_tip, chin, ...; see face/profile.h).
    std::map<std::string, std::uint32_t> sideFeatures;
    // Contour feature vertices on the front and side outlines.
    std::vector<ContourVertex> frontContour;
    std::vector<ContourVertex> sideContour;
    // The point between the ear holes (the side photo's centre); the built-in head has it at the origin.
    glm::dvec3 earHoleCentre{0.0};
    // Parts that move as one rigid piece (the eyeballs): the warp gives each its vertices' mean displacement, so a
    // sphere of small triangles is never bent.
    std::vector<std::vector<std::uint32_t>> rigidParts;
    // The shapes the fit's first step blends (the MakeHuman head's; none for a head without them).
    std::shared_ptr<const ModifierBasis> modifiers;
    // A skin texture on the head's UVs (BGR) for what no photo sees; empty: the photos' colours are spread there.
    cv::Mat skin;
    // The meshes bound to this head that become the avatar's other parts (eyes, eyebrows, eyelashes; hair, beard):
    // head_proxy.h. None for the built-in head.
    std::vector<HeadProxy> proxies;

    // Midpoint of the two eye centres (mean of ibug 36-41 and of 42-47): the front photo's centre.
    glm::dvec3 eyeMidpoint() const;
};

// The built-in base head, made by code (see base_head_generator.cpp for how, and how to make another).
const BaseHead& builtinBaseHead();
// The same, owned: a holder keeps it alive past the process's static destructors (a thread still loading the
// landmark model at exit reads it).
std::shared_ptr<const BaseHead> sharedBuiltinBaseHead();

// The product's base head: MakeHuman's (makehuman_import.h), made at build time into share/avatarbooth/base_head/
// and looked for in $AVATARBOOTH_ASSET_DIR/base_head, <exe>/../share/avatarbooth/base_head, the build tree and
// /usr/share/avatarbooth/base_head. Loaded once; throws BoothError(BadConfig) saying where it looked when none is
// there. The built-in head above stays as the small test fixture.
std::shared_ptr<const BaseHead> productBaseHead();
// The folder it is loaded from, or empty.
std::filesystem::path findMakeHumanBaseHead();

// Loads an operator's own base head: a glTF binary mesh (positions, UVs, one primitive) and a feature file
// (JSON, the format written by saveBaseHead). Errors name the file and the field.
BaseHead loadBaseHead(const std::filesystem::path& meshGlb, const std::filesystem::path& featureJson);

// Writes the feature file of a base head (its mesh is written with the glb exporter). The modifier basis and skin
// files, when named, are recorded relative to the feature file, and loadBaseHead reads them from there. The head's
// proxies are written into parts/ beside it (saveHeadProxy) and listed in it.
void saveFeatureFile(const BaseHead& head, const std::filesystem::path& featureJson,
                     const std::string& modifiersFile = "", const std::string& skinFile = "");

// Finds the contour vertices of a mesh seen orthographically along `viewAxis` (0 = from +z: front, 1 = from -x:
// the subject's right side), by rays from `centre` (projected) at the given angles.
std::vector<ContourVertex> findContourVertices(const Mesh& mesh, const glm::dvec3& centre, int viewAxis,
                                               const std::vector<double>& anglesDeg);

// The default ray angles for the front and side contours (the outline parts no landmark covers: the skull
// over the top and sides for the front; forehead, top, back of the head and nape for the side).
std::vector<double> defaultFrontContourAngles();
std::vector<double> defaultSideContourAngles();

}  // namespace avatarbooth
