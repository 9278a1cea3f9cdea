// src/security/pki.*: a document signed for DDS Security reads back and verifies with OpenSSL.
#include <gtest/gtest.h>

#include <openssl/bio.h>
#include <openssl/pkcs7.h>
#include <openssl/x509_vfy.h>

#include <ctime>
#include <string>

#include "security/mission_keys.h"
#include "security/pki.h"

namespace {

using namespace eamos::security;

struct Signed {
  Credential ca;
  std::string document;
};

Signed sign_permissions() {
  Signed s;
  std::string error;
  Validity v{std::time(nullptr), 1};
  EXPECT_TRUE(make_ca("CN=test permissions CA,O=eamos", v, s.ca, error)) << error;
  EXPECT_TRUE(smime_sign(s.ca, governance_xml(), s.document, error)) << error;
  return s;
}

PKCS7* read_smime(const std::string& text, BIO** content) {
  BIO* in = BIO_new_mem_buf(text.data(), static_cast<int>(text.size()));
  PKCS7* p7 = SMIME_read_PKCS7(in, content);
  BIO_free(in);
  return p7;
}

TEST(Pki, ASignedDocumentVerifiesAgainstItsCa) {
  Signed s = sign_permissions();
  BIO* content = nullptr;
  PKCS7* p7 = read_smime(s.document, &content);
  ASSERT_NE(p7, nullptr) << s.document;
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, s.ca.cert.get());
  BIO* out = BIO_new(BIO_s_mem());
  EXPECT_EQ(PKCS7_verify(p7, nullptr, store, content, out, PKCS7_TEXT), 1);
  char* data = nullptr;
  long n = BIO_get_mem_data(out, &data);
  std::string text(data, static_cast<std::size_t>(n));
  std::erase(text, '\r');  // S/MIME's canonical text has CRLF line ends
  EXPECT_EQ(text, governance_xml());
  BIO_free(out);
  X509_STORE_free(store);
  BIO_free(content);
  PKCS7_free(p7);
}

TEST(Pki, ASignedDocumentCarriesNoSmimeCapabilities) {
  // DDS Security reads the signature, never which ciphers a mail reply may use; listing them
  // looked up every cipher OpenSSL knows, for each of a fleet's documents.
  Signed s = sign_permissions();
  BIO* content = nullptr;
  PKCS7* p7 = read_smime(s.document, &content);
  ASSERT_NE(p7, nullptr);
  STACK_OF(PKCS7_SIGNER_INFO)* signers = PKCS7_get_signer_info(p7);
  ASSERT_EQ(sk_PKCS7_SIGNER_INFO_num(signers), 1);
  PKCS7_SIGNER_INFO* si = sk_PKCS7_SIGNER_INFO_value(signers, 0);
  EXPECT_EQ(PKCS7_get_signed_attribute(si, NID_SMIMECapabilities), nullptr);
  EXPECT_NE(PKCS7_get_signed_attribute(si, NID_pkcs9_messageDigest), nullptr);
  BIO_free(content);
  PKCS7_free(p7);
}

}  // namespace
