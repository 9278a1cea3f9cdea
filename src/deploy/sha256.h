#pragma once
// SHA-256 (FIPS 180-4), fed in pieces. The mission hash is the compiler's only use of a
// digest, and linking and initialising OpenSSL's libcrypto for it cost about 4 MB of the
// compiler's peak memory (docs/performance.md); these few lines cost nothing.
#include <cstddef>
#include <cstdint>
#include <string>

namespace eamos::deploy {

class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t size);
  /// The digest of everything fed so far, as 64 lowercase hex digits. Call it once.
  std::string hex_digest();

 private:
  void compress(const unsigned char* block);  ///< one 64-byte block into state_

  std::uint32_t state_[8];
  unsigned char block_[64];       ///< bytes not yet compressed
  std::size_t block_used_ = 0;
  std::uint64_t total_bytes_ = 0;
};

}  // namespace eamos::deploy
