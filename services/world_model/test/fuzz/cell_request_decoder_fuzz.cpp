// libFuzzer target: any bytes become a CellRequest sample (any op value, null strings, the fixture cell with
// one value replaced at a JSON pointer, or any text), handled by a CellKeeper on the fixture cell (history in
// memory). It must never crash or throw; every reply has a code and, refused, a message; a refused request
// leaves the running revision and the history as they were; a reply's result_json is JSON.
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <iterator>

#include "cell_keeper.hpp"
#include "fuzz_input.hpp"
#include "rigger/world_protocol/cell_protocol.hpp"

namespace {

using namespace rigger::world;
using json = nlohmann::json;

const std::string kFixture = std::string(RIGGER_SOURCE_DIR) + "/services/world_model/test/data/cell_fixture.json";

const std::string& fixture_text() {
  static const std::string text = [] {
    std::ifstream in(kFixture, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }();
  return text;
}

CellKeeper& keeper() {
  static CellKeeper k({kFixture, "", 8}, Stamp(std::chrono::seconds(1000)));
  return k;
}

// The fixture with one value (found by walking the document with the fuzzer's choices) replaced.
std::string edited_fixture(FuzzedDataProvider& in) {
  json doc = json::parse(fixture_text());
  json* at = &doc;
  for (int depth = 0; depth < 6 && (at->is_object() || at->is_array()) && !at->empty() && in.ConsumeBool(); ++depth) {
    const std::size_t i = in.ConsumeIntegralInRange<std::size_t>(0, at->size() - 1);
    at = at->is_array() ? &(*at)[i] : &std::next(at->begin(), static_cast<std::ptrdiff_t>(i)).value();
  }
  switch (in.ConsumeIntegralInRange<int>(0, 4)) {
    case 0:
      *at = fuzz::any_double(in) == 0.0 ? json(0.0) : json(in.ConsumeIntegral<int>());
      break;
    case 1:
      *at = fuzz::any_id(in);
      break;
    case 2:
      *at = nullptr;
      break;
    case 3:
      *at = json::array();
      break;
    default:
      *at = in.ConsumeBool();
      break;
  }
  return doc.dump();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzedDataProvider in(data, size);
  const std::string client = in.ConsumeRandomLengthString(40), who = in.ConsumeRandomLengthString(300),
                    comment = in.ConsumeRandomLengthString(100);
  std::string text;
  switch (in.ConsumeIntegralInRange<int>(0, 2)) {
    case 0:
      text = fixture_text();
      break;
    case 1:
      text = edited_fixture(in);
      break;
    default:
      text = in.ConsumeRandomLengthString(4096);
      break;
  }
  rigger_world_CellRequest w{};
  w.client_id = in.ConsumeBool() ? nullptr : const_cast<char*>(client.c_str());
  w.cell_json = in.ConsumeBool() ? nullptr : const_cast<char*>(text.c_str());
  w.who = in.ConsumeBool() ? nullptr : const_cast<char*>(who.c_str());
  w.comment = const_cast<char*>(comment.c_str());
  w.request_id = in.ConsumeIntegral<std::uint64_t>();
  w.revision = in.ConsumeBool() ? in.ConsumeIntegralInRange<std::uint64_t>(0, 12) : in.ConsumeIntegral<std::uint64_t>();
  w.dry_run = in.ConsumeBool();
  w.op = static_cast<rigger_world_CellOp>(in.ConsumeBool() ? in.ConsumeIntegralInRange<int>(0, 3)
                                                           : in.ConsumeIntegral<int>());

  CellKeeper& k = keeper();
  const std::uint64_t running = k.running().record.revision;
  const std::size_t kept = k.history().revisions().size();
  const CellOutcome out = k.handle(rigger::world_protocol::from_wire(w), {}, Stamp(std::chrono::seconds(2000)));
  if (out.reply.code.empty() || (!out.reply.ok && out.reply.message.empty())) __builtin_trap();
  if (!out.revision && (k.running().record.revision != running || k.history().revisions().size() != kept))
    __builtin_trap();
  if (out.revision && out.reply.cell_revision != k.running().record.revision) __builtin_trap();
  if (!out.reply.result_json.empty()) (void)json::parse(out.reply.result_json);  // throws (and fails) if not JSON
  return 0;
}
