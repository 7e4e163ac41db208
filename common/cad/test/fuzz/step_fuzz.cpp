// Any bytes as a STEP file: read in this process (the fuzzer is the crash detector, so no child), with
// small bounds, then classified. A CadError is the expected answer to junk; anything else is a bug.
#include "rigger/cad/features.hpp"
#include "rigger/cad/model.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rigger::cad::ReadLimits limits;
  limits.isolate = false;
  limits.max_bytes = 1 << 20;
  limits.max_assembly_depth = 8;
  try {
    const rigger::cad::Model model =
        rigger::cad::read_step_bytes(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz", limits);
    rigger::cad::classify(model);
  } catch (const rigger::cad::CadError&) {
  }
  return 0;
}
