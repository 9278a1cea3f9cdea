// EC_KEY is deprecated in OpenSSL 3 but kept there; see new_key() for why it is used. Before
// the first OpenSSL header, pki.h's included.
#define OPENSSL_SUPPRESS_DEPRECATED
#include "security/pki.h"

#include <openssl/bio.h>
#include <openssl/bn.h>
#include <openssl/ec.h>
#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509v3.h>

#include <vector>

namespace eamos::security {

namespace {

struct BioFree {
  void operator()(BIO* b) const { BIO_free(b); }
};
using Bio = std::unique_ptr<BIO, BioFree>;

/// OpenSSL's own words for what went wrong, after ours.
std::string ssl_error(const std::string& what) {
  std::string out = what;
  char buf[256];
  for (unsigned long e = ERR_get_error(); e != 0; e = ERR_get_error()) {
    ERR_error_string_n(e, buf, sizeof buf);
    out += std::string(out == what ? ": " : "; ") + buf;
  }
  return out;
}

/// Sets `error` to OpenSSL's account of `what` failing; returns false.
bool failed(std::string& error, const std::string& what) {
  error = ssl_error(what);
  return false;
}

std::string bio_text(BIO* b) {
  char* data = nullptr;
  long n = BIO_get_mem_data(b, &data);
  return n > 0 ? std::string(data, static_cast<std::size_t>(n)) : std::string();
}

/// P-256, made once and copied into each key: building the curve from its parameters for
/// each key (EC_KEY_new_by_curve_name) cost more than generating the key.
const EC_GROUP* p256() {
  static const EC_GROUP* group = EC_GROUP_new_by_curve_name(NID_X9_62_prime256v1);
  return group;
}

Key new_key() {
  // P-256: one of the two curves/key types Cyclone's authentication plugin accepts. Made as
  // an EC_KEY rather than with EVP_EC_gen: OpenSSL 3 encodes a provider key through its
  // encoder look-up on every certificate and PEM (about 0.3 ms per drone, most of a
  // 1,000-drone mission's credentials), a legacy key directly; the key and its PEM
  // (PKCS#8 "PRIVATE KEY") are the same either way.
  EC_KEY* ec = EC_KEY_new();
  if (!ec || !p256() || EC_KEY_set_group(ec, p256()) != 1 || EC_KEY_generate_key(ec) != 1) {
    EC_KEY_free(ec);
    return nullptr;
  }
  Key key(EVP_PKEY_new());
  if (!key || EVP_PKEY_assign_EC_KEY(key.get(), ec) != 1) {
    EC_KEY_free(ec);
    return nullptr;
  }
  return key;
}

/// "CN=Drone1,O=eamos" into an X509_NAME, attribute by attribute in the given order.
bool set_subject(X509_NAME* name, const std::string& subject) {
  std::size_t start = 0;
  while (start < subject.size()) {
    std::size_t comma = subject.find(',', start);
    std::string part = subject.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
    std::size_t eq = part.find('=');
    if (eq == std::string::npos) return false;
    std::string field = part.substr(0, eq), value = part.substr(eq + 1);
    if (!X509_NAME_add_entry_by_txt(name, field.c_str(), MBSTRING_UTF8,
                                    reinterpret_cast<const unsigned char*>(value.c_str()), -1, -1, 0))
      return false;
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return true;
}

bool add_extension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (!ext) return false;
  bool ok = X509_add_ext(cert, ext, -1) == 1;
  X509_EXTENSION_free(ext);
  return ok;
}

/// A certificate for `key` named `subject`, its serial random, not yet signed.
Cert new_cert(EVP_PKEY* key, const std::string& subject, const Validity& v) {
  Cert cert(X509_new());
  if (!cert || !X509_set_version(cert.get(), 2)) return nullptr;
  unsigned char serial[16];
  if (RAND_bytes(serial, sizeof serial) != 1) return nullptr;
  serial[0] &= 0x7F;  // a positive serial
  BIGNUM* bn = BN_bin2bn(serial, sizeof serial, nullptr);
  bool ok = bn && BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(cert.get()));
  BN_free(bn);
  std::time_t now = v.now;
  ok = ok && X509_time_adj_ex(X509_getm_notBefore(cert.get()), 0, -3600, &now) &&
       X509_time_adj_ex(X509_getm_notAfter(cert.get()), v.days, 0, &now) &&
       X509_set_pubkey(cert.get(), key) && set_subject(X509_get_subject_name(cert.get()), subject);
  return ok ? std::move(cert) : nullptr;
}

}  // namespace

bool make_ca(const std::string& subject, const Validity& v, Credential& out, std::string& error) {
  out.key = new_key();
  if (!out.key) return failed(error, "cannot make a key for " + subject);
  out.cert = new_cert(out.key.get(), subject, v);
  X509* c = out.cert.get();
  // digitalSignature too: the permissions CA signs the governance and permissions
  // documents itself, and S/MIME verification checks the signer's key usage.
  bool ok = c && X509_set_issuer_name(c, X509_get_subject_name(c)) &&
            add_extension(c, c, NID_basic_constraints, "critical,CA:TRUE") &&
            add_extension(c, c, NID_key_usage, "critical,keyCertSign,cRLSign,digitalSignature") &&
            add_extension(c, c, NID_subject_key_identifier, "hash") &&
            X509_sign(c, out.key.get(), EVP_sha256()) > 0;
  if (!ok) return failed(error, "cannot make the certificate of " + subject);
  return true;
}

bool make_identity(const Credential& ca, const std::string& subject, const Validity& v, Credential& out,
                   std::string& error) {
  out.key = new_key();
  if (!out.key) return failed(error, "cannot make a key for " + subject);
  out.cert = new_cert(out.key.get(), subject, v);
  X509* c = out.cert.get();
  bool ok = c && X509_set_issuer_name(c, X509_get_subject_name(ca.cert.get())) &&
            add_extension(c, ca.cert.get(), NID_basic_constraints, "critical,CA:FALSE") &&
            add_extension(c, ca.cert.get(), NID_key_usage, "critical,digitalSignature,keyAgreement") &&
            X509_sign(c, ca.key.get(), EVP_sha256()) > 0;
  if (!ok) return failed(error, "cannot make the certificate of " + subject);
  return true;
}

std::string cert_pem(const X509* cert) {
  Bio b(BIO_new(BIO_s_mem()));
  PEM_write_bio_X509(b.get(), const_cast<X509*>(cert));
  return bio_text(b.get());
}

std::string key_pem(EVP_PKEY* key) {
  Bio b(BIO_new(BIO_s_mem()));
  PEM_write_bio_PrivateKey(b.get(), key, nullptr, nullptr, 0, nullptr, nullptr);
  return bio_text(b.get());
}

bool read_credential(const std::string& cert_text, const std::string& key_text, Credential& out,
                     std::string& error) {
  Bio c(BIO_new_mem_buf(cert_text.data(), static_cast<int>(cert_text.size())));
  Bio k(BIO_new_mem_buf(key_text.data(), static_cast<int>(key_text.size())));
  out.cert.reset(PEM_read_bio_X509(c.get(), nullptr, nullptr, nullptr));
  out.key.reset(PEM_read_bio_PrivateKey(k.get(), nullptr, nullptr, nullptr));
  if (!out.cert) return failed(error, "not a PEM certificate");
  if (!out.key) return failed(error, "not an unencrypted PEM private key");
  if (X509_check_private_key(out.cert.get(), out.key.get()) != 1)
    return failed(error, "the private key is not the certificate's");
  return true;
}

bool smime_sign(const Credential& signer, const std::string& text, std::string& out, std::string& error) {
  // As `openssl smime -sign -text -nosmimecap`: detached (multipart/signed), the content a
  // text/plain MIME part, the signer's certificate included; streamed, so the content is read
  // once. No S/MIME capabilities attribute: it tells a mail client which ciphers to encrypt a
  // reply with, which DDS Security never reads, and listing them looks up every cipher
  // OpenSSL knows for each document signed.
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM | PKCS7_NOSMIMECAP;
  Bio in(BIO_new_mem_buf(text.data(), static_cast<int>(text.size())));
  PKCS7* p7 = PKCS7_sign(signer.cert.get(), signer.key.get(), nullptr, in.get(), flags);
  if (!p7) return failed(error, "cannot sign");
  Bio b(BIO_new(BIO_s_mem()));
  bool ok = SMIME_write_PKCS7(b.get(), p7, in.get(), flags) == 1;
  PKCS7_free(p7);
  if (!ok) return failed(error, "cannot write the S/MIME document");
  out = bio_text(b.get());
  return true;
}


}  // namespace eamos::security
