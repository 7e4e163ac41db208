#pragma once
// Shared by the integration tests of cell_sim and the crane gateway (cell_sim_*_test.cpp,
// crane_*_test.cpp): a free TCP port for each test's PLC emulator, the simulator's status and
// fault-injection topics from the test's side.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "rigger/base/time.hpp"
#include "rigger/dds/conversions.hpp"
#include "rigger/dds/pubsub.hpp"
#include "rigger/protocol/sim.hpp"
#include "rigger/testing/cell.hpp"

namespace rigger::testing {

/// A TCP port that was free on 127.0.0.1 a moment ago (bound to port 0, then released). Another
/// process could take it in between; parallel tests draw from the kernel's ephemeral range, so they
/// practically never collide. A fixed port would collide for certain.
inline std::uint16_t free_tcp_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) throw std::runtime_error("socket() failed");
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  addr.sin_port = 0;
  socklen_t length = sizeof addr;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &length) != 0) {
    close(fd);
    throw std::runtime_error("cannot find a free TCP port");
  }
  close(fd);
  return ntohs(addr.sin_port);
}

/// A repository file, for --config.
inline std::string repo_file(const std::string& relative) {
  return std::string(RIGGER_SOURCE_DIR) + "/" + relative;
}

/// One rigger/sim/status sample, the fields the tests look at.
struct SimStatusView {
  WallTime stamp{};
  double sim_time_s = 0.0;
  bool estop_pressed = false;
  bool plc_link_up = false;
  std::uint16_t plc_port = 0;
  std::uint16_t plc_status_word = 0;
  std::uint16_t plc_fault_code = 0;
  Eigen::Vector3d plc_setpoint_mps = Eigen::Vector3d::Zero();
  Eigen::Vector3d crane_position_m = Eigen::Vector3d::Zero();
  Eigen::Vector3d crane_velocity_mps = Eigen::Vector3d::Zero();
  std::uint64_t camera_frames = 0;
  double gripper_holding_force_n = 0.0;
  Eigen::Vector3d load_external_force_n = Eigen::Vector3d::Zero();
};

/// The simulator's side channel, from a test: its status (every sample kept) and fault injection
/// with acknowledgements. Handlers run on the cell's event loop.
class SimChannel {
 public:
  /// `can_control` false: status only, no writer on rigger/sim/control (a test participant whose DDS
  /// permissions only let it read: send() then answers nothing).
  explicit SimChannel(Cell& cell, bool can_control = true)
      : status_(cell.participant(), protocol::sim::kStatus, dds::qos::sensor_stream().keep_last(256)),
        events_(cell.participant(), protocol::sim::kEvent),
        cell_(cell) {
    if (can_control) control_.emplace(cell.participant(), protocol::sim::kControl);
    cell.loop().on_data(status_, [this] {
      status_.take([this](const rigger_sim_SimStatus& s, const dds_sample_info_t&) {
        SimStatusView v;
        v.stamp = dds::to_domain(s.header.stamp);
        v.sim_time_s = s.sim_time_s;
        v.estop_pressed = s.estop_pressed;
        v.plc_link_up = s.plc_link_up;
        v.plc_port = s.plc_port;
        v.plc_status_word = s.plc_status_word;
        v.plc_fault_code = s.plc_fault_code;
        v.plc_setpoint_mps = Eigen::Vector3d(s.plc_setpoint_mps[0], s.plc_setpoint_mps[1], s.plc_setpoint_mps[2]);
        v.crane_position_m = Eigen::Vector3d(s.crane_position_m[0], s.crane_position_m[1], s.crane_position_m[2]);
        v.crane_velocity_mps =
            Eigen::Vector3d(s.crane_velocity_mps[0], s.crane_velocity_mps[1], s.crane_velocity_mps[2]);
        v.camera_frames = s.camera_frames;
        v.gripper_holding_force_n = s.gripper_holding_force_n;
        v.load_external_force_n = dds::to_domain(s.load_external_force_n);
        history_.push_back(v);
        if (on_status_) on_status_(v);
      });
    });
    cell.loop().on_data(events_, [this] {
      events_.take([this](const rigger_sim_SimEvent& e, const dds_sample_info_t&) {
        if (dds::to_string(e.control_source) == kSource) acks_[e.control_seq] = {e.accepted, dds::to_string(e.message)};
      });
    });
  }

  /// Sends a control and waits for its acknowledgement; returns it (nullopt: no answer within 5 s).
  std::optional<std::pair<bool, std::string>> send(rigger_sim_SimControlKind kind, bool on, double value = 0.0,
                                                   const Eigen::Vector3d& vector = Eigen::Vector3d::Zero()) {
    if (!control_ || !control_->wait_for_readers(1, std::chrono::seconds(5))) return std::nullopt;
    rigger_sim_SimControl c{};
    c.header.stamp = dds::wire_now();
    c.seq = ++seq_;
    c.kind = kind;
    c.on = on;
    c.value = value;
    c.vector = dds::to_wire_vector(vector);
    c.source = const_cast<char*>(kSource);
    control_->write(c);
    const std::uint64_t seq = seq_;
    if (!cell_.wait_until([&] { return acks_.count(seq) > 0; }, std::chrono::seconds(5))) return std::nullopt;
    return acks_.at(seq);
  }

  /// Calls `handler` with every status sample as it arrives (on the cell's event loop), after history().
  void on_status(std::function<void(const SimStatusView&)> handler) { on_status_ = std::move(handler); }

  bool has_status() const { return !history_.empty(); }
  const SimStatusView& latest() const { return history_.back(); }
  const std::vector<SimStatusView>& history() const { return history_; }

 private:
  static constexpr const char* kSource = "integration-test";
  dds::Reader<rigger_sim_SimStatus> status_;
  dds::Reader<rigger_sim_SimEvent> events_;
  std::optional<dds::Writer<rigger_sim_SimControl>> control_;
  Cell& cell_;
  std::vector<SimStatusView> history_;
  std::function<void(const SimStatusView&)> on_status_;
  std::map<std::uint64_t, std::pair<bool, std::string>> acks_;
  std::uint64_t seq_ = 0;
};

/// Starts `binary` with `config_text` as its configuration file and expects it to refuse it: exit code 2
/// and a log naming `pointer` (the JSON pointer of the bad key).
inline void expect_refused_configuration(Cell& cell, const std::string& binary, const std::string& config_text,
                                         const std::string& pointer) {
  const std::string path = cell.log_dir() + "/bad_" + binary + ".json";
  std::ofstream(path) << config_text;
  auto& p = cell.start(binary, binary, {"--config", path});
  const auto status = p.wait(std::chrono::seconds(20));
  ASSERT_TRUE(status.has_value()) << binary << " did not exit on a bad configuration";
  EXPECT_EQ(status->code, 2);
  EXPECT_NE(p.log().find(pointer), std::string::npos) << p.log();
}

/// Milliseconds from `from` to `to` (wall clock).
inline double ms_between(WallTime from, WallTime to) {
  return std::chrono::duration<double, std::milli>(to - from).count();
}

}  // namespace rigger::testing
