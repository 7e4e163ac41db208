#include "rigger/safety/safe_stop.hpp"

#include <algorithm>

#include "rigger/dds/conversions.hpp"
#include "rigger/dds/qos.hpp"

namespace rigger::safety {

const std::vector<std::string>& stoppable_resources() {
  static const std::vector<std::string> resources = {"robot", "crane", "gripper", "admittance"};
  return resources;
}

SafeStopListener::SafeStopListener(const dds::Participant& participant, dds::EventLoop& loop,
                                   std::vector<std::string> resources, Handler on_change)
    : resources_(std::move(resources)),
      on_change_(std::move(on_change)),
      reader_(participant, protocol::safety::kStop, dds::qos::state_changes()) {
  loop.on_data(reader_, [this] { on_data(); });
}

void SafeStopListener::on_data() {
  reader_.take([this](const rigger_safety_SafeStop& s, const dds_sample_info_t& info) {
    if (!info.valid_data) return;  // a writer that left does not reset a latched stop
    const std::string resource = dds::to_string(s.resource);
    if (std::find(resources_.begin(), resources_.end(), resource) == resources_.end()) return;
    StopState state{s.active, dds::to_string(s.source), dds::to_string(s.reason)};
    StopState& held = stops_[resource];
    if (held.active == state.active && !state.active) return;  // a reset of what was not stopped
    held = state;
    if (on_change_) on_change_(resource, held);
  });
}

bool SafeStopListener::active() const {
  return std::any_of(stops_.begin(), stops_.end(), [](const auto& s) { return s.second.active; });
}

std::string SafeStopListener::describe() const {
  std::string out;
  for (const auto& [resource, s] : stops_) {
    if (!s.active) continue;
    if (!out.empty()) out += "; ";
    out += resource + " (by " + s.source + ": " + s.reason + ")";
  }
  return out;
}

SafeStopWriter::SafeStopWriter(const dds::Participant& participant)
    : writer_(participant, protocol::safety::kStop) {}

dds_return_t SafeStopWriter::command(const std::string& resource, bool active, const std::string& source,
                                     const std::string& reason) const {
  rigger_safety_SafeStop s{};
  s.resource = dds::wire_string(resource);
  s.active = active;
  s.source = dds::wire_string(source);
  s.reason = dds::wire_string(reason);
  s.stamp = dds::wire_now();
  return writer_.write(s);
}

}  // namespace rigger::safety
