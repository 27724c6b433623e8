#pragma once
// The few OpenSSL operations DDS Security needs: EC P-256 keys, X.509 certificates signed with
// ECDSA-SHA256 (what Fast DDS's builtin plugins accept), and S/MIME signing of the governance
// and permissions documents as `openssl smime -sign -text` makes them. Errors throw InputError
// with OpenSSL's reason.
#include <openssl/evp.h>
#include <openssl/x509.h>

#include <memory>
#include <string>

namespace hiveslam::communication::security {

struct KeyFree {
  void operator()(EVP_PKEY* k) const { EVP_PKEY_free(k); }
};
struct CertFree {
  void operator()(X509* c) const { X509_free(c); }
};
using Key = std::unique_ptr<EVP_PKEY, KeyFree>;
using Cert = std::unique_ptr<X509, CertFree>;

Key makeKey();
// A certificate for subject "CN=<common_name>", valid from a day ago for `days`; self-signed
// (a CA) when issuer is null, else signed by issuer_cert/issuer_key.
Cert makeCertificate(const std::string& common_name, EVP_PKEY* key, int days, bool ca, X509* issuer_cert = nullptr,
                     EVP_PKEY* issuer_key = nullptr);

std::string keyPem(EVP_PKEY* key);
std::string certPem(X509* cert);
Key readKeyPem(const std::string& pem, const std::string& what);
Cert readCertPem(const std::string& pem, const std::string& what);

// The document as S/MIME, signed by cert/key (detached signature over its text/plain form).
std::string signSmime(const std::string& text, X509* cert, EVP_PKEY* key);
// The signed text if `smime` carries a valid signature by a certificate issued by `ca` (as Fast
// DDS checks it); throws InputError otherwise.
std::string verifySmime(const std::string& smime, X509* ca);

}  // namespace hiveslam::communication::security
