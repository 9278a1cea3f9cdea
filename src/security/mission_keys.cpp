#include "security/mission_keys.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <ctime>
#include <filesystem>

#include "diag/file_read.h"
#include "security/pki.h"
#include "transport/partitions.h"

namespace eamos::security {

namespace fs = std::filesystem;

namespace {

/// Writes `text` to `path` readable by its owner only (`secret`) or by anyone.
bool write_file(const fs::path& path, const std::string& text, bool secret, std::string& error) {
  // Created with its final mode: a key is never readable by others, not even briefly.
  int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, secret ? 0600 : 0644);
  bool ok = fd >= 0 && (!secret || ::fchmod(fd, 0600) == 0);
  for (std::size_t done = 0; ok && done < text.size();) {
    ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    ok = n > 0;
    done += ok ? static_cast<std::size_t>(n) : 0;
  }
  if (fd >= 0 && ::close(fd) != 0) ok = false;
  if (!ok) error = "cannot write '" + path.string() + "'; check the folder's permissions";
  return ok;
}

bool read_file(const fs::path& path, std::string& text) {
  // A CA's certificate or key in PEM is a few kilobytes.
  constexpr std::uint64_t kMaxPemBytes = std::uint64_t{1} << 20;
  return diag::read_bounded_file(path.string(), kMaxPemBytes, text).status == diag::FileRead::ok;
}

std::string xml_date(std::time_t t) {
  char buf[32];
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S", &tm);
  return buf;
}

/// The mission's two CAs.
struct Authorities {
  Credential identity;
  Credential permissions;
};

const char* kCaFiles[] = {"identity_ca.pem", "identity_ca_key.pem", "permissions_ca.pem", "permissions_ca_key.pem"};

bool make_authorities(const std::string& org, const Validity& v, Authorities& cas, std::string& error) {
  return make_ca("CN=eamos identity CA,O=" + org, v, cas.identity, error) &&
         make_ca("CN=eamos permissions CA,O=" + org, v, cas.permissions, error);
}

/// The CAs of `--keys DIR`: read when there, made (and kept there) when DIR has none.
bool keys_dir_authorities(const MissionKeysRequest& r, const Validity& v, Authorities& cas,
                          std::vector<std::string>& notes, std::string& error) {
  fs::path dir(r.keys_dir);
  std::error_code ec;
  int present = 0;
  std::string missing;
  for (const char* f : kCaFiles) {
    if (fs::exists(dir / f, ec)) ++present;
    else missing += (missing.empty() ? "" : ", ") + std::string(f);
  }
  if (present == 0) {
    fs::create_directories(dir, ec);
    fs::permissions(dir, fs::perms::owner_all, ec);
    // Valid for ten years: the CAs outlive many missions; rotating them is making new ones.
    Validity ca_validity{v.now, 3650};
    if (!make_authorities("eamos", ca_validity, cas, error)) return false;
    std::string pem[] = {cert_pem(cas.identity.cert.get()), key_pem(cas.identity.key.get()),
                         cert_pem(cas.permissions.cert.get()), key_pem(cas.permissions.key.get())};
    for (int i = 0; i < 4; ++i)
      if (!write_file(dir / kCaFiles[i], pem[i], i % 2 == 1, error)) return false;
    notes.push_back("made a new identity CA and permissions CA in " + dir.string() +
                    " (keep the *_key.pem files secret; every mission compiled with --keys " + dir.string() +
                    " is trusted by the same CAs)");
    return true;
  }
  if (present < 4) {
    error = "--keys " + dir.string() + " lacks " + missing + "; it must hold all of " +
            "identity_ca.pem, identity_ca_key.pem, permissions_ca.pem and permissions_ca_key.pem, or none (then they are made)";
    return false;
  }
  std::string pem[4];
  for (int i = 0; i < 4; ++i)
    if (!read_file(dir / kCaFiles[i], pem[i])) {
      error = "cannot read " + (dir / kCaFiles[i]).string();
      return false;
    }
  std::string why;
  if (!read_credential(pem[0], pem[1], cas.identity, why)) {
    error = (dir / "identity_ca.pem").string() + ": " + why;
    return false;
  }
  if (!read_credential(pem[2], pem[3], cas.permissions, why)) {
    error = (dir / "permissions_ca.pem").string() + ": " + why;
    return false;
  }
  notes.push_back("signed the mission's credentials with the CAs in " + dir.string());
  return true;
}

/// What every participant's folder holds the same of, encoded once.
struct SharedFiles {
  std::string identity_ca, permissions_ca, governance;
};

/// `folder` made (or kept) readable by its owner only.
bool make_private_folder(const fs::path& folder, std::string& error) {
  // The drone's folder exists (write_deployment made it): one mkdir, no walk up the path.
  if (::mkdir(folder.c_str(), 0700) == 0 || (errno == EEXIST && ::chmod(folder.c_str(), 0700) == 0)) return true;
  std::error_code ec;
  fs::create_directories(folder, ec);
  fs::permissions(folder, fs::perms::owner_all, ec);
  if (!ec) return true;
  error = "cannot create '" + folder.string() + "': " + ec.message();
  return false;
}

/// One participant's folder: the public CA certificates and governance, its identity,
/// its private key and its permissions.
bool write_participant(const MissionKeysRequest& r, const Authorities& cas, const SharedFiles& shared,
                       const Validity& v, int who, const fs::path& folder, std::string& error) {
  if (!make_private_folder(folder, error)) return false;
  std::string name = who == transport::kGroundParticipant ? std::string("ground") : r.drones[who];
  // No ',', '/', '|' or '=' in the values: DDS Security's access control splits subjects there.
  std::string subject = "CN=" + name + ",O=eamos-mission-" + r.mission_hash.substr(0, 16);
  Credential id;
  if (!make_identity(cas.identity, subject, v, id, error)) return false;
  std::string permissions;
  std::string doc = permissions_xml(subject, r.mission_hash, who, xml_date(v.now - 3600),
                                    xml_date(v.now + static_cast<std::time_t>(v.days) * 86400));
  if (!smime_sign(cas.permissions, doc, permissions, error)) return false;
  return write_file(folder / "identity_ca.pem", shared.identity_ca, false, error) &&
         write_file(folder / "permissions_ca.pem", shared.permissions_ca, false, error) &&
         write_file(folder / "governance.p7s", shared.governance, false, error) &&
         write_file(folder / "identity.pem", cert_pem(id.cert.get()), false, error) &&
         write_file(folder / "identity_key.pem", key_pem(id.key.get()), true, error) &&
         write_file(folder / "permissions.p7s", permissions, false, error);
}

}  // namespace

bool write_mission_keys(const MissionKeysRequest& r, std::vector<std::string>& notes, std::string& error) {
  if (r.valid_days < 1) {
    error = "credentials must be valid for at least one day";
    return false;
  }
  Validity v{std::time(nullptr), r.valid_days};
  Authorities cas;
  if (r.keys_dir.empty()) {
    if (!make_authorities("eamos-mission-" + r.mission_hash.substr(0, 16), v, cas, error)) return false;
  } else if (!keys_dir_authorities(r, v, cas, notes, error)) {
    return false;
  }
  SharedFiles shared{cert_pem(cas.identity.cert.get()), cert_pem(cas.permissions.cert.get()), ""};
  if (!smime_sign(cas.permissions, governance_xml(), shared.governance, error)) return false;
  fs::path dir(r.deploy_dir);
  for (int d = 0; d < static_cast<int>(r.drones.size()); ++d)
    if (!write_participant(r, cas, shared, v, d, dir / r.drones[d] / kSecuritySubfolder, error)) return false;
  return write_participant(r, cas, shared, v, transport::kGroundParticipant, dir / kGroundFolder / kSecuritySubfolder,
                           error);
}

}  // namespace eamos::security
