#include "jog_input.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>

namespace rigger::ctl::jog {
namespace {

constexpr const char* kAxisNames[6] = {"x", "y", "z", "rx", "ry", "rz"};

Key key_of(char c) {
  switch (c) {
    case 'w':
    case 'W':
      return Key::kXPlus;
    case 's':
    case 'S':
      return Key::kXMinus;
    case 'a':
    case 'A':
      return Key::kYPlus;
    case 'd':
    case 'D':
      return Key::kYMinus;
    case 'r':
    case 'R':
      return Key::kZPlus;
    case 'f':
    case 'F':
      return Key::kZMinus;
    case ' ':
      return Key::kStop;
    case 'q':
    case 'Q':
    case 0x03:
    case 0x04:
      return Key::kQuit;
    default:
      return Key::kOther;
  }
}

double parse_double(const std::string& text, const std::string& what) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0' || !std::isfinite(v))
    throw std::invalid_argument(what + ": '" + text + "' is not a number");
  return v;
}

double parse_duration(std::string text, const std::string& where) {
  double scale = 1.0;
  if (text.size() > 2 && text.compare(text.size() - 2, 2, "ms") == 0) {
    scale = 1e-3;
    text.resize(text.size() - 2);
  } else if (text.size() > 1 && text.back() == 's') {
    text.pop_back();
  }
  const double d = parse_double(text, where + " duration") * scale;
  if (d < 0 || d > 3600) throw std::invalid_argument(where + ": duration must be within [0, 3600] s");
  return d;
}

}  // namespace

std::vector<Key> decode_keys(std::string& buffer) {
  std::vector<Key> keys;
  std::size_t i = 0;
  while (i < buffer.size()) {
    if (buffer[i] != '\x1b') {
      keys.push_back(key_of(buffer[i]));
      ++i;
      continue;
    }
    // ESC [ A..D (or ESC O A..D in application cursor mode): arrows. A lone ESC waits for more bytes.
    if (i + 1 >= buffer.size()) break;
    if (buffer[i + 1] != '[' && buffer[i + 1] != 'O') {
      keys.push_back(Key::kOther);
      ++i;
      continue;
    }
    if (i + 2 >= buffer.size()) break;
    switch (buffer[i + 2]) {
      case 'A':
        keys.push_back(Key::kXPlus);
        break;
      case 'B':
        keys.push_back(Key::kXMinus);
        break;
      case 'C':
        keys.push_back(Key::kYMinus);
        break;
      case 'D':
        keys.push_back(Key::kYPlus);
        break;
      default:
        keys.push_back(Key::kOther);
        break;
    }
    i += 3;
  }
  buffer.erase(0, i);
  return keys;
}

Twist key_twist(Key key, double speed) {
  Twist t{};
  switch (key) {
    case Key::kXPlus:
      t[0] = speed;
      break;
    case Key::kXMinus:
      t[0] = -speed;
      break;
    case Key::kYPlus:
      t[1] = speed;
      break;
    case Key::kYMinus:
      t[1] = -speed;
      break;
    case Key::kZPlus:
      t[2] = speed;
      break;
    case Key::kZMinus:
      t[2] = -speed;
      break;
    case Key::kStop:
    case Key::kQuit:
    case Key::kOther:
      break;
  }
  return t;
}

double normalise_axis(std::int16_t raw, double deadband) {
  const double v = std::clamp(static_cast<double>(raw) / 32767.0, -1.0, 1.0);
  const double magnitude = std::abs(v);
  if (magnitude <= deadband || deadband >= 1.0) return 0.0;
  return std::copysign((magnitude - deadband) / (1.0 - deadband), v);
}

AxisMap parse_axis_map(const std::string& text) {
  AxisMap map;
  std::size_t start = 0;
  for (int k = 0; k < 3; ++k) {
    const auto end = text.find(',', start);
    if ((k < 2) == (end == std::string::npos))
      throw std::invalid_argument("axis map '" + text + "': expected three axes [+-]N,[+-]N,[+-]N (x, y, z)");
    std::string item = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    map.sign[k] = 1.0;
    if (!item.empty() && (item[0] == '-' || item[0] == '+')) {
      map.sign[k] = item[0] == '-' ? -1.0 : 1.0;
      item.erase(0, 1);
    }
    if (item.empty() || item.size() > 2 || item.find_first_not_of("0123456789") != std::string::npos)
      throw std::invalid_argument("axis map '" + text + "': '" + item + "' is not an axis number");
    map.index[k] = std::stoi(item);
    start = end + 1;
  }
  return map;
}

Twist stick_twist(const std::vector<double>& axes, const AxisMap& map, double speed) {
  Twist t{};
  double norm2 = 0;
  for (int k = 0; k < 3; ++k) {
    const auto i = static_cast<std::size_t>(map.index[k]);
    t[k] = i < axes.size() ? map.sign[k] * std::clamp(axes[i], -1.0, 1.0) * speed : 0.0;
    norm2 += t[k] * t[k];
  }
  const double norm = std::sqrt(norm2);
  if (norm > speed && norm > 0)
    for (int k = 0; k < 3; ++k) t[k] *= speed / norm;
  return t;
}

std::vector<ScriptStep> parse_script(const std::string& text, double max_linear_mps, double max_angular_radps) {
  std::vector<ScriptStep> steps;
  std::size_t start = 0;
  int number = 0;
  for (;;) {
    const auto end = text.find(',', start);
    const std::string item = text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    const std::string where = "script step " + std::to_string(++number) + " '" + item + "'";
    ScriptStep step;
    const auto colon = item.find(':');
    const std::string terms = item.substr(0, colon);
    if (colon != std::string::npos) step.duration_s = parse_duration(item.substr(colon + 1), where);
    if (terms == "stop") {
      steps.push_back(step);
    } else {
      if (colon == std::string::npos) throw std::invalid_argument(where + ": expected TERMS:DURATION, e.g. x+0.05:2s");
      if (terms.empty()) throw std::invalid_argument(where + ": no axis, expected e.g. x+0.05");
      std::size_t i = 0;
      while (i < terms.size()) {
        int axis = -1;
        for (int a = 5; a >= 0 && axis < 0; --a) {  // two-letter names first
          const std::string name = kAxisNames[a];
          if (terms.compare(i, name.size(), name) == 0) {
            axis = a;
            i += name.size();
          }
        }
        if (axis < 0)
          throw std::invalid_argument(where + ": expected an axis x, y, z, rx, ry or rz at '" + terms.substr(i) + "'");
        if (i >= terms.size() || (terms[i] != '+' && terms[i] != '-'))
          throw std::invalid_argument(where + ": expected + or - after axis " + kAxisNames[axis]);
        const auto next = terms.find_first_not_of("0123456789.", i + 1);
        const std::string value = terms.substr(i, next == std::string::npos ? std::string::npos : next - i);
        step.twist[axis] = parse_double(value, where);
        const double limit = axis < 3 ? max_linear_mps : max_angular_radps;
        if (std::abs(step.twist[axis]) > limit) {
          char buffer[96];
          std::snprintf(buffer, sizeof buffer, ": |%s| = %g is above the limit %g %s", kAxisNames[axis],
                        std::abs(step.twist[axis]), limit, axis < 3 ? "m/s" : "rad/s");
          throw std::invalid_argument(where + buffer);
        }
        i = next == std::string::npos ? terms.size() : next;
      }
      steps.push_back(step);
    }
    if (end == std::string::npos) break;
    start = end + 1;
  }
  double linear2 = 0;
  for (const auto& s : steps) {
    linear2 = s.twist[0] * s.twist[0] + s.twist[1] * s.twist[1] + s.twist[2] * s.twist[2];
    if (std::sqrt(linear2) > max_linear_mps * (1 + 1e-9))
      throw std::invalid_argument("script '" + text + "': a step's linear speed is above the limit");
  }
  return steps;
}

std::optional<Twist> script_twist_at(const std::vector<ScriptStep>& script, double t_s) {
  double end = 0;
  for (const auto& step : script) {
    end += step.duration_s;
    if (t_s < end) return step.twist;
  }
  return std::nullopt;
}

std::string describe(const Twist& twist) {
  std::string out;
  for (int a = 0; a < 6; ++a) {
    if (twist[a] == 0.0) continue;
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%s%s%+g", out.empty() ? "" : " ", kAxisNames[a], twist[a]);
    out += buffer;
  }
  return out.empty() ? "stop" : out;
}

}  // namespace rigger::ctl::jog
