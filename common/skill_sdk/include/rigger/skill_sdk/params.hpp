#pragma once
/// @file
/// Declaring a skill's parameters by name, one line each, instead of filling ParamSpec's fields by
/// position:
///
///   d.params = {
///       params::pose("goal").doc("Tool goal pose in the robot base frame."),
///       params::number("speed_scale").range(0.01, 1.0).fallback(0.2).doc("Fraction of the maximum speed."),
///       params::number("max_force_n").unit("N").range(1, 500).fallback(80).doc("…"),
///       params::timeout_s(30.0),
///   };
///
/// A parameter without fallback() is required. The result is checked where every description is: when
/// the skill is registered (SkillRegistry::add), with the errors of rigger::skill::parse_description
/// (an unknown unit, min > max, a default out of range).
/// Parameters that several skills share with one meaning are declared once here (timeout_s,
/// speed_scale, object, …), so that their ranges and words cannot drift apart.

#include <initializer_list>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/skill/param_spec.hpp"

namespace rigger::skill_sdk::params {

/// One parameter's declaration under construction; converts to skill::ParamSpec.
class Param {
 public:
  Param(std::string name, skill::ParamType type);

  /// Inclusive bounds: the value (number, integer, each of a number_list), the length (string), the count
  /// (string_list).
  Param& range(double min, double max);
  Param& at_least(double min);
  Param& at_most(double max);
  /// The SI unit of a number or integer ("" = dimensionless); see rigger/skill/units.hpp.
  Param& unit(std::string unit);
  /// The value when a recipe leaves the parameter out; without one the parameter is required.
  Param& fallback(nlohmann::json value);
  /// For people: UIs, `riggerctl skills`, the skill reference.
  Param& doc(std::string text);

  const skill::ParamSpec& spec() const { return spec_; }
  operator skill::ParamSpec() const { return spec_; }  // NOLINT: a Param is written where a ParamSpec goes

 private:
  friend Param choice(std::string name, std::vector<std::string> values);
  skill::ParamSpec spec_;
};

Param number(std::string name);
Param integer(std::string name);
Param boolean(std::string name);
Param text(std::string name);
Param choice(std::string name, std::vector<std::string> values);
Param pose(std::string name);
Param feature(std::string name);
Param string_list(std::string name);
/// An array of numbers in unit(); range() bounds each of them.
Param number_list(std::string name);

// Shared parameters, declared once.

/// "timeout_s" in [0.1, 600] s; `doc` says what runs out (the default text: the skill fails with
/// TIMEOUT after its safe stop).
Param timeout_s(double default_s, std::string doc = "");
/// "speed_scale": fraction of the robot's maximum speed, 0.01–1.
Param speed_scale(double fallback_value = 0.2);
/// A world-model object id: "object", "target", …; required unless `default_id` is given.
Param object(std::string name, std::string doc, std::string default_id = "");

}  // namespace rigger::skill_sdk::params
