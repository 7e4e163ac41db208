#include "rigger/dds/configuration.hpp"

#include <gtest/gtest.h>

#include <unistd.h>
#include <cstdlib>
#include <fstream>

#include "rigger/base/install.hpp"

namespace rigger::dds {
namespace {

class ConfigurationTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("rigger_configuration_test_" + std::to_string(getpid()));
    std::filesystem::create_directories(dir_ / "share" / "rigger");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(ConfigurationTest, EnvironmentWinsWhenSet) {
  std::ofstream(dir_ / "share" / "rigger" / "cyclonedds.xml") << "<CycloneDDS/>";
  const auto c = resolve_configuration("file:///etc/multihost.xml", dir_ / "share" / "rigger");
  EXPECT_EQ(c.origin, ConfigurationOrigin::kEnvironment);
  EXPECT_EQ(c.uri, "file:///etc/multihost.xml");
}

TEST_F(ConfigurationTest, InstallationFileWhenUnsetOrEmpty) {
  std::ofstream(dir_ / "share" / "rigger" / "cyclonedds.xml") << "<CycloneDDS/>";
  for (const char* env : {static_cast<const char*>(nullptr), ""}) {
    const auto c = resolve_configuration(env, dir_ / "share" / "rigger");
    EXPECT_EQ(c.origin, ConfigurationOrigin::kInstallation);
    EXPECT_EQ(c.uri, "file://" + std::filesystem::canonical(dir_ / "share" / "rigger" / "cyclonedds.xml").string());
  }
}

TEST_F(ConfigurationTest, CycloneDefaultsWhenNoFile) {
  const auto c = resolve_configuration(nullptr, dir_ / "share" / "rigger");
  EXPECT_EQ(c.origin, ConfigurationOrigin::kCycloneDefaults);
  EXPECT_TRUE(c.uri.empty());
  EXPECT_EQ(resolve_configuration(nullptr, {}).origin, ConfigurationOrigin::kCycloneDefaults);
}

// The build tree is laid out like an installation: this test binary (build/tests/) finds the staged
// copy of deploy/cyclonedds.xml in build/share/rigger/.
TEST(BuildTreeConfiguration, TestBinaryFindsTheStagedFile) {
  const auto c = resolve_configuration(nullptr, data_dir());
  ASSERT_EQ(c.origin, ConfigurationOrigin::kInstallation);
  std::ifstream in(c.uri.substr(std::string("file://").size()));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("<NetworkInterface name=\"lo\" />"), std::string::npos) << c.uri;
}

}  // namespace
}  // namespace rigger::dds
