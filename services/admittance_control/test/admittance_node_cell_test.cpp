// The admittance_control node follows the cell's revisions (rigger/world/cell on its private domain): a moved
// robot base is taken while admittance is off and refused while a law runs.
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "admittance_node_fixture.hpp"
#include "rigger/protocol/world.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace rigger::control {
namespace {

using namespace std::chrono_literals;
using namespace testing_support;

class AdmittanceNodeRevisionTest : public AdmittanceNodeCellTest {
 protected:
  /// Revision `number` of the shipped cell with the robot base at `position`.
  void publish_base_at(std::uint64_t number, const Eigen::Vector3d& position) {
    std::ifstream in(std::string(RIGGER_SOURCE_DIR) + "/deploy/cell/simulated_cell.json", std::ios::binary);
    nlohmann::json cell = nlohmann::json::parse(std::string(std::istreambuf_iterator<char>(in), {}));
    for (nlohmann::json& entity : cell["entities"]) {
      if (entity["id"] == "robot") entity["pose"]["position_m"] = {position.x(), position.y(), position.z()};
    }
    world_protocol::CellRevision revision;
    revision.cell_revision = number;
    revision.previous_revision = number - 1;
    revision.cell_json = cell.dump(2);
    revision.sha256 = "sha-" + std::to_string(number);
    revision.changes_json = R"({"moved":[{"id":"robot"}]})";
    rigger_world_CellRevision wire{};
    world_protocol::to_wire(revision, wire);
    ASSERT_EQ(cell_writer_.write(wire), DDS_RETCODE_OK);
  }

  dds::Writer<rigger_world_CellRevision> cell_writer_{participant_, protocol::world::kCell};
};

TEST_F(AdmittanceNodeRevisionTest, AMovedRobotBaseIsTakenWhileAdmittanceIsOff) {
  const cell_follower::CellFollower* follower = node_->cell_follower();
  ASSERT_NE(follower, nullptr);
  publish_base_at(2, Eigen::Vector3d(2.60, 2.0, 0.9));
  ASSERT_TRUE(loop_.run_until([&] { return follower->revision() == 2; }, 5s)) << follower->last_refusal();
  EXPECT_TRUE(node_->pose_world_base().translation().isApprox(Eigen::Vector3d(2.60, 2.0, 0.9), 1e-12));
}

TEST_F(AdmittanceNodeRevisionTest, AMovedRobotBaseIsRefusedWhileTheRobotLawRuns) {
  publish_robot_state();
  start_wrench_stream(Vector6d::Zero());
  command(rigger_admittance_ADMITTANCE_ROBOT);
  const cell_follower::CellFollower* follower = node_->cell_follower();
  publish_base_at(2, Eigen::Vector3d(2.60, 2.0, 0.9));
  ASSERT_TRUE(loop_.run_until([&] { return !follower->last_refusal().empty(); }, 5s));
  EXPECT_NE(follower->last_refusal().find("admittance is on"), std::string::npos) << follower->last_refusal();
  EXPECT_NE(follower->revision(), 2U);
  EXPECT_TRUE(node_->pose_world_base().translation().isApprox(Eigen::Vector3d(2.55, 2.0, 0.9), 1e-12))
      << "the running base stays";
}

}  // namespace
}  // namespace rigger::control
