#pragma once
/// @file
/// Numbers in messages people read: "1 s", "0.1 m", "2.5 N" — not std::to_string's "1.000000".

#include <string>

namespace rigger {

/// `value` with at most 6 significant digits and no trailing zeros (printf's %g): 1 → "1",
/// 0.1 → "0.1", 1200 → "1200", 3.14159265 → "3.14159"; NaN and infinities as "nan", "inf", "-inf".
std::string number_text(double value);

}  // namespace rigger
