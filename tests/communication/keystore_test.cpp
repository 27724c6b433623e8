// The keys `hiveslam keys` makes, checked the way Fast DDS's builtin plugins read them: the
// governance and permissions verify against the permissions CA (S/MIME, text), each node's
// certificate against the identity CA, and a private key is never readable by others.
#include <gtest/gtest.h>
#include <openssl/x509_vfy.h>
#include <sys/stat.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "common/error.hpp"
#include "communication/security/keystore.hpp"
#include "communication/security/pki.hpp"
#include "temp_dir.hpp"

namespace hiveslam::communication::security {
namespace {

namespace fs = std::filesystem;

std::string readText(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

mode_t modeOf(const fs::path& p) {
  struct stat st {};
  EXPECT_EQ(::stat(p.c_str(), &st), 0) << p;
  return st.st_mode & 0777;
}

Cert cert(const fs::path& p) { return readCertPem(readText(p), p.string()); }

bool issuedBy(X509* c, X509* ca) {
  X509_STORE* store = X509_STORE_new();
  X509_STORE_add_cert(store, ca);
  X509_STORE_CTX* ctx = X509_STORE_CTX_new();
  X509_STORE_CTX_init(ctx, store, c, nullptr);
  const bool ok = X509_verify_cert(ctx) == 1;
  X509_STORE_CTX_free(ctx);
  X509_STORE_free(store);
  return ok;
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

TEST(Keystore, MakesSignedDocumentsAndOwnerOnlyKeys) {
  testing::TempDir dir;
  makeKeystore({dir.path(), {parseIdentity("tr"), parseIdentity("lm"), parseIdentity("view")}, 30});
  const Cert permissions_ca = cert(dir / "permissions_ca.pem"), identity_ca = cert(dir / "identity_ca.pem");
  const std::string governance = verifySmime(readText(dir / "governance.p7s"), permissions_ca.get());
  EXPECT_NE(governance.find("<allow_unauthenticated_participants>false"), std::string::npos);
  EXPECT_NE(governance.find("<data_protection_kind>ENCRYPT"), std::string::npos);
  const std::string tr = verifySmime(readText(dir / "tr" / "permissions.p7s"), permissions_ca.get());
  EXPECT_NE(tr.find("<subject_name>CN=tr</subject_name>"), std::string::npos);
  EXPECT_NE(tr.find("<topic>rt/hiveslam/tr/keyframes</topic>"), std::string::npos);
  // The identity CA signs certificates, not documents: a node must not be able to grant itself.
  EXPECT_THROW(verifySmime(readText(dir / "tr" / "permissions.p7s"), identity_ca.get()), InputError);
  for (const char* node : {"tr", "lm", "view"}) {
    EXPECT_TRUE(issuedBy(cert(dir / node / "cert.pem").get(), identity_ca.get())) << node;
    EXPECT_FALSE(issuedBy(cert(dir / node / "cert.pem").get(), permissions_ca.get())) << node;
    EXPECT_EQ(modeOf(dir / node / "key.pem"), 0600u) << node;
  }
  EXPECT_EQ(modeOf(dir / "private"), 0700u);
  EXPECT_EQ(modeOf(dir / "private" / "identity_ca.key.pem"), 0600u);
}

TEST(Keystore, RunAgainItKeepsTheAuthoritiesAndAddsNodes) {
  testing::TempDir dir;
  makeKeystore({dir.path(), {parseIdentity("tr")}, 30});
  const std::string ca = readText(dir / "identity_ca.pem");
  makeKeystore({dir.path(), {parseIdentity("cam2:tr")}, 30});
  EXPECT_EQ(readText(dir / "identity_ca.pem"), ca);
  EXPECT_TRUE(issuedBy(cert(dir / "cam2" / "cert.pem").get(), cert(dir / "identity_ca.pem").get()));
  EXPECT_TRUE(fs::exists(dir / "tr" / "cert.pem"));
}

TEST(Keystore, AnotherDomainsDocumentsDoNotVerify) {
  testing::TempDir a, b;
  makeKeystore({a.path(), {parseIdentity("lm")}, 30});
  makeKeystore({b.path(), {parseIdentity("lm")}, 30});
  EXPECT_THROW(verifySmime(readText(b / "lm" / "permissions.p7s"), cert(a / "permissions_ca.pem").get()), InputError);
  EXPECT_FALSE(issuedBy(cert(b / "lm" / "cert.pem").get(), cert(a / "identity_ca.pem").get()));
}

TEST(Keystore, AnIdentityWithAKeyOthersCanReadIsRefused) {
  testing::TempDir dir;
  makeKeystore({dir.path(), {parseIdentity("lc")}, 30});
  EXPECT_NO_THROW(loadIdentity(dir.path(), "lc"));
  fs::permissions(dir / "lc" / "key.pem", fs::perms::group_read | fs::perms::others_read, fs::perm_options::add);
  try {
    loadIdentity(dir.path(), "lc");
    FAIL() << "a group- and world-readable key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("readable by others"), std::string::npos) << e.what();
    EXPECT_EQ(std::string(e.what()).find("PRIVATE KEY"), std::string::npos) << "the key's text in a message";
  }
  EXPECT_THROW(loadIdentity(dir.path(), "lm"), InputError);  // never made
}

TEST(Grants, EachRoleWritesOnlyWhatItsTasksWrite) {
  const TopicGrant tr = topicsOf(parseIdentity("tr")), lm = topicsOf(parseIdentity("lm")),
                   lc = topicsOf(parseIdentity("lc")), view = topicsOf(parseIdentity("view")),
                   play = topicsOf(parseIdentity("play"));
  EXPECT_TRUE(has(tr.publish, "rt/hiveslam/tr/keyframes"));
  EXPECT_FALSE(has(lm.publish, "rt/hiveslam/tr/keyframes"));
  EXPECT_FALSE(has(lc.publish, "rt/hiveslam/tr/keyframes"));
  EXPECT_FALSE(has(lc.publish, "rt/hiveslam/lm/map"));
  EXPECT_TRUE(has(lc.publish, "rt/hiveslam/lc/map"));
  EXPECT_TRUE(has(lm.subscribe, "rt/hiveslam/tr/keyframes"));
  EXPECT_FALSE(has(tr.subscribe, "rt/hiveslam/tr/keyframes"));  // what TR sends is for mapping
  EXPECT_TRUE(has(tr.publish, "rt/hiveslam/tr/pose"));
  EXPECT_FALSE(has(lm.publish, "rt/hiveslam/tr/pose"));  // a node writes its own ROS topics only
  EXPECT_TRUE(view.publish.empty());
  EXPECT_FALSE(has(view.subscribe, "rt/hiveslam/tr/keyframes"));
  EXPECT_TRUE(play.subscribe.empty());
}

TEST(Grants, NamesAndRolesAreChecked) {
  EXPECT_EQ(parseIdentity("cam2:tr").role, Role::Tracking);
  EXPECT_EQ(parseIdentity("cam2:tr").name, "cam2");
  EXPECT_EQ(parseIdentity("play").role, Role::Camera);
  EXPECT_THROW(parseIdentity("x:boss"), InputError);
  EXPECT_THROW(parseIdentity("bad name:tr"), InputError);
  EXPECT_THROW(parseIdentity("2cam:tr"), InputError);
  EXPECT_THROW(parseIdentity("a/b:lm"), InputError);
  EXPECT_THROW(parseIdentity(""), InputError);
}

}  // namespace
}  // namespace hiveslam::communication::security
