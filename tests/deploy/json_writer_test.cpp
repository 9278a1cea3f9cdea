// The streaming JSON writer: whatever it writes reads back, with nlohmann::json, as the
// values it was given — the promise that lets mission files skip the document tree.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <sstream>

#include <nlohmann/json.hpp>

#include "deploy/json_writer.h"

namespace eamos {
namespace {

using deploy::JsonWriter;
using nlohmann::json;

std::string written_string(const std::string& s) {
  std::ostringstream out;
  {
    JsonWriter w(out);
    w.value(s);
  }
  return out.str();
}

std::string written_double(double v) {
  std::ostringstream out;
  {
    JsonWriter w(out);
    w.value(v);
  }
  return out.str();
}

TEST(JsonWriter, EscapesStringsAsNlohmannDoes) {
  for (std::string s : {std::string("plain"), std::string("quote \" and backslash \\"),
                        std::string("tab\tnew line\ncarriage\rbell\a\b\f"), std::string("nul\0x", 5),
                        std::string("\x1f\x7f"), std::string("Grüße, 無人機 🚁"), std::string("")})
    EXPECT_EQ(written_string(s), json(s).dump()) << s;
}

TEST(JsonWriter, InvalidUtf8BecomesTheReplacementCharacter) {
  for (std::string s : {std::string("a\xff"), std::string("\xc3"), std::string("\xe0\x80\x80"),
                        std::string("\xed\xa0\x80"), std::string("\xf4\x90\x80\x80"), std::string("\x80z")}) {
    std::string text = written_string(s);
    json parsed = json::parse(text);  // throws on invalid UTF-8
    EXPECT_NE(parsed.get<std::string>().find("\xEF\xBF\xBD"), std::string::npos) << text;
  }
}

TEST(JsonWriter, DoublesReadBackExactlyAndStayFloatingPoint) {
  for (double v : {0.0, -0.0, 1.0, -5.0, 0.1, 1.0 / 3.0, 2.5e-7, 1e14, 1e15, 1e20, 123456789012.0,
                   1e300, std::numeric_limits<double>::denorm_min(), std::numeric_limits<double>::max()}) {
    json parsed = json::parse(written_double(v));
    ASSERT_TRUE(parsed.is_number_float()) << written_double(v);
    EXPECT_EQ(parsed.get<double>(), v) << written_double(v);
    EXPECT_EQ(std::signbit(parsed.get<double>()), std::signbit(v)) << written_double(v);
  }
}

TEST(JsonWriter, NonFiniteDoublesAreNullAsNlohmannWritesThem) {
  EXPECT_EQ(written_double(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(written_double(std::nan("")), "null");
}

TEST(JsonWriter, NestedContainersReadBackAsTheSameDocument) {
  std::ostringstream out;
  {
    JsonWriter w(out, 2);
    w.begin_object();
    w.member("format", "test");
    w.member("version", 1);
    w.member("big", 9'000'000'000LL);
    w.member("ok", true);
    w.key("nothing");
    w.null();
    w.key("empty");
    w.begin_array();
    w.end_array();
    w.key("nodes");
    w.begin_array();
    for (int i = 0; i < 3; ++i) {
      w.begin_object();
      w.member("index", i);
      w.key("args");
      w.begin_array();
      w.value(-1.5);
      w.begin_object();
      w.end_object();
      w.end_array();
      w.end_object();
    }
    w.end_array();
    w.end_object();
  }
  json expected = {{"format", "test"}, {"version", 1}, {"big", 9'000'000'000LL}, {"ok", true},
                   {"nothing", nullptr}, {"empty", json::array()}, {"nodes", json::array()}};
  for (int i = 0; i < 3; ++i)
    expected["nodes"].push_back({{"index", i}, {"args", json::array({-1.5, json::object()})}});
  EXPECT_EQ(json::parse(out.str()), expected) << out.str();
}

TEST(JsonWriter, WrapDepthPutsEachNodeOnALineOfItsOwn) {
  std::ostringstream out;
  {
    JsonWriter w(out, 2);
    w.begin_object();
    w.key("nodes");
    w.begin_array();
    for (int i = 0; i < 2; ++i) {
      w.begin_object();
      w.member("index", i);
      w.member("kind", "action");
      w.end_object();
    }
    w.end_array();
    w.end_object();
  }
  EXPECT_EQ(out.str(),
            "{\n"
            " \"nodes\":[\n"
            "  {\"index\":0,\"kind\":\"action\"},\n"
            "  {\"index\":1,\"kind\":\"action\"}\n"
            " ]\n"
            "}");
}

}  // namespace
}  // namespace eamos

namespace eamos {
namespace {

/// A stream that keeps what it is given and the largest piece it was given at once.
class Pieces : public std::streambuf {
 public:
  std::string text;
  std::size_t largest = 0;

 protected:
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    text.append(s, static_cast<std::size_t>(n));
    largest = std::max(largest, static_cast<std::size_t>(n));
    return n;
  }
  int_type overflow(int_type ch) override {
    if (traits_type::eq_int_type(ch, traits_type::eof())) return traits_type::not_eof(ch);
    char c = traits_type::to_char_type(ch);
    return xsputn(&c, 1) == 1 ? ch : traits_type::eof();
  }
};

// The trace header's source is one string of up to tens of megabytes: written to a stream
// it goes in pieces of about 64 KB, escapes and all, and reads back as the same string;
// appended to a string, the same bytes.
TEST(JsonWriter, ALongStringGoesToAStreamInPiecesAndToAStringWhole) {
  std::string source;
  for (int i = 0; source.size() < 1000000; ++i)
    source += "func SEQ_" + std::to_string(i) + "() {\n\tD1.FlyTo(1, 2, 3) // \"caf\xc3\xa9\" \\ \x01\n}\n";
  Pieces pieces;
  std::ostream out(&pieces);
  {
    JsonWriter w(out);
    w.value(source);
  }
  EXPECT_EQ(json::parse(pieces.text).get<std::string>(), source);
  EXPECT_EQ(pieces.text, json(source).dump());
  EXPECT_LE(pieces.largest, 80u * 1024) << "the escaped string was held whole";
  std::string appended = "[";
  {
    JsonWriter w(appended);
    w.value(source);
  }
  EXPECT_EQ(appended, "[" + pieces.text);
}

}  // namespace
}  // namespace eamos
