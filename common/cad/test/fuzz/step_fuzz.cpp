// Any bytes through rigger's STEP boundary, as the service uses it: read in the bounded child process,
// then classified. A CadError is the expected answer to junk; a crash of this process is a bug.
// OCCT 7.6's reader itself crashes within seconds of fuzzing (e.g. test/data/occt_segv_face_bound.step,
// a null dereference in StepShape_FaceBound::Bound): that is why it runs in a child, and why this target
// fuzzes the boundary (the child's coverage does not guide the fuzzer) rather than OCCT in process.
#include "rigger/cad/features.hpp"
#include "rigger/cad/model.hpp"

#include <cstddef>
#include <cstdint>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  rigger::cad::ReadLimits limits;
  limits.timeout = std::chrono::milliseconds(5000);
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
