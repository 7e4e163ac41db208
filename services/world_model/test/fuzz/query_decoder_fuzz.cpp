// libFuzzer target: any bytes become a WorldQuery sample (any kind value, null strings, NaN ages).
// Decoding and answering it from the fixture cell must never crash or throw; a failed answer has a code.
#include <cstddef>
#include <cstdint>

#include "fuzz_input.hpp"
#include "wire_decoding.hpp"
#include "world_answers.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace rigger::world;
  FuzzedDataProvider in(data, size);
  const std::string client = in.ConsumeRandomLengthString(40), entity = fuzz::any_id(in), frame = fuzz::any_id(in),
                    feature = in.ConsumeBool() ? std::string() : fuzz::any_id(in);
  rigger_world_WorldQuery w{};
  w.client_id = in.ConsumeBool() ? nullptr : const_cast<char*>(client.c_str());
  w.entity_id = in.ConsumeBool() ? nullptr : const_cast<char*>(entity.c_str());
  w.frame_id = in.ConsumeBool() ? nullptr : const_cast<char*>(frame.c_str());
  w.feature_id = in.ConsumeBool() ? nullptr : const_cast<char*>(feature.c_str());
  w.request_id = in.ConsumeIntegral<std::uint64_t>();
  w.kind = static_cast<rigger_world_QueryKind>(in.ConsumeBool() ? in.ConsumeIntegralInRange<int>(0, 4)
                                                                : in.ConsumeIntegral<int>());
  w.max_age_s = fuzz::any_double(in);

  const auto decoded = decode_query(w);
  if (const auto* err = std::get_if<DecodeError>(&decoded)) {
    if (err->code.empty()) __builtin_trap();
    return 0;
  }
  const Stamp now(std::chrono::seconds(in.ConsumeIntegralInRange<std::int64_t>(0, 4000000000LL)));
  const QueryAnswer answer = answer_query(fuzz::fixture_store(), std::get<WorldQuery>(decoded), now);
  if (answer.code.empty() || (!answer.ok && answer.message.empty())) __builtin_trap();
  (void)answer.result.dump();  // the reply's JSON must serialise
  return 0;
}
