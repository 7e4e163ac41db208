#pragma once
/// @file
/// A topic declared once: its name, its IDL type (the template parameter, so a reader of the wrong type
/// does not compile), its QoS profile, its key, who writes it and who reads it. Every service, riggerctl,
/// the tests and the benchmarks open topics through these descriptors (one header per area under
/// rigger/protocol/); docs/topics.md is generated from them (rigger-topic-catalog).
///
///   dds::Writer<rigger_task_Recipe> recipes(participant, protocol::task::kRecipe);      // its profile
///   dds::Reader<rigger_task_NodeStatus> nodes(participant, protocol::task::kNodeStatus,
///                                             dds::qos::state_changes());             // another QoS
///
/// Header-only (rigger_protocol_topics, which rigger_dds links); the catalog of every topic is
/// rigger/protocol/catalog.hpp (rigger_protocol).

namespace rigger::protocol {

/// The named QoS profiles of rigger/dds/qos.hpp (dds::qos::of() makes one).
enum class QosProfile { kCommands, kEvents, kState, kAnnouncements, kSensorStream, kSetpoints };

/// "commands", "events", "state", "announcements", "sensor_stream", "setpoints".
constexpr const char* to_string(QosProfile profile) {
  switch (profile) {
    case QosProfile::kCommands:
      return "commands";
    case QosProfile::kEvents:
      return "events";
    case QosProfile::kState:
      return "state";
    case QosProfile::kAnnouncements:
      return "announcements";
    case QosProfile::kSensorStream:
      return "sensor_stream";
    case QosProfile::kSetpoints:
      return "setpoints";
  }
  return "?";
}

/// One topic. Literal type: descriptors are `inline constexpr` in the area headers.
template <typename T>
struct Topic {
  using Type = T;
  const char* name;      ///< "rigger/<area>/<what>"
  QosProfile qos;        ///< the profile writers and (unless noted) readers use
  const char* key;       ///< the key fields, "" for a keyless topic
  const char* writers;   ///< who writes it (text for people: docs/topics.md, riggerctl topics)
  const char* readers;   ///< who reads it
  const char* summary;   ///< what a sample carries
  const char* qos_note;  ///< a reader that departs from the profile, and why ("" when none)
};

}  // namespace rigger::protocol
