#pragma once
// Reading STEP with OCCT, in this process or in a forked child. Internal to rigger_cad.

#include "rigger/cad/model.hpp"

#include <string>
#include <string_view>

namespace rigger::cad::detail {

struct StepContent {
  TopoDS_Shape shape_m;
  ProductNode product;
};

/// Parses and transfers `bytes` with the XCAF reader in this process (lengths converted to metres).
StepContent read_step_in_process(std::string_view bytes, const std::string& source, const ReadLimits& limits);

/// The same in a forked child with a time and memory limit; the B-rep comes back in OCCT's binary format.
StepContent read_step_isolated(std::string_view bytes, const std::string& source, const ReadLimits& limits);

}  // namespace rigger::cad::detail
