#pragma once
// Internal: validation helpers of the cell file reader (cell_file.cpp, entity_parser.cpp), bound to one
// source name; every failure throws CellFileError naming the file, the JSON pointer and what was expected.

#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "rigger/cell_config/cell_file.hpp"
#include "rigger/cell_config/json_text.hpp"

namespace rigger::cell {

using nlohmann::json;  // private to the reader's sources

// Validation helpers bound to one source name; every failure throws CellFileError.
class Checker {
 public:
  explicit Checker(std::string file) : file_(std::move(file)) {}

  [[noreturn]] void fail(const std::string& pointer, const std::string& expected, const std::string& got = {}) const {
    throw CellFileError(file_, pointer, expected, got);
  }

  // An object whose keys are all in `allowed` ("comment" is always allowed).
  const json& object(const json& value, const std::string& pointer,
                     std::initializer_list<std::string_view> allowed) const {
    if (!value.is_object()) fail(pointer, "an object", describe_json(value));
    for (const auto& item : value.items()) {
      const std::string& key = item.key();
      if (key == "comment") {
        if (!item.value().is_string()) fail(pointer + "/comment", "a string", describe_json(item.value()));
        continue;
      }
      if (std::find(allowed.begin(), allowed.end(), key) == allowed.end()) {
        std::string names;
        for (const auto name : allowed) names += (names.empty() ? "" : ", ") + std::string(name);
        fail(join_pointer(pointer, key), "one of the keys {" + names + ", comment}", "unknown key \"" + key + "\"");
      }
    }
    return value;
  }

  static const json* find(const json& object_value, std::string_view key) {
    const auto it = object_value.find(key);
    return it == object_value.end() ? nullptr : &*it;
  }

  const json& require(const json& object_value, const std::string& pointer, std::string_view key,
                      const std::string& expected) const {
    const json* value = find(object_value, key);
    if (value == nullptr) fail(join_pointer(pointer, key), expected, "nothing (missing key)");
    return *value;
  }

  std::string string(const json& value, const std::string& pointer) const {
    if (!value.is_string()) fail(pointer, "a string", describe_json(value));
    return value.get<std::string>();
  }

  // Ids name entities and features on the wire and in recipes: keep them plain.
  std::string identifier(const json& value, const std::string& pointer) const {
    const std::string text = string(value, pointer);
    if (!is_valid_identifier(text)) {
      fail(pointer, "an identifier of 1 to 64 characters from [A-Za-z0-9_.-]", describe_json(value));
    }
    return text;
  }

  double number(const json& value, const std::string& pointer) const {
    if (!value.is_number()) fail(pointer, "a number", describe_json(value));
    const double number_value = value.get<double>();
    if (!std::isfinite(number_value)) fail(pointer, "a finite number", describe_json(value));
    return number_value;
  }

  double positive(const json& value, const std::string& pointer) const {
    const double number_value = number(value, pointer);
    if (!(number_value > 0.0)) fail(pointer, "a number > 0", describe_json(value));
    return number_value;
  }

  std::int64_t integer(const json& value, const std::string& pointer, std::int64_t min_value,
                       std::int64_t max_value) const {
    const std::string expected = "an integer in [" + std::to_string(min_value) + ", " + std::to_string(max_value) + "]";
    if (!value.is_number_integer()) fail(pointer, expected, describe_json(value));
    if (value.is_number_unsigned()) {
      const auto unsigned_value = value.get<std::uint64_t>();
      if (unsigned_value > static_cast<std::uint64_t>(max_value)) fail(pointer, expected, describe_json(value));
      return static_cast<std::int64_t>(unsigned_value);
    }
    const auto signed_value = value.get<std::int64_t>();
    if (signed_value < min_value || signed_value > max_value) fail(pointer, expected, describe_json(value));
    return signed_value;
  }

  bool boolean(const json& value, const std::string& pointer) const {
    if (!value.is_boolean()) fail(pointer, "true or false", describe_json(value));
    return value.get<bool>();
  }

  std::vector<double> numbers(const json& value, const std::string& pointer, std::initializer_list<std::size_t> lengths,
                              const std::string& expected) const {
    if (!value.is_array() || std::find(lengths.begin(), lengths.end(), value.size()) == lengths.end()) {
      fail(pointer, expected, describe_json(value));
    }
    std::vector<double> result;
    result.reserve(value.size());
    for (std::size_t i = 0; i < value.size(); ++i)
      result.push_back(number(value[i], pointer + "/" + std::to_string(i)));
    return result;
  }

  Eigen::Vector3d vector3(const json& value, const std::string& pointer) const {
    const auto values = numbers(value, pointer, {3}, "an array of 3 numbers");
    return {values[0], values[1], values[2]};
  }

  Eigen::Isometry3d pose(const json& value, const std::string& pointer) const {
    object(value, pointer, {"position_m", "rpy_deg"});
    const Eigen::Vector3d position_m =
        vector3(require(value, pointer, "position_m", "[x, y, z] in metres"), pointer + "/position_m");
    const Eigen::Vector3d rpy_deg =
        vector3(require(value, pointer, "rpy_deg", "[roll, pitch, yaw] in degrees"), pointer + "/rpy_deg");
    return pose_from_position_rpy_deg(position_m, rpy_deg);
  }

  // Attributes are free, but must be plain JSON: no NaN or infinity smuggled in by code.
  void finite_everywhere(const json& value, const std::string& pointer, int depth = 0) const {
    if (depth > kMaxCellFileDepth) fail(pointer, "at most " + std::to_string(kMaxCellFileDepth) + " levels of nesting");
    if (value.is_number_float() && !std::isfinite(value.get<double>()))
      fail(pointer, "a finite number", describe_json(value));
    if (value.is_object()) {
      for (const auto& item : value.items())
        finite_everywhere(item.value(), join_pointer(pointer, item.key()), depth + 1);
    } else if (value.is_array()) {
      for (std::size_t i = 0; i < value.size(); ++i)
        finite_everywhere(value[i], pointer + "/" + std::to_string(i), depth + 1);
    }
  }

 private:
  std::string file_;
};

}  // namespace rigger::cell
