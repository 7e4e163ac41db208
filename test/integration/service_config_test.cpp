// Bad configuration stops a service at start with a message naming the file, the key and what was
// expected, and exit code 2. Exercised on the echo service, and on a bad key of each service converted to a
// settings table; every service uses the same loader (rigger::Config) and the same run_service().
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "rigger/testing/cell.hpp"
#include "rigger/testing/domain.hpp"

namespace rigger::testing {
namespace {

using namespace std::chrono_literals;

class ServiceConfigTest : public ::testing::Test {
 protected:
  /// Runs echo with `config_text` written to a file (or the path itself when `write` is false) and
  /// returns its exit status and log.
  std::pair<ExitStatus, std::string> run_with(const std::string& config_text, bool write = true) {
    return run_service_with("echo", config_text, write);
  }
  /// The same for `service` (its binary), its configuration file named `<name>-config.json`.
  std::pair<ExitStatus, std::string> run_service_with(const std::string& service, const std::string& config_text,
                                                      bool write = true, const std::string& name = "") {
    std::string path = config_text;
    if (write) {
      path = cell_.log_dir() + "/" + (name.empty() ? service : name) + "-config.json";
      std::ofstream(path) << config_text;
    }
    auto& p = cell_.start(name.empty() ? service : name, service, {"--config", path});
    auto st = p.wait(20s);
    EXPECT_TRUE(st.has_value()) << service << " did not exit on a bad configuration";
    return {st.value_or(ExitStatus{}), p.log()};
  }
  Cell cell_;
};

TEST_F(ServiceConfigTest, MissingFile) {
  auto [st, log] = run_with("/nonexistent/echo.json", false);
  EXPECT_TRUE(st.exited);
  EXPECT_EQ(st.code, 2);
  EXPECT_NE(log.find("/nonexistent/echo.json"), std::string::npos) << log;
  EXPECT_NE(log.find("cannot open"), std::string::npos) << log;
}

TEST_F(ServiceConfigTest, WrongType) {
  auto [st, log] = run_with(R"({"max_payload_bytes": "lots"})");
  EXPECT_EQ(st.code, 2);
  EXPECT_NE(log.find("echo-config.json"), std::string::npos) << log;
  EXPECT_NE(log.find("/max_payload_bytes"), std::string::npos) << log;
  EXPECT_NE(log.find("expected a non-negative integer"), std::string::npos) << log;
}

TEST_F(ServiceConfigTest, UnknownKey) {
  auto [st, log] = run_with(R"({"publish_peer_veiw": false})");
  EXPECT_EQ(st.code, 2);
  EXPECT_NE(log.find("/publish_peer_veiw"), std::string::npos) << log;
  EXPECT_NE(log.find("unknown key"), std::string::npos) << log;
}

TEST_F(ServiceConfigTest, OutOfRange) {
  auto [st, log] = run_with(R"({"max_payload_bytes": 99999999999})");
  EXPECT_EQ(st.code, 2);
  EXPECT_NE(log.find("/max_payload_bytes"), std::string::npos) << log;
}

TEST_F(ServiceConfigTest, BadCommandLine) {
  auto& p = cell_.start("echo", "echo", {"--domain", "999"}, false);
  auto st = p.wait(20s);
  ASSERT_TRUE(st.has_value());
  EXPECT_EQ(st->code, 2);
  EXPECT_NE(p.log().find("--domain"), std::string::npos) << p.log();
}

// The liveliness lease every service offers can be lengthened for a loaded machine; a value that is not
// a lease stops the service at start, naming the variable and what it expects.
TEST_F(ServiceConfigTest, BadLivelinessLeaseInTheEnvironment) {
  auto& p = cell_.start("echo", "echo", {}, true, {{"RIGGER_LIVELINESS_LEASE_MS", "50"}});
  auto st = p.wait(20s);
  ASSERT_TRUE(st.has_value()) << "echo did not exit on a bad lease";
  EXPECT_EQ(st->code, 2);
  EXPECT_NE(p.log().find("RIGGER_LIVELINESS_LEASE_MS='50'"), std::string::npos) << p.log();
  EXPECT_NE(p.log().find("[100, 10000]"), std::string::npos) << p.log();
}

// Every service reads its keys through its settings table (docs/config-reference.md): a value out of its
// range, or an unknown key, stops it at start naming the file and the key.
TEST_F(ServiceConfigTest, ConvertedServicesNameTheFileAndTheKey) {
  struct Case {
    const char* service;
    const char* out_of_range;
    const char* pointer;
    /// An otherwise valid file with an unknown key (a service needing some keys gives them).
    const char* unknown = R"({"no_such_key": 1})";
  };
  const Case cases[] = {
      {"console", R"({"port": 70000})", "/port"},
      {"crane_gateway", R"({"plc": {"port": 0}})", "/plc/port"},
      {"cell_sim", R"({"camera": {"blur_sigma_px": 11}})", "/camera/blur_sigma_px"},
      {"scripted_executor", R"({"default": {"delay_s": 4000}})", "/default/delay_s"},
      {"scripted_operator", R"({"rules": [{"answer": "done", "delay_s": -1}]})", "/rules/0/delay_s"},
      {"skill_executor", R"({"resolve_timeout_s": 60})", "/resolve_timeout_s"},
      {"admittance_control", R"({"robot": {"gains": {"damping": [100, 100, 0, 10, 10, 10]}}})",
       "/robot/gains/damping/2"},
      {"ros2_bridge", R"({"wrench": {"topic": "/w", "max_age_s": 20}})", "/wrench/max_age_s",
       R"({"wrench": {"topic": "/w"}, "no_such_key": 1})"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.service);
    if (!std::filesystem::exists(bin_dir() + "/" + c.service)) continue;  // left out by RIGGER_ONLY
    auto [st, log] = run_service_with(c.service, c.out_of_range);
    EXPECT_EQ(st.code, 2);
    EXPECT_NE(log.find(std::string(c.service) + "-config.json"), std::string::npos) << log;
    EXPECT_NE(log.find(c.pointer), std::string::npos) << log;
    auto [unknown_st, unknown_log] = run_service_with(c.service, c.unknown, true, std::string(c.service) + "-unknown");
    EXPECT_EQ(unknown_st.code, 2);
    EXPECT_NE(unknown_log.find(std::string(c.service) + "-unknown-config.json"), std::string::npos) << unknown_log;
    EXPECT_NE(unknown_log.find("/no_such_key"), std::string::npos) << unknown_log;
  }
}

}  // namespace
}  // namespace rigger::testing
