#include "monitor.hpp"

#include <cmath>
#include <cstdio>
#include <set>

namespace rigger::monitor {
namespace {

using nlohmann::json;

std::string format_number(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%g", value);
  return buffer;
}

std::string describe(const json& value) {
  std::string text = value.dump(-1, ' ', false, json::error_handler_t::replace);
  if (text.size() > 40) text = text.substr(0, 40) + "...";
  return std::string(value.type_name()) + " " + text;
}

std::string expected_text(const ParamSpec& spec) {
  std::string text;
  switch (spec.type) {
    case ParamType::kNumber:
      text = "a number";
      break;
    case ParamType::kInteger:
      text = "an integer";
      break;
    case ParamType::kBoolean:
      return "true or false";
    case ParamType::kString:
      return "a string";
    case ParamType::kEnum:
      text = "one of";
      for (std::size_t i = 0; i < spec.enum_values.size(); ++i) {
        text += (i == 0 ? " \"" : ", \"") + spec.enum_values[i] + "\"";
      }
      return text;
  }
  if (spec.min && spec.max) {
    text += " in [" + format_number(*spec.min) + ", " + format_number(*spec.max) + "]";
  } else if (spec.min) {
    text += " >= " + format_number(*spec.min);
  } else if (spec.max) {
    text += " <= " + format_number(*spec.max);
  }
  if (!spec.unit.empty()) text += " " + spec.unit;
  return text;
}

bool matches(const ParamSpec& spec, const json& value) {
  switch (spec.type) {
    case ParamType::kNumber:
    case ParamType::kInteger: {
      if (!value.is_number()) return false;
      if (spec.type == ParamType::kInteger && !value.is_number_integer()) return false;
      const double number = value.get<double>();
      if (!std::isfinite(number)) return false;
      if (spec.min && number < *spec.min) return false;
      if (spec.max && number > *spec.max) return false;
      return true;
    }
    case ParamType::kBoolean:
      return value.is_boolean();
    case ParamType::kString:
      return value.is_string();
    case ParamType::kEnum:
      if (!value.is_string()) return false;
      for (const auto& allowed : spec.enum_values) {
        if (value.get<std::string>() == allowed) return true;
      }
      return false;
  }
  return false;
}

}  // namespace

std::string_view to_string(ParamType type) {
  switch (type) {
    case ParamType::kNumber:
      return "number";
    case ParamType::kInteger:
      return "integer";
    case ParamType::kBoolean:
      return "boolean";
    case ParamType::kString:
      return "string";
    case ParamType::kEnum:
      return "enum";
  }
  return "unknown";
}

json MonitorDescription::to_json() const {
  json params_json = json::array();
  for (const ParamSpec& spec : params) {
    json param = {{"name", spec.name}, {"type", std::string(to_string(spec.type))}};
    if (!spec.unit.empty()) param["unit"] = spec.unit;
    if (spec.min) param["min"] = *spec.min;
    if (spec.max) param["max"] = *spec.max;
    if (spec.default_value) param["default"] = *spec.default_value;
    if (spec.type == ParamType::kEnum) param["values"] = spec.enum_values;
    param["description"] = spec.description;
    params_json.push_back(std::move(param));
  }
  return {{"name", name}, {"kind", "monitor"}, {"description", description}, {"params", params_json},
          {"resources", json::array()}};
}

double ParamValues::number(std::string_view name) const { return values.at(std::string(name)).get<double>(); }
std::string ParamValues::string(std::string_view name) const { return values.at(std::string(name)).get<std::string>(); }
bool ParamValues::boolean(std::string_view name) const { return values.at(std::string(name)).get<bool>(); }

ParamValues validate_params(const MonitorDescription& description, const json& params, std::vector<std::string>& errors) {
  ParamValues result;
  if (!params.is_null() && !params.is_object()) {
    errors.push_back("(params): expected an object of parameters, got " + describe(params));
    return result;
  }
  std::set<std::string> known;
  for (const ParamSpec& spec : description.params) known.insert(spec.name);
  if (params.is_object()) {
    for (const auto& item : params.items()) {
      if (known.count(item.key()) == 0) {
        std::string names;
        for (const auto& name : known) names += (names.empty() ? "" : ", ") + name;
        errors.push_back("/" + item.key() + ": unknown parameter of " + description.name + "; expected one of " + names);
      }
    }
  }
  for (const ParamSpec& spec : description.params) {
    const json* value = nullptr;
    if (params.is_object()) {
      const auto it = params.find(spec.name);
      if (it != params.end()) value = &*it;
    }
    if (value == nullptr) {
      if (spec.default_value) {
        result.values[spec.name] = *spec.default_value;
      } else {
        errors.push_back("/" + spec.name + ": required, expected " + expected_text(spec));
      }
      continue;
    }
    if (!matches(spec, *value)) {
      errors.push_back("/" + spec.name + ": expected " + expected_text(spec) + ", got " + describe(*value));
      continue;
    }
    result.values[spec.name] = *value;
  }
  return result;
}

std::string ParamCheck::message() const {
  std::string text;
  for (const auto& error : errors) text += (text.empty() ? "" : "; ") + error;
  return text;
}

ParamCheck Monitor::reset(const json& params, Stamp start_stamp) {
  armed_ = false;
  latched_.reset();
  last_sample_.reset();
  rejected_samples_ = 0;
  ParamCheck check;
  const ParamValues values = validate_params(description(), params, check.errors);
  if (!check.ok()) return check;
  check.errors = configure(values);
  if (!check.ok()) return check;
  if (description().uses_wrench) max_sample_age_ = from_seconds(values.number("max_sample_age_s"));
  start_ = start_stamp;
  start(start_stamp);
  armed_ = true;
  return check;
}

Verdict Monitor::on_wrench(Stamp stamp, const Eigen::Vector3d& force_n, const Eigen::Vector3d& torque_nm) {
  if (!armed_) return Verdict::fire(kCodeNotArmed, description().name + " is not armed (no valid parameters)", 0.0);
  if (latched_) return *latched_;
  if (!description().uses_wrench) return Verdict::ok();
  if (last_sample_ && stamp <= *last_sample_) {
    // A duplicate or a sample from the past (a burst of old samples after a network drop) carries no
    // new information and would make the differentiators divide by zero or a negative interval.
    ++rejected_samples_;
    return Verdict::ok();
  }
  const auto gap = std::chrono::duration_cast<std::chrono::nanoseconds>(stamp - staleness_reference());
  if (gap > max_sample_age_) {
    char text[128];
    std::snprintf(text, sizeof text, "no wrench sample for %.3f s (allowed %.3f s)", to_seconds(gap),
                  to_seconds(max_sample_age_));
    return latch(Verdict::fire(kCodeSensorStale, text, to_seconds(gap)));
  }
  if (!force_n.allFinite() || !torque_nm.allFinite()) {
    return latch(Verdict::fire(kCodeSensorInvalid, "wrench sample contains NaN or infinity", 0.0));
  }
  std::optional<double> dt_s;
  if (last_sample_) dt_s = to_seconds(std::chrono::duration_cast<std::chrono::nanoseconds>(stamp - *last_sample_));
  last_sample_ = stamp;
  return latch(sample(stamp, force_n, torque_nm, dt_s));
}

Verdict Monitor::on_time(Stamp now) {
  if (!armed_) return Verdict::fire(kCodeNotArmed, description().name + " is not armed (no valid parameters)", 0.0);
  if (latched_) return *latched_;
  if (description().uses_wrench) {
    const auto age = std::chrono::duration_cast<std::chrono::nanoseconds>(now - staleness_reference());
    if (age > max_sample_age_) {
      char text[128];
      std::snprintf(text, sizeof text, "no wrench sample for %.3f s (allowed %.3f s)", to_seconds(age),
                    to_seconds(max_sample_age_));
      return latch(Verdict::fire(kCodeSensorStale, text, to_seconds(age)));
    }
  }
  return latch(tick(now));
}

std::optional<Stamp> Monitor::next_deadline() const {
  if (!armed_ || latched_) return std::nullopt;
  std::optional<Stamp> result = deadline();
  if (description().uses_wrench) {
    // Staleness fires once the age exceeds the limit: one nanosecond after reference + max age.
    const Stamp stale_at = staleness_reference() + std::chrono::duration_cast<Stamp::duration>(max_sample_age_) +
                           std::chrono::duration_cast<Stamp::duration>(std::chrono::nanoseconds(1));
    result = result ? std::min(*result, stale_at) : stale_at;
  }
  return result;
}

Verdict Monitor::sample(Stamp, const Eigen::Vector3d&, const Eigen::Vector3d&, std::optional<double>) { return Verdict::ok(); }
Verdict Monitor::tick(Stamp) { return Verdict::ok(); }
std::optional<Stamp> Monitor::deadline() const { return std::nullopt; }

Verdict Monitor::latch(Verdict verdict) {
  if (verdict.fired()) latched_ = verdict;
  return verdict;
}

Stamp Monitor::staleness_reference() const { return last_sample_ ? std::max(*last_sample_, start_) : start_; }

ParamSpec max_sample_age_param() {
  return ParamSpec{"max_sample_age_s", ParamType::kNumber, "s", 0.001, 10.0, json(0.1), {},
                   "Fires SENSOR_STALE when no wrench sample arrives for longer than this."};
}

ParamSpec cutoff_param(double default_hz, double max_hz) {
  return ParamSpec{"cutoff_hz", ParamType::kNumber, "Hz", 0.1, max_hz, json(default_hz), {},
                   "Cut-off frequency of the first-order low-pass filter(s) on the force; lower rejects more noise "
                   "and detects later."};
}

ParamSpec axis_param(const std::string& what) {
  return ParamSpec{"axis", ParamType::kEnum, "", std::nullopt, std::nullopt, json("norm"), {"norm", "x", "y", "z"},
                   "Which " + what + " to compare with the limit: the vector's magnitude (norm) or the absolute value "
                   "of one sensor-frame component."};
}

Axis axis_from_string(std::string_view text) {
  if (text == "x") return Axis::kX;
  if (text == "y") return Axis::kY;
  if (text == "z") return Axis::kZ;
  return Axis::kNorm;
}

double magnitude(const Eigen::Vector3d& v, Axis axis) {
  switch (axis) {
    case Axis::kNorm:
      return v.norm();
    case Axis::kX:
      return std::abs(v.x());
    case Axis::kY:
      return std::abs(v.y());
    case Axis::kZ:
      return std::abs(v.z());
  }
  return v.norm();
}

std::string_view to_string(Axis axis) {
  switch (axis) {
    case Axis::kNorm:
      return "norm";
    case Axis::kX:
      return "x";
    case Axis::kY:
      return "y";
    case Axis::kZ:
      return "z";
  }
  return "norm";
}

double to_seconds(std::chrono::nanoseconds d) { return std::chrono::duration<double>(d).count(); }

std::chrono::nanoseconds from_seconds(double s) {
  return std::chrono::nanoseconds(static_cast<std::int64_t>(std::llround(s * 1e9)));
}

}  // namespace rigger::monitor
