#include "skill_json_util.hpp"

#include <cmath>
#include <cstdio>

namespace rigger::skill {

std::string format_number(double value) {
  if (std::isfinite(value) && std::floor(value) == value && std::abs(value) < 1e15) {
    return std::to_string(static_cast<long long>(value));
  }
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.10g", value);
  return buffer;
}

std::string describe_json(const nlohmann::json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return "null";
    case nlohmann::json::value_t::boolean:
      return std::string("boolean ") + (value.get<bool>() ? "true" : "false");
    case nlohmann::json::value_t::number_integer:
    case nlohmann::json::value_t::number_unsigned:
      return "integer " + value.dump();
    case nlohmann::json::value_t::number_float:
      return "number " + format_number(value.get<double>());
    case nlohmann::json::value_t::string: {
      std::string text = value.dump();
      if (text.size() > 60) {
        text = text.substr(0, 57) + "…\"";
      }
      return "string " + text;
    }
    case nlohmann::json::value_t::object:
      return "object";
    case nlohmann::json::value_t::array:
      return "array of " + std::to_string(value.size()) + (value.size() == 1 ? " item" : " items");
    case nlohmann::json::value_t::binary:
    case nlohmann::json::value_t::discarded:
      break;
  }
  return "invalid value";
}

}  // namespace rigger::skill

namespace rigger::skill::detail {

namespace {
template <typename Items>
std::string join_impl(const Items& items, bool quote) {
  std::string out;
  bool first = true;
  for (const auto& item : items) {
    if (!first) {
      out += ", ";
    }
    first = false;
    if (quote) {
      out += "\"";
    }
    out += item;
    if (quote) {
      out += "\"";
    }
  }
  return out;
}
}  // namespace

std::string join(const std::vector<std::string_view>& items, bool quote) { return join_impl(items, quote); }
std::string join(const std::vector<std::string>& items, bool quote) { return join_impl(items, quote); }

void check_keys(const nlohmann::json& object, const std::string& pointer, std::initializer_list<std::string_view> allowed,
                std::vector<ModelError>& errors) {
  for (const auto& item : object.items()) {
    bool known = false;
    for (const auto key : allowed) {
      known = known || key == item.key();
    }
    if (!known) {
      errors.push_back({pointer + "/" + escape_pointer_token(item.key()),
                        "unknown key \"" + item.key() + "\"; expected one of " +
                            join(std::vector<std::string_view>(allowed), true)});
    }
  }
}

bool is_identifier(std::string_view text, IdentifierStyle style) {
  if (text.empty() || text.size() > 64) {
    return false;
  }
  const char first = text.front();
  if (style == IdentifierStyle::kSnake ? !(first >= 'a' && first <= 'z') : !(first >= 'A' && first <= 'Z')) {
    return false;
  }
  for (const char c : text) {
    const bool lower = c >= 'a' && c <= 'z';
    const bool upper = c >= 'A' && c <= 'Z';
    const bool digit = c >= '0' && c <= '9';
    if (!(lower || digit || c == '_' || (upper && style == IdentifierStyle::kPascal))) {
      return false;
    }
  }
  return true;
}

void read_identifier(const nlohmann::json& object, const char* key, const std::string& pointer, IdentifierStyle style,
                     std::string& out, std::vector<ModelError>& errors) {
  const std::string shape = style == IdentifierStyle::kSnake ? "a snake_case name ([a-z][a-z0-9_]*, at most 64)"
                                                             : "a PascalCase name ([A-Z][A-Za-z0-9_]*, at most 64)";
  if (!object.contains(key)) {
    errors.push_back({pointer, std::string("missing \"") + key + "\": expected " + shape});
    return;
  }
  const auto& value = object[key];
  if (!value.is_string() || !is_identifier(value.get_ref<const std::string&>(), style)) {
    errors.push_back({pointer + "/" + key, "expected " + shape + ", got " + describe_json(value)});
    return;
  }
  out = value.get<std::string>();
}

}  // namespace rigger::skill::detail
