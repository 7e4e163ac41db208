#pragma once
/// @file
/// Configuration files are JSON. A Config is a view of one JSON object that remembers which keys were
/// read, so that a typo ("rate_hx") is reported instead of silently ignored. Every error names the
/// file, the JSON pointer of the key, and what was expected.
///
/// Usage (setup time only; everything here throws ConfigError):
///   auto cfg = rigger::Config::load(path);
///   double rate_hz = cfg.get_in_range("rate_hz", 50.0, 1.0, 1000.0);
///   auto plc = cfg.child("plc");
///   std::string host = plc.get<std::string>("host");
///   cfg.finish();  // throws on any key that nobody read

#include <map>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/base/bounded_json.hpp"

namespace rigger {

/// A configuration problem: where (file, JSON pointer) and what was expected.
class ConfigError : public std::runtime_error {
 public:
  ConfigError(const std::string& file, const std::string& pointer, const std::string& problem);
  const std::string& file() const { return file_; }
  const std::string& pointer() const { return pointer_; }

 private:
  std::string file_;
  std::string pointer_;
};

/// A view of one object of a configuration document. Cheap to copy; copies share the read-key record.
class Config {
 public:
  /// Bounds of a configuration file, applied while it is parsed (rigger/base/bounded_json.hpp).
  static constexpr JsonLimits kConfigLimits{1024U * 1024U, 32};

  /// Reads and parses a JSON file. @throws ConfigError when missing, unreadable, larger than 1 MiB, nested
  /// deeper than 32, not JSON (duplicate keys included) or not a JSON object.
  static Config load(const std::string& path);
  /// Parses JSON text; `origin` names it in errors. @throws ConfigError.
  static Config parse(const std::string& text, const std::string& origin);
  /// An empty configuration (all defaults).
  static Config empty(const std::string& origin = "<defaults>");

  const std::string& file() const;
  /// JSON pointer of this object inside the file ("" for the root).
  const std::string& pointer() const { return pointer_; }
  bool has(const std::string& key) const;

  /// The value at `key`, which must be present. T: bool, int, unsigned, int64_t, uint16_t, double,
  /// std::string, std::vector<double>, std::vector<std::string>.
  template <typename T>
  T get(const std::string& key) const;
  /// The value at `key`, or `fallback` when absent.
  template <typename T>
  T get(const std::string& key, const T& fallback) const;
  /// A number within [lo, hi], or `fallback` when absent.
  template <typename T>
  T get_in_range(const std::string& key, T fallback, T lo, T hi) const;
  /// One of `allowed`, or `fallback` when absent.
  std::string get_enum(const std::string& key, const std::string& fallback,
                       const std::vector<std::string>& allowed) const;

  /// The object at `key` (required).
  Config child(const std::string& key) const;
  /// The object at `key`, or an empty object when absent.
  Config child_or_empty(const std::string& key) const;
  /// The array of objects at `key` (empty when absent).
  std::vector<Config> children(const std::string& key) const;
  /// Raw JSON at `key` (marked as read; its inside is the caller's to check).
  const nlohmann::json& raw(const std::string& key) const;

  /// @throws ConfigError naming every key in the document that was never read.
  void finish() const;

  /// Error helper for checks the caller makes itself (e.g. cross-field): "<file> at <pointer>/<key>: <problem>".
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;

 private:
  struct Document {
    std::string file;
    nlohmann::json root;
    std::map<std::string, std::set<std::string>> read_keys;  // object pointer -> keys read
  };
  Config(std::shared_ptr<Document> doc, const nlohmann::json* node, std::string pointer);
  /// The root object of a parse's result. @throws ConfigError for a parse error or a non-object.
  static Config from_parsed(JsonParseResult parsed, const std::string& origin);
  const nlohmann::json& at(const std::string& key) const;
  std::string key_pointer(const std::string& key) const;

  std::shared_ptr<Document> doc_;
  const nlohmann::json* node_;
  std::string pointer_;
};

}  // namespace rigger
