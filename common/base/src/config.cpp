#include "rigger/base/config.hpp"

#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <sstream>

#include "rigger/base/bounded_json.hpp"

namespace rigger {
namespace {

std::string type_name(const nlohmann::json& j) {
  if (j.is_string()) return "string " + j.dump();
  if (j.is_boolean()) return std::string("boolean ") + (j.get<bool>() ? "true" : "false");
  if (j.is_number_integer()) return "integer " + j.dump();
  if (j.is_number()) return "number " + j.dump();
  if (j.is_array()) return "an array";
  if (j.is_object()) return "an object";
  return "null";
}

std::string escape_pointer_token(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

// Converts `j` to T or explains what was expected; one overload set per supported type.
template <typename T>
struct Convert;

template <>
struct Convert<bool> {
  static const char* expected() { return "a boolean"; }
  static bool ok(const nlohmann::json& j) { return j.is_boolean(); }
};
template <>
struct Convert<std::string> {
  static const char* expected() { return "a string"; }
  static bool ok(const nlohmann::json& j) { return j.is_string(); }
};
template <>
struct Convert<double> {
  static const char* expected() { return "a number"; }
  static bool ok(const nlohmann::json& j) { return j.is_number() && std::isfinite(j.get<double>()); }
};
template <typename I>
struct ConvertInt {
  static const char* expected() { return "an integer"; }
  static bool ok(const nlohmann::json& j) {
    if (j.is_number_unsigned()) return j.get<std::uint64_t>() <= static_cast<std::uint64_t>(std::numeric_limits<I>::max());
    if (j.is_number_integer()) {
      const auto v = j.get<std::int64_t>();
      return v >= static_cast<std::int64_t>(std::numeric_limits<I>::min()) &&
             (v < 0 || static_cast<std::uint64_t>(v) <= static_cast<std::uint64_t>(std::numeric_limits<I>::max()));
    }
    return false;
  }
};
template <>
struct Convert<int> : ConvertInt<int> {};
template <>
struct Convert<unsigned> : ConvertInt<unsigned> {
  static const char* expected() { return "a non-negative integer"; }
};
template <>
struct Convert<std::int64_t> : ConvertInt<std::int64_t> {};
template <>
struct Convert<std::uint16_t> : ConvertInt<std::uint16_t> {
  static const char* expected() { return "an integer in [0, 65535]"; }
};
template <>
struct Convert<std::vector<double>> {
  static const char* expected() { return "an array of numbers"; }
  static bool ok(const nlohmann::json& j) {
    if (!j.is_array()) return false;
    for (const auto& e : j)
      if (!Convert<double>::ok(e)) return false;
    return true;
  }
};
template <>
struct Convert<std::vector<std::string>> {
  static const char* expected() { return "an array of strings"; }
  static bool ok(const nlohmann::json& j) {
    if (!j.is_array()) return false;
    for (const auto& e : j)
      if (!e.is_string()) return false;
    return true;
  }
};

}  // namespace

ConfigError::ConfigError(const std::string& file, const std::string& pointer, const std::string& problem)
    : std::runtime_error("configuration error in " + file + (pointer.empty() ? "" : " at " + pointer) + ": " +
                         problem),
      file_(file),
      pointer_(pointer) {}

Config::Config(std::shared_ptr<Document> doc, const nlohmann::json* node, std::string pointer)
    : doc_(std::move(doc)), node_(node), pointer_(std::move(pointer)) {
  doc_->read_keys[pointer_];  // registers this object, so finish() checks its keys
}

Config Config::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw ConfigError(path, "", "cannot open the file (does it exist and is it readable?)");
  in.close();
  return from_parsed(parse_json_file_bounded(path, kConfigLimits), path);
}

Config Config::parse(const std::string& text, const std::string& origin) {
  return from_parsed(parse_json_bounded(text, kConfigLimits), origin);
}

Config Config::from_parsed(JsonParseResult parsed, const std::string& origin) {
  if (!parsed.ok()) {
    const JsonParseError& e = *parsed.error;
    throw ConfigError(origin, e.pointer,
                      "not valid JSON at line " + std::to_string(e.line) + ", column " + std::to_string(e.column) +
                          ": " + e.message);
  }
  auto doc = std::make_shared<Document>();
  doc->file = origin;
  doc->root = std::move(parsed.value);
  if (!doc->root.is_object()) throw ConfigError(origin, "", "expected a JSON object at the top, got " + type_name(doc->root));
  const nlohmann::json* root = &doc->root;
  return Config(std::move(doc), root, "");
}

Config Config::empty(const std::string& origin) { return parse("{}", origin); }

const std::string& Config::file() const { return doc_->file; }

bool Config::has(const std::string& key) const { return node_->contains(key); }

std::string Config::key_pointer(const std::string& key) const { return pointer_ + "/" + escape_pointer_token(key); }

void Config::fail(const std::string& key, const std::string& problem) const {
  throw ConfigError(doc_->file, key.empty() ? pointer_ : key_pointer(key), problem);
}

const nlohmann::json& Config::at(const std::string& key) const {
  auto it = node_->find(key);
  if (it == node_->end()) fail(key, "missing required key");
  doc_->read_keys[pointer_].insert(key);
  return *it;
}

template <typename T>
T Config::get(const std::string& key) const {
  const auto& j = at(key);
  if (!Convert<T>::ok(j)) fail(key, std::string("expected ") + Convert<T>::expected() + ", got " + type_name(j));
  return j.get<T>();
}

template <typename T>
T Config::get(const std::string& key, const T& fallback) const {
  if (!has(key)) return fallback;
  return get<T>(key);
}

template <typename T>
T Config::get_in_range(const std::string& key, T fallback, T lo, T hi) const {
  const T v = get<T>(key, fallback);
  if (v < lo || v > hi) {
    std::ostringstream os;
    os << "expected a value in [" << lo << ", " << hi << "], got " << v;
    fail(key, os.str());
  }
  return v;
}

std::string Config::get_enum(const std::string& key, const std::string& fallback,
                             const std::vector<std::string>& allowed) const {
  const auto v = get<std::string>(key, fallback);
  for (const auto& a : allowed)
    if (a == v) return v;
  std::string list;
  for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
  fail(key, "expected one of " + list + ", got \"" + v + "\"");
}

Config Config::child(const std::string& key) const {
  const auto& j = at(key);
  if (!j.is_object()) fail(key, "expected an object, got " + type_name(j));
  return Config(doc_, &j, key_pointer(key));
}

Config Config::child_or_empty(const std::string& key) const {
  if (has(key)) return child(key);
  static const nlohmann::json kEmpty = nlohmann::json::object();
  return Config(doc_, &kEmpty, key_pointer(key));
}

std::vector<Config> Config::children(const std::string& key) const {
  std::vector<Config> out;
  if (!has(key)) return out;
  const auto& j = at(key);
  if (!j.is_array()) fail(key, "expected an array of objects, got " + type_name(j));
  for (std::size_t i = 0; i < j.size(); ++i) {
    const auto p = key_pointer(key) + "/" + std::to_string(i);
    if (!j[i].is_object()) throw ConfigError(doc_->file, p, "expected an object, got " + type_name(j[i]));
    out.push_back(Config(doc_, &j[i], p));
  }
  return out;
}

const nlohmann::json& Config::raw(const std::string& key) const { return at(key); }

void Config::finish() const {
  std::string unknown;
  std::string first_pointer;
  for (const auto& [pointer, read] : doc_->read_keys) {
    const auto ptr = pointer.empty() ? nlohmann::json::json_pointer() : nlohmann::json::json_pointer(pointer);
    if (!doc_->root.contains(ptr)) continue;  // child_or_empty() of an absent key
    const auto& obj = doc_->root.at(ptr);
    for (const auto& item : obj.items()) {
      if (read.count(item.key())) continue;
      const auto p = pointer + "/" + escape_pointer_token(item.key());
      if (first_pointer.empty()) first_pointer = p;
      unknown += (unknown.empty() ? "" : ", ") + p;
    }
  }
  if (!unknown.empty())
    throw ConfigError(doc_->file, first_pointer, "unknown key(s) " + unknown + " (misspelt? see the service's documented keys)");
}

#define RIGGER_CONFIG_INSTANTIATE(T)                                       \
  template T Config::get<T>(const std::string&) const;                     \
  template T Config::get<T>(const std::string&, const T&) const;
RIGGER_CONFIG_INSTANTIATE(bool)
RIGGER_CONFIG_INSTANTIATE(int)
RIGGER_CONFIG_INSTANTIATE(unsigned)
RIGGER_CONFIG_INSTANTIATE(std::int64_t)
RIGGER_CONFIG_INSTANTIATE(std::uint16_t)
RIGGER_CONFIG_INSTANTIATE(double)
RIGGER_CONFIG_INSTANTIATE(std::string)
RIGGER_CONFIG_INSTANTIATE(std::vector<double>)
RIGGER_CONFIG_INSTANTIATE(std::vector<std::string>)
#undef RIGGER_CONFIG_INSTANTIATE
template double Config::get_in_range<double>(const std::string&, double, double, double) const;
template int Config::get_in_range<int>(const std::string&, int, int, int) const;
template unsigned Config::get_in_range<unsigned>(const std::string&, unsigned, unsigned, unsigned) const;

}  // namespace rigger
