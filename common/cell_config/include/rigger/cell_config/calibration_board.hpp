#pragma once
/// @file
/// The name a robot's calibration board (cell file key calibration_board) goes by outside the cell file:
/// the simulator's camera draws it, the tracker measures it and the calibration asks for it under this id.

#include <string>

namespace rigger::cell {

inline constexpr const char* kCalibrationBoardSuffix = "/calibration_board";

/// The id of the calibration board on `device_id`'s tool, e.g. "robot/calibration_board". No entity id
/// contains '/', so it names no entity.
inline std::string calibration_board_id(const std::string& device_id) {
  return device_id + kCalibrationBoardSuffix;
}

/// Whether `id` names a calibration board (calibration_board_id of some device).
inline bool is_calibration_board_id(const std::string& id) {
  const std::string suffix = kCalibrationBoardSuffix;
  return id.size() > suffix.size() && id.compare(id.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace rigger::cell
