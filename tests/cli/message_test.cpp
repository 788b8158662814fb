// one_line() and valid_utf8(): the sanitiser behind the one-line error contract (issue 10: raw
// `[json.exception.type_error.302]` text, names with embedded newlines or raw bytes echoed
// verbatim). Oracle: hand-written byte strings and RFC 3629's table of well-formed sequences.

#include "dynid/common/message.hpp"

#include <gtest/gtest.h>

namespace dynid {
namespace {

TEST(Message, DropsLibraryTagsAndKeepsTheText) {
  EXPECT_EQ(one_line("[json.exception.type_error.302] type must be string, but is number"),
            "type must be string, but is number");
  EXPECT_EQ(one_line("'r.json' is not valid JSON ([json.exception.parse_error.101] parse error)"),
            "'r.json' is not valid JSON (parse error)");
  EXPECT_EQ(one_line("joint [a] and [1, 2]"), "joint [a] and [1, 2]");  // not dotted tags
}

TEST(Message, EscapesControlCharactersAndInvalidUtf8) {
  EXPECT_EQ(one_line("robot 'a\nb\tc\rd\x01' not found"), "robot 'a\\nb\\tc\\rd\\x01' not found");
  EXPECT_EQ(one_line("file \xff\xfe.csv"), "file \\xFF\\xFE.csv");
  EXPECT_EQ(one_line("overlong \xc0\xaf, surrogate \xed\xa0\x80"),
            "overlong \\xC0\\xAF, surrogate \\xED\\xA0\\x80");
  EXPECT_EQ(one_line("C1 \xc2\x85 end"), "C1 \\xC2\\x85 end");
  EXPECT_EQ(one_line("truncated \xe2\x82"), "truncated \\xE2\\x82");
  EXPECT_EQ(one_line("  \n"), "\\n");
  EXPECT_EQ(one_line("   "), "");
}

TEST(Message, KeepsValidUtf8) {
  const std::string text = "τ = 3 N·m at joint «épaule» 肩 \xf0\x9f\xa4\x96";
  EXPECT_EQ(one_line(text), text);
  EXPECT_EQ(valid_utf8(text), text);
}

TEST(Message, PrintableKeepsTagsAndCutsLongInputAtACharacterBoundary) {
  EXPECT_EQ(printable("[a.b] x\n"), "[a.b] x\\n");  // input text is quoted, not cleaned of tags
  EXPECT_EQ(printable(std::string(500, 'a'), 10), std::string(10, 'a') + "...");
  // 'é' is two bytes: a cut after 9 bytes must not split it.
  EXPECT_EQ(printable("aaaaaaaaa\xc3\xa9zz", 10), "aaaaaaaaa\xc3\xa9...");
  EXPECT_EQ(printable("\x01\xff", 40), "\\x01\\xFF");
}

TEST(Message, ValidUtf8ReplacesEachBadByte) {
  EXPECT_EQ(valid_utf8("run\xff.csv"), "run\xEF\xBF\xBD.csv");
  EXPECT_EQ(valid_utf8("\xe2\x82"), "\xEF\xBF\xBD\xEF\xBF\xBD");
  EXPECT_EQ(valid_utf8("a\nb"), "a\nb");  // control characters are valid UTF-8
}

}  // namespace
}  // namespace dynid
