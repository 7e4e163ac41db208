#pragma once
/// @file
/// The common interface of monitors: sample-driven fault detectors that never report success.
///
/// A monitor has no clock of its own. The host feeds it wrench samples (on_wrench) and the current
/// time (on_time, for timers and sensor staleness) on one clock: wall-clock time since the Unix epoch,
/// the clock of the samples' header stamps. A Verdict is either "ok" (nothing detected *yet*; never a
/// success) or "fired" with a code, a message and the value that fired. Once fired, a monitor stays
/// fired (the verdict is latched) until reset.
///
/// Common behaviour of monitors that read the wrench (uses_wrench()):
/// - no sample within `max_sample_age_s` (after reset, or after the last accepted sample) fires
///   SENSOR_STALE, whether noticed by on_time or by a late sample;
/// - a sample with NaN or infinity fires SENSOR_INVALID;
/// - a sample not newer than the previous one (duplicate or backwards stamp) is rejected: ignored and
///   counted (rejected_samples()), the verdict stays as it was.
///
/// Thread safety: none; the host's work loop owns its monitors.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace rigger::monitor {

/// Wall-clock time since the Unix epoch (the type of `rigger::WallTime`).
using Stamp = std::chrono::system_clock::time_point;

/// Codes a fired verdict carries (the FAILURE code the controller receives).
inline constexpr std::string_view kCodeTimeout = "TIMEOUT";              ///< value: elapsed time, s
inline constexpr std::string_view kCodeForceLimit = "FORCE_LIMIT";       ///< value: filtered force (N) or torque (N m)
inline constexpr std::string_view kCodeYankLimit = "YANK_LIMIT";         ///< value: filtered yank, N/s
inline constexpr std::string_view kCodeSensorStale = "SENSOR_STALE";     ///< value: age of the newest sample, s
inline constexpr std::string_view kCodeSensorInvalid = "SENSOR_INVALID"; ///< value: 0
inline constexpr std::string_view kCodeNotArmed = "NOT_ARMED";           ///< value: 0; reset() has not succeeded

/// What a monitor says about one sample or one point in time.
struct Verdict {
  enum class Kind { kOk, kFired };

  Kind kind = Kind::kOk;
  std::string code;     ///< one of the kCode* strings when fired
  std::string message;  ///< a sentence for people: what, how much, against which limit
  double value = 0.0;   ///< the measured value that fired (unit per code)

  /// True when the monitor detected something (there is no "success").
  bool fired() const { return kind == Kind::kFired; }
  /// Nothing detected yet.
  static Verdict ok() { return Verdict{}; }
  /// A detection with its code, message and value.
  static Verdict fire(std::string_view code, std::string message, double value) {
    return Verdict{Kind::kFired, std::string(code), std::move(message), value};
  }
};

/// The type of a parameter, as named in descriptions: "number", "integer", "boolean", "string", "enum"
/// (the names of rigger::skill::ParamType).
enum class ParamType { kNumber, kInteger, kBoolean, kString, kEnum };
/// "number", "integer", "boolean", "string" or "enum".
std::string_view to_string(ParamType type);

/// One parameter of a monitor: what the recipe validator and the skill library see. Mirrors
/// rigger::skill::ParamSpec field for field.
struct ParamSpec {
  std::string name;
  ParamType type = ParamType::kNumber;
  std::string unit;                            ///< SI unit ("s", "N", "Nm", "N/s", "Hz"); empty when unitless
  std::optional<double> min;                   ///< inclusive bounds for numbers and integers
  std::optional<double> max;
  std::optional<nlohmann::json> default_value;  ///< absent: the parameter is required
  std::vector<std::string> enum_values;        ///< the allowed strings of an enum parameter
  std::string description;
};

/// A monitor's description for the skill library.
struct MonitorDescription {
  std::string name;         ///< the recipe's "monitor" value, e.g. "ForceMonitor"
  std::string description;
  std::vector<ParamSpec> params;
  bool uses_wrench = false;  ///< reads rigger/robot/wrench

  /// `{ "name", "kind": "monitor", "description", "params": [{"name", "type", "unit"?, "min"?, "max"?,
  /// "default"?, "values"? (enum), "description"}], "resources": [] }`, the form of
  /// rigger::skill::to_json(SkillDescription): keys without a value (no unit, no bound, no default
  /// because the parameter is required) are left out.
  nlohmann::json to_json() const;
};

/// Validated parameters with defaults applied.
class ParamValues {
 public:
  /// The value of a number or integer parameter.
  double number(std::string_view name) const;
  /// The value of a string or enum parameter.
  std::string string(std::string_view name) const;
  /// The value of a boolean parameter.
  bool boolean(std::string_view name) const;

  nlohmann::json values = nlohmann::json::object();
};

/// Checks `params` (a JSON object, or null for "all defaults") against `description`: unknown names,
/// types, bounds, enum values, required parameters. Appends one message per problem to `errors`, each
/// starting with the parameter's JSON pointer relative to the params object (e.g. "/dwell_s: ...").
ParamValues validate_params(const MonitorDescription& description, const nlohmann::json& params,
                            std::vector<std::string>& errors);

/// The outcome of Monitor::reset.
struct ParamCheck {
  std::vector<std::string> errors;  ///< empty when the monitor is armed

  /// True when the parameters were valid.
  bool ok() const { return errors.empty(); }
  /// The errors joined by "; " (for a FAILURE message).
  std::string message() const;
};

/// Base of every monitor. Subclasses implement configure/start/sample/tick; the base handles arming,
/// latching, sample ordering, NaN and staleness so that every monitor behaves alike.
class Monitor {
 public:
  virtual ~Monitor() = default;

  /// The monitor's description (static for each monitor type).
  virtual const MonitorDescription& description() const = 0;

  /// Validates `params`, applies defaults and arms the monitor from `start` (forgetting any earlier
  /// run and latched verdict). On errors the monitor is left disarmed. Never throws.
  ParamCheck reset(const nlohmann::json& params, Stamp start);

  /// Feeds one wrench sample: `stamp` (when it was measured), force in N and torque in N m in the
  /// sensor frame. Returns the verdict after this sample (latched once fired; NOT_ARMED when not armed).
  Verdict on_wrench(Stamp stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm);

  /// Tells the monitor the time: fires TIMEOUT or SENSOR_STALE when due.
  Verdict on_time(Stamp now);

  /// The earliest time at which on_time could fire, so the host can sleep until then; std::nullopt
  /// when nothing is pending (not armed, or already fired).
  std::optional<Stamp> next_deadline() const;

  /// True after a successful reset().
  bool armed() const { return armed_; }
  /// True once a verdict fired (it is latched until the next reset()).
  bool fired() const { return latched_.has_value(); }
  /// Samples rejected because their stamp was not newer than the previous sample's.
  std::uint64_t rejected_samples() const { return rejected_samples_; }

 protected:
  /// Reads validated values; returns cross-parameter errors (empty when fine).
  virtual std::vector<std::string> configure(const ParamValues& values) = 0;
  /// Starts a run at `start` (filters cleared).
  virtual void start(Stamp start) = 0;
  /// One valid sample, newer than the previous one; `dt_s` is the spacing to it (nullopt for the first).
  virtual Verdict sample(Stamp stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm,
                         std::optional<double> dt_s);
  /// The time has moved on to `now`.
  virtual Verdict tick(Stamp now);
  /// A monitor-specific deadline (e.g. a timer's end), if any.
  virtual std::optional<Stamp> deadline() const;

 private:
  Verdict latch(Verdict verdict);
  Stamp staleness_reference() const;

  bool armed_ = false;
  std::optional<Verdict> latched_;
  Stamp start_{};
  std::optional<Stamp> last_sample_;
  std::chrono::nanoseconds max_sample_age_{0};
  std::uint64_t rejected_samples_ = 0;
};

/// The "max_sample_age_s" parameter shared by the monitors that read the wrench.
ParamSpec max_sample_age_param();
/// The "cutoff_hz" parameter (first-order filter cut-off) with the given default and upper bound.
ParamSpec cutoff_param(double default_hz, double max_hz);
/// The "axis" parameter: "norm" (vector magnitude) or one sensor axis "x", "y", "z".
ParamSpec axis_param(const std::string& what);

/// Which component of a vector a monitor watches.
enum class Axis { kNorm, kX, kY, kZ };
/// Parses "norm", "x", "y", "z" (validated values only).
Axis axis_from_string(std::string_view text);
/// |v| for kNorm, |v_i| for an axis.
double magnitude(const Eigen::Vector3d& v, Axis axis);
/// "norm", "x", "y" or "z".
std::string_view to_string(Axis axis);

/// Seconds as a double (for messages and parameters).
double to_seconds(std::chrono::nanoseconds d);
/// A duration from seconds, rounded to the nearest nanosecond.
std::chrono::nanoseconds from_seconds(double s);

}  // namespace rigger::monitor
