#include "rigger/cell_config/json_text.hpp"

#include <cmath>

#include "rigger/base/bounded_json.hpp"

namespace rigger::cell {
namespace {
constexpr std::size_t kMaxDescribedChars = 60;
}  // namespace

std::string join_pointer(const std::string& base, std::string_view key) { return base + "/" + escape_pointer_token(key); }

std::string describe_json(const nlohmann::json& value) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > kMaxDescribedChars) text = text.substr(0, kMaxDescribedChars) + "...";
  if (value.is_number_float() && !std::isfinite(value.get<double>())) text = std::to_string(value.get<double>());
  return std::string(value.type_name()) + " " + text;
}

bool is_valid_identifier(std::string_view text) {
  if (text.empty() || text.size() > 64) return false;
  for (const char c : text) {
    const bool ok =
        (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '.' || c == '-';
    if (!ok) return false;
  }
  return true;
}

}  // namespace rigger::cell
