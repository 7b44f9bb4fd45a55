// The hair part: the bundled MakeHuman hair proxy of the style the hair analysis chose (fit/face/hair_analysis.h),
// placed on the fitted head and tinted with the hair's colour from the photo.
#pragma once

#include "fit/face/hair_analysis.h"
#include "fit/head/base_head.h"
#include "fit/parts/avatar_part.h"
#include "fit/parts/head_proxy.h"

#include <optional>

namespace avatarbooth {

// The MakeHuman proxy that wears a style ("short02", "bob02", "long01", "ponytail01"; none for HairStyle::None).
const char* hairProxyName(HairStyle style);

// A proxy that is one of the hair styles (named "hair"): an alternative, placed only when chosen.
bool isHairStyleProxy(const HeadProxy& proxy);

// The style's proxy among base.proxies (its source "proxies/hair/NAME"), or null when the base head has none.
const HeadProxy* findHairProxy(const BaseHead& base, HairStyle style);

// How far hair keeps off the face (keepFaceClear), in millimetres.
struct FaceClearance {
    double depth = 10.0;  // under the brows, what was ahead of the plane through the jaw's top keeps within this of it
    double ramp = 15.0;   // over the brows, the push fades out over this height
};

// Moves the hair that would hang in front of the face the photo shows. MakeHuman's styles are made for its default
// head; on the fitted heads bob02's fringe fell over an eye and its sides hid the cheeks from three-quarter view.
// Under the brows, the hair ahead of the plane through the jaw's top (ibug 0 and 16) is pushed back to within
// `depth` of it; over the brows the push fades out. Inside the face's outline that puts the hair under the skin;
// beside it, the hair frames the face from behind the cheeks. The fit applies it (all 68 landmarks were found, so the
// photo showed the face); the synthetic visitors wear the proxies as MakeHuman made them, fringes included, which
// the booth must cope with.
void keepFaceClear(Mesh& hair, const BaseHead& base, const Mesh& fittedHead, const FaceClearance& clearance = {});

// The hair part on `fittedHead` (the base head's topology), its strands in the estimate's colour; nothing when the
// estimate says bald or the base head has no proxy for the style.
std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, const HairEstimate& hair);

}  // namespace avatarbooth
