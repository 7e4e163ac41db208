#include "rigger/protocol/catalog.hpp"

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "rigger/dds/qos.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/task.hpp"

namespace rigger::protocol {
namespace {

namespace fs = std::filesystem;

std::string read(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Catalog, EveryTopicOnceWithItsType) {
  std::set<std::string> names;
  for (const auto& t : catalog()) {
    EXPECT_TRUE(names.insert(t.name).second) << "declared twice: " << t.name;
    EXPECT_EQ(t.name.rfind("rigger/", 0), 0u) << t.name;
    EXPECT_NE(t.descriptor, nullptr) << t.name;
    EXPECT_FALSE(t.writers.empty()) << t.name;
    EXPECT_FALSE(t.readers.empty()) << t.name;
  }
  EXPECT_EQ(names.size(), 50u);
  ASSERT_NE(find_topic("rigger/operator/prompt"), nullptr);
  EXPECT_EQ(find_topic("rigger/operator/prompt")->idl_type, "rigger::operator_ui::OperatorPrompt");
  EXPECT_EQ(find_topic("rigger/robot/wrench")->idl_type, "rigger::sensing::WrenchStamped");
  EXPECT_EQ(find_topic("rigger/cad/request")->idl_type, "rigger::cad::CadRequest");
  EXPECT_EQ(find_topic("rigger/world/cell")->idl_type, "rigger::world::CellRevision");
  EXPECT_EQ(find_topic("rigger/world/cell_model")->idl_type, "rigger::world::CellModel");
  ASSERT_NE(find_topic("rigger/camera/depth"), nullptr);
  EXPECT_EQ(find_topic("rigger/camera/depth")->idl_type, "rigger::vision::Image");
  EXPECT_EQ(find_topic("rigger/no/such"), nullptr);
}

TEST(Catalog, DescriptorsCarryTheirProfile) {
  EXPECT_EQ(task::kRecipe.qos, QosProfile::kCommands);
  EXPECT_EQ(crane::kState.qos, QosProfile::kState);
  EXPECT_EQ(robot::kWrench.qos, QosProfile::kSensorStream);
  dds_reliability_kind_t kind{};
  dds_duration_t blocking = 0;
  ASSERT_TRUE(dds_qget_reliability(dds::qos::of(QosProfile::kSensorStream).get(), &kind, &blocking));
  EXPECT_EQ(kind, DDS_RELIABILITY_BEST_EFFORT);
  dds_durability_kind_t durability{};
  ASSERT_TRUE(dds_qget_durability(dds::qos::of(QosProfile::kState).get(), &durability));
  EXPECT_EQ(durability, DDS_DURABILITY_TRANSIENT_LOCAL);
}

TEST(Catalog, CloseNamesForATypo) {
  EXPECT_THAT(close_topic_names("rigger/crane/stat"), ::testing::Contains("rigger/crane/state"));
  EXPECT_THAT(close_topic_names("rigger/crane/sate"), ::testing::Contains("rigger/crane/state"));
  EXPECT_EQ(close_topic_names("rigger/crane/sate").front(), "rigger/crane/state");
  EXPECT_THAT(close_topic_names("state"), ::testing::Contains("rigger/robot/state"));
  EXPECT_TRUE(close_topic_names("completely/unrelated/thing/here").empty());
}

// docs/topics.md is generated (tools/update-topic-reference): fails when a descriptor changed and the
// page was not regenerated.
TEST(Catalog, TopicsPageIsUpToDate) {
  EXPECT_EQ(read(fs::path(RIGGER_SOURCE_DIR) / "docs" / "topics.md"), catalog_markdown())
      << "docs/topics.md is stale: run tools/update-topic-reference";
}

// The catalog's rule: outside tests and docs, a topic's name is spelled once, in its
// descriptor. Scans the C++ sources of common/, services/ and tools/ (their test/ folders excepted).
TEST(Catalog, EachTopicNameSpelledOnceInTheSources) {
  std::map<std::string, std::vector<std::string>> places;
  for (const char* top : {"common", "services", "tools", "idl"}) {
    for (const auto& entry : fs::recursive_directory_iterator(fs::path(RIGGER_SOURCE_DIR) / top)) {
      if (!entry.is_regular_file()) continue;
      const auto ext = entry.path().extension();
      if (ext != ".cpp" && ext != ".hpp" && ext != ".h") continue;
      const auto rel = fs::relative(entry.path(), RIGGER_SOURCE_DIR).string();
      if (rel.find("/test/") != std::string::npos) continue;
      const auto text = read(entry.path());
      for (const auto& t : catalog()) {
        const std::string quoted = "\"" + t.name + "\"";
        for (auto at = text.find(quoted); at != std::string::npos; at = text.find(quoted, at + 1))
          places[t.name].push_back(rel);
      }
    }
  }
  for (const auto& t : catalog()) {
    const auto& where = places[t.name];
    ASSERT_EQ(where.size(), 1u) << t.name << " spelled in: " << ::testing::PrintToString(where);
    EXPECT_EQ(where.front(), "common/protocol/include/rigger/protocol/" + t.area + ".hpp") << t.name;
  }
}

}  // namespace
}  // namespace rigger::protocol
