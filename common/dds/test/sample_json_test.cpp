// The sample formatter on real protocol types and on test-only types: each test builds a sample in C,
// formats it, parses the JSON back and checks every field against the sample it built.
#include "rigger/dds/sample_json.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <rigger/idl/types.hpp>

#include "rigger/protocol/catalog.hpp"
#include "sample_json_test_types.h"

namespace rigger::dds {
namespace {

using json = nlohmann::ordered_json;  // keeps the fields in the order printed

json parsed(const SampleFormat& format, const void* sample, const FormatLimits& limits = {}) {
  const std::string line = format.to_json(sample, limits);
  EXPECT_EQ(line.find('\n'), std::string::npos) << "one line per sample";
  return json::parse(line);
}

/// Points an idlc sequence at `n` elements the test owns.
template <typename Seq, typename T>
void borrow(Seq& seq, T* buffer, std::uint32_t n) {
  seq._length = n;
  seq._maximum = n;
  seq._buffer = buffer;
}

std::vector<std::string> keys(const json& object) {
  std::vector<std::string> out;
  for (auto it = object.begin(); it != object.end(); ++it) out.push_back(it.key());
  return out;
}

TEST(SampleJson, CraneStateHasTheIdlFieldNamesInOrderAndItsValues) {
  char frame[] = "crane";
  char fault[] = "PLC \"E42\"\nline two";
  rigger_crane_CraneState s{};
  s.header.stamp.sec = -12;
  s.header.stamp.nanosec = 4000000000u;
  s.header.frame_id = frame;
  s.mode = rigger_crane_CRANE_EXTERNAL;
  s.position_m[0] = 1.5;
  s.position_m[1] = -0.1;
  s.position_m[2] = 1e-300;
  s.velocity_mps[2] = 0.25;
  s.load_mass_kg = 812.125;
  s.link_ok = true;
  s.fault = true;
  s.status_word = 0xbeef;
  s.fault_code = 42;
  s.fault_text = fault;
  s.plc_heartbeat = 65535;
  s.last_command_seq = std::numeric_limits<std::uint64_t>::max() - 1;

  const SampleFormat format(rigger_crane_CraneState_desc);
  EXPECT_EQ(format.type_name(), "rigger::crane::CraneState");
  const json j = parsed(format, &s);
  EXPECT_EQ(keys(j),
            (std::vector<std::string>{"header", "mode", "position_m", "velocity_mps", "load_mass_kg", "link_ok",
                                      "ready", "enabled", "external_control", "moving", "fault", "estop", "overload",
                                      "status_word", "fault_code", "fault_text", "plc_heartbeat", "last_command_seq"}));
  EXPECT_EQ(j["header"]["stamp"]["sec"], -12);
  EXPECT_EQ(j["header"]["stamp"]["nanosec"], 4000000000u);
  EXPECT_EQ(j["header"]["frame_id"], "crane");
  EXPECT_EQ(j["mode"], "CRANE_EXTERNAL");
  EXPECT_EQ(j["position_m"], json::array({1.5, -0.1, 1e-300}));
  EXPECT_EQ(j["velocity_mps"], json::array({0.0, 0.0, 0.25}));
  EXPECT_EQ(j["load_mass_kg"].get<double>(), 812.125);
  EXPECT_EQ(j["link_ok"], true);
  EXPECT_EQ(j["ready"], false);
  EXPECT_EQ(j["fault"], true);
  EXPECT_EQ(j["status_word"], 0xbeef);
  EXPECT_EQ(j["fault_code"], 42);
  EXPECT_EQ(j["fault_text"], fault);
  EXPECT_EQ(j["plc_heartbeat"], 65535);
  EXPECT_EQ(j["last_command_seq"].get<std::uint64_t>(), s.last_command_seq);
}

TEST(SampleJson, SequencesOfStructsAndEnumsOfTaskStatus) {
  char task[] = "t-1", code[] = "RECIPE_INVALID", empty[] = "";
  char p0[] = "/nodes/0", m0[] = "unknown skill", p1[] = "/nodes/1/params", m1[] = "expected number";
  rigger_task_RecipeError errors[2] = {{p0, m0}, {p1, m1}};
  rigger_task_TaskStatus s{};
  s.task_id = task;
  s.state = rigger_task_TASK_REJECTED;
  s.code = code;
  s.message = empty;
  s.failed_node = nullptr;  // a null string reads as ""
  borrow(s.errors, errors, 2);
  s.stamp.sec = 1700000000;

  const json j = parsed(SampleFormat(rigger_task_TaskStatus_desc), &s);
  EXPECT_EQ(j["task_id"], "t-1");
  EXPECT_EQ(j["state"], "TASK_REJECTED");
  EXPECT_EQ(j["failed_node"], "");
  ASSERT_TRUE(j["errors"].is_array());
  ASSERT_EQ(j["errors"].size(), 2u);
  EXPECT_EQ(j["errors"][1]["pointer"], "/nodes/1/params");
  EXPECT_EQ(j["errors"][1]["message"], "expected number");
  EXPECT_EQ(j["errors"][0]["message"], "unknown skill");
  EXPECT_EQ(j["stamp"]["sec"], 1700000000);
  EXPECT_EQ(j["submitted"]["nanosec"], 0);
}

TEST(SampleJson, JointStateSequencesOfStringsAndDoubles) {
  char a[] = "shoulder", b[] = "elbow";
  char* names[] = {a, b};
  double pos[] = {0.5, -1.25};
  rigger_sensing_JointState s{};
  borrow(s.name, names, 2);
  borrow(s.position, pos, 2);
  const json j = parsed(SampleFormat(rigger_sensing_JointState_desc), &s);
  EXPECT_EQ(j["name"], json::array({"shoulder", "elbow"}));
  EXPECT_EQ(j["position"], json::array({0.5, -1.25}));
  EXPECT_EQ(j["velocity"], json::array());
}

TEST(SampleJson, EveryConstructOfTheTestTypes) {
  char id[] = "everything", tag0[] = "a", tag1[] = "b\\c", name0[] = "n0", name1[] = "n1", label[] = "lbl";
  char* tags[] = {tag0, tag1};
  rigger_test_json_Point points[3] = {{1, 2}, {3, 4}, {5, 6}};
  double samples[] = {0.125, NAN};
  rigger_test_json_Color hue_seq[] = {rigger_test_json_BLUE, rigger_test_json_RED};
  int32_t inner0[] = {1, 2}, inner1[] = {-3};
  dds_sequence_int32 nested[2] = {};
  borrow(nested[0], inner0, 2);
  borrow(nested[1], inner1, 1);
  double maybe = 2.5;

  rigger_test_json_Everything s{};
  s.id = id;
  s.letter = 'A';
  s.raw = 200;
  s.tiny = -5;
  s.utiny = 250;
  s.s16 = -32768;
  s.u16 = 65535;
  s.s32 = -2147483647 - 1;
  s.u32 = 4294967295u;
  s.s64 = std::numeric_limits<std::int64_t>::min();
  s.u64 = std::numeric_limits<std::uint64_t>::max();
  s.f32 = 0.1f;
  s.f64 = 1.0 / 3.0;
  s.flag = true;
  s.hue = rigger_test_json_GREEN;
  s.hues[0] = rigger_test_json_BLUE;
  s.hues[1] = static_cast<rigger_test_json_Color>(7);  // not an enumerator: printed as its number
  std::strcpy(s.short_name, "eight_ch");
  s.names[0] = name0;
  s.names[1] = name1;
  borrow(s.tags, tags, 2);
  borrow(s.few_points, points, 1);
  borrow(s.points, points, 3);
  s.corners[1] = {7, 8};
  borrow(s.samples, samples, 2);
  borrow(s.hue_seq, hue_seq, 2);
  borrow(s.nested, nested, 2);
  s.shape._d = 3;  // the second label of the case `corner`
  s.shape._u.corner = {9, 10};
  s.by_color._d = rigger_test_json_BLUE;
  s.by_color._u.b = label;
  s.maybe = &maybe;
  s.maybe_point = nullptr;

  const SampleFormat format(rigger_test_json_Everything_desc);
  const json j = parsed(format, &s);
  EXPECT_EQ(j["id"], "everything");
  EXPECT_EQ(j["letter"], 65);  // char and int8 are alike in 0.10's type information
  EXPECT_EQ(j["raw"], 200);
  EXPECT_EQ(j["tiny"], -5);
  EXPECT_EQ(j["utiny"], 250);
  EXPECT_EQ(j["s16"], -32768);
  EXPECT_EQ(j["u16"], 65535);
  EXPECT_EQ(j["s32"], s.s32);
  EXPECT_EQ(j["u32"], s.u32);
  EXPECT_EQ(j["s64"].get<std::int64_t>(), s.s64);
  EXPECT_EQ(j["u64"].get<std::uint64_t>(), s.u64);
  EXPECT_EQ(j["f32"].get<float>(), 0.1f);
  EXPECT_EQ(j["f64"].get<double>(), 1.0 / 3.0) << "doubles print exactly (shortest round-trip form)";
  EXPECT_EQ(j["flag"], true);
  EXPECT_EQ(j["hue"], "GREEN");
  EXPECT_EQ(j["hues"], json::array({"BLUE", 7}));
  EXPECT_EQ(j["short_name"], "eight_ch");
  EXPECT_EQ(j["names"], json::array({"n0", "n1"}));
  EXPECT_EQ(j["tags"], json::array({"a", "b\\c"}));
  EXPECT_EQ(j["few_points"], json::parse(R"([{"x":1,"y":2}])"));
  EXPECT_EQ(j["points"], json::parse(R"([{"x":1,"y":2},{"x":3,"y":4},{"x":5,"y":6}])"));
  EXPECT_EQ(j["corners"], json::parse(R"([{"x":0,"y":0},{"x":7,"y":8}])"));
  EXPECT_EQ(j["samples"], json::parse("[0.125,null]")) << "NaN is null in JSON";
  EXPECT_EQ(j["hue_seq"], json::array({"BLUE", "RED"}));
  EXPECT_EQ(j["nested"], json::parse("[[1,2],[-3]]"));
  EXPECT_EQ(j["shape"], json::parse(R"({"discriminator":3,"corner":{"x":9,"y":10}})"));
  EXPECT_EQ(j["by_color"], json::parse(R"({"discriminator":"BLUE","b":"lbl"})"));
  EXPECT_EQ(j["maybe"], 2.5);
  EXPECT_TRUE(j["maybe_point"].is_null());
  EXPECT_EQ(j["blob"], json::array());

  // The union's other cases: a plain label, the default, and a label of no case (only the discriminator).
  s.shape._d = 1;
  s.shape._u.radius = 0.75;
  EXPECT_EQ(parsed(format, &s)["shape"], json::parse(R"({"discriminator":1,"radius":0.75})"));
  s.shape._d = 99;
  s.shape._u.other = -4;
  EXPECT_EQ(parsed(format, &s)["shape"], json::parse(R"({"discriminator":99,"other":-4})"));
  s.by_color._d = rigger_test_json_GREEN;
  EXPECT_EQ(parsed(format, &s)["by_color"], json::parse(R"({"discriminator":"GREEN"})"));
}

TEST(SampleJson, LongSequencesAndStringsAreBounded) {
  std::vector<std::uint8_t> blob(100000, 7);
  std::string long_id(5000, 'x');
  long_id[10] = '\x01';  // a control character is escaped
  rigger_test_json_Everything s{};
  s.id = long_id.data();
  borrow(s.blob, blob.data(), static_cast<std::uint32_t>(blob.size()));

  FormatLimits limits;
  limits.max_elements = 4;
  limits.max_string = 16;
  const SampleFormat format(rigger_test_json_Everything_desc);
  const std::string line = format.to_json(&s, limits);
  EXPECT_LT(line.size(), 2000u);
  const json j = json::parse(line);
  EXPECT_EQ(j["blob"]["length"], 100000);
  EXPECT_EQ(j["blob"]["first"], json::array({7, 7, 7, 7}));
  EXPECT_EQ(j["id"], std::string("xxxxxxxxxx\x01xxxxx") + "\xe2\x80\xa6");
  EXPECT_FALSE(j.contains("truncated"));

  // Past max_output the remaining sequences show only their length, and the top level says so.
  limits.max_output = 64;
  limits.max_elements = 1000;
  const json cut = json::parse(format.to_json(&s, limits));
  EXPECT_EQ(cut["truncated"], true);
  EXPECT_EQ(cut["blob"]["length"], 100000);
  EXPECT_LE(cut["blob"]["first"].size(), 1000u);
}

TEST(SampleJson, TextFormIsIndentedNameValueLines) {
  char frame[] = "base";
  rigger_sensing_WrenchStamped w{};
  w.header.frame_id = frame;
  w.wrench.force.z = -9.81;
  const std::string text = SampleFormat(rigger_sensing_WrenchStamped_desc).to_text(&w);
  EXPECT_NE(text.find("header:\n  stamp:\n    sec: 0\n    nanosec: 0\n  frame_id: base\n"), std::string::npos) << text;
  EXPECT_NE(text.find("wrench:\n  force:\n    x: 0\n    y: 0\n    z: -9.81\n"), std::string::npos) << text;

  char fault[] = "";
  rigger_crane_CraneState c{};
  c.fault_text = fault;
  c.position_m[0] = 2;
  const std::string crane = SampleFormat(rigger_crane_CraneState_desc).to_text(&c);
  EXPECT_NE(crane.find("mode: CRANE_LOCAL\nposition_m: [2, 0, 0]\n"), std::string::npos) << crane;
  EXPECT_NE(crane.find("fault_text: \"\"\n"), std::string::npos) << crane;
}

// Every topic of the catalog can be formatted: a zeroed sample of each type (null strings, empty
// sequences) gives an object with one key per top-level field of the type.
TEST(SampleJson, EveryCatalogTopicFormats) {
  for (const auto& topic : protocol::catalog()) {
    SCOPED_TRACE(topic.name);
    const SampleFormat format(*topic.descriptor);
    // dds_alloc zeroes (a vector of max_align_t would leave the long double's padding undefined).
    const std::unique_ptr<void, void (*)(void*)> zero(dds_alloc(topic.descriptor->m_size), dds_free);
    const json j = json::parse(format.to_json(zero.get()));
    EXPECT_TRUE(j.is_object());
    EXPECT_FALSE(j.empty());
    EXPECT_FALSE(format.to_text(zero.get()).empty());
  }
}

TEST(SampleJson, DescriptorWithoutTypeInformationIsRefused) {
  const dds_topic_descriptor_t& d = rigger_crane_CraneState_desc;
  const dds_topic_descriptor_t bare{d.m_size, d.m_align, 0u,       d.m_nkeys, d.m_typename, d.m_keys,
                                    d.m_nops, d.m_ops,   d.m_meta, {},        {},           0u};
  try {
    SampleFormat format(bare);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("rigger::crane::CraneState"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no XTypes type information"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigger::dds
