// SHA-256 against the test vectors of FIPS 180-2 (appendix B) and NIST's examples.
#include <gtest/gtest.h>

#include <string>

#include "deploy/sha256.h"

namespace eamos {
namespace {

std::string sha256(const std::string& text) {
  deploy::Sha256 sha;
  sha.update(text.data(), text.size());
  return sha.hex_digest();
}

TEST(Sha256, EmptyInput) {
  EXPECT_EQ(sha256(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(Sha256, OneBlockMessage) {
  EXPECT_EQ(sha256("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

TEST(Sha256, TwoBlockMessage) {
  EXPECT_EQ(sha256("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
}

TEST(Sha256, MessageWhosePaddingNeedsAnExtraBlock) {
  // 56 to 63 bytes leave no room for the length in the last block.
  EXPECT_EQ(sha256(std::string(56, 'a')),
            "b35439a4ac6f0948b6d6f9e3c6af0f5f590ce20f1bde7090ef7970686ec6738a");
  EXPECT_EQ(sha256(std::string(64, 'a')),
            "ffe054fe7ae0cb6dc65c3af9b61d5209f439851db43d0ba5997337df154668eb");
}

TEST(Sha256, OneMillionAs) {
  EXPECT_EQ(sha256(std::string(1'000'000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, FeedingInPiecesGivesTheSameDigest) {
  std::string text;
  for (int i = 0; i < 1000; ++i) text += std::to_string(i * 7919) + ",";
  deploy::Sha256 pieces;
  for (std::size_t at = 0, step = 1; at < text.size(); at += step, step = step % 97 + 1)
    pieces.update(text.data() + at, std::min(step, text.size() - at));
  EXPECT_EQ(pieces.hex_digest(), sha256(text));
}

}  // namespace
}  // namespace eamos
