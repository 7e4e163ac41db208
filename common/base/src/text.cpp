#include "rigger/base/text.hpp"

#include <cstdio>

namespace rigger {

std::string number_text(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

}  // namespace rigger
