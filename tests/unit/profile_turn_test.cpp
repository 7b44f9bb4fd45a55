// The side photo's turn past or short of the profile: the ear read from its columns of skin folds, and the rules
// that join it to the eye (fit/face/profile.h).
#include "fit/face/profile.h"

#include <gtest/gtest.h>

#include <vector>

namespace {

using avatarbooth::degreesPastProfile;
using avatarbooth::EarPlace;
using avatarbooth::readEarColumns;
using avatarbooth::ProfileTurn;
using avatarbooth::turnedPastProfile;
using avatarbooth::turnedShortCues;

// 100 columns of 0.01 V behind the nasion at `cheek`, with an ear of `ear` in columns 40-49 (0.40-0.50 V).
std::vector<double> columnsWithEar(double cheek, double ear) {
    std::vector<double> c(100, cheek);
    for (int i = 40; i < 50; ++i) c[static_cast<std::size_t>(i)] = ear;
    return c;
}

}  // namespace

TEST(EarColumns, FrontAndFoldBehindTheNoseTip) {
    // Smoothed over 5 columns: column 39 holds two of the ear's (4.6 > 4 times the cheek's 1), column 42 is the
    // first wholly inside it.
    const EarPlace ear = readEarColumns(columnsWithEar(1.0, 10.0), 0.10, 1.4);
    ASSERT_TRUE(ear.found);
    EXPECT_NEAR(ear.front, 0.395 + 0.10, 1e-12);
    EXPECT_NEAR(ear.fold, 0.425 + 0.10, 1e-12);
    EXPECT_DOUBLE_EQ(ear.headLength, 1.4);
}

TEST(EarColumns, NotFoundWhenNotFourTimesTheCheek) {
    EXPECT_FALSE(readEarColumns(columnsWithEar(1.0, 3.9), 0.1, 1.4).found);
    EXPECT_FALSE(readEarColumns(columnsWithEar(5.0, 15.0), 0.1, 1.4).found) << "a textured cheek";
    EXPECT_TRUE(readEarColumns(columnsWithEar(5.0, 25.0), 0.1, 1.4).found);
}

TEST(EarColumns, CheekLevelAtLeastOne) {
    // A cheek without any gradient counts as 1: columns 41 (4 of the ear's 5 = 4.0) is not above 4, 42 is.
    const EarPlace ear = readEarColumns(columnsWithEar(0.0, 5.0), 0.0, 1.4);
    ASSERT_TRUE(ear.found);
    EXPECT_NEAR(ear.front, 0.425, 1e-12);
}

TEST(EarColumns, NoColumnsNoEar) {
    EXPECT_FALSE(readEarColumns({}, 0.1, 1.4).found);
    EXPECT_FALSE(readEarColumns(std::vector<double>(29, 1.0), 0.1, 1.4).found);
}

TEST(TurnedPastProfile, NeedsTheEarCloseAndTheEyeAgreeing) {
    EarPlace ear;
    ear.found = true;
    ear.front = 0.318;  // exactly kEarShareTurnBack of a head 1 V long
    ear.fold = 0.60;    // exactly kEarFoldTurnBack
    ear.headLength = 1.0;
    EXPECT_TRUE(turnedPastProfile(8.0, ear));  // exactly kEyeTurnBackDegrees
    EXPECT_FALSE(turnedPastProfile(7.9, ear)) << "the eye says not past";
    EarPlace far = ear;
    far.front = 0.319;
    EXPECT_FALSE(turnedPastProfile(20.0, far)) << "the ear too far back";
    far = ear;
    far.headLength = 1.4;
    far.front = 0.42;  // 0.300 of a longer head
    EXPECT_TRUE(turnedPastProfile(20.0, far));
    EarPlace hairline = ear;
    hairline.fold = 0.61;
    EXPECT_FALSE(turnedPastProfile(20.0, hairline)) << "the strongest folds far behind: not this ear";
    EarPlace none = ear;
    none.found = false;
    EXPECT_FALSE(turnedPastProfile(20.0, none));
    none = ear;
    none.headLength = 0.0;
    EXPECT_FALSE(turnedPastProfile(20.0, none));
}

TEST(ProfileTurn, DegreesPastTheProfileFromTheEarsShare) {
    EarPlace ear;
    ear.found = true;
    ear.headLength = 1.4;
    ear.front = 0.525 * 1.4;  // where the ear lies in a profile
    EXPECT_NEAR(degreesPastProfile(ear), 0.0, 1e-12);
    ear.front = 0.27 * 1.4;  // 0.255 of the head nearer the face: 0.0085 a degree
    EXPECT_NEAR(degreesPastProfile(ear), 30.0, 1e-9);
    ear.front = 0.60 * 1.4;  // turned short of the profile: nothing past it
    EXPECT_DOUBLE_EQ(degreesPastProfile(ear), 0.0);
    ear.found = false;
    EXPECT_DOUBLE_EQ(degreesPastProfile(ear), 0.0);
}

TEST(TurnedShortCues, NeedTheEyeWellShortAndTheEarFarBackOrTheEyeShortAndNoEar) {
    ProfileTurn turn;
    turn.known = true;
    turn.degrees = -25.0;  // exactly kEyeTurnMoreDegrees
    turn.ear.found = true;
    turn.ear.headLength = 1.4;
    turn.ear.front = 0.67 * 1.4;  // exactly kEarShareTurnMore of the head
    EXPECT_TRUE(turnedShortCues(turn));
    ProfileTurn eye = turn;
    eye.degrees = -24.9;
    EXPECT_FALSE(turnedShortCues(eye)) << "the eye not far enough short (a visitor at 70 degrees: -24)";
    ProfileTurn ear = turn;
    ear.ear.front = 0.66 * 1.4;
    EXPECT_FALSE(turnedShortCues(ear)) << "the ear nearer the face than at 60 degrees";
    ProfileTurn unseen = turn;
    unseen.ear.found = false;  // a dark or textured cheek: the eye and the face decide, the eye from 20 degrees short
    EXPECT_TRUE(turnedShortCues(unseen));
    unseen.degrees = -20.0;  // exactly kEyeTurnMoreNoEarDegrees (a dark-skinned visitor at 60 degrees: -22)
    EXPECT_TRUE(turnedShortCues(unseen));
    unseen.degrees = -19.9;
    EXPECT_FALSE(turnedShortCues(unseen));
    eye.ear.found = false;
    EXPECT_TRUE(turnedShortCues(eye)) << "without an ear, -24.9 is short enough";
    ProfileTurn unknown = turn;
    unknown.known = false;
    EXPECT_FALSE(turnedShortCues(unknown)) << "no eye read: nothing to say";
    ProfileTurn noLength = turn;
    noLength.ear.headLength = 0.0;
    EXPECT_FALSE(turnedShortCues(noLength));
}
