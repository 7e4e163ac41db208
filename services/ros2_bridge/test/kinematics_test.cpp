// The bridge's kinematics of the simulated arm (the shipped deploy/config/ros2_bridge.json: the iiwa 14 as
// standard DH rows, the magnet's face as the tool) against MuJoCo's own model of that arm
// (services/cell_sim/physics/models/cell.xml): flange and tool poses from MuJoCo's kinematics, the tool
// velocity from mj_objectVelocity, at many joint configurations and velocities within the joint ranges.
// The DH form is exact for this arm (every axis meets the next at a right angle, and the links are
// straight in the zero position), so the bound asserted is rounding: 1 µm and 1 µrad, far below the
// 0.05 mm / 0.01° a pose consumer would notice; the figures of the run are printed.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <memory>
#include <random>
#include <string>

#include "bridge_config.hpp"
#include "kinematics.hpp"

namespace rigger::ros2_bridge {
namespace {

using ModelPtr = std::unique_ptr<mjModel, decltype(&mj_deleteModel)>;
using DataPtr = std::unique_ptr<mjData, decltype(&mj_deleteData)>;

Eigen::Isometry3d site_pose(const mjData& d, int site) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(d.site_xpos[3 * site], d.site_xpos[3 * site + 1], d.site_xpos[3 * site + 2]);
  t.linear() = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d.site_xmat + 9 * site);
  return t;
}

Eigen::Isometry3d body_pose(const mjData& d, int body) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.translation() = Eigen::Vector3d(d.xpos[3 * body], d.xpos[3 * body + 1], d.xpos[3 * body + 2]);
  const mjtNum* q = d.xquat + 4 * body;
  t.linear() = Eigen::Quaterniond(q[0], q[1], q[2], q[3]).toRotationMatrix();
  return t;
}

double angle_between(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle();
}

class SimulatedArm : public ::testing::Test {
 protected:
  void SetUp() override {
    char error[1000] = "";
    model_.reset(mj_loadXML(RIGGER_CELL_MJCF, nullptr, error, sizeof(error)));
    ASSERT_TRUE(model_) << RIGGER_CELL_MJCF << ": " << error;
    data_.reset(mj_makeData(model_.get()));
    for (int i = 0; i < 7; ++i) {
      const std::string name = "iiwa_a" + std::to_string(i + 1);
      joints_[i] = mj_name2id(model_.get(), mjOBJ_JOINT, name.c_str());
      ASSERT_GE(joints_[i], 0) << name;
    }
    base_ = mj_name2id(model_.get(), mjOBJ_BODY, "robot_base");
    flange_ = mj_name2id(model_.get(), mjOBJ_SITE, "flange");
    tool_ = mj_name2id(model_.get(), mjOBJ_SITE, "tool");
    ASSERT_TRUE(base_ >= 0 && flange_ >= 0 && tool_ >= 0);
    const Config c = Config::load(RIGGER_SHIPPED_BRIDGE_CONFIG);
    config_ = read_bridge_config(c);
    c.finish();
    ASSERT_TRUE(config_.joint_states && config_.joint_states->kinematics);
  }

  /// MuJoCo's state of the arm at q, q̇ (the rest of the cell at rest in its initial configuration).
  void set(const Eigen::VectorXd& q, const Eigen::VectorXd& qd) {
    mj_resetData(model_.get(), data_.get());
    for (int i = 0; i < 7; ++i) {
      data_->qpos[model_->jnt_qposadr[joints_[i]]] = q[i];
      data_->qvel[model_->jnt_dofadr[joints_[i]]] = qd[i];
    }
    mj_forward(model_.get(), data_.get());
  }

  ModelPtr model_{nullptr, mj_deleteModel};
  DataPtr data_{nullptr, mj_deleteData};
  std::array<int, 7> joints_{};
  int base_ = -1, flange_ = -1, tool_ = -1;
  BridgeConfig config_;
};

TEST_F(SimulatedArm, TheShippedKinematicsGiveMujocosFlangeAndToolPosesAndToolVelocity) {
  const JointStatesStream& cfg = *config_.joint_states;
  std::mt19937 random(20261125);
  double max_flange_m = 0, max_flange_rad = 0, max_tool_m = 0, max_tool_rad = 0, max_linear = 0, max_angular = 0;
  constexpr int kConfigurations = 2000;
  for (int n = 0; n < kConfigurations; ++n) {
    Eigen::VectorXd q(7), qd(7);
    for (int i = 0; i < 7; ++i) {
      const mjtNum* range = model_->jnt_range + 2 * joints_[i];
      q[i] = std::uniform_real_distribution<double>(range[0], range[1])(random);
      qd[i] = std::uniform_real_distribution<double>(-1.5, 1.5)(random);
    }
    set(q, qd);
    const Eigen::Isometry3d base_world = body_pose(*data_, base_).inverse();
    const Eigen::Isometry3d flange = base_world * site_pose(*data_, flange_);
    const Eigen::Isometry3d tool = base_world * site_pose(*data_, tool_);
    mjtNum velocity[6];  // angular, linear; world frame
    mj_objectVelocity(model_.get(), data_.get(), mjOBJ_SITE, tool_, velocity, 0);
    const Eigen::Vector3d angular = base_world.linear() * Eigen::Vector3d(velocity[0], velocity[1], velocity[2]);
    const Eigen::Vector3d linear = base_world.linear() * Eigen::Vector3d(velocity[3], velocity[4], velocity[5]);

    const ArmState arm = cfg.kinematics->evaluate(q, qd, cfg.pose_flange_tool);
    max_flange_m = std::max(max_flange_m, (arm.pose_base_flange.translation() - flange.translation()).norm());
    max_flange_rad = std::max(max_flange_rad, angle_between(arm.pose_base_flange, flange));
    max_tool_m = std::max(max_tool_m, (arm.pose_base_tool.translation() - tool.translation()).norm());
    max_tool_rad = std::max(max_tool_rad, angle_between(arm.pose_base_tool, tool));
    max_linear = std::max(max_linear, (arm.tool_linear_mps - linear).norm());
    max_angular = std::max(max_angular, (arm.tool_angular_radps - angular).norm());
  }
  std::printf(
      "%d configurations: flange %.3g m %.3g rad, tool %.3g m %.3g rad, tool velocity %.3g m/s %.3g rad/s (max)\n",
      kConfigurations, max_flange_m, max_flange_rad, max_tool_m, max_tool_rad, max_linear, max_angular);
  EXPECT_LT(max_flange_m, 1e-6);
  EXPECT_LT(max_flange_rad, 1e-6);
  EXPECT_LT(max_tool_m, 1e-6);
  EXPECT_LT(max_tool_rad, 1e-6);
  EXPECT_LT(max_linear, 1e-6);
  EXPECT_LT(max_angular, 1e-6);
}

// The chain form (URDF's origins and axes), taken from MuJoCo's model itself (each arm body's offset and
// orientation from its parent, each joint's axis, the flange site in the last link), is exact too: the form an
// integrator would copy from a URDF whose arm is not DH-shaped.
TEST_F(SimulatedArm, TheChainFormFromTheModelsBodiesAndAxesIsExactToo) {
  const auto offset = [](const mjtNum* pos, const mjtNum* quat) {
    Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
    t.translation() = Eigen::Vector3d(pos[0], pos[1], pos[2]);
    t.linear() = Eigen::Quaterniond(quat[0], quat[1], quat[2], quat[3]).toRotationMatrix();
    return t;
  };
  std::vector<RevoluteJoint> joints;
  for (int i = 0; i < 7; ++i) {
    const int j = joints_[i];
    const int body = model_->jnt_bodyid[j];
    ASSERT_EQ(model_->body_parentid[body], i == 0 ? base_ : model_->jnt_bodyid[joints_[i - 1]]);
    ASSERT_EQ(Eigen::Vector3d(model_->jnt_pos[3 * j], model_->jnt_pos[3 * j + 1], model_->jnt_pos[3 * j + 2]).norm(),
              0.0)
        << "a joint away from its body's origin needs an extra fixed offset";
    joints.push_back(
        {offset(model_->body_pos + 3 * body, model_->body_quat + 4 * body),
         Eigen::Vector3d(model_->jnt_axis[3 * j], model_->jnt_axis[3 * j + 1], model_->jnt_axis[3 * j + 2])});
  }
  ASSERT_EQ(model_->site_bodyid[flange_], model_->jnt_bodyid[joints_[6]]);
  const SerialChain chain =
      SerialChain::from_joints(joints, offset(model_->site_pos + 3 * flange_, model_->site_quat + 4 * flange_));
  std::mt19937 random(18);
  double max_m = 0, max_rad = 0;
  for (int n = 0; n < 500; ++n) {
    Eigen::VectorXd q(7), qd = Eigen::VectorXd::Zero(7);
    for (int i = 0; i < 7; ++i) {
      const mjtNum* range = model_->jnt_range + 2 * joints_[i];
      q[i] = std::uniform_real_distribution<double>(range[0], range[1])(random);
    }
    set(q, qd);
    const Eigen::Isometry3d flange = body_pose(*data_, base_).inverse() * site_pose(*data_, flange_);
    const ArmState arm = chain.evaluate(q, qd, Eigen::Isometry3d::Identity());
    max_m = std::max(max_m, (arm.pose_base_flange.translation() - flange.translation()).norm());
    max_rad = std::max(max_rad, angle_between(arm.pose_base_flange, flange));
  }
  std::printf("chain form, 500 configurations: flange %.3g m %.3g rad (max)\n", max_m, max_rad);
  EXPECT_LT(max_m, 1e-6);
  EXPECT_LT(max_rad, 1e-6);
}

// A wrong table must fail the comparison above: one alpha sign flipped moves the flange by decimetres.
TEST_F(SimulatedArm, AWrongDhTableIsSeen) {
  std::vector<DhRow> rows = {
      {0.36, 0, -M_PI / 2, 0}, {0, 0, M_PI / 2, 0}, {0.42, 0, M_PI / 2, 0}, {0, 0, -M_PI / 2, 0},
      {0.4, 0, M_PI / 2, 0},   {0, 0, M_PI / 2, 0}, {0.126, 0, 0, 0}};  // row 5's alpha should be -90°
  const SerialChain wrong = SerialChain::from_dh(rows);
  Eigen::VectorXd q(7), qd = Eigen::VectorXd::Zero(7);
  q << 0.3, 0.5, -0.2, -1.0, 0.4, 0.8, 0.1;
  set(q, qd);
  const Eigen::Isometry3d flange = body_pose(*data_, base_).inverse() * site_pose(*data_, flange_);
  EXPECT_GT((wrong.evaluate(q, qd, Eigen::Isometry3d::Identity()).pose_base_flange.translation() - flange.translation())
                .norm(),
            0.01);
}

// The tool twist is the pose's time derivative: a central difference of the forward kinematics along q̇.
TEST(SerialChain, ToolTwistIsTheDerivativeOfThePose) {
  // UR5e's published DH table and a tool with an offset and a tilt.
  const SerialChain ur5e = SerialChain::from_dh({{0.1625, 0, M_PI / 2, 0},
                                                 {0, -0.425, 0, 0},
                                                 {0, -0.3922, 0, 0},
                                                 {0.1333, 0, M_PI / 2, 0},
                                                 {0.0997, 0, -M_PI / 2, 0},
                                                 {0.0996, 0, 0, 0}});
  const Eigen::Isometry3d tool =
      Eigen::Translation3d(0.01, -0.02, 0.15) * Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX());
  Eigen::VectorXd q(6), qd(6);
  q << 0.1, -1.2, 1.4, -0.5, 1.1, 0.7;
  qd << 0.4, -0.3, 0.2, 0.5, -0.6, 0.9;
  const ArmState at = ur5e.evaluate(q, qd, tool);
  const double h = 1e-6;
  const ArmState ahead = ur5e.evaluate(q + h * qd, qd, tool);
  const ArmState behind = ur5e.evaluate(q - h * qd, qd, tool);
  const Eigen::Vector3d linear = (ahead.pose_base_tool.translation() - behind.pose_base_tool.translation()) / (2 * h);
  const Eigen::AngleAxisd turn(ahead.pose_base_tool.linear() * behind.pose_base_tool.linear().transpose());
  const Eigen::Vector3d angular = turn.axis() * turn.angle() / (2 * h);
  EXPECT_LT((linear - at.tool_linear_mps).norm(), 1e-8);
  EXPECT_LT((angular - at.tool_angular_radps).norm(), 1e-8);
  EXPECT_LT((ur5e.jacobian(q, at.pose_base_tool.translation()) * qd -
             (Eigen::Matrix<double, 6, 1>() << at.tool_linear_mps, at.tool_angular_radps).finished())
                .norm(),
            1e-12);
}

// `base` goes before the first joint and `flange` after the last, in the DH form as in the chain form.
TEST(SerialChain, BaseAndFlangePosesFrameTheArm) {
  const std::vector<DhRow> rows = {{0.1625, 0, M_PI / 2, 0.1}, {0, -0.425, 0, -0.2}, {0.1333, 0, -M_PI / 2, 0}};
  const Eigen::Isometry3d base(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()));
  const Eigen::Isometry3d flange = Eigen::Translation3d(0, 0, 0.02) * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY());
  const SerialChain bare = SerialChain::from_dh(rows);
  const SerialChain framed = SerialChain::from_dh(rows, base, flange);
  Eigen::VectorXd q(3), qd(3);
  q << 0.4, -0.9, 1.3;
  qd << 0.2, 0.1, -0.3;
  const ArmState a = bare.evaluate(q, qd, Eigen::Isometry3d::Identity());
  const ArmState b = framed.evaluate(q, qd, Eigen::Isometry3d::Identity());
  EXPECT_TRUE(b.pose_base_flange.isApprox(base * a.pose_base_flange * flange, 1e-12));
  // The twist of the (moved) flange point, expressed in the turned base frame.
  const Eigen::Vector3d offset_base = a.pose_base_flange.linear() * flange.translation();
  EXPECT_TRUE(
      b.tool_linear_mps.isApprox(base.linear() * (a.tool_linear_mps + a.tool_angular_radps.cross(offset_base)), 1e-12));
  EXPECT_TRUE(b.tool_angular_radps.isApprox(base.linear() * a.tool_angular_radps, 1e-12));
}

TEST(SerialChain, RefusesWhatIsNotAnArm) {
  EXPECT_THROW(SerialChain::from_dh({}), std::invalid_argument);
  EXPECT_THROW(SerialChain::from_dh({{NAN, 0, 0, 0}}), std::invalid_argument);
  EXPECT_THROW(SerialChain::from_joints({}), std::invalid_argument);
  EXPECT_THROW(SerialChain::from_joints({{Eigen::Isometry3d::Identity(), Eigen::Vector3d(0, 0, 2)}}),
               std::invalid_argument);
}

}  // namespace
}  // namespace rigger::ros2_bridge
