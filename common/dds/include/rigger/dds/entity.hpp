#pragma once
/// @file
/// The one owner of a Cyclone DDS entity handle, and the one exception type for C API errors.

#include <stdexcept>
#include <string>

#include <dds/dds.h>

namespace rigger::dds {

/// A failed Cyclone DDS C API call: what was attempted and dds_strretcode's explanation.
class DdsError : public std::runtime_error {
 public:
  DdsError(const std::string& what, dds_return_t code);
  dds_return_t code() const { return code_; }

 private:
  dds_return_t code_;
};

/// Returns `rc` when it is not an error. @throws DdsError naming `what` otherwise.
dds_return_t check(dds_return_t rc, const char* what);

/// Move-only owner of a dds_entity_t: deletes it (and, as DDS does, its children) on destruction.
/// Destructors never throw. Not thread-safe itself; Cyclone entities are.
class Entity {
 public:
  Entity() = default;
  /// Takes ownership of `handle`. @throws DdsError when `handle` is an error code from a create call.
  Entity(dds_entity_t handle, const char* what);
  Entity(Entity&& other) noexcept;
  Entity& operator=(Entity&& other) noexcept;
  Entity(const Entity&) = delete;
  Entity& operator=(const Entity&) = delete;
  ~Entity();

  dds_entity_t handle() const { return handle_; }
  explicit operator bool() const { return handle_ > 0; }

 private:
  dds_entity_t handle_ = 0;
};

}  // namespace rigger::dds
