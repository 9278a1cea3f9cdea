// Text from outside quoted in a message: no control byte reaches the terminal, a long value
// is cut without splitting a character.
#include <gtest/gtest.h>

#include "diag/printable.h"

namespace eamos::diag {
namespace {

TEST(Printable, ControlBytesBecomeQuestionMarks) {
  EXPECT_EQ(printable("a\x01\x1b[2Jb\x7f"), "a??[2Jb?");
  EXPECT_EQ(printable(std::string_view("x\0y", 3)), "x?y");
}

TEST(Printable, PlainAndUtf8TextIsKept) {
  EXPECT_EQ(printable("udp://:14540"), "udp://:14540");
  EXPECT_EQ(printable("Höhe 5 m"), "Höhe 5 m");
}

TEST(Printable, LongTextIsCutAtACharacterBoundary) {
  EXPECT_EQ(printable(std::string(50, 'a'), 40), std::string(40, 'a') + "...");
  // 'ö' is two bytes; a cut after its first byte drops the whole character.
  EXPECT_EQ(printable(std::string(39, 'a') + "ö" + "bbb", 40), std::string(39, 'a') + "...");
  EXPECT_EQ(printable("abcdef", 6), "abcdef");
}

}  // namespace
}  // namespace eamos::diag
