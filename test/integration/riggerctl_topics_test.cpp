// `riggerctl topics` and `riggerctl echo` against a running cell (cell_sim + crane_gateway as real
// processes on a private domain): echo prints parseable JSON with the IDL's field names for a reliable
// transient-local state topic, a best-effort sensor stream and an announcements topic; --hz reports a
// rate; topics names the gateway as the writer of rigger/crane/state; unknown topics and missing writers
// are clear errors.
#include <gtest/gtest.h>

#include <csignal>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cell_sim_test_support.hpp"
#include "rigger/protocol/catalog.hpp"
#include "rigger/protocol/crane.hpp"
#include "rigger/protocol/robot.hpp"
#include "rigger/protocol/system.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;
using json = nlohmann::ordered_json;  // keeps the fields in the order printed

/// The lines of `output` that are JSON objects (riggerctl's stdout and stderr share one log file).
std::vector<json> json_lines(const std::string& output) {
  std::vector<json> out;
  std::istringstream in(output);
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line.front() == '{') out.push_back(json::parse(line));
  return out;
}

std::vector<std::string> keys(const json& object) {
  std::vector<std::string> out;
  for (auto it = object.begin(); it != object.end(); ++it) out.push_back(it.key());
  return out;
}

class RiggerctlTopicsTest : public MultiProcessTest {
 protected:
  void start_cell() {
    const std::string port = std::to_string(free_tcp_port());
    cell_.start("cell_sim", "cell_sim", {"--config", repo_file("deploy/config/cell_sim.json"), "--plc-port", port});
    ASSERT_TRUE(cell_.wait_ready({"cell_sim"}, 20s));
    cell_.start("crane_gateway", "crane_gateway",
                {"--config", repo_file("deploy/config/crane_gateway.json"), "--plc-port", port});
    ASSERT_TRUE(cell_.wait_ready({"crane_gateway"}, 20s));
  }

  CtlResult ctl(const std::string& name, const std::vector<std::string>& args,
                std::chrono::milliseconds timeout = 30s) {
    return run_riggerctl(cell_, name, args, timeout);
  }
};

TEST_F(RiggerctlTopicsTest, EchoPrintsJsonLinesWithTheIdlFieldNames) {
  start_cell();

  // Reliable, transient-local, written periodically by the gateway.
  const CtlResult crane = ctl("echo-crane", {"echo", protocol::crane::kState.name, "--count", "5", "--json"});
  ASSERT_EQ(crane.code(), 0) << crane.output;
  const auto states = json_lines(crane.output);
  ASSERT_EQ(states.size(), 5u) << crane.output;
  for (const auto& s : states) {
    EXPECT_EQ(keys(s), (std::vector<std::string>{"header", "mode", "position_m", "velocity_mps", "load_mass_kg",
                                                 "link_ok", "ready", "enabled", "external_control", "moving", "fault",
                                                 "estop", "overload", "status_word", "fault_code", "fault_text",
                                                 "plc_heartbeat", "last_command_seq"}))
        << s.dump();
    EXPECT_TRUE(s["header"]["stamp"]["sec"].is_number_integer());
    EXPECT_TRUE(s["mode"].is_string()) << "enums print as their names: " << s.dump();
    EXPECT_EQ(s["position_m"].size(), 3u);
    EXPECT_TRUE(s["link_ok"].is_boolean());
  }
  // Five distinct states in order, not one repeated.
  const auto stamp_ns = [](const json& s) {
    return s["header"]["stamp"]["sec"].get<std::int64_t>() * 1000000000 +
           s["header"]["stamp"]["nanosec"].get<std::int64_t>();
  };
  for (std::size_t i = 1; i < states.size(); ++i)
    EXPECT_GT(stamp_ns(states[i]), stamp_ns(states[i - 1])) << crane.output;

  // Best effort: the simulated wrist F/T stream.
  const CtlResult wrench = ctl("echo-wrench", {"echo", protocol::robot::kWrench.name, "--count", "5", "--json"});
  ASSERT_EQ(wrench.code(), 0) << wrench.output;
  const auto wrenches = json_lines(wrench.output);
  ASSERT_EQ(wrenches.size(), 5u) << wrench.output;
  for (const auto& w : wrenches) {
    EXPECT_EQ(keys(w), (std::vector<std::string>{"header", "wrench"})) << w.dump();
    EXPECT_EQ(keys(w["wrench"]), (std::vector<std::string>{"force", "torque"})) << w.dump();
    EXPECT_TRUE(w["wrench"]["force"]["z"].is_number()) << w.dump();
  }

  // Transient-local state: the gripper's last state, written before this reader existed.
  const CtlResult gripper =
      ctl("echo-gripper", {"echo", protocol::robot::kGripperState.name, "--count", "1", "--json"});
  ASSERT_EQ(gripper.code(), 0) << gripper.output;
  const auto grips = json_lines(gripper.output);
  ASSERT_EQ(grips.size(), 1u) << gripper.output;
  EXPECT_EQ(keys(grips[0]), (std::vector<std::string>{"header", "energized", "contact", "holding", "holding_force_n",
                                                      "last_command_seq"}));

  // Announcements (transient-local, liveliness-monitored): both services' READY. Each service also
  // re-announces every second, so the samples are collected for a while rather than counted.
  const CtlResult services =
      ctl("echo-services", {"echo", protocol::system::kServiceState.name, "--duration", "2.5", "--json"});
  ASSERT_EQ(services.code(), 0) << services.output;
  std::set<std::string> ids;
  for (const auto& s : json_lines(services.output)) {
    ids.insert(s["service_id"].get<std::string>());
    EXPECT_EQ(s["state"], "SERVICE_READY") << s.dump();
  }
  EXPECT_EQ(ids, (std::set<std::string>{"cell_sim", "crane_gateway"})) << services.output;

  // The readable form: indented name: value lines, samples separated by ---.
  const CtlResult text = ctl("echo-text", {"echo", protocol::crane::kState.name, "--count", "2"});
  ASSERT_EQ(text.code(), 0) << text.output;
  EXPECT_NE(text.output.find("header:\n  stamp:\n    sec: "), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("\nposition_m: ["), std::string::npos) << text.output;
  EXPECT_NE(text.output.find("---\n"), std::string::npos) << text.output;
}

TEST_F(RiggerctlTopicsTest, EchoHzReportsTheRate) {
  start_cell();
  // The crane state arrives at the gateway's publishing rate; three rate lines (one a second).
  const CtlResult r =
      ctl("hz", {"echo", protocol::crane::kState.name, "--hz", "--json", "--duration", "3.5", "--window", "20"});
  ASSERT_EQ(r.code(), 0) << r.output;
  const auto lines = json_lines(r.output);
  ASSERT_GE(lines.size(), 2u) << r.output;
  for (const auto& l : lines) {
    EXPECT_GT(l["rate_hz"].get<double>(), 0.0) << l.dump();
    EXPECT_LE(l["min_s"].get<double>(), l["max_s"].get<double>()) << l.dump();
    EXPECT_LE(l["window"].get<int>(), 20) << l.dump();
  }
}

TEST_F(RiggerctlTopicsTest, TopicsListsTheGatewayAsWriterOfTheCraneState) {
  start_cell();
  // A writer of a topic outside the catalog, from this test's participant (which announces no service).
  const dds::Writer<rigger_crane_CraneState> stray(cell_.participant(), "rigger_test/not_in_catalog",
                                                   dds::qos::state());
  const CtlResult r = ctl("topics", {"topics", "--json", "--timeout", "2"});
  ASSERT_EQ(r.code(), 0) << r.output;
  const auto docs = json_lines(r.output);
  ASSERT_EQ(docs.size(), 1u) << r.output;
  const json& topics = docs[0]["topics"];
  const json* crane = nullptr;
  std::size_t in_catalog = 0;
  for (const auto& t : topics) {
    if (t["name"] == protocol::crane::kState.name) crane = &t;
    if (t["in_catalog"] == true) ++in_catalog;
  }
  EXPECT_EQ(in_catalog, protocol::catalog().size());
  ASSERT_NE(crane, nullptr) << r.output;
  EXPECT_EQ((*crane)["type"], "rigger::crane::CraneState");
  EXPECT_EQ((*crane)["qos"], "state");
  EXPECT_EQ((*crane)["writers"], json::array({"crane_gateway"})) << crane->dump();
  const json* extra = nullptr;
  for (const auto& t : topics)
    if (t["name"] == "rigger_test/not_in_catalog") extra = &t;
  ASSERT_NE(extra, nullptr) << r.output;
  EXPECT_EQ((*extra)["in_catalog"], false);
  EXPECT_TRUE((*extra)["qos"].is_null());
  EXPECT_EQ((*extra)["type"], "rigger::crane::CraneState");
  ASSERT_EQ((*extra)["writers"].size(), 1u) << extra->dump();
  EXPECT_EQ((*extra)["writers"][0].get<std::string>().rfind("participant ", 0), 0u) << extra->dump();

  // The table names it too.
  const CtlResult table = ctl("topics-table", {"topics", "--timeout", "2"});
  ASSERT_EQ(table.code(), 0) << table.output;
  std::istringstream in(table.output);
  std::string line, crane_line;
  while (std::getline(in, line))
    if (line.rfind(std::string(protocol::crane::kState.name) + " ", 0) == 0) crane_line = line;
  EXPECT_NE(crane_line.find("writers: crane_gateway"), std::string::npos) << table.output;
  EXPECT_NE(table.output.find("(not in the catalog)"), std::string::npos) << table.output;
}

TEST_F(RiggerctlTopicsTest, UnknownTopicAndMissingWriterAreClearErrors) {
  const CtlResult unknown = ctl("unknown", {"echo", "rigger/crane/stat", "--timeout", "1"});
  EXPECT_EQ(unknown.code(), 2) << unknown.output;
  EXPECT_NE(unknown.output.find("unknown topic 'rigger/crane/stat'"), std::string::npos) << unknown.output;
  EXPECT_NE(unknown.output.find("rigger/crane/state"), std::string::npos) << unknown.output;

  // Nobody writes the crane state on this domain (no cell started).
  const CtlResult none = ctl("no-writer", {"echo", protocol::crane::kState.name, "--timeout", "0.5"});
  EXPECT_EQ(none.code(), 1) << none.output;
  EXPECT_NE(none.output.find("no writer of rigger/crane/state"), std::string::npos) << none.output;
  EXPECT_NE(none.output.find("domain " + std::to_string(cell_.domain_id()) + " (DDS configuration "), std::string::npos)
      << none.output;
}

}  // namespace
}  // namespace rigger::testing
