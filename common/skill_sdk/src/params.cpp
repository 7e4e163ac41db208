#include "rigger/skill_sdk/params.hpp"

#include <utility>

namespace rigger::skill_sdk::params {

Param::Param(std::string name, skill::ParamType type) {
  spec_.name = std::move(name);
  spec_.type = type;
}

Param& Param::range(double min, double max) {
  spec_.min = min;
  spec_.max = max;
  return *this;
}

Param& Param::at_least(double min) {
  spec_.min = min;
  return *this;
}

Param& Param::at_most(double max) {
  spec_.max = max;
  return *this;
}

Param& Param::unit(std::string unit) {
  spec_.unit = std::move(unit);
  return *this;
}

Param& Param::fallback(nlohmann::json value) {
  spec_.default_value = std::move(value);
  return *this;
}

Param& Param::doc(std::string text) {
  spec_.description = std::move(text);
  return *this;
}

Param number(std::string name) { return Param(std::move(name), skill::ParamType::kNumber); }
Param integer(std::string name) { return Param(std::move(name), skill::ParamType::kInteger); }
Param boolean(std::string name) { return Param(std::move(name), skill::ParamType::kBoolean); }
Param text(std::string name) { return Param(std::move(name), skill::ParamType::kString); }
Param pose(std::string name) { return Param(std::move(name), skill::ParamType::kPose); }
Param feature(std::string name) { return Param(std::move(name), skill::ParamType::kFeatureRef); }
Param string_list(std::string name) { return Param(std::move(name), skill::ParamType::kStringList); }
Param number_list(std::string name) { return Param(std::move(name), skill::ParamType::kNumberList); }

Param choice(std::string name, std::vector<std::string> values) {
  Param param(std::move(name), skill::ParamType::kEnum);
  param.spec_.enum_values = std::move(values);
  return param;
}

Param timeout_s(double default_s, std::string doc) {
  if (doc.empty()) doc = "The skill fails with TIMEOUT (after its safe stop) when it takes longer.";
  return number("timeout_s").unit("s").range(0.1, 600.0).fallback(default_s).doc(std::move(doc));
}

Param speed_scale(double fallback_value) {
  return number("speed_scale").range(0.01, 1.0).fallback(fallback_value).doc("Fraction of the robot's maximum speed.");
}

Param object(std::string name, std::string doc, std::string default_id) {
  Param param = Param(std::move(name), skill::ParamType::kObjectId).doc(std::move(doc));
  if (!default_id.empty()) param.fallback(std::move(default_id));
  return param;
}

}  // namespace rigger::skill_sdk::params
