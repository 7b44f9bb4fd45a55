// The hair part keeps the face clear (fit/parts/hair_part.h): hair under the brows and ahead of the plane through the
// jaw's top goes back to within FaceClearance::depth of it, keeping its order; over the brows it fades out; nothing
// else moves.
#include "fit/parts/hair_part.h"

#include "common/error.h"
#include "common/landmark_names.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace avatarbooth;

namespace {

// A "fitted head" whose only vertices are its landmarks: the jaw's top (ibug 0 and 16) at z 10 and 14 (the plane at
// z 12), the brows (17-26) with their lowest point at y 40, every other landmark at the origin.
struct Face {
    BaseHead base;
    Mesh head;
};

Face face() {
    Face f;
    f.head.positions.assign(68, glm::dvec3(0.0));
    for (int k = 0; k < 68; ++k) f.base.frontFeatures[landmarkName(k)] = static_cast<std::uint32_t>(k);
    f.head.positions[0] = {-70.0, 20.0, 10.0};
    f.head.positions[16] = {70.0, 20.0, 14.0};
    for (int k = 17; k <= 26; ++k) f.head.positions[static_cast<std::size_t>(k)] = {-50.0 + 10.0 * (k - 17), k == 21 ? 40.0 : 45.0, 80.0};
    return f;
}

}  // namespace

TEST(HairPart, HairUnderTheBrowsGoesBehindTheFacesFrontKeepingItsOrder) {
    const Face f = face();
    Mesh hair;
    // Under the brows: a fringe strand over an eye (z 90, 100) and hair beside the cheek (z 40); one behind the
    // plane (z 0).
    hair.positions = {{-30.0, 30.0, 90.0}, {-30.0, 25.0, 100.0}, {-80.0, 0.0, 40.0}, {-80.0, 0.0, 0.0}};
    FaceClearance c;
    keepFaceClear(hair, f.base, f.head, c);
    const double plane = 12.0;
    // Within `depth` of the plane, by 10 (1 - exp(-d / 10)) for what was d ahead.
    EXPECT_NEAR(hair.positions[0].z, plane + 10.0 * (1.0 - std::exp(-78.0 / 10.0)), 1e-9);
    EXPECT_NEAR(hair.positions[1].z, plane + 10.0 * (1.0 - std::exp(-88.0 / 10.0)), 1e-9);
    EXPECT_LT(hair.positions[0].z, hair.positions[1].z);  // the strands stay layered
    EXPECT_NEAR(hair.positions[2].z, plane + 10.0 * (1.0 - std::exp(-28.0 / 10.0)), 1e-9);
    EXPECT_EQ(hair.positions[3].z, 0.0);
    // Only depth changes.
    EXPECT_EQ(hair.positions[0].x, -30.0);
    EXPECT_EQ(hair.positions[0].y, 30.0);
    EXPECT_EQ(hair.positions[2].x, -80.0);
}

TEST(HairPart, OverTheBrowsThePushFadesOut) {
    const Face f = face();
    Mesh hair;
    // At the brows' lowest point (y 40), a third of the way up the 15 mm ramp, and over it.
    hair.positions = {{0.0, 40.0, 62.0}, {0.0, 45.0, 62.0}, {0.0, 55.0, 62.0}, {0.0, 80.0, 62.0}};
    keepFaceClear(hair, f.base, f.head);
    const double kept = 12.0 + 10.0 * (1.0 - std::exp(-5.0));
    EXPECT_NEAR(hair.positions[0].z, kept, 1e-9);
    // t = 2/3: smoothstep 20/27 of the push.
    EXPECT_NEAR(hair.positions[1].z, 62.0 - 20.0 / 27.0 * (62.0 - kept), 1e-9);
    EXPECT_EQ(hair.positions[2].z, 62.0);
    EXPECT_EQ(hair.positions[3].z, 62.0);
}

TEST(HairPart, AHeadWithoutTheFeatureVerticesIsAnInternalError) {
    Face f = face();
    f.base.frontFeatures.erase(landmarkName(16));
    Mesh hair;
    hair.positions = {{0.0, 0.0, 50.0}};
    try {
        keepFaceClear(hair, f.base, f.head);
        FAIL() << "no error";
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::Internal);
        EXPECT_NE(std::string(e.what()).find("ibug_16"), std::string::npos) << e.what();
    }
}
