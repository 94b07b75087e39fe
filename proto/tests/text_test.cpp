// Protocol text: what is valid UTF-8, and how any bytes become one valid line.
#include "drapegen/proto/text.hpp"

#include <gtest/gtest.h>

#include <string>

#include "drapegen/proto/worker.pb.h"

namespace drapegen::proto {
namespace {

TEST(Text, RecognisesWellFormedUtf8) {
  EXPECT_TRUE(is_utf8(""));
  EXPECT_TRUE(is_utf8("plain ascii"));
  EXPECT_TRUE(is_utf8("caf\xC3\xA9 \xE2\x82\xAC \xF0\x9F\x98\x80"));  // é, €, an emoji
  EXPECT_FALSE(is_utf8("bad\xFF"));
  EXPECT_FALSE(is_utf8("\xC3"));              // cut short
  EXPECT_FALSE(is_utf8("\xC0\xAF"));          // overlong '/'
  EXPECT_FALSE(is_utf8("\xE0\x80\xAF"));      // overlong '/'
  EXPECT_FALSE(is_utf8("\xED\xA0\x80"));      // a surrogate
  EXPECT_FALSE(is_utf8("\xF4\x90\x80\x80"));  // above U+10FFFF
  EXPECT_FALSE(is_utf8("\x80"));              // a lone continuation byte
}

TEST(Text, AnyBytesBecomeOneValidLine) {
  EXPECT_EQ(one_line_utf8("cannot create /tmp/bad\xFF/x\nsecond line\r"), "cannot create /tmp/bad?/x second line ");
  EXPECT_EQ(one_line_utf8("caf\xC3\xA9"), "caf\xC3\xA9");
  EXPECT_EQ(one_line_utf8("\xE2\x82"), "??");  // an incomplete euro sign: each byte replaced
  // Cut at a character boundary: the euro sign (3 bytes) does not fit in 5 bytes after "abc".
  EXPECT_EQ(one_line_utf8("abc\xE2\x82\xAC", 5), "abc");
  EXPECT_EQ(one_line_utf8("abcdef", 4), "abcd");
  const std::string garbage = "\xFF\xFE\xC0\x80\xED\xA0\x80 ok";
  EXPECT_TRUE(is_utf8(one_line_utf8(garbage)));
  // What protobuf's own check accepts: a message field set to the result serialises and parses back.
  v1::Envelope e;
  e.mutable_failure()->set_message(one_line_utf8(garbage));
  std::string wire;
  ASSERT_TRUE(e.SerializeToString(&wire));
  v1::Envelope back;
  EXPECT_TRUE(back.ParseFromString(wire));
}

}  // namespace
}  // namespace drapegen::proto
