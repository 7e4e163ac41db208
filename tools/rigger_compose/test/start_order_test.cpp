#include "rigger/compose/start_order.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace rigger::compose {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

// The simulated cell's shape: a diamond plus independent services.
const std::vector<ServiceDeps> kCell{
    {"task_controller", {"world_model", "robot-skills"}},
    {"cell_sim", {}},
    {"crane_gateway", {"cell_sim"}},
    {"world_model", {}},
    {"admittance_control", {"crane_gateway", "cell_sim"}},
    {"robot-skills", {"world_model", "admittance_control"}},
    {"monitor_host", {}},
};

std::size_t index_of(const std::vector<std::string>& order, const std::string& name) {
  return static_cast<std::size_t>(std::find(order.begin(), order.end(), name) - order.begin());
}

TEST(StartOrderTest, EveryServiceComesAfterItsDependencies) {
  const auto order = start_order(kCell);
  ASSERT_EQ(order.size(), kCell.size());
  for (const auto& node : kCell) {
    for (const auto& dep : node.depends_on)
      EXPECT_LT(index_of(order, dep), index_of(order, node.name)) << dep << " before " << node.name;
  }
}

TEST(StartOrderTest, IndependentServicesKeepTheFileOrder) {
  EXPECT_THAT(start_order({{"c", {}}, {"a", {}}, {"b", {}}}), ElementsAre("c", "a", "b"));
  // Dependencies are pulled in front of the first service that needs them, in listed order.
  EXPECT_THAT(start_order(kCell), ElementsAre("world_model", "cell_sim", "crane_gateway", "admittance_control",
                                              "robot-skills", "task_controller", "monitor_host"));
}

TEST(StartOrderTest, EmptyGraph) { EXPECT_THAT(start_order({}), IsEmpty()); }

TEST(StartOrderTest, CycleIsReportedWithItsPath) {
  try {
    start_order({{"x", {}}, {"a", {"b"}}, {"b", {"c"}}, {"c", {"a"}}});
    FAIL() << "no cycle found";
  } catch (const DependencyCycleError& e) {
    EXPECT_THAT(e.cycle(), ElementsAre("a", "b", "c", "a"));
    EXPECT_STREQ(e.what(), "dependency cycle: a -> b -> c -> a");
  }
  EXPECT_THROW(start_order({{"a", {"a"}}}), DependencyCycleError);
}

TEST(StartOrderTest, CycleBehindADependencyIsFound) {
  try {
    start_order({{"top", {"a"}}, {"a", {"b"}}, {"b", {"a"}}});
    FAIL() << "no cycle found";
  } catch (const DependencyCycleError& e) {
    EXPECT_THAT(e.cycle(), ElementsAre("a", "b", "a"));
  }
}

TEST(StartOrderTest, UnknownDependencyAndDuplicateNamesAreRejected) {
  EXPECT_THROW(start_order({{"a", {"ghost"}}}), std::invalid_argument);
  EXPECT_THROW(start_order({{"a", {}}, {"a", {}}}), std::invalid_argument);
}

TEST(StartOrderTest, SelectionPullsInDependenciesTransitively) {
  EXPECT_THAT(with_dependencies(kCell, {"admittance_control"}),
              ElementsAre("cell_sim", "crane_gateway", "admittance_control"));
  EXPECT_THAT(with_dependencies(kCell, {"monitor_host", "crane_gateway"}),
              ElementsAre("cell_sim", "crane_gateway", "monitor_host"));
  // The order does not depend on the order of the selection.
  EXPECT_EQ(with_dependencies(kCell, {"crane_gateway", "monitor_host"}),
            with_dependencies(kCell, {"monitor_host", "crane_gateway"}));
  EXPECT_EQ(with_dependencies(kCell, {}), start_order(kCell));
  EXPECT_THROW(with_dependencies(kCell, {"nope"}), std::invalid_argument);
}

TEST(StartOrderTest, DependantsOf) {
  EXPECT_THAT(dependants_of(kCell, "cell_sim"), ElementsAre("crane_gateway", "admittance_control"));
  EXPECT_THAT(dependants_of(kCell, "task_controller"), IsEmpty());
}

}  // namespace
}  // namespace rigger::compose
