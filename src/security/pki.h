#pragma once
// The X.509 and S/MIME work of a mission's PKI, all of it done by OpenSSL's libcrypto
// (never by hand): EC P-256 keys, certificates signed by a CA, and documents signed in
// the S/MIME form DDS Security reads (multipart/signed, detached, text/plain content).
#include <ctime>
#include <memory>
#include <string>

#include <openssl/evp.h>
#include <openssl/x509.h>

namespace eamos::security {

struct KeyFree {
  void operator()(EVP_PKEY* k) const { EVP_PKEY_free(k); }
};
struct CertFree {
  void operator()(X509* c) const { X509_free(c); }
};
using Key = std::unique_ptr<EVP_PKEY, KeyFree>;
using Cert = std::unique_ptr<X509, CertFree>;

/// A certificate with its private key: a CA, or a participant's identity.
struct Credential {
  Key key;
  Cert cert;
};

/// How long what is made now is valid: from an hour ago (clocks disagree a little) to
/// `days` from now.
struct Validity {
  std::time_t now = 0;
  int days = 30;
};

/// A fresh self-signed CA with subject `subject` ("CN=...,O=..."); false with `error`.
bool make_ca(const std::string& subject, const Validity& v, Credential& out, std::string& error);
/// A fresh key and a certificate for `subject`, signed by `ca`.
bool make_identity(const Credential& ca, const std::string& subject, const Validity& v, Credential& out,
                   std::string& error);

std::string cert_pem(const X509* cert);
/// The private key unencrypted: the file it goes to is readable by its owner only.
std::string key_pem(EVP_PKEY* key);
/// Reads a certificate and its key from PEM text; false when either does not parse or the
/// key is not the certificate's.
bool read_credential(const std::string& cert_pem, const std::string& key_pem, Credential& out, std::string& error);

/// `text` signed by `signer` as S/MIME (what `openssl smime -sign -text` writes).
bool smime_sign(const Credential& signer, const std::string& text, std::string& out, std::string& error);

}  // namespace eamos::security
