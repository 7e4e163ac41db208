#pragma once
// What the DDS Security tests share (docs/security.md): a PKI made by deploy/security/make-pki
// into a private folder, the "rogue" folder of an intruder whose permissions the identity CA signed, the
// environment that puts a process on the secured domain as an identity, and the three intruders
// (rigger_security_probe) with the checks on what their logs say.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/task.hpp"
#include "rigger/testing/domain.hpp"
#include "rigger/testing/process.hpp"

namespace rigger::testing::security {

using namespace std::chrono_literals;

inline std::string secure_uri() {
  return std::string("file://") + RIGGER_SOURCE_DIR + "/deploy/cyclonedds-secure.xml";
}
/// rigger-compose and the probe of this build (the services may come from $RIGGER_BIN_DIR).
inline std::string own_binary(const std::string& name) {
  return std::string(RIGGER_BINARY_DIR) + "/bin/" + name;
}

inline std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path);
  out << text;
}

/// Runs a command to its end; its output goes to <log_dir>/<name>.log. Returns (status, output).
inline std::pair<ExitStatus, std::string> run(const std::string& log_dir, const std::string& name,
                                              const std::string& binary, const std::vector<std::string>& args,
                                              const std::map<std::string, std::string>& env = {},
                                              std::chrono::milliseconds timeout = 120s) {
  ChildProcess p(binary, args, env, log_dir + "/" + name + ".log");
  auto st = p.wait(timeout);
  if (!st) {
    p.signal(SIGKILL);
    st = p.wait(5s);
    ADD_FAILURE() << name << " did not finish within " << timeout.count() << " ms";
  }
  return {st.value_or(ExitStatus{}), p.log()};
}

/// The PKI of one test program, in /tmp/<tag>-<pid> (keys never go into the repository: make-pki refuses):
///   pki()    made by deploy/security/make-pki from this build's access table;
///   rogue()  an intruder who holds the identity CA's key (or got the cell's identity CA to sign a CA of
///            their own): a real identity (vision_tracker's certificate and key), permissions granting every
///            topic, signed by the identity CA, which its own configuration trusts as permissions CA.
/// make() records failures with ADD_FAILURE/ASSERT (check HasFatalFailure()); remove() deletes the keys.
class TestPki {
 public:
  void make(const std::string& log_dir, const std::string& tag) {
    log_dir_ = log_dir;
    keys_ = "/tmp/" + tag + "-" + std::to_string(getpid());
    pki_ = keys_ + "/pki";
    rogue_ = keys_ + "/rogue";
    std::filesystem::create_directories(log_dir_);
    const auto [made, out] = run(log_dir_, "make-pki", std::string(RIGGER_SOURCE_DIR) + "/deploy/security/make-pki",
                                 {"--catalog", own_binary("rigger-topic-catalog"), pki_});
    ASSERT_TRUE(made.ok()) << out;
    ASSERT_EQ(std::filesystem::status(pki_ + "/identities/task_controller/key.pem").permissions() &
                  std::filesystem::perms::all,
              std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
    make_rogue();
  }

  void remove() const {
    if (!keys_.empty()) std::filesystem::remove_all(keys_);
  }

  const std::string& pki() const { return pki_; }
  const std::string& rogue() const { return rogue_; }

  /// The environment of a process on secured domain `domain` as `identity` (from `pki`, default pki()).
  std::map<std::string, std::string> env(const std::string& identity, std::uint32_t domain,
                                         const std::string& pki = "") const {
    return {{"CYCLONEDDS_URI", secure_uri()},
            {"RIGGER_SECURITY_DIR", pki.empty() ? pki_ : pki},
            {"RIGGER_IDENTITY", identity},
            {"RIGGER_DOMAIN", std::to_string(domain)}};
  }

  /// Makes this process's own participants (made after the call) join as `identity`.
  void join_as(const std::string& identity) const {
    setenv("CYCLONEDDS_URI", secure_uri().c_str(), 1);
    setenv("RIGGER_SECURITY_DIR", pki_.c_str(), 1);
    setenv("RIGGER_IDENTITY", identity.c_str(), 1);
  }

 private:
  void make_rogue() {
    namespace fs = std::filesystem;
    const std::string id = rogue_ + "/identities/vision_tracker";
    fs::create_directories(id);
    fs::create_directories(rogue_ + "/ca");
    fs::copy_file(pki_ + "/ca/identity_ca.pem", rogue_ + "/ca/identity_ca.pem");
    fs::copy_file(pki_ + "/ca/identity_ca.pem", rogue_ + "/ca/permissions_ca.pem");
    fs::copy_file(pki_ + "/identities/vision_tracker/cert.pem", id + "/cert.pem");
    fs::copy_file(pki_ + "/identities/vision_tracker/key.pem", id + "/key.pem");
    const std::string mine = slurp(pki_ + "/identities/vision_tracker/permissions.xml");
    const auto a = mine.find("<subject_name>"), b = mine.find("</subject_name>");
    ASSERT_NE(a, std::string::npos);
    const std::string subject = mine.substr(a, b - a + 15);
    write_text(id + "/permissions.xml",
               "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n<dds><permissions><grant name=\"everything\">" + subject +
                   "<validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after>"
                   "</validity><allow_rule><domains><id_range><min>0</min><max>230</max></id_range></domains>"
                   "<publish><topics><topic>*</topic></topics></publish>"
                   "<subscribe><topics><topic>*</topic></topics></subscribe></allow_rule>"
                   "<default>DENY</default></grant></permissions></dds>\n");
    for (const auto& [in, out] : {std::pair{id + "/permissions.xml", id + "/permissions.p7s"},
                                  std::pair{pki_ + "/governance.xml", rogue_ + "/governance.p7s"}}) {
      const auto [signed_ok, log] = run(log_dir_, "rogue-sign", "/usr/bin/openssl",
                                        {"smime", "-sign", "-in", in, "-text", "-out", out, "-signer",
                                         pki_ + "/ca/identity_ca.pem", "-inkey", pki_ + "/ca/identity_ca.key"});
      ASSERT_TRUE(signed_ok.ok()) << log;
    }
  }

  std::string log_dir_, keys_, pki_, rogue_;
};

/// One rigger_security_probe run: it CANCELs a task, submits a recipe of its own (task "attack-<label>")
/// and writes a crane velocity (source "probe-<label>"), logging what DDS did with each.
struct Probe {
  std::string label;
  std::map<std::string, std::string> env;
  std::unique_ptr<ChildProcess> process;
};

/// The three intruders (docs/security.md): (1) no identity (the plain configuration), (2) the valid identity
/// vision_tracker, which has no permission for those topics, (3) vision_tracker's certificate with the
/// rogue permissions signed by the identity CA. Not started yet.
inline std::vector<Probe> intruders(const TestPki& pki, std::uint32_t domain) {
  std::vector<Probe> probes;
  probes.push_back(
      {"no-identity",
       {{"CYCLONEDDS_URI", default_dds_config_uri()}, {"RIGGER_IDENTITY", ""}, {"RIGGER_SECURITY_DIR", ""}},
       nullptr});
  probes.push_back({"no-permission", pki.env("vision_tracker", domain), nullptr});
  probes.push_back({"rogue-permissions", pki.env("vision_tracker", domain, pki.rogue()), nullptr});
  return probes;
}

/// The probe's arguments: CANCEL `task`, wait up to `window_ms` for a reader to match each writer.
inline std::vector<std::string> probe_args(const Probe& p, std::uint32_t domain, const std::string& task,
                                           int window_ms = 2500) {
  return {"--domain",          std::to_string(domain),   "--label", p.label, "--cancel", task,
          "--match-window-ms", std::to_string(window_ms)};
}

/// Every attempt is in the intruders' logs (<log_dir>/probe-<label>.log), none matched a reader of the
/// cell, and the identity without permission was refused by its own DDS before anything reached the wire.
inline void expect_intruders_logged(const std::string& log_dir) {
  const auto probe_log = [&](const std::string& label) { return slurp(log_dir + "/probe-" + label + ".log"); };
  for (const auto& label : {"no-identity", "no-permission", "rogue-permissions"}) {
    const auto log = probe_log(label);
    for (const auto* topic :
         {protocol::task::kCommand.name, protocol::task::kRecipe.name, protocol::crane::kCmdVelocity.name}) {
      EXPECT_NE(log.find(std::string(topic) + ": "), std::string::npos) << label << " did not try " << topic << "\n"
                                                                        << log;
      EXPECT_EQ(log.find(std::string(topic) + ": MATCHED"), std::string::npos)
          << label << " matched a reader of " << topic << "\n"
          << log;
    }
  }
  EXPECT_NE(probe_log("no-permission").find(std::string(protocol::task::kRecipe.name) + ": writer REFUSED locally"),
            std::string::npos)
      << probe_log("no-permission");
}

/// What a participant of the cell logs when it rejects the rogue permissions.
inline constexpr const char* kRoguePermissionsRejected =
    "permissions from plugin: Failed to parse PKCS7 SMIME document";

}  // namespace rigger::testing::security
