#include "rigger/compose/security.hpp"

#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <vector>

namespace rigger::compose {
namespace {

namespace fs = std::filesystem;

// Cyclone 0.10's governance parser takes domain ids up to 230 (deploy/security/governance.xml).
constexpr std::uint32_t kMaxSecureDomain = 230;
constexpr const char* kSelfIdentity = "rigger-compose";

bool readable(const fs::path& p) { return access(p.c_str(), R_OK) == 0; }

// The files one identity needs, or a line saying what is missing.
std::string check_identity(const fs::path& dir, const std::string& identity, const std::string& who) {
  std::string missing;
  for (const char* f : {"cert.pem", "key.pem", "permissions.p7s"})
    if (!readable(dir / "identities" / identity / f)) missing += std::string(missing.empty() ? "" : ", ") + f;
  if (missing.empty()) return "";
  return who + ": identity '" + identity + "' has no " + missing + " in " + (dir / "identities" / identity).string();
}

}  // namespace

std::string default_security_dir() {
  const char* env = std::getenv("RIGGER_SECURITY_DIR");
  return env && *env ? env : "/var/tmp/rigger/security";
}

void apply_security(ComposeFile& file, const std::string& security_dir) {
  const fs::path dir = fs::absolute(security_dir).lexically_normal();
  const std::string make = "make it with `deploy/security/make-pki " + dir.string() + "` (docs/security.md)";
  if (!readable(dir / "governance.p7s") || !readable(dir / "ca" / "identity_ca.pem") ||
      !readable(dir / "ca" / "permissions_ca.pem"))
    throw std::runtime_error("--secure: no DDS Security PKI in " + dir.string() +
                             " (governance.p7s, ca/identity_ca.pem, ca/permissions_ca.pem): " + make +
                             ", or point RIGGER_SECURITY_DIR at yours");
  const char* config_env = std::getenv("RIGGER_SECURE_DDS_CONFIG");
  const fs::path config = config_env && *config_env ? fs::path(config_env) : fs::path(file.root) / "deploy" /
                                                                                 "cyclonedds-secure.xml";
  if (!readable(config))
    throw std::runtime_error("--secure: the secured DDS configuration " + config.string() + " is not readable");
  if (file.domain > kMaxSecureDomain)
    throw std::runtime_error("--secure: DDS domain " + std::to_string(file.domain) +
                             ": the governance covers domains 0.." + std::to_string(kMaxSecureDomain));

  std::vector<std::string> problems;
  const char* self_env = std::getenv("RIGGER_IDENTITY");
  const std::string self = self_env && *self_env ? self_env : kSelfIdentity;
  if (auto p = check_identity(dir, self, "rigger-compose itself"); !p.empty()) problems.push_back(p);
  for (const auto& s : file.services) {
    const auto it = s.env.find("RIGGER_IDENTITY");
    const std::string identity = it != s.env.end() ? it->second : s.name;
    if (auto p = check_identity(dir, identity, "service " + s.name); !p.empty()) problems.push_back(p);
  }
  if (!problems.empty()) {
    std::string message = "--secure: missing identities:";
    for (const auto& p : problems) message += "\n  " + p;
    message += "\nadd them to the access table (common/protocol/src/access.cpp, or make-pki --extra FILE) and run "
               "`deploy/security/make-pki " + dir.string() + "` again";
    throw std::runtime_error(message);
  }

  file.dds_config = config.string();
  for (auto& s : file.services) {
    s.env.emplace("RIGGER_IDENTITY", s.name);  // keeps one given in the file
    s.env["RIGGER_SECURITY_DIR"] = dir.string();
  }
  setenv("RIGGER_SECURITY_DIR", dir.c_str(), 1);
  setenv("RIGGER_IDENTITY", self.c_str(), 1);
}

}  // namespace rigger::compose
