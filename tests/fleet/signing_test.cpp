// A drone's MAVLink 2 signing key in the fleet file: inline or from a key file beside it,
// which must be private to its owner; every mistake is an error at its place.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "helpers.h"

namespace eamos::fleet {
namespace {

namespace fs = std::filesystem;
using test::first_error;
using test::parse;

const std::string kKey = "0f1e2d3c4b5a69788796a5b4c3d2e1f000112233445566778899aabbccddeeff";

bool mentions(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct KeyDir {
  fs::path dir = fs::temp_directory_path() / ("eamos-signing-" + std::to_string(::getpid()));
  KeyDir() { fs::create_directories(dir); }
  ~KeyDir() { fs::remove_all(dir); }
  fs::path write(const std::string& name, const std::string& text, mode_t mode) {
    fs::path p = dir / name;
    std::ofstream(p) << text;
    chmod(p.c_str(), mode);
    return p;
  }
};

TEST(Signing, AnInlineKeyAndSetupReachTheDronesSettings) {
  auto p = parse("drones:\n  D1: {adapter: mavlink, signing: {key: " + kKey + ", setup: true}}\n");
  ASSERT_TRUE(p.ok) << first_error(p.diags).message;
  EXPECT_EQ(p.fleet.drones.at("D1").signing_key, kKey);
  EXPECT_TRUE(p.fleet.drones.at("D1").signing_setup);
}

TEST(Signing, AKeyFileOnlyItsOwnerReadsIsTaken) {
  KeyDir d;
  fs::path key = d.write("d1.key", kKey + "\n", 0600);
  auto p = parse("drones:\n  D1: {signing: {key_file: '" + key.string() + "'}}\n");
  ASSERT_TRUE(p.ok) << first_error(p.diags).message;
  EXPECT_EQ(p.fleet.drones.at("D1").signing_key, kKey);
  EXPECT_FALSE(p.fleet.drones.at("D1").signing_setup);
}

TEST(Signing, AKeyFileOthersMayReadIsRefusedWithTheFix) {
  KeyDir d;
  fs::path key = d.write("open.key", kKey, 0644);
  auto p = parse("drones:\n  D1:\n    signing: {key_file: '" + key.string() + "'}\n");
  EXPECT_FALSE(p.ok);
  Diagnostic e = first_error(p.diags);
  EXPECT_EQ(e.loc.line, 3);
  EXPECT_EQ(e.loc.col, 25) << "at the key_file's value";
  EXPECT_TRUE(mentions(e.message, "may be read or written by others (mode 0644)")) << e.message;
  EXPECT_TRUE(mentions(e.message, "chmod 600")) << e.message;
}

TEST(Signing, BadKeysAndMissingFilesAreErrors) {
  EXPECT_TRUE(mentions(first_error(parse("drones:\n  D1: {signing: {key: abc}}\n").diags).message, "64 hexadecimal digits"));
  EXPECT_TRUE(mentions(first_error(parse("drones:\n  D1: {signing: {key: " + std::string(64, '0') + "}}\n").diags).message,
                       "all-zero"));
  EXPECT_TRUE(mentions(first_error(parse("drones:\n  D1: {signing: {key_file: /no/such/key}}\n").diags).message,
                       "cannot read signing key file '/no/such/key'"));
  EXPECT_TRUE(mentions(first_error(parse("drones:\n  D1: {signing: {setup: true}}\n").diags).message,
                       "exactly one of `key_file: PATH` and `key: HEX`"));
  EXPECT_TRUE(mentions(first_error(parse("drones:\n  D1: {signing: {key: " + kKey + ", setup: maybe}}\n").diags).message,
                       "must be true or false"));
  EXPECT_TRUE(mentions(first_error(parse("drones:\n  D1: {signing: {kye: x}}\n").diags).message, "unknown key 'kye'"));
}

}  // namespace
}  // namespace eamos::fleet
