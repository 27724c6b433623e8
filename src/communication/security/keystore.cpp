#include "communication/security/keystore.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <sstream>

#include <fmt/chrono.h>
#include <fmt/format.h>

#include "common/error.hpp"
#include "communication/security/pki.hpp"

namespace hiveslam::communication::security {

namespace fs = std::filesystem;

namespace {

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw InputError("cannot read " + p.string());
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Written whole with `mode` from the start: a key is never readable by others, even briefly.
void writeFile(const fs::path& p, const std::string& text, mode_t mode) {
  const int fd = ::open(p.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, mode);
  if (fd < 0) throw InputError("cannot write " + p.string());
  const bool ok = ::fchmod(fd, mode) == 0 && ::write(fd, text.data(), text.size()) == static_cast<ssize_t>(text.size());
  ::close(fd);
  if (!ok) throw InputError("cannot write " + p.string());
}

struct Authority {
  Key key;
  Cert cert;
};

// The CA `name` from DIR/private and DIR, or a new one.
Authority authority(const fs::path& dir, const std::string& name, int days) {
  const fs::path key_file = dir / "private" / (name + ".key.pem"), cert_file = dir / (name + ".pem");
  if (fs::exists(key_file) && fs::exists(cert_file))
    return {readKeyPem(readText(key_file), key_file.string()), readCertPem(readText(cert_file), cert_file.string())};
  Key key = makeKey();
  Cert cert = makeCertificate("hiveslam " + name, key.get(), days, true);
  writeFile(key_file, keyPem(key.get()), 0600);
  writeFile(cert_file, certPem(cert.get()), 0644);
  return {std::move(key), std::move(cert)};
}

std::string isoUtc(std::chrono::system_clock::time_point t) {
  return fmt::format("{:%Y-%m-%dT%H:%M:%S}", std::chrono::floor<std::chrono::seconds>(t));
}

// The <topic> entries of every <`rule`> element of a permissions document.
std::vector<std::string> topicsIn(const std::string& xml, const std::string& rule) {
  std::vector<std::string> topics;
  const std::string open = "<" + rule + ">", close = "</" + rule + ">";
  for (size_t at = xml.find(open); at != std::string::npos; at = xml.find(open, at)) {
    const size_t end = std::min(xml.find(close, at), xml.size());
    for (size_t t = xml.find("<topic>", at); t < end; t = xml.find("<topic>", t)) {
      t += 7;
      const size_t e = xml.find("</topic>", t);
      if (e == std::string::npos || e > end) break;
      topics.push_back(xml.substr(t, e - t));
    }
    at = end;
  }
  return topics;
}

void checkOwnerOnly(const fs::path& p) {
  struct stat st {};
  if (::stat(p.c_str(), &st) != 0) throw InputError("missing " + p.string() + " (make it with `hiveslam keys`)");
  if (st.st_mode & 077)
    throw InputError(fmt::format("private key {} is readable by others (mode {:o}): chmod 600 it", p.string(),
                                 st.st_mode & 0777));
}

}  // namespace

void makeKeystore(const KeystoreRequest& r) {
  if (r.nodes.empty()) throw InputError("keys: name at least one node");
  if (r.days < 1) throw InputError("keys: --days must be at least 1");
  fs::create_directories(r.dir / "private");
  fs::permissions(r.dir / "private", fs::perms::owner_all, fs::perm_options::replace);
  const Authority identity = authority(r.dir, "identity_ca", r.days);
  const Authority permissions = authority(r.dir, "permissions_ca", r.days);
  writeFile(r.dir / "governance.p7s", signSmime(governanceXml(), permissions.cert.get(), permissions.key.get()), 0644);
  const auto now = std::chrono::system_clock::now();
  const std::string not_before = isoUtc(now - std::chrono::hours(24));
  const std::string not_after = isoUtc(now + std::chrono::hours(24) * r.days);
  for (const Identity& node : r.nodes) {
    const fs::path d = r.dir / node.name;
    fs::create_directories(d);
    Key key = makeKey();
    Cert cert = makeCertificate(node.name, key.get(), r.days, false, identity.cert.get(), identity.key.get());
    writeFile(d / "key.pem", keyPem(key.get()), 0600);
    writeFile(d / "cert.pem", certPem(cert.get()), 0644);
    const std::string xml = permissionsXml(node, not_before, not_after);
    writeFile(d / "permissions.xml", xml, 0644);  // for reading; the signed copy is what counts
    writeFile(d / "permissions.p7s", signSmime(xml, permissions.cert.get(), permissions.key.get()), 0644);
  }
}

SecureIdentity loadIdentity(const fs::path& dir, const std::string& name) {
  SecureIdentity id{name,
                    dir / "identity_ca.pem",
                    dir / "permissions_ca.pem",
                    dir / "governance.p7s",
                    dir / name / "cert.pem",
                    dir / name / "key.pem",
                    dir / name / "permissions.p7s",
                    {},
                    {}};
  for (const fs::path& p : {id.identity_ca, id.permissions_ca, id.governance, id.certificate, id.permissions})
    if (!fs::is_regular_file(p))
      throw InputError("missing " + p.string() + " (make it with `hiveslam keys --out " + dir.string() + " --nodes " + name + "`)");
  checkOwnerOnly(id.private_key);
  const auto ca = readCertPem(readText(id.permissions_ca), id.permissions_ca.string());
  std::string granted;
  try {
    granted = verifySmime(readText(id.permissions), ca.get());
  } catch (const InputError&) {
    throw InputError(id.permissions.string() + " does not carry the signature of " + id.permissions_ca.string());
  }
  id.publish = topicsIn(granted, "publish");
  id.subscribe = topicsIn(granted, "subscribe");
  for (auto* p : {&id.identity_ca, &id.permissions_ca, &id.governance, &id.certificate, &id.private_key, &id.permissions})
    *p = fs::absolute(*p);
  return id;
}

}  // namespace hiveslam::communication::security
