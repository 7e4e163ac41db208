#include "rigger/base/config.hpp"

#include <cstdio>
#include <fstream>

#include <gtest/gtest.h>

#include "error_of.hpp"

namespace rigger {
namespace {

TEST(Config, ReadsTypedValuesAndDefaults) {
  auto cfg = Config::parse(R"({"rate_hz": 50, "host": "127.0.0.1", "axes": [1, 2.5], "plc": {"port": 1502}})", "t.json");
  EXPECT_DOUBLE_EQ(cfg.get<double>("rate_hz"), 50.0);
  EXPECT_EQ(cfg.get<std::string>("host"), "127.0.0.1");
  EXPECT_EQ(cfg.get<std::vector<double>>("axes"), (std::vector<double>{1.0, 2.5}));
  EXPECT_EQ(cfg.child("plc").get<std::uint16_t>("port"), 1502);
  EXPECT_EQ(cfg.get<int>("absent", 7), 7);
  EXPECT_NO_THROW(cfg.finish());
}

TEST(Config, MissingFileNamesTheFile) {
  const auto msg = error_of([] { Config::load("/nonexistent/rigger.json"); });
  EXPECT_NE(msg.find("/nonexistent/rigger.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("cannot open"), std::string::npos) << msg;
}

TEST(Config, WrongTypeNamesFileKeyAndExpectation) {
  auto cfg = Config::parse(R"({"crane": {"rate_hz": "fast"}})", "cell.json");
  const auto msg = error_of([&] { cfg.child("crane").get<double>("rate_hz"); });
  EXPECT_NE(msg.find("cell.json"), std::string::npos) << msg;
  EXPECT_NE(msg.find("/crane/rate_hz"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected a number"), std::string::npos) << msg;
  EXPECT_NE(msg.find("\"fast\""), std::string::npos) << msg;
}

TEST(Config, UnknownKeyIsReportedByFinish) {
  auto cfg = Config::parse(R"({"rate_hz": 50, "rate_hx": 60, "plc": {"port": 1, "prot": 2}})", "gw.json");
  cfg.get<double>("rate_hz");
  cfg.child("plc").get<int>("port");
  const auto msg = error_of([&] { cfg.finish(); });
  EXPECT_NE(msg.find("/rate_hx"), std::string::npos) << msg;
  EXPECT_NE(msg.find("/plc/prot"), std::string::npos) << msg;
  EXPECT_NE(msg.find("gw.json"), std::string::npos) << msg;
}

TEST(Config, RangeAndIntegerChecks) {
  auto cfg = Config::parse(R"({"rate_hz": 5000, "port": 70000, "count": 1.5, "neg": -1})", "r.json");
  EXPECT_NE(error_of([&] { cfg.get_in_range("rate_hz", 50.0, 1.0, 1000.0); }).find("[1, 1000]"), std::string::npos);
  EXPECT_NE(error_of([&] { cfg.get<std::uint16_t>("port"); }).find("[0, 65535]"), std::string::npos);
  EXPECT_NE(error_of([&] { cfg.get<int>("count"); }).find("an integer"), std::string::npos);
  EXPECT_NE(error_of([&] { cfg.get<unsigned>("neg"); }).find("non-negative"), std::string::npos);
}

TEST(Config, EnumsAndMalformedJson) {
  auto cfg = Config::parse(R"({"mode": "turbo"})", "m.json");
  EXPECT_NE(error_of([&] { cfg.get_enum("mode", "off", {"off", "robot"}); }).find("one of off, robot"), std::string::npos);
  EXPECT_NE(error_of([] { Config::parse("{\"a\": ", "bad.json"); }).find("not valid JSON"), std::string::npos);
  EXPECT_NE(error_of([] { Config::parse("[1]", "arr.json"); }).find("JSON object"), std::string::npos);
}

TEST(Config, ChildrenArrayAndMissingKey) {
  auto cfg = Config::parse(R"({"services": [{"id": "a"}, 3]})", "s.json");
  const auto msg = error_of([&] { cfg.children("services"); });
  EXPECT_NE(msg.find("/services/1"), std::string::npos) << msg;
  EXPECT_NE(error_of([&] { cfg.get<std::string>("absent"); }).find("missing required key"), std::string::npos);
}

TEST(Config, LoadsFromFile) {
  const std::string path = ::testing::TempDir() + "rigger_config_test.json";
  std::ofstream(path) << R"({"x": true})";
  auto cfg = Config::load(path);
  EXPECT_TRUE(cfg.get<bool>("x"));
  EXPECT_EQ(cfg.file(), path);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rigger
