#include "rigger/base/settings.hpp"

#include <gtest/gtest.h>

#include "error_of.hpp"

namespace rigger {
namespace {

using namespace std::chrono_literals;

enum class Sync { kNormal, kFull };

struct Example {
  bool enabled{};
  std::string name;
  double rate_hz{};
  unsigned count{};
  int offset{};
  std::chrono::nanoseconds timeout{};
  std::chrono::milliseconds lease{};
  double tolerance_m{};
  Sync sync{};
  std::vector<std::string> tags;
};

unsigned lease_default() {
  return 150;
}

const SettingsTable<Example>& example_settings() {
  using S = Example;
  static const SettingsTable<S> table{
      setting<S>("enabled", true, &S::enabled, "whether it runs"),
      setting<S>("name", "rig", &S::name, "its name"),
      setting<S>("rate_hz", 50.0, {1.0, 1000.0}, &S::rate_hz, "how often"),
      setting<S>("count", 20u, {0u, 100u}, &S::count, "how many"),
      setting<S>("offset", -3, {-10, 10}, &S::offset, "how far"),
      setting<S>("timeout_s", 0.2, {0.01, 60.0}, &S::timeout, "how long"),
      setting<S>("lease_ms", RuntimeDefault<unsigned>{&lease_default, "150"}, {100u, 10000u}, &S::lease, "a lease"),
      setting<S>(
          "tolerance_mm", 10.0, {0.1, 1000.0}, [](S& s, double mm) { s.tolerance_m = mm / 1000.0; }, "how near"),
      choice<S>("sync", Sync::kNormal, {{"normal", Sync::kNormal}, {"full", Sync::kFull}}, &S::sync, "fsync or not"),
      setting<S>("tags", std::vector<std::string>{}, &S::tags, "labels"),
  };
  return table;
}

Example read(const std::string& json) {
  return read_settings(Config::parse(json, "x.json"), example_settings());
}

TEST(Settings, DefaultsApplyToAbsentKeys) {
  const Example s = read("{}");
  EXPECT_TRUE(s.enabled);
  EXPECT_EQ(s.name, "rig");
  EXPECT_DOUBLE_EQ(s.rate_hz, 50.0);
  EXPECT_EQ(s.count, 20u);
  EXPECT_EQ(s.offset, -3);
  EXPECT_EQ(s.timeout, 200ms);
  EXPECT_EQ(s.lease, 150ms);
  EXPECT_DOUBLE_EQ(s.tolerance_m, 0.010);
  EXPECT_EQ(s.sync, Sync::kNormal);
  EXPECT_TRUE(s.tags.empty());
}

TEST(Settings, ReadsEveryKeyConvertingDurationsFromTheKeysUnit) {
  const Example s = read(R"({"enabled": false, "name": "b", "rate_hz": 1000, "count": 0, "offset": 10,
      "timeout_s": 0.29, "lease_ms": 290, "tolerance_mm": 25, "sync": "full", "tags": ["a"]})");
  EXPECT_FALSE(s.enabled);
  EXPECT_EQ(s.name, "b");
  EXPECT_DOUBLE_EQ(s.rate_hz, 1000.0);
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.offset, 10);
  EXPECT_EQ(s.timeout, 290ms);
  EXPECT_EQ(s.lease, 290ms);
  EXPECT_DOUBLE_EQ(s.tolerance_m, 0.025);
  EXPECT_EQ(s.sync, Sync::kFull);
  EXPECT_EQ(s.tags, std::vector<std::string>{"a"});
}

TEST(Settings, ErrorsAreConfigsOwn) {
  // The same messages as Config's readers: file, JSON pointer, what was expected.
  const auto type = error_of([] { read(R"({"rate_hz": "fast"})"); });
  EXPECT_NE(type.find("x.json at /rate_hz: expected a number, got string \"fast\""), std::string::npos) << type;
  const auto range = error_of([] { read(R"({"count": 101})"); });
  EXPECT_NE(range.find("at /count: expected a value in [0, 100], got 101"), std::string::npos) << range;
  const auto negative = error_of([] { read(R"({"count": -1})"); });
  EXPECT_NE(negative.find("expected a non-negative integer"), std::string::npos) << negative;
  const auto enumeration = error_of([] { read(R"({"sync": "sometimes"})"); });
  EXPECT_NE(enumeration.find("at /sync: expected one of normal, full, got \"sometimes\""), std::string::npos)
      << enumeration;
  const auto flag = error_of([] { read(R"({"enabled": 1})"); });
  EXPECT_NE(flag.find("expected a boolean"), std::string::npos) << flag;
}

TEST(Settings, UnknownKeysAreRefused) {
  const auto msg = error_of([] { read(R"({"rate_hz": 10, "rate_hx": 20})"); });
  EXPECT_NE(msg.find("x.json at /rate_hx: unknown key(s) /rate_hx"), std::string::npos) << msg;
}

TEST(Settings, ReadIntoLeavesFinishToTheCaller) {
  const Config config = Config::parse(R"({"count": 3, "extra": {"a": 1}})", "x.json");
  Example s;
  read_into(config, example_settings(), s);
  EXPECT_EQ(s.count, 3u);
  EXPECT_EQ(config.child("extra").get<int>("a"), 1);
  EXPECT_NO_THROW(config.finish());
}

struct Link {
  unsigned port{};
  std::chrono::milliseconds backoff_min{};
};

const SettingsTable<Link>& link_settings() {
  using S = Link;
  static const SettingsTable<S> table{
      nested("plc", setting<S>("port", 1502u, {1u, 65535u}, &S::port, "its port")),
      nested("backoff_ms", setting<S>(
                               "min", 20, {1, 60000},
                               [](S& s, int ms) { s.backoff_min = std::chrono::milliseconds(ms); }, "the first retry")),
  };
  return table;
}

TEST(Settings, NestedKeysAreReadFromTheirObject) {
  EXPECT_EQ(read_settings(Config::parse("{}", "x.json"), link_settings()).port, 1502u);
  const Link s =
      read_settings(Config::parse(R"({"plc": {"port": 502}, "backoff_ms": {"min": 5}})", "x.json"), link_settings());
  EXPECT_EQ(s.port, 502u);
  EXPECT_EQ(s.backoff_min, 5ms);
  const auto range =
      error_of([] { read_settings(Config::parse(R"({"plc": {"port": 0}})", "x.json"), link_settings()); });
  EXPECT_NE(range.find("x.json at /plc/port"), std::string::npos) << range;
  const auto unknown =
      error_of([] { read_settings(Config::parse(R"({"plc": {"prot": 502}})", "x.json"), link_settings()); });
  EXPECT_NE(unknown.find("/plc/prot"), std::string::npos) << unknown;
  const auto info = describe(link_settings());
  EXPECT_EQ(info[0].key, "plc/port");
  EXPECT_EQ(info[1].key, "backoff_ms/min");
  EXPECT_EQ(info[1].unit, "ms");
}

TEST(Settings, AnOwnSettingReadsItsKeyItself) {
  struct Rules {
    std::vector<int> ids;
  };
  const SettingsTable<Rules> table{own_setting<Rules>(
      "rules", "array of rule objects", "[]", "",
      [](const Config& config, const std::string& key, Rules& r) {
        for (const auto& rule : config.children(key)) r.ids.push_back(rule.get<int>("id"));
      },
      "the rules")};
  EXPECT_EQ(read_settings(Config::parse(R"({"rules": [{"id": 4}, {"id": 2}]})", "x.json"), table).ids,
            (std::vector<int>{4, 2}));
  const auto unknown =
      error_of([&] { read_settings(Config::parse(R"({"rules": [{"id": 4, "di": 1}]})", "x.json"), table); });
  EXPECT_NE(unknown.find("/rules/0/di"), std::string::npos) << unknown;
  EXPECT_EQ(describe(table)[0].type, "array of rule objects");
}

TEST(Settings, DescribesEveryKeyForTheReference) {
  const auto info = describe(example_settings());
  ASSERT_EQ(info.size(), example_settings().size());
  EXPECT_EQ(info[0].type, "boolean");
  EXPECT_EQ(info[0].default_text, "true");
  EXPECT_EQ(info[1].type, "string");
  EXPECT_EQ(info[1].default_text, "\"rig\"");
  EXPECT_EQ(info[2].type, "number");
  EXPECT_EQ(info[2].range_text, "[1, 1000]");
  EXPECT_EQ(info[2].unit, "Hz");
  EXPECT_EQ(info[4].default_text, "-3");
  EXPECT_EQ(info[5].unit, "s");
  EXPECT_EQ(info[5].default_text, "0.2");
  EXPECT_EQ(info[6].default_text, "150");
  EXPECT_EQ(info[6].unit, "ms");
  EXPECT_EQ(info[8].type, "enum");
  EXPECT_EQ(info[8].default_text, "\"normal\"");
  EXPECT_EQ(info[8].range_text, "\"normal\", \"full\"");
  EXPECT_EQ(info[9].type, "array of strings");
  EXPECT_EQ(info[9].default_text, "[]");
  const std::string md = settings_markdown(info);
  EXPECT_NE(md.find("| `rate_hz` | number | `50` | `[1, 1000]` | Hz | how often |"), std::string::npos) << md;
}

TEST(Settings, UnitsComeFromTheKeysName) {
  EXPECT_EQ(unit_of_key("busy_wait_s"), "s");
  EXPECT_EQ(unit_of_key("flush_delay_us"), "µs");
  EXPECT_EQ(unit_of_key("rope_offset_gain_per_s"), "1/s");
  EXPECT_EQ(unit_of_key("max_linear_speed_mps"), "m/s");
  EXPECT_EQ(unit_of_key("max_recipe_bytes"), "bytes");
  EXPECT_EQ(unit_of_key("max_plausible_torque_nm"), "N·m");
  EXPECT_EQ(unit_of_key("journal_path"), "");
  EXPECT_EQ(unit_of_key("_s"), "");
}

TEST(Settings, ADurationKeyWithoutATimeUnitIsATableMistake) {
  struct Bad {
    std::chrono::milliseconds period{};
  };
  const SettingsTable<Bad> table{setting<Bad>("period", 5u, {1u, 10u}, &Bad::period, "no unit")};
  EXPECT_THROW(read_settings(Config::empty(), table), std::logic_error);
}

}  // namespace
}  // namespace rigger
