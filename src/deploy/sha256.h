#pragma once
// SHA-256 fed in pieces, over GNU Nettle's implementation. The mission hash is the
// compiler's only digest; Nettle is a small, well-kept library, where linking and
// initialising OpenSSL's libcrypto for it cost about 4 MB of the compiler's peak memory
// (docs/performance.md).
#include <cstddef>
#include <string>

#include <nettle/sha2.h>

namespace eamos::deploy {

class Sha256 {
 public:
  Sha256();
  void update(const void* data, std::size_t size);
  /// The digest of everything fed so far, as 64 lowercase hex digits. Call it once.
  std::string hex_digest();

 private:
  sha256_ctx ctx_;
};

}  // namespace eamos::deploy
