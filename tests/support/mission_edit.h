#pragma once
// Editing a mission file the way a careless tool would, for the reader's tests: change a
// member, then (optionally) recompute the file hash so that only the edited member is
// wrong and the reader has to find it by its own checks.
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

#include "deploy/sha256.h"

namespace eamos_test {

/// `text` with the first `from` replaced by `to`; throws when `from` is not in it, so a
/// test cannot silently edit nothing.
inline std::string replace_once(std::string text, const std::string& from, const std::string& to) {
  std::size_t at = text.find(from);
  if (at == std::string::npos) throw std::runtime_error("'" + from + "' is not in the mission file");
  return text.replace(at, from.size(), to);
}

/// `text` with its file hash recomputed over the bytes before the member (as the writer
/// does), so the file passes the hash check.
inline std::string reseal(std::string text) {
  const std::string member = ",\n \"file_hash\":\"";
  std::size_t at = text.rfind(member);
  if (at == std::string::npos) throw std::runtime_error("no file_hash in the mission file");
  eamos::deploy::Sha256 sha;
  sha.update(text.data(), at);
  return text.replace(at + member.size(), 64, sha.hex_digest());
}

/// A mission file written from an edited document, sealed with a fresh file hash (over the
/// bytes before the member's comma), so only the edit itself is what the reader judges.
inline std::string sealed(nlohmann::json file) {
  file.erase("file_hash");
  std::string body = file.dump();
  body.pop_back();  // the closing brace
  eamos::deploy::Sha256 sha;
  sha.update(body.data(), body.size());
  return body + ",\"file_hash\":\"" + sha.hex_digest() + "\"}";
}

}  // namespace eamos_test
