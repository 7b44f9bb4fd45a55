// UTF-8 decoding for on-screen text: every form of valid input, and invalid bytes shown as U+FFFD.
#include "booth/screens/text_renderer.h"

#include "common/error.h"

#include <gtest/gtest.h>

using namespace avatarbooth;

TEST(Utf8, DecodesOneToFourByteForms) {
    EXPECT_EQ(decodeUtf8("A"), U"A");
    EXPECT_EQ(decodeUtf8("é"), U"\u00e9");                 // 2 bytes
    EXPECT_EQ(decodeUtf8("あ…"), U"\u3042\u2026");          // 3 bytes each
    EXPECT_EQ(decodeUtf8("\xF0\x9F\x98\x80"), U"\U0001F600");  // 4 bytes
    EXPECT_EQ(decodeUtf8("写真 1/2"), U"\u5199\u771f 1/2");
    EXPECT_EQ(decodeUtf8(""), U"");
}

TEST(Utf8, InvalidBytesBecomeReplacementCharacters) {
    EXPECT_EQ(decodeUtf8("a\xFF" "b"), U"a\uFFFDb");             // never a lead byte
    EXPECT_EQ(decodeUtf8("\x80"), U"\uFFFD");                     // a lone continuation byte
    EXPECT_EQ(decodeUtf8("\xE3\x81"), U"\uFFFD\uFFFD");           // truncated at the end
    EXPECT_EQ(decodeUtf8("\xE3\x41\x42"), U"\uFFFDAB");           // a lead byte without its continuation
    EXPECT_EQ(decodeUtf8("\xC0\xAF"), U"\uFFFD\uFFFD");           // overlong '/'
    EXPECT_EQ(decodeUtf8("\xED\xA0\x80"), U"\uFFFD\uFFFD\uFFFD");  // a UTF-16 surrogate
    EXPECT_EQ(decodeUtf8("\xF4\x90\x80\x80"), U"\uFFFD\uFFFD\uFFFD\uFFFD");  // beyond U+10FFFF
}

TEST(Language, CodesBothWays) {
    EXPECT_EQ(parseLanguage("en"), Language::English);
    EXPECT_EQ(parseLanguage("ja"), Language::Japanese);
    EXPECT_STREQ(languageCode(Language::Japanese), "ja");
    EXPECT_STREQ(languageCode(Language::English), "en");
    try {
        parseLanguage("fr");
        FAIL();
    } catch (const BoothError& e) {
        EXPECT_EQ(e.kind(), ErrorKind::BadConfig);
        EXPECT_EQ(e.where(), "language");
    }
}
