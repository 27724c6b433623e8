#include "communication/security/pki.hpp"

#include <openssl/err.h>
#include <openssl/pem.h>
#include <openssl/pkcs7.h>
#include <openssl/rand.h>
#include <openssl/x509v3.h>

#include "common/error.hpp"

namespace hiveslam::communication::security {

namespace {

struct BioFree {
  void operator()(BIO* b) const { BIO_free(b); }
};
using Bio = std::unique_ptr<BIO, BioFree>;

[[noreturn]] void fail(const std::string& what) {
  char reason[256] = "unknown reason";
  if (const unsigned long e = ERR_get_error()) ERR_error_string_n(e, reason, sizeof reason);
  ERR_clear_error();
  throw InputError(what + ": " + reason);
}

std::string drain(BIO* b) {
  char* data = nullptr;
  const long n = BIO_get_mem_data(b, &data);
  return std::string(data, static_cast<size_t>(n));
}

Bio memoryOf(const std::string& s) { return Bio(BIO_new_mem_buf(s.data(), static_cast<int>(s.size()))); }

void addExtension(X509* cert, X509* issuer, int nid, const char* value) {
  X509V3_CTX ctx;
  X509V3_set_ctx_nodb(&ctx);
  X509V3_set_ctx(&ctx, issuer ? issuer : cert, cert, nullptr, nullptr, 0);
  X509_EXTENSION* ext = X509V3_EXT_conf_nid(nullptr, &ctx, nid, value);
  if (!ext || !X509_add_ext(cert, ext, -1)) fail("cannot add a certificate extension");
  X509_EXTENSION_free(ext);
}

}  // namespace

Key makeKey() {
  Key k(EVP_EC_gen("prime256v1"));
  if (!k) fail("cannot make an EC key");
  return k;
}

Cert makeCertificate(const std::string& common_name, EVP_PKEY* key, int days, bool ca, X509* issuer_cert,
                     EVP_PKEY* issuer_key) {
  Cert c(X509_new());
  if (!c) fail("cannot make a certificate");
  X509_set_version(c.get(), 2);
  unsigned char serial[16];
  if (RAND_bytes(serial, sizeof serial) != 1) fail("no random serial number");
  serial[0] &= 0x7f;  // a positive integer
  BIGNUM* bn = BN_bin2bn(serial, sizeof serial, nullptr);
  BN_to_ASN1_INTEGER(bn, X509_get_serialNumber(c.get()));
  BN_free(bn);
  X509_gmtime_adj(X509_getm_notBefore(c.get()), -86400L);  // a peer's clock a little behind
  X509_gmtime_adj(X509_getm_notAfter(c.get()), 86400L * days);
  X509_set_pubkey(c.get(), key);
  X509_NAME* name = X509_get_subject_name(c.get());
  X509_NAME_add_entry_by_txt(name, "CN", MBSTRING_UTF8, reinterpret_cast<const unsigned char*>(common_name.c_str()), -1,
                             -1, 0);
  X509_set_issuer_name(c.get(), issuer_cert ? X509_get_subject_name(issuer_cert) : name);
  addExtension(c.get(), issuer_cert, NID_basic_constraints, ca ? "critical,CA:TRUE" : "CA:FALSE");
  addExtension(c.get(), issuer_cert, NID_key_usage,
               ca ? "critical,keyCertSign,cRLSign,digitalSignature" : "critical,digitalSignature,keyAgreement");
  addExtension(c.get(), issuer_cert, NID_subject_key_identifier, "hash");
  if (!X509_sign(c.get(), issuer_key ? issuer_key : key, EVP_sha256())) fail("cannot sign the certificate of " + common_name);
  return c;
}

std::string keyPem(EVP_PKEY* key) {
  Bio b(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_PrivateKey(b.get(), key, nullptr, nullptr, 0, nullptr, nullptr)) fail("cannot write a key");
  return drain(b.get());
}

std::string certPem(X509* cert) {
  Bio b(BIO_new(BIO_s_mem()));
  if (!PEM_write_bio_X509(b.get(), cert)) fail("cannot write a certificate");
  return drain(b.get());
}

Key readKeyPem(const std::string& pem, const std::string& what) {
  Bio b = memoryOf(pem);
  Key k(PEM_read_bio_PrivateKey(b.get(), nullptr, nullptr, nullptr));
  if (!k) fail(what + " is not a PEM private key");
  return k;
}

Cert readCertPem(const std::string& pem, const std::string& what) {
  Bio b = memoryOf(pem);
  Cert c(PEM_read_bio_X509(b.get(), nullptr, nullptr, nullptr));
  if (!c) fail(what + " is not a PEM certificate");
  return c;
}

std::string signSmime(const std::string& text, X509* cert, EVP_PKEY* key) {
  const int flags = PKCS7_DETACHED | PKCS7_TEXT | PKCS7_STREAM;
  Bio in = memoryOf(text);
  PKCS7* p7 = PKCS7_sign(cert, key, nullptr, in.get(), flags);
  if (!p7) fail("cannot sign a document");
  Bio out(BIO_new(BIO_s_mem()));
  const int ok = SMIME_write_PKCS7(out.get(), p7, in.get(), flags);
  PKCS7_free(p7);
  if (!ok) fail("cannot write a signed document");
  return drain(out.get());
}

std::string verifySmime(const std::string& smime, X509* ca) {
  Bio in = memoryOf(smime);
  BIO* content = nullptr;
  PKCS7* p7 = SMIME_read_PKCS7(in.get(), &content);
  if (!p7) fail("not an S/MIME document");
  Bio content_owner(content);
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, ca);
  Bio out(BIO_new(BIO_s_mem()));
  const int ok = PKCS7_verify(p7, nullptr, store, content, out.get(), PKCS7_TEXT);
  X509_STORE_free(store);
  PKCS7_free(p7);
  if (ok != 1) fail("the signature does not verify");
  return drain(out.get());
}

}  // namespace hiveslam::communication::security
