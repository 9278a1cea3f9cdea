// eamos-credentials: the last step of `eamos compile`, which replaces itself with this program
// (exec) once the mission files are written. The credentials need only
// the mission hash and the drones' names; made here, OpenSSL's libcrypto is never mapped
// beside the compile's data, so the command's peak memory is the larger of the two steps, not
// their sum (docs/performance.md). Not meant to be run by hand: the arguments are checked as
// any input is, and a wrong one is reported, never trusted.
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include <openssl/crypto.h>
#include <openssl/rand.h>

#include "security/mission_keys.h"

namespace {

struct Arguments {
  eamos::security::MissionKeysRequest request;
  bool color = false;
  std::string done;  ///< printed on standard output once every folder is written
};

const char* kUsage =
    "usage: eamos-credentials --deploy-dir DIR --mission-hash HEX [--valid-days N] [--keys DIR] "
    "[--color always|never] [--done TEXT] -- DRONE...\n"
    "(run by `eamos compile` as its last step; docs/security.md)\n";

bool is_hex(const std::string& s) {
  if (s.empty()) return false;
  for (char c : s)
    if (!((c >= '0' && c <= '9') || (c >= 'a' && c <= 'f'))) return false;
  return true;
}

/// A drone's folder name as the compiler writes it: an identifier.
bool is_identifier(const std::string& s) {
  if (s.empty() || !(std::isalpha(static_cast<unsigned char>(s[0])) || s[0] == '_')) return false;
  for (char c : s)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_')) return false;
  return true;
}

bool whole_days(const std::string& s, int& days) {
  if (s.empty() || s.size() > 4 || s.find_first_not_of("0123456789") != std::string::npos) return false;
  days = std::stoi(s);
  return days >= 1 && days <= 3650;
}

/// Reads argv into `a`; every problem goes into `errors`.
void parse(int argc, char** argv, Arguments& a, std::vector<std::string>& errors) {
  int i = 1;
  for (; i < argc && std::strcmp(argv[i], "--") != 0; i += 2) {
    std::string option = argv[i];
    if (i + 1 >= argc) {
      errors.push_back(option + " needs a value");
      break;
    }
    std::string value = argv[i + 1];
    if (option == "--deploy-dir") a.request.deploy_dir = value;
    else if (option == "--mission-hash") a.request.mission_hash = value;
    else if (option == "--keys") a.request.keys_dir = value;
    else if (option == "--done") a.done = value;
    else if (option == "--color" && (value == "always" || value == "never")) a.color = value == "always";
    else if (option == "--valid-days" && whole_days(value, a.request.valid_days)) continue;
    else errors.push_back("'" + option + " " + value + "' is not an option of eamos-credentials");
  }
  for (++i; i < argc; ++i) {
    a.request.drones.emplace_back(argv[i]);
    if (!is_identifier(a.request.drones.back())) errors.push_back("'" + a.request.drones.back() + "' is not a drone name");
  }
  if (a.request.deploy_dir.empty()) errors.push_back("--deploy-dir is missing");
  if (!is_hex(a.request.mission_hash)) errors.push_back("--mission-hash needs the mission hash in lower-case hex");
  if (a.request.drones.empty()) errors.push_back("no drones after --");
}

std::string error_prefix(const char* who, bool color) {
  return std::string(who) + ": " + (color ? "\033[1;31merror:\033[0m " : "error: ");
}

}  // namespace

int main(int argc, char** argv) {
  // Random numbers from HASH-DRBG over SHA-256 rather than OpenSSL's default CTR-DRBG over
  // AES-256: both are SP 800-90A DRBGs of 256-bit strength, and SHA-256 is what every
  // signature here uses, while CTR-DRBG's first use builds OpenSSL's table of every cipher
  // (5 % of the work for 20 drones). Set before OpenSSL reads its configuration file, so a
  // site's own choice there (its [random] section) still wins. Should this fail, OpenSSL's
  // default DRBG is used, as good a source.
  RAND_set_DRBG_type(nullptr, "HASH-DRBG", nullptr, nullptr, "SHA256");
  // The process ends right after the files are written: OpenSSL's clean-up at exit would only
  // free memory the kernel takes back anyway (a tenth of a millisecond).
  OPENSSL_init_crypto(OPENSSL_INIT_NO_ATEXIT, nullptr);
  Arguments a;
  std::vector<std::string> errors;
  parse(argc, argv, a, errors);
  if (!errors.empty()) {
    for (const std::string& e : errors) std::fprintf(stderr, "%s%s\n", error_prefix("eamos-credentials", a.color).c_str(), e.c_str());
    std::fputs(kUsage, stderr);
    return 1;
  }
  std::vector<std::string> notes;
  std::string error;
  if (!eamos::security::write_mission_keys(a.request, notes, error)) {
    std::fprintf(stderr, "%scannot make the mission's DDS Security credentials: %s\n",
                 error_prefix("eamos", a.color).c_str(), error.c_str());
    return 1;
  }
  for (const std::string& n : notes) std::printf("%s\n", n.c_str());
  std::fputs(a.done.c_str(), stdout);
  return std::fflush(stdout) == 0 ? 0 : 1;
}
