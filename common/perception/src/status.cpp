// The names of the localizer's statuses, as they travel in a TrackedPose's status.
#include "rigger/perception/localize.hpp"

namespace rigger::perception {

const char* to_string(LocalizeStatus status) {
  switch (status) {
    case LocalizeStatus::kFound:
      return "FOUND";
    case LocalizeStatus::kNotFound:
      return "NOT_FOUND";
    case LocalizeStatus::kAmbiguous:
      return "AMBIGUOUS";
    case LocalizeStatus::kLowFit:
      return "LOW_FIT";
    case LocalizeStatus::kBadDepth:
      return "BAD_DEPTH";
    case LocalizeStatus::kNoVisibleSurface:
      return "NO_VISIBLE_SURFACE";
    case LocalizeStatus::kBadMesh:
      return "BAD_MESH";
  }
  return "UNKNOWN";
}

}  // namespace rigger::perception
