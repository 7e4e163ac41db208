// CellPhysics's magnetic gripper (the grip, its spring-damper on the held body) and wrist F/T sensor.
#include <algorithm>
#include <cmath>

#include "cell_physics_impl.hpp"
#include "rigger/sim/pose_math.hpp"

namespace rigger::sim {
namespace {

// Linear and angular velocity of a body at a world point.
void body_point_velocity(const mjModel& model, const mjData& data, int body,
                         const Eigen::Vector3d& point_world, Eigen::Vector3d& linear,
                         Eigen::Vector3d& angular) {
  mjtNum velocity[6];
  mj_objectVelocity(&model, &data, mjOBJ_BODY, body, velocity, 0);
  angular = vec3(velocity);
  linear = vec3(velocity + 3) + angular.cross(point_world - vec3(data.xpos + 3 * body));
}

}  // namespace

// The magnet's spring-damper for the body it holds. Its forces are applied explicitly (xfrc_applied), and an
// explicit spring-damper on a light body is stable at the step only while c·dt/m and k·dt²/m stay small (the
// arm's servo on the other side makes it worse: held 1.5 mm across the air gap, a 3 kg part oscillated against
// the tool at half the step rate with c·dt/m = 0.5): the gains are capped for the body's mass and smallest
// principal inertia (c ≤ 0.1 m/dt, k ≤ 0.25 m/dt²). The 40 kg load is far below the caps (it keeps the
// configured gains); a 3 kg part's damping is capped.
MagnetSpring CellPhysics::Impl::magnet_spring_for(int body) const {
  MagnetSpring params = options.magnet_spring;
  if (body < 0) return params;
  const double mass = model->body_mass[body];
  const double inertia =
      std::min({model->body_inertia[3 * body], model->body_inertia[3 * body + 1], model->body_inertia[3 * body + 2]});
  const double dt = timestep_s;
  params.damping_n_s_per_m = std::min(params.damping_n_s_per_m, 0.1 * mass / dt);
  params.stiffness_n_per_m = std::min(params.stiffness_n_per_m, 0.25 * mass / (dt * dt));
  params.rotational_damping_nm_s_per_rad = std::min(params.rotational_damping_nm_s_per_rad, 0.1 * inertia / dt);
  params.rotational_stiffness_nm_per_rad = std::min(params.rotational_stiffness_nm_per_rad, 0.25 * inertia / (dt * dt));
  return params;
}

// The free object whose geom the magnet face touches flat (a planar face: the contact normal is within the
// grip angle of the tool z), or -1.
int CellPhysics::Impl::aligned_face_contact() const {
  const Eigen::Vector3d tool_z = site_pose_world(index.tool_site).linear().col(2);
  const double min_cosine = std::cos(options.magnet_spring.max_contact_angle_rad);
  for (int i = 0; i < data->ncon; ++i) {
    const mjContact& contact = data->contact[i];
    int other = -1;
    if (contact.geom1 == index.gripper_face_geom) other = contact.geom2;
    if (contact.geom2 == index.gripper_face_geom) other = contact.geom1;
    if (other >= 0 && index.free_object_geom[static_cast<std::size_t>(other)] &&
        std::abs(tool_z.dot(vec3(contact.frame))) >= min_cosine) {
      return model->geom_bodyid[other];
    }
  }
  return -1;
}

void CellPhysics::Impl::control_gripper(double dt_s) {
  const int touched_body = aligned_face_contact();
  face_in_contact = touched_body >= 0;
  const Eigen::Isometry3d tool = site_pose_world(index.tool_site);
  // What the magnet holds (or is about to grip): a free object.
  const int grip_body = holding ? held_body : touched_body;
  const Eigen::Isometry3d load = grip_body >= 0 ? body_pose_world(grip_body) : Eigen::Isometry3d::Identity();

  // The magnet as a stiff spring-damper between the face centre and the load point that touched
  // it, holding the relative orientation of the moment of grasp.
  Eigen::Vector3d force_on_load = Eigen::Vector3d::Zero();
  Eigen::Vector3d torque_on_load = Eigen::Vector3d::Zero();
  Eigen::Vector3d load_point = tool.translation();
  const auto spring = [&]() {
    const MagnetSpring params = magnet_spring_for(grip_body);
    load_point = load * anchor_load;
    Eigen::Vector3d load_velocity;
    Eigen::Vector3d load_angular;
    Eigen::Vector3d gripper_velocity;
    Eigen::Vector3d gripper_angular;
    body_point_velocity(*model, *data, grip_body, load_point, load_velocity, load_angular);
    body_point_velocity(*model, *data, index.gripper_body, tool.translation(), gripper_velocity,
                        gripper_angular);
    force_on_load = -params.stiffness_n_per_m * (load_point - tool.translation()) -
                    params.damping_n_s_per_m * (load_velocity - gripper_velocity);
    const Eigen::Matrix3d load_wanted = tool.linear() * rotation_tool_load;
    torque_on_load =
        -params.rotational_stiffness_nm_per_rad * rotation_error(load.linear(), load_wanted) -
        params.rotational_damping_nm_s_per_rad * (load_angular - gripper_angular);
  };

  double current_utilisation = 0.0;
  if (holding) {
    spring();
    const Eigen::Matrix3d to_tool = tool.linear().transpose();
    current_utilisation =
        magnet_utilisation(to_tool * force_on_load, to_tool * torque_on_load, capacity);
  }
  switch (magnet.update(face_in_contact, current_utilisation, dt_s)) {
    case GripAction::Attach:
      holding = true;
      held_body = grip_body;
      anchor_load = load.inverse() * tool.translation();
      rotation_tool_load = tool.linear().transpose() * load.linear();
      spring();
      break;
    case GripAction::Release:
      holding = false;
      held_body = -1;
      break;
    case GripAction::None:
      break;
  }
  utilisation = holding ? magnet.filtered_utilisation() : 0.0;
  if (holding) {
    // Equal and opposite, at the same point, so momentum is conserved.
    add_wrench_at(*data, held_body, force_on_load, torque_on_load, load_point);
    add_wrench_at(*data, index.gripper_body, -force_on_load, -torque_on_load, load_point);
  }
}

void CellPhysics::Impl::record_wrench() {
  // MuJoCo's force/torque sensors: what the flange exerts on the gripper, in the sensor frame,
  // torque about the sensor origin.  The gripper side exerts the opposite on the flange.
  const Eigen::Vector3d force = -vec3(data->sensordata + index.ft_force_address);
  const Eigen::Vector3d torque_sensor = -vec3(data->sensordata + index.ft_torque_address);
  // Tool frame: same axes as the sensor (both sites are unrotated on the gripper body).
  const Eigen::Vector3d tool_offset = vec3(model->site_pos + 3 * index.tool_site);
  Wrench raw;
  raw.force_n = force;
  raw.torque_nm = torque_sensor - tool_offset.cross(force);

  // Static weight of the gripper, as a controller's tool-load data would predict it.
  const Eigen::Matrix3d rotation_world_sensor = site_pose_world(index.ft_site).linear();
  const double gripper_mass = model->body_mass[index.gripper_body];
  const Eigen::Vector3d weight_sensor =
      rotation_world_sensor.transpose() * (gripper_mass * vec3(model->opt.gravity));
  const Eigen::Vector3d com_sensor = vec3(model->body_ipos + 3 * index.gripper_body);
  Wrench weight;
  weight.force_n = weight_sensor;
  weight.torque_nm = (com_sensor - tool_offset).cross(weight_sensor);

  const WrenchNoise& noise = options.wrench_noise;
  for (int i = 0; i < 3; ++i) {
    if (noise.force_stddev_n > 0.0) {
      raw.force_n[i] += noise.force_stddev_n * unit_normal(noise_engine);
    }
    if (noise.torque_stddev_nm > 0.0) {
      raw.torque_nm[i] += noise.torque_stddev_nm * unit_normal(noise_engine);
    }
  }
  wrench_raw = raw;
  wrench_external.force_n = raw.force_n - weight.force_n;
  wrench_external.torque_nm = raw.torque_nm - weight.torque_nm;
}
}  // namespace rigger::sim
