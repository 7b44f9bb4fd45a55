// The MakeHuman synthetic visitor: a person drawn at random (seeded) from MakeHuman's own shape space, photographed
// front and side like the booth photographs a visitor, with the true head and landmarks known exactly. A seeded
// set of them is the fit's regression corpus (tests/data/makehuman_population_data_test.cpp).
//
// The person is the product's base head (MakeHuman's) with the modifier weights drawn here: sex, age, ethnicity,
// weight, muscle and proportions through the macro directions, a handful of face modifiers (ears among them) at
// moderate weights, mostly symmetric. The true head is the basis applied to the base head, so the fit's first step
// could in principle find it exactly; what it cannot is the scale (the eye distance is assumed), the photos' noise
// and what dlib makes of them. The texture is the MakeHuman skin of the drawn age, sex and ethnicity, with eyes
// (iris, pupil) painted on the eyeballs, brows, and hair (a colour above a hairline; some are bald).
#pragma once

#include "fit/head/base_head.h"
#include "render/mesh_renderer.h"
#include "sim/synthetic_visitor.h"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace avatarbooth {

struct MakeHumanVisitorOptions {
    // Picks the person, the hair, the eyes and the backdrop's folds; sex, age group and ethnicity (so the skin) go
    // round with it, every combination once in any 18 seeds in a row.
    unsigned seed = 1;
    double mmPerPixel = 0.6;
    cv::Size imageSize{972, 720};
    bool sideNoseImageRight = true;
    double sideYawDeg = 90.0;  // the side photo's angle from the front (SyntheticPhotoSetup::sideYawDeg)
    bool lit = true;
    // Where the skins are (NAME.jpg on the base head's UVs, as make-base-head writes them); empty: the skins/ folder
    // beside the product's base head (findMakeHumanBaseHead()).
    std::filesystem::path skinsDir;
    // Wear the drawn hair style's MakeHuman proxy (fit/parts/hair_part.h) over the painted scalp. Off for the fit's
    // regression corpus until the profile analysis copes with a fringe or a bob over the profile (with it on, 16 of
    // 60 side photos are refused and the median face RMS is 2.7 / 2.3 mm instead of 1.0 / 1.6).
    bool hairProxies = false;
};

// Who was drawn.
struct MakeHumanPerson {
    std::string sex;        // "female", "male"
    std::string age;        // "young", "middleage", "old"
    std::string ethnicity;  // "african", "asian", "caucasian" (the largest share; the others may be mixed in)
    std::string skin;       // the MakeHuman skin: AGE_ETHNICITY_SEX
    std::string hair;       // its colour, or "bald"
    // The hair as the photos show it (fit/face/hair_analysis.h's styles): "none" (bald, or balding: a horseshoe),
    // or the style drawn; "short" is a painted cap of hair on the scalp.
    std::string hairStyle;
    cv::Vec3d hairColour{0.0, 0.0, 0.0};  // BGR, the painted hair's colour (before shading), when there is hair
    std::string beard;      // "none", "moustache" or "full" (chin, jaw and upper lip)
    std::string eyes;       // the iris colour
    cv::Vec3d irisBgr{0, 0, 0}, browBgr{0, 0, 0};  // the colours painted (0..255, before the photos' shading)
    std::vector<double> weights;  // one per modifier of the base head's basis, in [0, 1]
};

struct MakeHumanVisitor {
    SyntheticVisitor photos;  // photos, texture, true mesh, cameras, ground-truth landmarks
    MakeHumanPerson person;
};

// The random part alone: the person a seed gives for this basis (it must be MakeHuman's: the macro directions and
// face modifiers are looked up by name; BoothError(BadConfig) when one is missing).
MakeHumanPerson drawMakeHumanPerson(const ModifierBasis& basis, unsigned seed);

// `mh` must be the MakeHuman base head (productBaseHead()), with its modifier basis. Throws BoothError(BadConfig)
// when the basis or the skin file is missing. About 0.3 s (two renders).
MakeHumanVisitor makeMakeHumanVisitor(const BaseHead& mh, MeshRenderer& renderer, const MakeHumanVisitorOptions& options = {});

// The session folder of writeSyntheticVisitorFolder, and truth/person.json (who was drawn: sex, age, ethnicity,
// skin, hair, eyes and the modifiers' weights that are not 0).
void writeMakeHumanVisitorFolder(const MakeHumanVisitor& visitor, const BaseHead& mh, const std::filesystem::path& dir);

}  // namespace avatarbooth
