// `--secure` without processes: what apply_security() checks and what it changes (security.hpp).
#include "rigger/compose/security.hpp"

#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rigger::compose {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

class ApplySecurity : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("rigger-compose-security-" + std::to_string(getpid()));
    fs::create_directories(root_ / "deploy");
    touch(root_ / "deploy" / "cyclonedds-secure.xml");
    pki_ = root_ / "pki";
    file_.root = root_.string();
    file_.dds_config = (root_ / "deploy" / "cyclonedds.xml").string();
    file_.services.push_back(ServiceDef{});
    file_.services.back().name = "task_controller";
    file_.services.push_back(ServiceDef{});
    file_.services.back().name = "exec";
    file_.services.back().env["RIGGER_IDENTITY"] = "robot-skills";
    unsetenv("RIGGER_IDENTITY");
    unsetenv("RIGGER_SECURE_DDS_CONFIG");
  }
  void TearDown() override { fs::remove_all(root_); }

  static void touch(const fs::path& p) {
    fs::create_directories(p.parent_path());
    std::ofstream(p) << "x";
  }
  void make_pki(const std::vector<std::string>& identities) {
    for (const char* f : {"governance.p7s", "ca/identity_ca.pem", "ca/permissions_ca.pem"}) touch(pki_ / f);
    for (const auto& id : identities)
      for (const char* f : {"cert.pem", "key.pem", "permissions.p7s"}) touch(pki_ / "identities" / id / f);
  }
  std::string error() {
    try {
      apply_security(file_, pki_.string());
    } catch (const std::runtime_error& e) {
      return e.what();
    }
    return "";
  }

  fs::path root_, pki_;
  ComposeFile file_;
};

TEST_F(ApplySecurity, NoPkiSaysHowToMakeIt) {
  const auto e = error();
  EXPECT_THAT(e, HasSubstr("no DDS Security PKI in " + pki_.string()));
  EXPECT_THAT(e, HasSubstr("deploy/security/make-pki " + pki_.string()));
  EXPECT_EQ(file_.dds_config, (root_ / "deploy" / "cyclonedds.xml").string()) << "changed although it failed";
}

TEST_F(ApplySecurity, ListsEveryMissingIdentity) {
  make_pki({"task_controller"});
  const auto e = error();
  EXPECT_THAT(e, HasSubstr("service exec: identity 'robot-skills' has no cert.pem, key.pem, permissions.p7s"));
  EXPECT_THAT(e, HasSubstr("rigger-compose itself: identity 'rigger-compose'"));
  EXPECT_THAT(e, ::testing::Not(HasSubstr("service task_controller")));
  EXPECT_TRUE(file_.services[0].env.empty());
}

TEST_F(ApplySecurity, DomainAbove230IsRefused) {
  make_pki({"task_controller", "robot-skills", "rigger-compose"});
  file_.domain = 231;
  EXPECT_THAT(error(), HasSubstr("domains 0..230"));
}

TEST_F(ApplySecurity, GivesEachServiceItsIdentityAndTheSecuredConfiguration) {
  make_pki({"task_controller", "robot-skills", "rigger-compose"});
  ASSERT_EQ(error(), "");
  EXPECT_EQ(file_.dds_config, (root_ / "deploy" / "cyclonedds-secure.xml").string());
  EXPECT_EQ(file_.services[0].env.at("RIGGER_IDENTITY"), "task_controller");
  EXPECT_EQ(file_.services[1].env.at("RIGGER_IDENTITY"), "robot-skills");
  EXPECT_EQ(file_.services[1].env.at("RIGGER_SECURITY_DIR"), pki_.string());
  EXPECT_STREQ(std::getenv("RIGGER_IDENTITY"), "rigger-compose");
  EXPECT_STREQ(std::getenv("RIGGER_SECURITY_DIR"), pki_.c_str());
}

}  // namespace
}  // namespace rigger::compose
