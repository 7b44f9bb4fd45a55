// What the booth would measure on a synthetic visitor's photos if every landmark were found exactly: its
// ground-truth landmarks, and the silhouettes segmented against the empty booth.
#pragma once

#include "fit/face/silhouette.h"
#include "fit/head/head_fit.h"
#include "sim/synthetic_visitor.h"

namespace avatarbooth::test {

inline PhotoMeasurements truthMeasurements(const SyntheticVisitor& v, bool noseRight) {
    PhotoMeasurements m;
    m.frontPoints = v.frontLandmarks;
    m.sidePoints = v.sideLandmarks;
    m.frontMask = segmentPerson(v.front, v.background);
    m.sideMask = segmentPerson(v.side, v.background);
    m.sideNoseImageRight = noseRight;
    return m;
}

}  // namespace avatarbooth::test
