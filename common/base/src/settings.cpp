#include "rigger/base/settings.hpp"

#include <nlohmann/json.hpp>

#include "rigger/base/text.hpp"

namespace rigger {

std::string unit_of_key(const std::string& key) {
  // Longest suffixes first: "_per_s" before "_s", "_radps" before "_ps"-less ones.
  static const std::vector<std::pair<std::string, std::string>> kSuffixes{
      {"_per_s", "1/s"}, {"_radps", "rad/s"}, {"_mps", "m/s"}, {"_bytes", "bytes"}, {"_mib", "MiB"}, {"_deg", "deg"},
      {"_rad", "rad"},   {"_kg", "kg"},       {"_hz", "Hz"},   {"_nm", "N·m"},      {"_ms", "ms"},   {"_us", "µs"},
      {"_ns", "ns"},     {"_mm", "mm"},       {"_px", "px"},   {"_s", "s"},         {"_m", "m"},     {"_n", "N"}};
  for (const auto& [suffix, unit] : kSuffixes)
    if (key.size() > suffix.size() && key.compare(key.size() - suffix.size(), suffix.size(), suffix) == 0) return unit;
  return "";
}

namespace settings_detail {

std::string json_text(bool value) {
  return value ? "true" : "false";
}
std::string json_text(long long value) {
  return std::to_string(value);
}
std::string json_text(unsigned long long value) {
  return std::to_string(value);
}
std::string json_text(double value) {
  return number_text(value);
}
std::string json_text(const std::string& value) {
  return nlohmann::json(value).dump();
}
std::string json_text(const std::vector<std::string>& value) {
  return nlohmann::json(value).dump();
}
std::string json_text(const std::vector<double>& value) {
  std::string out;
  for (double v : value) out += (out.empty() ? "" : ", ") + number_text(v);
  return "[" + out + "]";
}

}  // namespace settings_detail

namespace {

// A table cell: code where it is a value, and no character that would end the cell or the row.
std::string cell(const std::string& text, bool code) {
  std::string out;
  for (char c : text) {
    if (c == '|')
      out += "\\|";
    else if (c == '\n')
      out += ' ';
    else
      out += c;
  }
  if (out.empty()) return "";
  return code ? "`" + out + "`" : out;
}

}  // namespace

std::string settings_markdown(const std::vector<SettingInfo>& settings) {
  std::string out = "| key | type | default | range | unit | description |\n|---|---|---|---|---|---|\n";
  for (const auto& s : settings) {
    out += "| " + cell(s.key, true) + " | " + cell(s.type, false) + " | " + cell(s.default_text, true) + " | " +
           cell(s.range_text, true) + " | " + cell(s.unit, false) + " | " + cell(s.description, false) + " |\n";
  }
  return out;
}

}  // namespace rigger
