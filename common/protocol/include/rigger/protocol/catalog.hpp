#pragma once
/// @file
/// Every topic of rigger, type-erased, for tools that work on any topic and for the generated reference
/// (docs/topics.md).

#include <string>
#include <vector>

#include <dds/dds.h>

#include "rigger/protocol/topic.hpp"

namespace rigger::protocol {

/// One topic of the catalog.
struct TopicInfo {
  std::string area;                          ///< "task", "crane", … (the area header it is declared in)
  std::string name;                          ///< e.g. rigger/task/recipe
  std::string idl_type;                      ///< the module-qualified IDL type, "rigger::task::Recipe"
  const dds_topic_descriptor_t* descriptor;  ///< idlc's type descriptor
  QosProfile qos;
  std::string key, writers, readers, summary, qos_note;
};

/// Every topic, in the order of docs/topics.md. Thread-safe (built once).
const std::vector<TopicInfo>& catalog();
/// The topic called `name`, or nullptr.
const TopicInfo* find_topic(const std::string& name);
/// Topic names close to `name` (edit distance or same last part), best first, at most `max`.
std::vector<std::string> close_topic_names(const std::string& name, std::size_t max = 3);

/// docs/topics.md: the QoS profiles and a table of topics per area (rigger-topic-catalog prints it).
std::string catalog_markdown();

}  // namespace rigger::protocol
