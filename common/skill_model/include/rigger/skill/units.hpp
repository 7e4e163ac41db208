#pragma once
/// SI units of skill parameters and the few non-SI units a recipe may write a quantity in.
///
/// Every parameter is declared in an SI unit ("m", "s", "N", "N/s", "Nm", "m/s", "rad", "Hz", …,
/// or "" for dimensionless). A recipe gives either a plain number, meaning that unit, or a
/// quantity object {"value": 300, "unit": "ms"} which is converted to the declared unit when the
/// two are commensurable ("ms" → "s", "mm" → "m", "deg" → "rad", "kN" → "N", …).

#include <optional>
#include <string_view>
#include <vector>

namespace rigger::skill {

/// True when `unit` is one of the SI units parameters may be declared in ("" included).
bool is_si_unit(std::string_view unit);

/// The SI units parameters may be declared in, for error messages and documentation.
const std::vector<std::string_view>& si_units();

/// Factor f such that value_in_si = value_in_from * f, when `from` converts to the SI unit `si`
/// (identity when equal). std::nullopt when they are not commensurable or `from` is unknown.
std::optional<double> conversion_factor(std::string_view from, std::string_view si);

}  // namespace rigger::skill
