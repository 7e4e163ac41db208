#include "rigger/base/install.hpp"

#include <gtest/gtest.h>

namespace rigger {
namespace {

TEST(InstallTest, DataDirIsBesideTheBinFolder) {
  EXPECT_EQ(data_dir("/opt/rigger/bin/riggerctl"), std::filesystem::path("/opt/rigger/share/rigger"));
  EXPECT_EQ(data_dir("/home/u/rigger/build/tests/x_test"), std::filesystem::path("/home/u/rigger/build/share/rigger"));
  EXPECT_TRUE(data_dir(std::filesystem::path{}).empty());
}

TEST(InstallTest, ExecutablePathIsThisTestBinary) {
  const auto exe = executable_path();
  ASSERT_FALSE(exe.empty());
  EXPECT_TRUE(exe.is_absolute());
  EXPECT_EQ(exe.filename(), "rigger_base_test");
}

}  // namespace
}  // namespace rigger
