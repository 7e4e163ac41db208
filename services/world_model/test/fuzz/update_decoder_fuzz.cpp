// libFuzzer target: any bytes become an EntityUpdate sample (null strings, NaNs, non-unit quaternions,
// bad stamps, odd JSON included). Decoding and applying it must never crash or throw, and a refused or
// rejected update must leave the store exactly as it was.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "wire_decoding.hpp"
#include "world_frame_tree.hpp"
#include "world_json.hpp"

namespace {

nlohmann::json snapshot(const rigger::world::WorldStore& store) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [id, e] : store.entities()) out[id] = rigger::world::entity_to_json(e);
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rigger::world;
  FuzzedDataProvider in(data, size);
  const std::string source = fuzz::any_id(in), entity = fuzz::any_id(in), parent = fuzz::any_id(in);
  const std::string attributes = in.ConsumeBool() ? std::string() : in.ConsumeRandomLengthString(400);
  rigger_world_EntityUpdate w{};
  w.source = in.ConsumeBool() ? nullptr : const_cast<char*>(source.c_str());
  w.entity_id = in.ConsumeBool() ? nullptr : const_cast<char*>(entity.c_str());
  w.parent_frame = in.ConsumeBool() ? nullptr : const_cast<char*>(parent.c_str());
  w.attributes_json = const_cast<char*>(attributes.c_str());
  w.seq = in.ConsumeIntegral<std::uint64_t>();
  w.has_pose = in.ConsumeBool();
  w.pose.pose.position = {fuzz::any_double(in), fuzz::any_double(in), fuzz::any_double(in)};
  w.pose.pose.orientation = {fuzz::any_double(in), fuzz::any_double(in), fuzz::any_double(in), fuzz::any_double(in)};
  w.has_covariance = in.ConsumeBool();
  for (double& c : w.pose.covariance) c = in.ConsumeBool() ? fuzz::any_double(in) : 0.0;
  w.has_quality = in.ConsumeBool();
  w.quality = fuzz::any_double(in);
  w.has_localized = in.ConsumeBool();
  w.localized = in.ConsumeBool();
  w.stamp.sec = in.ConsumeIntegral<std::int32_t>();
  w.stamp.nanosec = in.ConsumeIntegral<std::uint32_t>();

  const auto decoded = decode_update(w);
  if (std::holds_alternative<DecodeError>(decoded)) {
    if (std::get<DecodeError>(decoded).code.empty()) __builtin_trap();  // every refusal has a code
    return 0;
  }
  WorldStore store = fuzz::fixture_store();
  const nlohmann::json before = snapshot(store);
  const UpdateResult result = store.apply(std::get<EntityUpdate>(decoded));
  if (!result.accepted()) {
    if (result.reason.empty() || snapshot(store) != before) __builtin_trap();  // unchanged, and says why
    return 0;
  }
  // An accepted update keeps the tree a tree.
  for (const auto& [id, e] : store.entities()) {
    if (pose_in_frame(store.entities(), id, "world").status == QueryStatus::kFrameCycle) __builtin_trap();
  }
  return 0;
}
