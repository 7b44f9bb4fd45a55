// The hair part: the bundled MakeHuman hair proxy of the style the hair analysis chose (fit/face/hair_analysis.h),
// placed on the fitted head and tinted with the hair's colour from the photo.
#pragma once

#include "fit/face/hair_analysis.h"
#include "fit/head/base_head.h"
#include "fit/head/head_fit.h"
#include "fit/parts/avatar_part.h"
#include "fit/parts/head_proxy.h"

#include <optional>
#include <string_view>
#include <vector>

namespace avatarbooth {

// The MakeHuman proxy the avatar wears for a style ("short04", "bob02", "long01", "ponytail01"; none for
// HairStyle::None). Short hair is short04, a crop within 2 mm of the scalp: with short hair the head fit follows the
// photos' outline, hair included, so the part must add no volume of its own (short02 stands 14 mm off the scalp; over
// the fitted heads of FRMDB 002 and 003 it made a mushroom, README "Hair").
const char* hairProxyName(HairStyle style);

// A proxy that is one of the hair styles (named "hair"): an alternative, placed only when chosen.
bool isHairStyleProxy(const HeadProxy& proxy);

// The hair proxy of that name among base.proxies (its source "proxies/hair/NAME"), or null when the base head has none.
const HeadProxy* findHairProxy(const BaseHead& base, std::string_view proxyName);

// How far hair keeps off the face (keepFaceClear), in millimetres.
struct FaceClearance {
    double depth = 10.0;  // under the brows, what was ahead of the plane through the jaw's top keeps within this of it
    double ramp = 15.0;   // over the brows, the push fades out over this height
    // How far over the brows the face is kept clear as well: the forehead the photo shows as skin up to its hairline
    // (foreheadShownMm). 0: up to the brows, as under a fringe.
    double above = 0.0;
};

// How far over the brows the front photo shows the forehead's skin, in millimetres: going up each column of the
// forehead's middle (between brow points 19 and 24) from the brows, the first 2 mm of hair pixels (`hair`, CV_8U)
// is the hairline there; the median over the columns, less `margin`. 0 when hair lies on the brows (a fringe) or no
// hairline is found under the head's top.
double foreheadShownMm(const cv::Mat& hair, const std::array<cv::Point2d, 68>& points, const PhotoFrame& front,
                       double margin = 3.0);

// The depth of the plane through the jaw's top (ibug 0 and 16) on the fitted head, before which lies the face the
// photo shows (keepFaceClear, tuckEarsUnderHair). Throws BoothError(Internal) when the base head lacks those points.
double jawTopDepth(const BaseHead& base, const Mesh& fittedHead);

// Moves the hair that would hang in front of the face the photo shows. MakeHuman's styles are made for its default
// head; on the fitted heads bob02's fringe fell over an eye and its sides hid the cheeks from three-quarter view.
// Under the brows, the hair ahead of the plane through the jaw's top (ibug 0 and 16) is pushed back to within
// `depth` of it; over the brows the push fades out. Inside the face's outline that puts the hair under the skin;
// beside it, the hair frames the face from behind the cheeks. The fit applies it (all 68 landmarks were found, so the
// photo showed the face); the synthetic visitors wear the proxies as MakeHuman made them, fringes included, which
// the booth must cope with.
void keepFaceClear(Mesh& hair, const BaseHead& base, const Mesh& fittedHead, const FaceClearance& clearance = {});

// Where the head's ears keep under the hair (tuckEarsUnderHair), in millimetres, in the head's frame (the ear holes'
// centre at the origin).
struct EarTuck {
    double clearance = 1.5;              // an ear under hair keeps this far inside the hair's innermost layer
    double cell = 1.0;                   // the side-on map of the hair's innermost layer: its cell
    double above = 45.0, below = 40.0;   // the ears' window: over and under the ear holes' centre
    double ahead = 30.0, behind = 35.0;  // ... and before and behind it (never ahead of the jaw's top, `jawZ`)
    // The side of the head without its ears is the head's side-on outline opened by a disc of this radius (an ear
    // is about 30 mm long); hair more than `hiddenDepth` under it lies under the skin, unseen, and does not count.
    double skullOpening = 20.0;
    double hiddenDepth = 3.0;
};

// MakeHuman's hair styles cover the ears of its default head; a fitted head's ears stand out through long hair and
// showed as an arc drawn on the hair from the side (FRMDB 005, 006, 007). Seen from either side, each head vertex in
// the ears' window that lies outside the hair's innermost layer there (of the hair that is not under the skin) is
// moved in, towards the middle, to `clearance` inside it, but not under the side of the head round the ear: an ear
// under hair stays under it, the head's side keeps its shape; where no hair lies over it, the ear shows as it is.
// `jawZ`: the depth of the jaw's top (ibug 0 and 16) on the fitted head, before which nothing moves (the face is
// keepFaceClear's). Returns how many vertices moved.
int tuckEarsUnderHair(Mesh& head, const Mesh& hair, double jawZ, const EarTuck& tuck = {});

// Whether a style's proxy falls over the ears (long01, bob02), so that the fit tucks them under it. short04 and
// ponytail01 leave the ears out, as FRMDB's photos of short hair and of hair tied back show them: there the ears
// stand out of the proxy's edge as they do in the photo (tucked, they vanished under short04's sides).
constexpr bool hairCoversEars(HairStyle style) { return style == HairStyle::Long || style == HairStyle::Bob; }

// How the hair part follows the photos' silhouettes (fitHairToSilhouettes), in millimetres.
struct HairSilhouetteFit {
    double band = 2.0;      // the height of one band of the outline
    double smooth = 8.0;    // the stretch varies along the height with a Gaussian of this deviation
    double stands = 2.0;    // hair standing out less than this beyond the head is not stretched (nothing to stretch)
    double minStretch = 0.25, maxStretch = 2.5;
    double crown = 40.0;    // no stretch within a quarter of this under the head's top, all of it from this down
    // Whether the hair behind the head follows the side photo's outline too. Not for a ponytail: its knot and tail
    // are the proxy's own (stretched, the knot sank into the crown's hair and showed as a dark patch, FRMDB 004).
    bool behind = true;
};

// How far each band of height was stretched (for fit.json and tests): the band's centre and the stretch of the
// hair beside the head on the head's +x side, its -x side and behind it; 1 where nothing was measured.
struct HairStretch {
    double y = 0.0;
    double plusX = 1.0, minusX = 1.0, back = 1.0;
};

// Big hair is a MakeHuman proxy of its own width and depth; the visitor's is fuller or flatter. Band by band of
// height from the chin to the top, the hair standing out beyond the fitted head to either side (the front photo)
// and behind it (the side photo) is stretched away from the head so that the avatar's outline meets the photo's;
// under the chin, where the photos show shoulders, each side keeps the stretch of the chin's height. Each
// coordinate is mapped monotonically (x' = edge + k (x - edge) beyond the head's edge, k > 0), so the strands keep
// their order and no triangle turns over. `chinY`: the fitted head's chin. Returns the stretches of the bands.
std::vector<HairStretch> fitHairToSilhouettes(Mesh& hair, const Mesh& fittedHead, const PhotoFrame& front,
                                              const cv::Mat& frontMask, const PhotoFrame& side, const cv::Mat& sideMask,
                                              double chinY, const HairSilhouetteFit& options = {});

// How far down the hair hangs behind the head (fitHairLengthBehind), in millimetres of head space (the ear holes'
// middle at the origin, y up, z forward).
struct HairLengthFit {
    double behindZ = -10.0;   // hair behind this depth hangs behind the head; from it to the jaw's top the change fades
    double rowShare = 0.2;    // a height holds the photo's hair where this share of the band behind the head is hair
    double gap = 6.0;         // going down, the photo's hair ends at the first run of heights this long without it
    double step = 1.0;        // the band is read every this many millimetres, across and down
    // Only lengthened: the photo's hair mask loses the strands' thin ends against the backdrop, so it reads hair
    // shorter than it is (a synthetic visitor's bob02 by 11 mm of 64), never longer.
    double minFactor = 1.0, maxFactor = 1.6;
};

// What fitHairLengthBehind measured (for fit.json and tests): the lowest height of the photo's hair behind the head
// and of the hair part's, and the factor the hair part's length under the ear holes was scaled by (1: unchanged).
struct HairLength {
    bool measured = false;
    double photoBottom = 0.0, avatarBottom = 0.0;
    double factor = 1.0;
};

// A bob is MakeHuman's length; the visitor's hair may hang lower at the back (FRMDB 008's curls hang to his collar,
// under bob02's ends: the side photo's curls were painted on his neck under the hair). The side photo's hair (CV_8U,
// 255 on hair, the photo as taken; `side`: its frame) is read across the band behind the head (from the hair part's
// back to `behindZ`), height by height down from the ear holes; where it ends, the hair part's lowest point behind
// the head goes when that is lower, by scaling the hair's heights under the ear holes (y' = k y, k within
// [minFactor, maxFactor]), in full behind `behindZ` and fading out (smoothstep) towards `jawZ`, so that the locks
// beside the face keep their length. Never below the fitted head's lowest point (the bust's cut). Heights map
// monotonically, so no triangle turns over. (The fit reads long hair no longer: fit_pipeline.cpp says why.)
HairLength fitHairLengthBehind(Mesh& hair, const Mesh& fittedHead, const PhotoFrame& side, const cv::Mat& sideHair,
                               double jawZ, const HairLengthFit& options = {});

// Where the side photo shows the side of the face bare and its hair behind (tuckHairBehindTheFace), in millimetres
// of head space.
struct SideFaceClearance {
    double topY = 0.0, bottomY = 0.0;  // the heights read: the brows' top and the chin (set by the caller)
    double frontZ = 0.0;               // the side photo is read from this depth back (the eyes' outer corners)
    double innerX = 0.0;               // hair nearer the middle than this is the face's (keepFaceClear's) and stays
    double sideRamp = 20.0;            // from innerX out, the tuck comes in fully over this
    double ramp = 10.0;                // at the top and the bottom of the heights read, it fades out over this
    double run = 3.0;                  // the photo's hair begins at the first run of hair this long going back
    double band = 4.0;                 // what lay ahead of the photo's hair goes into this band behind its edge
    double margin = 3.0;               // ... less this: the photo's hair mask reaches over the ear's rim
    double smooth = 4.0;               // the hair's edge varies along the height with a Gaussian of this deviation
    double step = 0.5;                 // the photo is read every this many millimetres, back and down
};

// MakeHuman's long hair and bob hang over the ears down the side of the face; many visitors' hair lies behind the
// ears (FRMDB 008's and 001's profiles show the ear and the cheek before it bare, the hair behind them), and the
// avatar's side and three-quarter views showed a wall of hair across the cheek. Height by height between
// `bottomY` and `topY`, going back from `frontZ` in the side photo's hair pixels (CV_8U, 255 on hair; `side`: its
// frame), the photo's hair begins at the first run of `run` of hair; the edge is smoothed along the height, and
// heights whose row shows no hair are left. Hair vertices beside the face (|x| over innerX, in full from innerX +
// sideRamp) that lie ahead of that edge go back behind it: depth is mapped monotonically (z' = e - b + b tanh((z -
// e + b) / b) ahead of e - b, with e the edge and b `band`), so the strands keep their order and nothing turns over;
// the move fades out over `ramp` at the top and the bottom. Both sides read the one profile (faces are nearly
// symmetric). Returns how many vertices moved by more than 1 mm.
int tuckHairBehindTheFace(Mesh& hair, const PhotoFrame& side, const cv::Mat& sideHair, const SideFaceClearance& clearance);

// What the photos show of the hair (hairPixels: CV_8U, 255 on hair, in each photo as taken, with its person mask)
// and how their pixels map to the head (the fit's frames).
struct HairPhotoMasks {
    cv::Mat frontHair, frontPerson, sideHair, sidePerson;
    PhotoFrame front, side;
};

// How short hair is trimmed to the photos (trimShortHairToPhotos), in millimetres.
struct HairTrim {
    double lenient = 1.0;    // the photo's hair is grown by this first: a strand at the hair's edge stays
    double spread = 2.0;     // the share of skin round a spot is taken over a Gaussian of this deviation
    double inside = 2.0;     // a spot the photo sees edge-on is read this far inside its outline
    double reach = 16.0;     // hair farther than this from the head hangs free and is kept
    int smoothRounds = 4;    // the share of skin averaged over each hair vertex's neighbours this many times
    double cut = 0.5;        // a vertex whose share of skin is over this goes, with its triangles
    int cardVertices = 100;  // a connected piece of the hair this small is a strand card: cut at all, it goes whole
    double outside = 2.0;    // a strand card reaching farther than this out of either photo's outline goes whole
};

// MakeHuman's short04 is one haircut; visitors' are shorter at the sides (a fade), the temples or the nape. Each
// vertex of the hair part is looked at in the photo that sees its spot on the head most squarely (the front photo
// for the face's side of the head, the side photo, mirrored for the other side, for the sides and the back; the
// crown is kept): where that photo shows the person's skin rather than hair round the spot, the vertex goes with its
// triangles; and a strand card that reaches out of either photo's outline goes. `fittedHead`: the head the hair was
// placed on. Returns how many vertices went.
int trimShortHairToPhotos(Mesh& hair, const Mesh& fittedHead, const HairPhotoMasks& photos, const HairTrim& trim = {});

// How short hair is brought inside the photos' outlines (pullShortHairIntoOutlines), in millimetres.
struct HairPull {
    double margin = 1.0;     // a vertex may stand this far out of an outline
    double reach = 30.0;     // hair farther than this from the head hangs free and is left
    double minOffset = 0.5;  // no vertex is brought nearer the scalp than this (or than it was)
    double band = 3.0;       // the layers at and past the outline are compressed into this band under it
};

// Short hair lies in the head's own outline: the head fit followed the photos' outlines, hair included, and
// MakeHuman's short04 stands up to 10 mm off the scalp (FRMDB 002's and 003's haircut stood 9-10 mm out of the side
// photo's outline at the back of the head). Each hair vertex within `reach` of the head moves along its spot's
// normal: the offset from the scalp that either photo's outline (the person masks of `photos`, plus `margin`)
// allows there is read from the photos' signed distances, and the offsets within `band` of it and past it are
// compressed monotonically into that band, so the haircut's layers keep their order and do not meet; no vertex goes
// nearer the scalp than `minOffset`. Returns how many vertices moved by more than 1 mm.
int pullShortHairIntoOutlines(Mesh& hair, const Mesh& fittedHead, const HairPhotoMasks& photos, const HairPull& pull = {});

// The trim reads the photos' hair by colour (hairPixels): with the hair's colour this near the skin's (CIE L*a*b*
// distance of the estimate's models) light hair at the hairline reads as skin, and the fit leaves short04 whole
// (the blond of the short-hair test came out worse trimmed, at 24-28; everyone else is over 32).
inline constexpr double kTrimMinHairSkinContrast = 29.0;

// The colour to paint hair with so that it shows `seen` (the photo's, BGR 0..255) under the booth's lights: the
// lights show hair, which wraps round the head, at booth_lights::meanLightSeenOnSphere() (0.75) of its colour on
// average (the README gives what the synthetic visitors' photos showed of theirs).
cv::Vec3d hairPaint(const cv::Vec3d& seen);

// The hair part on `fittedHead` (the base head's topology), its strands painted to show the estimate's colour
// (hairPaint); nothing when the estimate says bald or the base head has no proxy for the style.
std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, const HairEstimate& hair);
// A named proxy of the base head painted `colour` (the synthetic visitors wear proxies the avatar does not).
std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, std::string_view proxyName,
                                        const cv::Vec3d& colour);

}  // namespace avatarbooth
