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

// The hair part on `fittedHead` (the base head's topology), its strands in the estimate's colour; nothing when the
// estimate says bald or the base head has no proxy for the style.
std::optional<AvatarPart> placeHairPart(const BaseHead& base, const Mesh& fittedHead, const HairEstimate& hair);

}  // namespace avatarbooth
