// Texturing the fitted head from the two photos (METHODS §1 step 6, with §4's multi-view practice): every texel
// takes its colour from the one photo that sees that surface point best, and the seam between the photos is
// blended band by band (OpenCV's multi-band blender) so that it does not show and no feature is doubled.
#pragma once

#include "fit/head/head_fit.h"
#include "fit/head/surface_texels.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <limits>
#include <vector>

namespace avatarbooth {

struct PhotoTextureOptions {
    int size = 1024;
    // Exponent on the cosine between surface normal and view direction: a photo's weight at a texel, which decides
    // (with frontPreference) which of the two photos a texel both see takes.
    double angleStrictness = 2.0;
    // How much the front photo is preferred: a texel both photos see goes to the side photo only where the side
    // weight exceeds frontPreference times the front weight (with cos^2 weights and 1.5: where the surface turns more
    // than about 51 degrees from the front). The front photo is registered by 68 landmarks in (x, y); the side
    // photo's colour lands through the fitted depth z, which off the profile line is the base head's guess, so on
    // the face (cheeks by the nose and mouth) it is the less trustworthy of the two. But the nearer the seam comes
    // to where the surface faces the front camera and not the side's, the darker the front photo's side of it
    // (the booth's light comes from the cameras): with 4 (63 degrees) every FRMDB profile showed a dark band down
    // the cheek from the brow to the jaw, 003's as a line; at 1.5 it is gone from all but the darkest-shaded fronts.
    double frontPreference = 1.5;
    // Round the eyes and brows (TextureTables' front features) the front photo is preferred more: there a side
    // photo's eye corner or brow tail a few millimetres off the head's is a second one on the temple. 4 puts the
    // seam there at about 63 degrees. (It was 40, 81 degrees, before the side photo was read shifted by its eye's
    // offset, HeadFit::eyeLeftMm: the front photo's darkest band then ran from the brow to the cheek.) Full within
    // featureReachMm of a feature vertex, fading to frontPreference over the next featureFadeMm.
    double featureFrontPreference = 4.0;
    double featureReachMm = 25.0;
    double featureFadeMm = 15.0;
    // Bands of the multi-band blend across the seam (more = a wider, softer transition of the low frequencies): the
    // finest switches at the seam at full resolution, the others are OpenCV's MultiBandBlender at half resolution.
    int blendBands = 5;
    // The side photo's exposure is matched to the front's locally: over a Gaussian of this share of the texture's
    // side (about 10 mm on the face at any size); 0: one gain per channel for the whole photo.
    double exposureSmoothing = 1.0 / 42.0;
    // Depth tolerance of the visibility test in millimetres, on top of what the pixel size and slope allow.
    double depthToleranceMm = 2.0;
    // Where the side photo's ear lies further off than the ears' sliders could move the head's (HeadFit::earLeftMm),
    // the side photo is read shifted by what is left round the ears, so that its ear lands on the head's instead of
    // beside it on the scalp or the neck: in full within earReachMm of the ear's middle (the ear itself), fading out
    // smoothly over earFadeMm, or over twice the shift if that is more (so that the shifted reading cannot fold).
    double earReachMm = 30.0;
    double earFadeMm = 40.0;
    // Up or down, the side photo's eye is read where it lies off the head's (HeadFit::eyeLeftMm) round the eye only:
    // in full within eyeReachMm of its middle, fading out over eyeFadeMm (or twice the shift if more).
    double eyeReachMm = 12.0;
    double eyeFadeMm = 20.0;
};

struct PhotoTexture {
    cv::Mat texture;    // BGR, size x size, in the mesh's UV layout
    double seenFraction = 0.0;  // share of the head's texels some photo saw (the rest was filled in)
    // Where each texel's colour came from: 0 filled in (no photo saw it, or no triangle covers it), 1 the front
    // photo, 2 the side photo (either side of the head; mirrored for the side it did not see).
    cv::Mat source;     // CV_8U, size x size
    enum Source : unsigned char { Filled = 0, Front = 1, Side = 2 };
    // The per-channel (B, G, R) gain that matches the side photo's colours to the front photo's exposure and white
    // balance over all the skin both saw, and how many half-resolution texels that was (0: too few to measure, gain
    // 1). Each texel takes the gain measured near it (PhotoTextureOptions::exposureSmoothing); this is the whole's.
    cv::Vec3f sideGain{1.0f, 1.0f, 1.0f};
    int sideGainTexels = 0;
};

// Pixels of each photo that are not the visitor's skin (hair, a beard: hairPixels of the hair analysis), CV_8U of the
// photo's size, non-zero where not skin; or empty. The side photo's exposure is matched to the front's on the
// surface both photos see: where one of them shows hair there and the other skin (long hair falls over the front
// photo's temples and cheeks and lies behind them in the side photo), comparing the two measures the hair, not the
// exposure.
struct ColourMatchMasks {
    cv::Mat frontNotSkin, sideNotSkin;
};

// front/side: the photos as taken; the masks: their silhouettes. A texel takes a photo's colour only where that
// photo sees the surface point: facing the camera, inside the silhouette, and not hidden by another part of the
// head (a z-buffer of the fitted mesh rendered from that photo's orthographic view). The side photo is used for
// both sides of the head. Texels no photo saw (the back of the head) are filled from their surroundings by a
// pull-push (coarse-to-fine) fill, so they continue the hair and skin colours around them.
// What textureFromPhotos needs once per UV layout and texture size: which texel lies in which triangle, at the
// texture's size and at half of it. Depends only on the UVs, so every fitted head of one base head shares it: a
// pipeline makes it with its other one-off loading, so that the first visitor's texture does not pay for it.
class TextureTables {
public:
    // Throws BoothError(Internal) for a size under 16 texels.
    // `skin`: the base head's skin layer on its UVs (BaseHead::skin), or empty. `frontFeatures`: the base head's
    // vertices whose place the front photo registers and the side photo does not (the eyes' and brows' landmarks),
    // round which the front photo is preferred (PhotoTextureOptions::featureFrontPreference); or none.
    TextureTables(const Mesh& base, const PhotoTextureOptions& options, const cv::Mat& skin = {},
                  const std::vector<std::uint32_t>& frontFeatures = {});
    int size() const { return full_.size.width; }
    const TexelMap& full() const { return full_; }
    const TexelMap& half() const { return half_; }
    // Whether `mesh` has the UV layout the tables were made for (same vertex and triangle counts).
    bool fits(const Mesh& mesh) const { return mesh.uvs.size() == vertices_ && mesh.triangles.size() == triangles_; }
    // The skin layer's fine detail at the texture's size (CV_8SC3, levels), or empty: see addBaseLayerDetail.
    const cv::Mat& skinDetail() const { return skinDetail_; }
    // Per vertex, how much the front photo is preferred (PhotoTextureOptions::frontPreference, more round the front
    // features); empty when no features were given (frontPreference everywhere).
    const std::vector<float>& frontPreference() const { return frontPreference_; }

private:
    std::size_t vertices_, triangles_;
    TexelMap full_, half_;
    cv::Mat skinDetail_;
    std::vector<float> frontPreference_;
};

// `tables`: made for the fitted mesh's base head and options.size (BoothError Internal otherwise).
PhotoTexture textureFromPhotos(const Mesh& fitted, const HeadFit& fit, const cv::Mat& front, const cv::Mat& frontMask,
                               const cv::Mat& side, const cv::Mat& sideMask, const PhotoTextureOptions& options,
                               const TextureTables& tables, const ColourMatchMasks& notSkin = {});
// The same, making the tables for this one call.
PhotoTexture textureFromPhotos(const Mesh& fitted, const HeadFit& fit, const cv::Mat& front, const cv::Mat& frontMask,
                               const cv::Mat& side, const cv::Mat& sideMask, const PhotoTextureOptions& options = {},
                               const ColourMatchMasks& notSkin = {});

// Long hair or a bob hanging past the face's sides: the photos show it over the cheeks and temples, and the avatar's
// hair part, which leaves the face clear, does not, so that the photos' hair lay painted on bare cheeks (FRMDB 006,
// 007, 008). The part of the head where that happens, in millimetres: outward of innerX on either side (the eyes'
// outer corners: the brows, lashes and eyes, which count as hair too, lie inside), ahead of frontOfZ (the ears' front:
// hair behind the ears is the hair's), between bottomY and topY (the brows' top; the chin, or the nose tip when a
// beard is grown). Above topY, behind frontOfZ and under bottomY the repaint fades out over fadeMm (smoothly): cut
// there, the photo's hair at the temples ended in a straight edge across them (FRMDB 008).
struct FaceSides {
    double innerX = 0.0;
    double frontOfZ = -std::numeric_limits<double>::infinity();
    double bottomY = 0.0, topY = 0.0;
    double fadeMm = 15.0;
};
// Repaints the texels of `sides` that took a photo where it shows hair (notSkin: each photo's pixels off the skin; an
// empty mask says none) with the skin round them: continued by pull-push from the texels that took either photo's
// skin, with the skin layer's fine detail (tables.skinDetail), feathered at the edge. `options`: those the texture
// was made with (where it read the side photo). Returns how many texels were repainted.
int skinOverHairBesideFace(PhotoTexture& texture, const Mesh& fitted, const HeadFit& fit, const ColourMatchMasks& notSkin,
                           const FaceSides& sides, const PhotoTextureOptions& options, const TextureTables& tables);

// Clothes the photos show where the bust has its neck: a hood, a collar or a shirt's neckline round the bottom of
// the neck (FRMDB 002's yellow hood and 003's black T-shirt were painted on the back of their necks, where the side
// photo shows them). Under the neck's top (head space, mm: topY ahead of frontZ, under the chin; backTopY behind
// backZ, under the ears, where a hood rises to the nape; smoothly between) and fading in over fadeMm above it, the
// texels that took a photo where it shows neither hair (`hair`: each photo's hair pixels, empty: none known) nor a
// colour near the skin's (skinLab: CIE L*a*b*, the hair analysis' skin; lightness at lightnessWeight, as shading moves
// it far more than the chroma) are repainted with the skin round them (the texels near the skin's colour); so are the
// texels no photo saw there that the fill continued in such a colour. keepHairBehind false (short hair, none): what
// the hair pixels show behind the ears under the neck's top is not hair that hangs there but a dark collar
// (FRMDB 003's black T-shirt), and is repainted too.
struct NeckClothes {
    double topY = 0.0, frontZ = 0.0;
    double backTopY = 0.0, backZ = 0.0;
    double fadeMm = 15.0;
    bool keepHairBehind = true;
    cv::Vec3d skinLab{0.0, 0.0, 0.0};
    double lightnessWeight = 0.5;
    double maxSkinDistance = 20.0;
};
// Returns how many texels were repainted (at half weight or more).
int skinOverClothesOnNeck(PhotoTexture& texture, const Mesh& fitted, const HeadFit& fit, const ColourMatchMasks& hair,
                          const NeckClothes& neck, const PhotoTextureOptions& options, const TextureTables& tables);

// Where no photo saw the head (texels the fill made up: under the chin, in and behind the ears, parts of the top),
// the base head's skin layer lends its detail (TextureTables::skinDetail, added by textureFromPhotos), so that ears,
// creases and lips keep their shading while the colour stays the one the fill continued from the photos (hair where
// the photos showed hair).
void addBaseLayerDetail(PhotoTexture& texture, const cv::Mat& detail);

// Fills texels where weight == 0 from the others, coarse to fine (pull-push); texels of partial weight blend
// with the fill. colour: CV_32FC3, weight: CV_32F (all 1 afterwards).
void pullPushFill(cv::Mat& colour, cv::Mat& weight);

// A cut-out texture's (CV_8UC4, BGRA) colour carried from its opaque texels (alpha at least `opaqueFrom`) into
// its clear and partly clear ones by pullPushFill; alpha kept. MakeHuman's hair and brow textures are black where
// clear and dark where partly clear, and a renderer's filtering mixes those texels' colour into the strands'
// edges (long01's hairline was drawn with a dark fringe).
void bleedIntoClearTexels(cv::Mat& bgra, int opaqueFrom = 224);

}  // namespace avatarbooth
