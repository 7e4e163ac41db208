#pragma once
/// @file
/// Pure helpers of `riggerctl jog` (no DDS, no terminal): keys and joystick axes to twists, and the
/// `--script` language. A twist is (x, y, z) in m/s and (rx, ry, rz) in rad/s in the robot's base frame
/// (x forward, y left, z up), the frame admittance_control expects of a joystick reference.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rigger::ctl::jog {

using Twist = std::array<double, 6>;  ///< x, y, z [m/s]; rx, ry, rz [rad/s]

enum class Key { kXPlus, kXMinus, kYPlus, kYMinus, kZPlus, kZMinus, kStop, kQuit, kOther };

/// Takes the complete keys at the front of `buffer` (raw terminal bytes) and leaves an incomplete
/// escape sequence there for the next read. Arrows up/down and W/S: x±; left/right and A/D: y±
/// (left is +y); R/F: z±; space: stop; q, Q, Ctrl-C, Ctrl-D: quit; anything else: kOther.
std::vector<Key> decode_keys(std::string& buffer);

/// The twist a held `key` commands: `speed` [m/s] along its axis; zero for stop, quit and other keys.
Twist key_twist(Key key, double speed);

/// A joystick axis reading (linux/joystick.h, -32767..32767) as -1..1 with a `deadband` (fraction of
/// full scale) cut out without a jump at its edge.
double normalise_axis(std::int16_t raw, double deadband);

/// Which joystick axis drives x, y and z, and with which sign (e.g. "-1,-0,-4": x = -axis 1 (left stick
/// forward), y = -axis 0 (left stick left), z = -axis 4 (right stick up)).
struct AxisMap {
  std::array<int, 3> index{1, 0, 4};
  std::array<double, 3> sign{-1.0, -1.0, -1.0};
};
/// Parses "[+-]N,[+-]N,[+-]N". @throws std::invalid_argument saying what is wrong.
AxisMap parse_axis_map(const std::string& text);

/// The twist for normalised axis values `axes` (index → -1..1; missing axes count as 0): linear only,
/// scaled uniformly so that its norm never exceeds `speed`.
Twist stick_twist(const std::vector<double>& axes, const AxisMap& map, double speed);

/// One step of a script: hold `twist` for `duration_s`.
struct ScriptStep {
  Twist twist{};
  double duration_s = 0.0;
};

/// Parses a script: steps separated by ',', each `TERMS:DURATION` or `stop[:DURATION]`, where TERMS is
/// one or more AXIS SIGN VALUE (axis x, y, z in m/s or rx, ry, rz in rad/s; e.g. "x+0.05y-0.02") and
/// DURATION a number of seconds with an optional "s" or "ms" suffix ("2s", "500ms").
/// Linear speeds above `max_linear_mps` and angular ones above `max_angular_radps` are refused.
/// @throws std::invalid_argument naming the step and what is wrong.
std::vector<ScriptStep> parse_script(const std::string& text, double max_linear_mps, double max_angular_radps);

/// The twist `t_s` seconds after the script started; nullopt once every step has run.
std::optional<Twist> script_twist_at(const std::vector<ScriptStep>& script, double t_s);

/// "x+0.05 y-0.02" style, or "stop" for the zero twist.
std::string describe(const Twist& twist);

}  // namespace rigger::ctl::jog
