// ros2_cdr_samples: test values for every ROS 2 message type rigger exchanges with drivers (idl/ros2), and
// the bytes Cyclone DDS puts on the wire for each, printed as one JSON document for compare.js, which
// serializes the same values with an independent ROS 2 serializer and compares (docs/ros2.md).
//
// The values are written once, here, as JSON in ROS 2's field names; each is converted to the idlc
// struct by a per-type function and written through a real DDS writer on a local participant. A
// reader on the same participant takes the sample as serialized data (dds_takecdr), so the bytes are
// those of the writer's serdata: what Cyclone sends, encapsulation header included.
//
// Output: {"cases": [{"name", "type" ("geometry_msgs/msg/WrenchStamped"), "value", "cdr" (hex)}]}.
// JSON has no NaN or infinities: a non-finite double is written as {"$f64": "NaN" | "Infinity" | "-Infinity"}.

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <iostream>
#include <limits>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>
#include <rigger/ros2/geometry_msgs.h>
#include <rigger/ros2/sensor_msgs.h>
#include <nlohmann/json.hpp>

#include "rigger/dds/entity.hpp"
#include "rigger/dds/sequences.hpp"

namespace {

using nlohmann::ordered_json;
using rigger::dds::check;
using rigger::dds::Entity;

// ---- JSON (ROS 2 field names) -> idlc struct ----------------------------------------------------

// One fill() per type; a struct's fill() names its members once, in order, through fill_members().
void fill(std::int32_t& s, const ordered_json& j) {
  s = j.get<std::int32_t>();
}
void fill(std::uint32_t& s, const ordered_json& j) {
  s = j.get<std::uint32_t>();
}
void fill(std::uint8_t& s, const ordered_json& j) {
  s = j.get<std::uint8_t>();
}
void fill(double& s, const ordered_json& j) {
  s = j.get<double>();
}
void fill(bool& s, const ordered_json& j) {
  s = j.get<bool>();
}
/// A fixed-size IDL array from a JSON array of exactly that many elements.
template <typename T, std::size_t N>
void fill(T (&array)[N], const ordered_json& j) {
  if (j.size() != N) throw std::runtime_error("a fixed array of " + std::to_string(N) + " elements, got " + j.dump());
  for (std::size_t i = 0; i < N; ++i) fill(array[i], j[i]);
}
void fill(char*& s, const ordered_json& j) {
  s = dds_string_dup(j.get<std::string>().c_str());
}
void fill(builtin_interfaces_msg_dds__Time_& s, const ordered_json& j);
void fill(std_msgs_msg_dds__Header_& s, const ordered_json& j);
void fill(geometry_msgs_msg_dds__Vector3_& s, const ordered_json& j);
void fill(geometry_msgs_msg_dds__Point_& s, const ordered_json& j);
void fill(geometry_msgs_msg_dds__Quaternion_& s, const ordered_json& j);
void fill(geometry_msgs_msg_dds__Pose_& s, const ordered_json& j);
void fill(geometry_msgs_msg_dds__Twist_& s, const ordered_json& j);
void fill(geometry_msgs_msg_dds__Wrench_& s, const ordered_json& j);
void fill(sensor_msgs_msg_dds__RegionOfInterest_& s, const ordered_json& j);

/// An idlc sequence from a JSON array, owning its elements (dds_sample_free frees them).
template <typename Seq>
void fill_sequence(Seq& seq, const ordered_json& array) {
  auto* elements = rigger::dds::alloc_sequence(seq, array.size());
  for (std::size_t i = 0; i < array.size(); ++i) fill(elements[i], array[i]);
}

template <typename Member, typename... Rest>
void fill_members(const ordered_json& j, const char* name, Member& member, Rest&&... rest) {
  fill(member, j.at(name));
  if constexpr (sizeof...(rest) > 0) fill_members(j, std::forward<Rest>(rest)...);
}

void fill(builtin_interfaces_msg_dds__Time_& s, const ordered_json& j) {
  fill_members(j, "sec", s.sec_, "nanosec", s.nanosec_);
}
void fill(std_msgs_msg_dds__Header_& s, const ordered_json& j) {
  fill_members(j, "stamp", s.stamp_, "frame_id", s.frame_id_);
}
void fill(geometry_msgs_msg_dds__Vector3_& s, const ordered_json& j) {
  fill_members(j, "x", s.x_, "y", s.y_, "z", s.z_);
}
void fill(geometry_msgs_msg_dds__Point_& s, const ordered_json& j) {
  fill_members(j, "x", s.x_, "y", s.y_, "z", s.z_);
}
void fill(geometry_msgs_msg_dds__Quaternion_& s, const ordered_json& j) {
  fill_members(j, "x", s.x_, "y", s.y_, "z", s.z_, "w", s.w_);
}
void fill(geometry_msgs_msg_dds__Pose_& s, const ordered_json& j) {
  fill_members(j, "position", s.position_, "orientation", s.orientation_);
}
void fill(geometry_msgs_msg_dds__PoseStamped_& s, const ordered_json& j) {
  fill_members(j, "header", s.header_, "pose", s.pose_);
}
void fill(geometry_msgs_msg_dds__Twist_& s, const ordered_json& j) {
  fill_members(j, "linear", s.linear_, "angular", s.angular_);
}
void fill(geometry_msgs_msg_dds__TwistStamped_& s, const ordered_json& j) {
  fill_members(j, "header", s.header_, "twist", s.twist_);
}
void fill(geometry_msgs_msg_dds__Wrench_& s, const ordered_json& j) {
  fill_members(j, "force", s.force_, "torque", s.torque_);
}
void fill(geometry_msgs_msg_dds__WrenchStamped_& s, const ordered_json& j) {
  fill_members(j, "header", s.header_, "wrench", s.wrench_);
}
void fill(sensor_msgs_msg_dds__JointState_& s, const ordered_json& j) {
  fill(s.header_, j.at("header"));
  fill_sequence(s.name_, j.at("name"));
  fill_sequence(s.position_, j.at("position"));
  fill_sequence(s.velocity_, j.at("velocity"));
  fill_sequence(s.effort_, j.at("effort"));
}
void fill(sensor_msgs_msg_dds__RegionOfInterest_& s, const ordered_json& j) {
  fill_members(j, "x_offset", s.x_offset_, "y_offset", s.y_offset_, "height", s.height_, "width", s.width_,
               "do_rectify", s.do_rectify_);
}
void fill(sensor_msgs_msg_dds__CameraInfo_& s, const ordered_json& j) {
  fill_members(j, "header", s.header_, "height", s.height_, "width", s.width_, "distortion_model",
               s.distortion_model_);
  fill_sequence(s.d_, j.at("d"));
  fill_members(j, "k", s.k_, "r", s.r_, "p", s.p_, "binning_x", s.binning_x_, "binning_y", s.binning_y_, "roi",
               s.roi_);
}
void fill(sensor_msgs_msg_dds__Image_& s, const ordered_json& j) {
  fill_members(j, "header", s.header_, "height", s.height_, "width", s.width_, "encoding", s.encoding_, "is_bigendian",
               s.is_bigendian_, "step", s.step_);
  fill_sequence(s.data_, j.at("data"));
}

// ---- Cyclone's serialization ----------------------------------------------------------------------

/// Frees what fill() allocated inside a sample.
class SampleContents {
 public:
  SampleContents(void* sample, const dds_topic_descriptor_t& desc) : sample_(sample), desc_(desc) {}
  SampleContents(const SampleContents&) = delete;
  SampleContents& operator=(const SampleContents&) = delete;
  ~SampleContents() { dds_sample_free(sample_, &desc_, DDS_FREE_CONTENTS); }

 private:
  void* sample_;
  const dds_topic_descriptor_t& desc_;
};

/// Drops the reference dds_takecdr handed out.
class SerdataRef {
 public:
  SerdataRef() = default;
  SerdataRef(const SerdataRef&) = delete;
  SerdataRef& operator=(const SerdataRef&) = delete;
  ~SerdataRef() {
    if (serdata) ddsi_serdata_unref(serdata);
  }
  struct ddsi_serdata* serdata = nullptr;
};

class CycloneSerializer {
 public:
  // Its own domain, configured here rather than from CYCLONEDDS_URI: nothing but this process's own
  // reader ever sees these samples, and parallel tests must not be disturbed.
  CycloneSerializer()
      : domain_(dds_create_domain(kDomain,
                                  "<General><Interfaces><NetworkInterface address=\"127.0.0.1\"/></Interfaces>"
                                  "<AllowMulticast>false</AllowMulticast></General>"
                                  "<Discovery><ParticipantIndex>none</ParticipantIndex></Discovery>"),
                "create domain"),
        participant_(dds_create_participant(kDomain, nullptr, nullptr), "create participant") {}

  /// The serialized form of `value` as a `T` (idlc type of `desc`), encapsulation header included.
  template <typename T>
  std::vector<unsigned char> serialize(const dds_topic_descriptor_t& desc, const ordered_json& value) {
    T sample{};
    SampleContents contents(&sample, desc);
    fill(sample, value);

    const std::string name = "rigger_cdr_probe_" + std::to_string(++topics_);
    Entity topic(dds_create_topic(participant_.handle(), &desc, name.c_str(), nullptr, nullptr), "create topic");
    dds_qos_t* qos = dds_create_qos();
    dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, DDS_LENGTH_UNLIMITED);
    Entity reader(dds_create_reader(participant_.handle(), topic.handle(), qos, nullptr), "create reader");
    Entity writer(dds_create_writer(participant_.handle(), topic.handle(), qos, nullptr), "create writer");
    dds_delete_qos(qos);

    // Local delivery to a reader in the same participant: the reader's condition triggers once the
    // sample is in its cache, which the waitset waits for (no sleep, no polling).
    Entity waitset(dds_create_waitset(participant_.handle()), "create waitset");
    Entity readable(dds_create_readcondition(reader.handle(), DDS_ANY_STATE), "create read condition");
    check(dds_waitset_attach(waitset.handle(), readable.handle(), 0), "attach read condition");
    check(dds_write(writer.handle(), &sample), "write");
    if (check(dds_waitset_wait(waitset.handle(), nullptr, 0, DDS_SECS(10)), "wait for the sample") == 0) {
      throw std::runtime_error("the local reader did not receive the sample of " + name + " within 10 s");
    }
    SerdataRef taken;
    dds_sample_info_t info;
    if (check(dds_takecdr(reader.handle(), &taken.serdata, 1, &info, DDS_ANY_STATE), "take serialized") != 1) {
      throw std::runtime_error("dds_takecdr returned no sample for " + name);
    }
    std::vector<unsigned char> bytes(ddsi_serdata_size(taken.serdata));
    ddsi_serdata_to_ser(taken.serdata, 0, bytes.size(), bytes.data());
    return bytes;
  }

 private:
  static constexpr dds_domainid_t kDomain = 231;
  Entity domain_;
  Entity participant_;
  int topics_ = 0;
};

// ---- the test values --------------------------------------------------------------------------------

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kDenormMin = std::numeric_limits<double>::denorm_min();
constexpr double kMax = std::numeric_limits<double>::max();
constexpr double kMinNormal = std::numeric_limits<double>::min();
constexpr std::int32_t kInt32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::uint32_t kUint32Max = std::numeric_limits<std::uint32_t>::max();

ordered_json time_of(std::int32_t sec, std::uint32_t nanosec) {
  return {{"sec", sec}, {"nanosec", nanosec}};
}
ordered_json header(std::int32_t sec, std::uint32_t nanosec, const std::string& frame_id) {
  return {{"stamp", time_of(sec, nanosec)}, {"frame_id", frame_id}};
}
ordered_json xyz(double x, double y, double z) {
  return {{"x", x}, {"y", y}, {"z", z}};
}
ordered_json xyzw(double x, double y, double z, double w) {
  return {{"x", x}, {"y", y}, {"z", z}, {"w", w}};
}
ordered_json pose(const ordered_json& position, const ordered_json& orientation) {
  return {{"position", position}, {"orientation", orientation}};
}
ordered_json pair(const char* a, const ordered_json& va, const char* b, const ordered_json& vb) {
  return {{a, va}, {b, vb}};
}

// More than 1,000 bytes of UTF-8: 2-, 3- and 4-byte sequences, so that a serializer counting characters
// or UTF-16 units instead of bytes is caught.
std::string long_utf8() {
  std::string s;
  while (s.size() < 1000) s += "Kranführer→Greifer 🤖 ";
  return s;
}

struct Case {
  std::string name;
  std::string type;
  ordered_json value;
};

std::vector<Case> cases() {
  std::vector<Case> c;
  const std::string utf8 = long_utf8();
  const std::string ascii_long(5000, 'x');

  c.push_back({"time zero", "builtin_interfaces/msg/Time", time_of(0, 0)});
  c.push_back({"time extremes", "builtin_interfaces/msg/Time", time_of(kInt32Min, kUint32Max)});
  c.push_back({"time int32 max", "builtin_interfaces/msg/Time", time_of(2147483647, 999999999)});

  c.push_back({"header empty frame", "std_msgs/msg/Header", header(0, 0, "")});
  c.push_back({"header long ascii frame", "std_msgs/msg/Header", header(1700000000, 5, ascii_long)});
  c.push_back({"header long utf-8 frame", "std_msgs/msg/Header", header(-1, 999999999, utf8)});

  c.push_back({"vector3 nan and infinities", "geometry_msgs/msg/Vector3", xyz(kNaN, kInf, -kInf)});
  c.push_back(
      {"vector3 denormals and signed zero", "geometry_msgs/msg/Vector3", xyz(kDenormMin, -0.0, -kDenormMin * 7)});
  c.push_back({"point extremes", "geometry_msgs/msg/Point", xyz(kMax, -kMax, kMinNormal)});
  c.push_back({"quaternion identity", "geometry_msgs/msg/Quaternion", xyzw(0, 0, 0, 1)});
  c.push_back({"quaternion nan", "geometry_msgs/msg/Quaternion", xyzw(0.5, -0.5, kNaN, 0.5)});
  c.push_back({"pose", "geometry_msgs/msg/Pose", pose(xyz(3.55, 1.75, 1.2), xyzw(0.1, 0.2, 0.3, 0.927))});

  // Frame ids of 0 to 8 bytes move every double after them through each alignment the encoder must pad.
  for (const std::string frame : {"", "a", "ab", "abc", "abcd", "abcde", "abcdef", "abcdefg", "tool0_fts"}) {
    c.push_back({"pose stamped frame '" + frame + "'", "geometry_msgs/msg/PoseStamped",
                 pair("header", header(12, 34, frame), "pose",
                      pose(xyz(1, -2, 3), xyzw(0, 0, 0.7071067811865476, 0.7071067811865476)))});
    c.push_back({"wrench stamped frame '" + frame + "'", "geometry_msgs/msg/WrenchStamped",
                 pair("header", header(1700000000, 123456789, frame), "wrench",
                      pair("force", xyz(12.5, -3.25, 981.0), "torque", xyz(0.125, 0, -1e-9)))});
  }
  c.push_back({"twist", "geometry_msgs/msg/Twist", pair("linear", xyz(0.1, 0, -0.1), "angular", xyz(0, 0, 0.5))});
  c.push_back({"twist stamped extremes", "geometry_msgs/msg/TwistStamped",
               pair("header", header(kInt32Min, kUint32Max, utf8), "twist",
                    pair("linear", xyz(kNaN, kInf, -kInf), "angular", xyz(kDenormMin, -0.0, kMax)))});
  c.push_back({"wrench", "geometry_msgs/msg/Wrench",
               pair("force", xyz(-kInf, kNaN, 1), "torque", xyz(kMinNormal / 2, 0, -0.0))});
  c.push_back({"wrench stamped extremes", "geometry_msgs/msg/WrenchStamped",
               pair("header", header(kInt32Min, kUint32Max, ""), "wrench",
                    pair("force", xyz(kNaN, -kInf, kInf), "torque", xyz(-kDenormMin, kMax, -kMax)))});

  const auto joint_state = [](const ordered_json& hdr, std::vector<std::string> names, std::vector<double> position,
                              std::vector<double> velocity, std::vector<double> effort) {
    return ordered_json{
        {"header", hdr}, {"name", names}, {"position", position}, {"velocity", velocity}, {"effort", effort}};
  };
  c.push_back({"joint state empty", "sensor_msgs/msg/JointState", joint_state(header(0, 0, ""), {}, {}, {}, {})});
  c.push_back({"joint state ur5e", "sensor_msgs/msg/JointState",
               joint_state(header(1700000000, 1, "base_link"),
                           {"shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint",
                            "wrist_2_joint", "wrist_3_joint"},
                           {0, -1.5707963267948966, 1.5707963267948966, -3.14159, 0.001, 6.283185307179586}, {},
                           {kNaN, kInf, -kInf, kDenormMin, -0.0, 150})});
  c.push_back({"joint state uneven lengths and empty names", "sensor_msgs/msg/JointState",
               joint_state(header(5, 6, "é"), {"", "ä", "", "joint"}, {1}, {1, 2, 3}, {})});
  {
    std::vector<std::string> names;
    std::vector<double> position, velocity, effort;
    for (int i = 0; i < 10000; ++i) {
      names.push_back("joint_" + std::to_string(i) + std::string(static_cast<std::size_t>(i % 4), '_'));
      position.push_back(i * 0.001 - 5);
      velocity.push_back(i % 97 == 0 ? kNaN : -i * 1e-3);
      effort.push_back(i % 101 == 0 ? kDenormMin * i : i * 1e300);
    }
    c.push_back({"joint state 10000 joints", "sensor_msgs/msg/JointState",
                 joint_state(header(1700000000, 999999999, "world"), names, position, velocity, effort)});
  }

  const auto image = [](const ordered_json& hdr, std::uint32_t height, std::uint32_t width, const std::string& encoding,
                        int is_bigendian, std::uint32_t step, const std::vector<std::uint8_t>& data) {
    return ordered_json{
        {"header", hdr}, {"height", height}, {"width", width}, {"encoding", encoding}, {"is_bigendian", is_bigendian},
        {"step", step},  {"data", data}};
  };
  c.push_back({"image empty", "sensor_msgs/msg/Image", image(header(0, 0, ""), 0, 0, "", 0, 0, {})});
  {
    std::vector<std::uint8_t> data(640u * 480u * 3u);
    for (std::size_t i = 0; i < data.size(); ++i) data[i] = static_cast<std::uint8_t>((i * 31u + i / 1920u) & 0xffu);
    c.push_back({"image 640x480 rgb8", "sensor_msgs/msg/Image",
                 image(header(1700000000, 42, "camera_optical_frame"), 480, 640, "rgb8", 0, 1920, data)});
  }
  c.push_back({"image odd sizes big endian", "sensor_msgs/msg/Image",
               image(header(kInt32Min, kUint32Max, "cam"), 1, 3, "mono16", 1, 7, {1, 2, 3, 4, 5, 6, 255})});
  const auto roi = [](std::uint32_t x, std::uint32_t y, std::uint32_t h, std::uint32_t w, bool rectify) {
    return ordered_json{{"x_offset", x}, {"y_offset", y}, {"height", h}, {"width", w}, {"do_rectify", rectify}};
  };
  const auto camera_info = [](const ordered_json& hdr, std::uint32_t height, std::uint32_t width,
                              const std::string& model, const std::vector<double>& d, std::uint32_t binning,
                              const ordered_json& region) {
    const double fx = 1000.0, fy = 1005.5, cx = 639.5, cy = 359.25;
    return ordered_json{{"header", hdr},
                        {"height", height},
                        {"width", width},
                        {"distortion_model", model},
                        {"d", d},
                        {"k", {fx, 0.0, cx, 0.0, fy, cy, 0.0, 0.0, 1.0}},
                        {"r", {1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0}},
                        {"p", {fx, 0.0, cx, 0.0, 0.0, fy, cy, 0.0, 0.0, 0.0, 1.0, 0.0}},
                        {"binning_x", binning},
                        {"binning_y", binning},
                        {"roi", region}};
  };
  // As cell_sim publishes it beside each image, and as the ros2_bridge reads a driver's.
  c.push_back({"camera info plumb_bob 1280x720", "sensor_msgs/msg/CameraInfo",
               camera_info(header(1700000000, 7, "camera"), 720, 1280, "plumb_bob", {-0.2, 0.05, 0.001, -0.001, 0.0},
                           0, roi(0, 0, 0, 0, false))});
  c.push_back({"camera info no distortion binned with a region", "sensor_msgs/msg/CameraInfo",
               camera_info(header(0, 0, ""), 360, 640, "", {}, 2, roi(10, 20, 300, 400, true))});
  return c;
}

// ---- output -------------------------------------------------------------------------------------------

std::string hex(const std::vector<unsigned char>& bytes) {
  static const char* digits = "0123456789abcdef";
  std::string s;
  s.reserve(bytes.size() * 2);
  for (unsigned char b : bytes) {
    s += digits[b >> 4];
    s += digits[b & 0xf];
  }
  return s;
}

// JSON cannot hold NaN or infinities; compare.js turns these tags back into numbers.
void tag_non_finite(ordered_json& j) {
  if (j.is_number_float() && !std::isfinite(j.get<double>())) {
    const double v = j.get<double>();
    j = ordered_json{{"$f64", std::isnan(v) ? "NaN" : (v > 0 ? "Infinity" : "-Infinity")}};
  } else if (j.is_structured()) {
    for (auto& element : j) tag_non_finite(element);
  }
}

// The ROS 2 name of an idlc type, read from its descriptor as a ROS 2 node would read it off the wire:
// "geometry_msgs::msg::dds_::WrenchStamped_" -> "geometry_msgs/msg/WrenchStamped". A type named against
// rmw_cyclonedds's convention gets a name compare.js finds no ROS 2 definition for.
std::string ros2_name(const dds_topic_descriptor_t& desc) {
  std::string name = desc.m_typename;
  for (const std::string from : {"::dds_::", "::"}) {
    for (auto at = name.find(from); at != std::string::npos; at = name.find(from)) name.replace(at, from.size(), "/");
  }
  if (!name.empty() && name.back() == '_') name.pop_back();
  return name;
}

struct IdlType {
  const dds_topic_descriptor_t* desc;
  std::vector<unsigned char> (CycloneSerializer::*serialize)(const dds_topic_descriptor_t&, const ordered_json&);
};

template <typename T>
IdlType idl(const dds_topic_descriptor_t& desc) {
  return {&desc, &CycloneSerializer::serialize<T>};
}

std::vector<unsigned char> serialize(CycloneSerializer& cyclone, const Case& c) {
  static const IdlType kTypes[] = {
      idl<builtin_interfaces_msg_dds__Time_>(builtin_interfaces_msg_dds__Time__desc),
      idl<std_msgs_msg_dds__Header_>(std_msgs_msg_dds__Header__desc),
      idl<geometry_msgs_msg_dds__Vector3_>(geometry_msgs_msg_dds__Vector3__desc),
      idl<geometry_msgs_msg_dds__Point_>(geometry_msgs_msg_dds__Point__desc),
      idl<geometry_msgs_msg_dds__Quaternion_>(geometry_msgs_msg_dds__Quaternion__desc),
      idl<geometry_msgs_msg_dds__Pose_>(geometry_msgs_msg_dds__Pose__desc),
      idl<geometry_msgs_msg_dds__PoseStamped_>(geometry_msgs_msg_dds__PoseStamped__desc),
      idl<geometry_msgs_msg_dds__Twist_>(geometry_msgs_msg_dds__Twist__desc),
      idl<geometry_msgs_msg_dds__TwistStamped_>(geometry_msgs_msg_dds__TwistStamped__desc),
      idl<geometry_msgs_msg_dds__Wrench_>(geometry_msgs_msg_dds__Wrench__desc),
      idl<geometry_msgs_msg_dds__WrenchStamped_>(geometry_msgs_msg_dds__WrenchStamped__desc),
      idl<sensor_msgs_msg_dds__JointState_>(sensor_msgs_msg_dds__JointState__desc),
      idl<sensor_msgs_msg_dds__Image_>(sensor_msgs_msg_dds__Image__desc),
      idl<sensor_msgs_msg_dds__RegionOfInterest_>(sensor_msgs_msg_dds__RegionOfInterest__desc),
      idl<sensor_msgs_msg_dds__CameraInfo_>(sensor_msgs_msg_dds__CameraInfo__desc),
  };
  for (const IdlType& t : kTypes) {
    if (ros2_name(*t.desc) == c.type) return (cyclone.*t.serialize)(*t.desc, c.value);
  }
  throw std::runtime_error("no IDL type named " + c.type + " in idl/ros2");
}

}  // namespace

int main() {
  try {
    CycloneSerializer cyclone;
    ordered_json out{{"cases", ordered_json::array()}};
    for (Case& c : cases()) {
      const std::vector<unsigned char> bytes = serialize(cyclone, c);
      tag_non_finite(c.value);
      out["cases"].push_back({{"name", c.name}, {"type", c.type}, {"value", std::move(c.value)}, {"cdr", hex(bytes)}});
    }
    std::cout << out.dump() << '\n';
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "ros2_cdr_samples: " << e.what() << '\n';
    return 1;
  }
}
