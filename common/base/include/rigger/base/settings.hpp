#pragma once
/// @file
/// Settings declared once. A service lists its configuration keys in one table: each entry has the key
/// (its unit in its name: `_s`, `_ms`, `_mm`, `_hz`…), its type, default, inclusive range and a
/// description for people, and is bound to a member of the service's settings struct. read_settings()
/// reads a Config into the struct with Config's own errors (file, JSON pointer, what was expected), then
/// refuses unknown keys; describe() hands the same facts to docs/config-reference.md
/// (tools/update-config-reference).
///
///   struct EchoSettings {
///     unsigned max_payload_bytes{};
///     std::chrono::milliseconds period{};
///   };
///   const SettingsTable<EchoSettings>& echo_settings() {
///     using S = EchoSettings;
///     static const SettingsTable<S> table{
///         setting<S>("max_payload_bytes", 1024u, {0u, 65536u}, &S::max_payload_bytes, "the largest payload"),
///         setting<S>("period_ms", 100u, {1u, 1000u}, &S::period, "how often"),  // a duration member
///     };
///     return table;
///   }
///   const EchoSettings s = read_settings(config, echo_settings());  // throws ConfigError
///
/// A value is stored by a member pointer or by a callable `void(S&, const T&)` (or `void(S&, const T&,
/// const Config&)`, to find a file the way config_path() does). A std::chrono::duration
/// member takes the value in the unit of the key's name (`_s`, `_ms`, `_us`, `_ns`). Tables are built
/// once at setup; reading is setup-time only (everything throws ConfigError).

#include <chrono>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rigger/base/config.hpp"
#include "rigger/base/install.hpp"

namespace rigger {

/// One setting as people read it in the reference; every field is text.
struct SettingInfo {
  std::string key;
  std::string type;          ///< "boolean", "integer", "number", "string", "path", "enum", "array of …"
  std::string default_text;  ///< as written in JSON: `5`, `"normal"`, `true`
  std::string range_text;    ///< `[0.01, 600]`, the enum's values, or empty
  std::string unit;          ///< from the key's name (unit_of_key), or empty
  std::string description;
};

/// The unit a key names by its suffix: "_s" → "s", "_ms" → "ms", "_us" → "µs", "_mm" → "mm", "_deg" →
/// "deg", "_hz" → "Hz", "_bytes" → "bytes", "_mib" → "MiB", "_per_s" → "1/s"…; "" when it names none.
std::string unit_of_key(const std::string& key);

/// An inclusive range [lo, hi].
template <typename T>
struct Range {
  T lo;
  T hi;
};

/// A default known only when the settings are read (one an environment variable may change, the
/// service's id); `text` is what the reference prints for it.
template <typename T>
struct RuntimeDefault {
  std::function<T()> value;
  std::string text;
};

/// One configuration key of a settings struct S: what the reference says about it, and how it is read.
template <typename S>
class Setting {
 public:
  using Reader = std::function<void(const Config&, S&)>;
  Setting(SettingInfo info, Reader read) : info_(std::move(info)), read_(std::move(read)) {}

  const SettingInfo& info() const { return info_; }
  /// Reads the key (or applies its default) into `settings`. @throws ConfigError.
  void read(const Config& config, S& settings) const { read_(config, settings); }

 private:
  SettingInfo info_;
  Reader read_;
};

/// A service's settings, in the order the reference lists them.
template <typename S>
using SettingsTable = std::vector<Setting<S>>;

namespace settings_detail {

template <typename T>
struct Value {
  using type = T;
};
template <>
struct Value<const char*> {
  using type = std::string;
};
/// What a key holds: a string literal default is a std::string setting.
template <typename T>
using ValueOf = typename Value<std::decay_t<T>>::type;

template <typename T>
std::string type_name() {
  if constexpr (std::is_same_v<T, bool>)
    return "boolean";
  else if constexpr (std::is_integral_v<T>)
    return "integer";
  else if constexpr (std::is_floating_point_v<T>)
    return "number";
  else if constexpr (std::is_same_v<T, std::string>)
    return "string";
  else if constexpr (std::is_same_v<T, std::vector<std::string>>)
    return "array of strings";
  else
    return "array of numbers";
}

std::string json_text(bool value);
std::string json_text(long long value);
std::string json_text(unsigned long long value);
std::string json_text(double value);
std::string json_text(const std::string& value);
std::string json_text(const std::vector<std::string>& value);
std::string json_text(const std::vector<double>& value);

template <typename T>
std::string value_text(const T& value) {
  if constexpr (std::is_same_v<T, bool>)
    return json_text(value);
  else if constexpr (std::is_integral_v<T> && std::is_signed_v<T>)
    return json_text(static_cast<long long>(value));
  else if constexpr (std::is_integral_v<T>)
    return json_text(static_cast<unsigned long long>(value));
  else if constexpr (std::is_floating_point_v<T>)
    return json_text(static_cast<double>(value));
  else
    return json_text(value);
}

/// `value`, given in `unit` ("s", "ms", "µs", "ns"), as the duration D. @throws std::logic_error when the
/// key names no time unit (a table's mistake, found by the service's tests).
template <typename D, typename T>
D duration_in(T value, const std::string& unit, const std::string& key) {
  using std::chrono::duration;
  using std::chrono::duration_cast;
  using Rep = std::conditional_t<std::is_floating_point_v<T>, double, long long>;
  const auto v = static_cast<Rep>(value);
  if (unit == "s") return duration_cast<D>(duration<Rep>(v));
  if (unit == "ms") return duration_cast<D>(duration<Rep, std::milli>(v));
  if (unit == "µs") return duration_cast<D>(duration<Rep, std::micro>(v));
  if (unit == "ns") return duration_cast<D>(duration<Rep, std::nano>(v));
  throw std::logic_error("setting " + key + " is bound to a duration but its name gives no time unit");
}

template <typename T>
struct IsDuration : std::false_type {};
template <typename R, typename P>
struct IsDuration<std::chrono::duration<R, P>> : std::true_type {};

/// Stores `value` into `settings` by a member pointer (converting a duration from the key's unit) or a
/// callable (given the Config too when it takes it, e.g. to find a file beside the configuration's).
template <typename S, typename T, typename Set>
void store(S& settings, const T& value, const Set& set, const std::string& unit, const std::string& key,
           const Config& config) {
  if constexpr (std::is_invocable_v<const Set&, S&, const T&, const Config&>) {
    set(settings, value, config);
  } else if constexpr (std::is_member_object_pointer_v<Set>) {
    auto& member = settings.*set;
    using M = std::decay_t<decltype(member)>;
    if constexpr (IsDuration<M>::value)
      member = duration_in<M>(value, unit, key);
    else
      member = static_cast<M>(value);
  } else {
    set(settings, value);
  }
}

template <typename T>
std::string range_text(const Range<T>& range) {
  return "[" + value_text(range.lo) + ", " + value_text(range.hi) + "]";
}

template <typename T>
RuntimeDefault<T> constant(T value) {
  const std::string text = value_text(value);
  return {[value = std::move(value)] { return value; }, text};
}

/// A setting read by `get(config, key, fallback)`.
template <typename S, typename T, typename Get, typename Set>
Setting<S> make(std::string key, RuntimeDefault<T> fallback, std::string range_text, Get get, Set set,
                std::string description) {
  SettingInfo info{
      key, type_name<T>(), std::move(fallback.text), std::move(range_text), unit_of_key(key), std::move(description)};
  const std::string unit = info.unit;
  return Setting<S>(std::move(info),
                    [key, unit, value = std::move(fallback.value), get, set](const Config& config, S& settings) {
                      store(settings, get(config, key, value()), set, unit, key, config);
                    });
}

template <typename T>
auto any_value() {
  return [](const Config& c, const std::string& k, const T& f) { return c.get<T>(k, f); };
}

template <typename T>
auto within(Range<T> range) {
  return [range](const Config& c, const std::string& k, const T& f) {
    return c.get_in_range<T>(k, f, range.lo, range.hi);
  };
}

}  // namespace settings_detail

/// A key without bounds: a boolean, a string, a number, an array of strings or numbers. T is the type
/// of `fallback` (a string literal: std::string).
template <typename S, typename F, typename Set>
Setting<S> setting(std::string key, F fallback, Set set, std::string description) {
  using T = settings_detail::ValueOf<F>;
  return settings_detail::make<S, T>(std::move(key), settings_detail::constant<T>(std::move(fallback)), "",
                                     settings_detail::any_value<T>(), set, std::move(description));
}

/// A key without bounds whose default is known only when the settings are read.
template <typename S, typename T, typename Set>
Setting<S> setting(std::string key, RuntimeDefault<T> fallback, Set set, std::string description) {
  return settings_detail::make<S, T>(std::move(key), std::move(fallback), "", settings_detail::any_value<T>(), set,
                                     std::move(description));
}

/// A number within `range` (inclusive): int, unsigned or double, the type of `fallback`.
template <typename S, typename T, typename Set>
Setting<S> setting(std::string key, T fallback, Range<T> range, Set set, std::string description) {
  return settings_detail::make<S, T>(std::move(key), settings_detail::constant(fallback),
                                     settings_detail::range_text(range), settings_detail::within(range), set,
                                     std::move(description));
}

/// A number within `range` whose default is known only when the settings are read.
template <typename S, typename T, typename Set>
Setting<S> setting(std::string key, RuntimeDefault<T> fallback, Range<T> range, Set set, std::string description) {
  return settings_detail::make<S, T>(std::move(key), std::move(fallback), settings_detail::range_text(range),
                                     settings_detail::within(range), set, std::move(description));
}

/// One of named values: the key holds a name of `options`, the struct the value it maps to (an enum
/// class, a bool, a string…). `fallback` must be one of the options' values.
template <typename S, typename E, typename Set>
Setting<S> choice(std::string key, E fallback, std::vector<std::pair<std::string, E>> options, Set set,
                  std::string description) {
  std::vector<std::string> names;
  std::string fallback_name;
  for (const auto& [name, value] : options) {
    names.push_back(name);
    if (value == fallback && fallback_name.empty()) fallback_name = name;
  }
  if (fallback_name.empty()) throw std::logic_error("setting " + key + ": its default is none of its options");
  std::string values;
  for (const auto& name : names) values += (values.empty() ? "" : ", ") + settings_detail::json_text(name);
  SettingInfo info{key,    "enum",           settings_detail::json_text(fallback_name),
                   values, unit_of_key(key), std::move(description)};
  return Setting<S>(std::move(info), [key, fallback_name, names, options, set](const Config& config, S& settings) {
    const std::string name = config.get_enum(key, fallback_name, names);
    for (const auto& [option, value] : options)
      if (option == name) return settings_detail::store(settings, value, set, "", key, config);
  });
}

/// A file named by the key, found as config_path() finds it (rigger/base/install.hpp): relative to the
/// configuration file, then the data folder; `fallback` relative to the data folder. The value is a
/// std::filesystem::path. @throws ConfigError (when read) when the file is not found.
template <typename S, typename Set>
Setting<S> path_setting(std::string key, std::string fallback, Set set, std::string description) {
  SettingInfo info{key, "path", settings_detail::json_text(fallback), "", "", std::move(description)};
  return Setting<S>(std::move(info), [key, fallback, set](const Config& config, S& settings) {
    settings_detail::store(settings, config_path(config, key, fallback), set, "", key, config);
  });
}

/// A key the service reads itself: an object or array of its own form (rule objects, behaviours by skill
/// name), or a value without a default. `type`, `default_text` and `range_text` are what the reference
/// prints; `read(config, key, settings)` reads it with Config's readers (and their errors).
template <typename S, typename Read>
Setting<S> own_setting(std::string key, std::string type, std::string default_text, std::string range_text, Read read,
                       std::string description) {
  SettingInfo info{
      key, std::move(type), std::move(default_text), std::move(range_text), unit_of_key(key), std::move(description)};
  return Setting<S>(std::move(info), [key, read](const Config& config, S& settings) { read(config, key, settings); });
}

/// `inner`, read from the object `parent` of the configuration (`{"plc": {"port": 1502}}`; absent: every
/// key of it takes its default). The reference lists it as `parent/key`; a key without a unit of its own
/// takes the parent's (`reconnect_backoff_ms/min`). A duration member needs the unit in the inner key's
/// name: bind one under a unit-named parent with a callable.
template <typename S>
Setting<S> nested(const std::string& parent, Setting<S> inner) {
  SettingInfo info = inner.info();
  info.key = parent + "/" + info.key;
  if (info.unit.empty()) info.unit = unit_of_key(parent);
  return Setting<S>(std::move(info), [parent, inner = std::move(inner)](const Config& config, S& settings) {
    inner.read(config.child_or_empty(parent), settings);
  });
}

/// Reads every setting of `table` (a default for each absent key) into `settings`; finish() is left to
/// the caller, for a service that reads more of the file itself. @throws ConfigError.
template <typename S>
void read_into(const Config& config, const SettingsTable<S>& table, S& settings) {
  for (const auto& s : table) s.read(config, settings);
}

/// Reads every setting of `table` into a value-initialized S, then config.finish() (unknown keys are
/// refused). @throws ConfigError naming the file, the key's JSON pointer and what was expected.
template <typename S>
S read_settings(const Config& config, const SettingsTable<S>& table) {
  S settings{};
  read_into(config, table, settings);
  config.finish();
  return settings;
}

/// The table as people read it.
template <typename S>
std::vector<SettingInfo> describe(const SettingsTable<S>& table) {
  std::vector<SettingInfo> out;
  for (const auto& s : table) out.push_back(s.info());
  return out;
}

/// A Markdown table of `settings`: key | type | default | range | unit | description.
std::string settings_markdown(const std::vector<SettingInfo>& settings);

}  // namespace rigger
