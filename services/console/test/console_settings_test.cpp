#include "rigger/console/settings.hpp"

#include <gtest/gtest.h>

namespace rigger::console {
namespace {

using namespace std::chrono_literals;

/// The error `json` gives, or "" when it is accepted.
std::string error_of(const std::string& json) {
  try {
    read_console_settings(Config::parse(json, "console.json"));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(ConsoleSettingsTest, DefaultsWithoutKeys) {
  const ConsoleSettings s = read_console_settings(Config::parse(R"({"web_dir": "."})", "console.json"));
  EXPECT_EQ(s.address, "127.0.0.1");
  EXPECT_EQ(s.port, 8080);
  EXPECT_EQ(s.users_file, "/var/tmp/rigger/console-users.json");
  EXPECT_EQ(s.audit_log, "/var/tmp/rigger/console-audit.log");
  EXPECT_TRUE(s.tls_cert.empty());
  EXPECT_EQ(s.confirm_timeout, 5000ms);
  EXPECT_EQ(s.max_body_bytes, 4u * 1024u * 1024u);
  EXPECT_DOUBLE_EQ(s.plot_rate_hz, 20.0);
  EXPECT_EQ(s.query_timeout, 3000ms);
  EXPECT_FALSE(s.rehearsal_domain.has_value());
}

TEST(ConsoleSettingsTest, ReadsEveryKey) {
  const ConsoleSettings s = read_console_settings(Config::parse(R"({
    "address": "0.0.0.0", "port": 0, "users_file": "u.json", "audit_log": "", "tls_cert": "c.pem",
    "tls_key": "k.pem", "confirm_timeout_s": 0.5, "max_body_bytes": 2048, "plot_rate_hz": 5,
    "query_timeout_s": 0.25, "rehearsal_domain": 7, "web_dir": "."})",
                                                                  "console.json"));
  EXPECT_EQ(s.address, "0.0.0.0");
  EXPECT_EQ(s.port, 0);
  EXPECT_EQ(s.users_file, "u.json");
  EXPECT_TRUE(s.audit_log.empty());
  EXPECT_EQ(s.tls_key, "k.pem");
  EXPECT_EQ(s.confirm_timeout, 500ms);
  EXPECT_EQ(s.max_body_bytes, 2048u);
  EXPECT_DOUBLE_EQ(s.plot_rate_hz, 5.0);
  EXPECT_EQ(s.query_timeout, 250ms);
  EXPECT_EQ(s.rehearsal_domain, 7u);
}

TEST(ConsoleSettingsTest, RefusesOutOfRangeUnknownKeysAndALoneCertificate) {
  const std::string range = error_of(R"({"web_dir": ".", "port": 70000})");
  EXPECT_NE(range.find("console.json"), std::string::npos) << range;
  EXPECT_NE(range.find("port"), std::string::npos) << range;
  EXPECT_NE(error_of(R"({"web_dir": ".", "rehearsal_domain": 231})").find("rehearsal_domain"), std::string::npos);
  const std::string unknown = error_of(R"({"web_dir": ".", "plot_hz": 5})");
  EXPECT_NE(unknown.find("console.json"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("plot_hz"), std::string::npos) << unknown;
  EXPECT_NE(error_of(R"({"web_dir": ".", "tls_cert": "c.pem"})").find("tls_key"), std::string::npos);
}

TEST(ConsoleSettingsTest, TheRehearsalCellOnDemand) {
  const ConsoleSettings none = read_console_settings(Config::parse(R"({"web_dir": "."})", "console.json"));
  EXPECT_TRUE(none.rehearsal_start.empty()) << "no start command by default: nothing is started";
  const ConsoleSettings s = read_console_settings(Config::parse(R"({"web_dir": ".", "rehearsal_domain": 7,
    "rehearsal": {"start": ["rigger-compose", "supervise"], "env": ["RIGGER_PLC_PORT=1509"], "log_file": "/tmp/r.log",
                  "start_timeout_s": 60, "idle_stop_s": 2.5, "stop_timeout_s": 4}})",
                                                                  "console.json"));
  EXPECT_EQ(s.rehearsal_start, (std::vector<std::string>{"rigger-compose", "supervise"}));
  EXPECT_EQ(s.rehearsal_env, std::vector<std::string>{"RIGGER_PLC_PORT=1509"});
  EXPECT_EQ(s.rehearsal_log, "/tmp/r.log");
  EXPECT_EQ(s.rehearsal_start_timeout, 60s);
  EXPECT_EQ(s.rehearsal_idle_stop, 2500ms);
  EXPECT_EQ(s.rehearsal_stop_timeout, 4s);
  // A start command without a domain to run on, an environment entry that is not NAME=value: refused there.
  const std::string lone = error_of(R"({"web_dir": ".", "rehearsal": {"start": ["x"]}})");
  EXPECT_NE(lone.find("/rehearsal/start"), std::string::npos) << lone;
  const std::string env = error_of(R"({"web_dir": ".", "rehearsal_domain": 7, "rehearsal": {"env": ["A=1", "=2"]}})");
  EXPECT_NE(env.find("/rehearsal/env/1"), std::string::npos) << env;
  EXPECT_NE(error_of(R"({"web_dir": ".", "rehearsal": {"idle_stop_s": 0}})").find("idle_stop_s"), std::string::npos);
}

}  // namespace
}  // namespace rigger::console
