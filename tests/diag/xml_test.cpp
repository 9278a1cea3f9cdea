#include "diag/xml.h"

#include <gtest/gtest.h>

using eamos::diag::xml_escape;

TEST(XmlEscape, EveryMarkupCharacterBecomesAReference) {
  EXPECT_EQ(xml_escape("a<b>&\"c\"'d'"), "a&lt;b&gt;&amp;&quot;c&quot;&#39;d&#39;");
}

TEST(XmlEscape, PlainTextAndUtf8PassUnchanged) {
  EXPECT_EQ(xml_escape("Drone1 → FlyByX(5) ✓"), "Drone1 → FlyByX(5) ✓");
  EXPECT_EQ(xml_escape(""), "");
}

TEST(XmlEscape, AnAmpersandIsEscapedOnceSoAReferenceInTheInputStaysText) {
  EXPECT_EQ(xml_escape("&amp;"), "&amp;amp;");
}
