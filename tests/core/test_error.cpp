// Error messages are printable UTF-8 whatever they quote (printable_text, fail).
#include <gtest/gtest.h>

#include "core/error.hpp"
#include "core/text.hpp"

namespace clumpforge {

TEST(PrintableText, KeepsUtf8AndWritesOutEverythingElse) {
  // Printable ASCII, a newline, a tab and valid multi-byte characters (2, 3 and 4 bytes) stay.
  const std::string kept = "drop-0.2m: 5 \xC2\xB5m\n\t\xE2\x88\x86 \xF0\x9F\x98\x80";
  EXPECT_EQ(printable_text(kept), kept);
  // Control characters other than a newline or a tab, and DEL.
  EXPECT_EQ(printable_text("a\x1B[2Jb\r\x7F"), "a\\x1B[2Jb\\x0D\\x7F");
  EXPECT_EQ(printable_text(std::string("x\0y", 3)), "x\\x00y");
  // Bytes that are not UTF-8: a stray continuation byte, a lead byte no sequence starts with, a
  // sequence cut short (at the end and in the middle), an overlong form and a surrogate.
  EXPECT_EQ(printable_text("\x80"), "\\x80");
  EXPECT_EQ(printable_text("0.0\xFC"), "0.0\\xFC");
  EXPECT_EQ(printable_text("\xE2\x88"), "\\xE2\\x88");
  EXPECT_EQ(printable_text("\xE2(x"), "\\xE2(x");
  EXPECT_EQ(printable_text("\xC0\xAF"), "\\xC0\\xAF");
  EXPECT_EQ(printable_text("\xED\xA0\x80"), "\\xED\\xA0\\x80");
  EXPECT_EQ(printable_text("\xF4\x90\x80\x80"), "\\xF4\\x90\\x80\\x80");  // beyond U+10FFFF
}

TEST(PrintableText, IsValidUtf8AcceptsTextAndRefusesOtherBytes) {
  EXPECT_TRUE(is_valid_utf8(""));
  EXPECT_TRUE(is_valid_utf8("tuber-01"));
  EXPECT_TRUE(is_valid_utf8("\xC2\xB5m \xE2\x88\x86 \xF0\x9F\x98\x80"));
  EXPECT_TRUE(is_valid_utf8("a\x1B[2Jb"));  // a control character is text; printing it is another matter
  for (const std::string bad : {"tub\xFFr", "\x80", "\xE2\x88", "\xC0\xAF", "\xED\xA0\x80", "\xF4\x90\x80\x80"})
    EXPECT_FALSE(is_valid_utf8(bad)) << printable_text(bad);
}

TEST(PrintableText, FailMakesEveryMessagePrintable) {
  const Result<int> r = fail(ErrorCode::ParseError, "t.csv:3: '\xFF' is not a number");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::ParseError);
  EXPECT_EQ(r.error().message, "t.csv:3: '\\xFF' is not a number");
}

TEST(PrintableText, OneLineTextKeepsACommentOnItsLine) {
  EXPECT_EQ(one_line_text("a\nshell x\tb"), "a\\x0Ashell x\\x09b");
  EXPECT_EQ(one_line_text("tuber \xCE\xB1"), "tuber \xCE\xB1");
  EXPECT_EQ(one_line_text("\x1b[2J"), "\\x1B[2J");
}

TEST(JsonNesting, TheFirstLineBeyondTheDepthIsFoundAndStringsDoNotCount) {
  EXPECT_EQ(json_nesting_beyond(R"({"a": [1, {"b": [2]}]})", 4), std::nullopt);  // four deep
  EXPECT_EQ(json_nesting_beyond(R"({"a": [1, {"b": [2]}]})", 3), 1u);
  EXPECT_EQ(json_nesting_beyond("{\n \"a\":\n  [[\n", 2), 3u);
  // Brackets in strings, after an escaped quote and an escaped backslash, are text.
  EXPECT_EQ(json_nesting_beyond(R"({"a": "[[[[\"[[{{", "b": "\\", "c": "]]]"})", 1), std::nullopt);
  EXPECT_EQ(json_nesting_beyond(R"({"a": "\\", "b": [[1]]})", 2), 1u);
  // Closing brackets beyond the opening ones do not lower the depth below zero.
  EXPECT_EQ(json_nesting_beyond("]]]]{[[", 2), 1u);
  // What a manifest holds is far within the default; 200,000 levels are not.
  EXPECT_EQ(json_nesting_beyond(R"({"trials": [{"summary": {"rebound_height_m": 0.03}}]})"), std::nullopt);
  EXPECT_EQ(json_nesting_beyond(std::string(200000, '[') + std::string(200000, ']')), 1u);
  EXPECT_EQ(json_nesting_beyond(std::string(kMaxJsonDepth, '[') + std::string(kMaxJsonDepth, ']')), std::nullopt);
}

TEST(PrintableText, CsvFieldQuotesOnlyWhatWouldSplitARow) {
  EXPECT_EQ(csv_field("tuber-01.stl"), "tuber-01.stl");
  EXPECT_EQ(csv_field("tuber, left.stl"), "\"tuber, left.stl\"");
  EXPECT_EQ(csv_field("the \"big\" one"), "\"the \"\"big\"\" one\"");
  EXPECT_EQ(csv_field("two\nlines"), "\"two\nlines\"");
  EXPECT_EQ(csv_field(""), "");
}

}  // namespace clumpforge
